// The stability sweep (issue 7), one test per case class at quick sizes. Each test runs the
// case through core::Core::Step twice and checks it tick by tick (study/stability.cpp). Where the
// core fails a check today, the test is tagged [!mayfail] and names the defect: the sweep reports
// it honestly and the core's engineer fixes it; the test then passes without a change here.
#include <sstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <tubeplan/cli/app.hpp>
#include <tubeplan/study/stability.hpp>

using namespace tubeplan;

namespace {

study::StabilityResult RunNamed(const std::string& name) {
  for (const study::StabilityCase& c : study::StabilityCases(true))
    if (c.name == name) return study::RunStabilityCase(c);
  FAIL("no case named " << name);
  return {};
}

}  // namespace

TEST_CASE("Stability: push into a wall, steel-stiff tube (E = 200 GPa)", "[stability]") {
  const study::StabilityResult r = RunNamed("push into a wall E=2e+11Pa");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
}

TEST_CASE(
    "Stability: push into a wall, the shipped rubber tube (core defect: driven into the "
    "wall)",
    "[stability][!mayfail]") {
  // Core defect: pressed at the device's force the rubber tube buckles and its axis ends 4 mm
  // inside the wall (tick 214 at quick size); the penalty allows 0.85 mm at 8.5 N.
  const study::StabilityResult r = RunNamed("push into a wall base");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
}

TEST_CASE("Stability: strain beyond the linear-elastic range is reported, not accepted",
          "[stability]") {
  const study::StabilityResult r = RunNamed("push into a wall E=100000Pa");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.warning.find("beyond the linear-elastic") != std::string::npos);
}

TEST_CASE("Stability: a stub (l/r1 = 2) is reported outside the model's validity", "[stability]") {
  const study::StabilityResult r = RunNamed("slide along a wall l/r1=2");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
  CHECK(r.warning.find("l/r1 = 2 < 10") != std::string::npos);
}

TEST_CASE("Stability: fast pass through a 1 mm wall at 2 m/s, steel-stiff tube", "[stability]") {
  const study::StabilityResult r = RunNamed("fast pass E=2e+11Pa");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
}

TEST_CASE("Stability: every case gives finite outputs and the same bits twice", "[stability]") {
  // The safety checks that hold for every case today, whatever else fails.
  for (const study::StabilityCase& c : study::StabilityCases(true)) {
    const study::StabilityResult r = study::RunStabilityCase(c);
    INFO(r.name << ": " << r.detail);
    CHECK(r.detail.find("finite outputs") == std::string::npos);
    CHECK(r.detail.find("same bits") == std::string::npos);
  }
}

TEST_CASE("Stability: fast pass at 2 m/s, rubber tube (core defect: tunnels through 1 mm)",
          "[stability][!mayfail]") {
  // Core defect: no sub-stepping or continuous collision; the tip is beyond the wall at tick 6.
  const study::StabilityResult r = RunNamed("fast pass base");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
  CHECK(r.warning.find("tunnelling") == std::string::npos);
}

TEST_CASE("Stability: slide along a wall (core defect: energy created at first contact)",
          "[stability][!mayfail]") {
  const study::StabilityResult r = RunNamed("slide along a wall base");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
}

TEST_CASE("Stability: roll over an edge (core defect: energy created as the side meets the edge)",
          "[stability][!mayfail]") {
  const study::StabilityResult r = RunNamed("roll over an edge base");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
}

TEST_CASE("Stability: squeeze between walls (core defect: operator force beyond the device's)",
          "[stability][!mayfail]") {
  const study::StabilityResult r = RunNamed("squeeze between walls base");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
}

TEST_CASE("tubeplan stability --json: one document, a failing case exits 1", "[stability][cli]") {
  const auto run = [](std::vector<std::string> args, std::string& out_text) {
    std::ostringstream out, err;
    const int code = cli::Run(args, out, err);
    out_text = out.str();
    return code;
  };
  std::string text;
  CHECK(run({"stability", "--quick", "--json", "--only", "push into a wall E=2e+11Pa"}, text) == 0);
  const nlohmann::json j = nlohmann::json::parse(text);
  REQUIRE(j["cases"].size() == 1);
  CHECK(j["cases"][0]["name"] == "push into a wall E=2e+11Pa");
  CHECK(j["cases"][0]["pass"] == true);
  // The squeeze fails today (the operator's force exceeds the device's): exit code 1.
  CHECK(run({"stability", "--quick", "--only", "squeeze between walls base"}, text) == 1);
  CHECK(text.find("FAIL @") != std::string::npos);
}
