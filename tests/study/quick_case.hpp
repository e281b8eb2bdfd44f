#pragma once
// The stability sweep's quick case of a given name, for the tests that drive one themselves.

#include <string>

#include <catch2/catch.hpp>

#include <tubeplan/study/stability.hpp>

namespace tubeplan::testing {

inline study::StabilityCase QuickCase(const std::string& name) {
  for (const study::StabilityCase& c : study::StabilityCases(true))
    if (c.name == name) return c;
  FAIL("no stability case named " << name);
  return {};
}

}  // namespace tubeplan::testing
