#pragma once
// The stability sweep's case of a given name (the quick sweep's by default), for the tests that
// drive one themselves.

#include <string>

#include <catch2/catch.hpp>

#include <tubeplan/study/stability.hpp>

namespace tubeplan::testing {

inline study::StabilityCase SweepCase(const std::string& name, bool quick) {
  for (const study::StabilityCase& c : study::StabilityCases(quick))
    if (c.name == name) return c;
  FAIL("no stability case named " << name << (quick ? " in the quick sweep" : ""));
  return {};
}

inline study::StabilityCase QuickCase(const std::string& name) { return SweepCase(name, true); }

}  // namespace tubeplan::testing
