#pragma once
// What the live tests share: the shipped insertion plan, and the check that `evaluate` of a live
// run's recording gives the live run's verdicts (batch and live judge the same ticks).
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <tubeplan/io/plan_file.hpp>

#include "../cli/run_tool.hpp"
#include "cli/app.hpp"
#include "io/text_file.hpp"

namespace tubeplan::testing {

inline const io::PlanLoadResult& InsertPlan() {
  static const io::PlanLoadResult loaded = io::LoadPlanFile(SourcePath("plans/groove-insert.yaml"));
  return loaded;
}

/// `evaluate --json` of the insertion plan with `recording` for its trajectory (the plan written
/// to `plan_file`): its exit code and report.
struct Evaluated {
  int exit_code = -1;
  nlohmann::json report;
};
inline Evaluated EvaluateRecording(const std::filesystem::path& recording,
                                   const std::filesystem::path& plan_file) {
  plan::Plan p = *InsertPlan().plan;
  p.scene = SourcePath("scenes/groove.yaml");
  p.trajectory = recording.string();
  REQUIRE(io::WriteTextFileAtomically(plan_file, io::FormatPlanYaml(p)).empty());
  std::ostringstream out, err;
  const int code =
      cli::Run(std::vector<std::string>{"evaluate", plan_file.string(), "--json"}, out, err);
  INFO(err.str());
  return {code, nlohmann::json::parse(out.str())};
}

/// The live run's verdicts equal the batch replay's, to the bit: the replay steps the core with
/// the poses the live run gave it.
inline void CheckSameVerdicts(const nlohmann::json& live_report, const nlohmann::json& batch) {
  const nlohmann::json& a = live_report["plans"][0];
  const nlohmann::json& b = batch["plans"][0];
  CHECK(a["transitions"] == b["transitions"]);
  CHECK(a["observed"] == b["observed"]);
  CHECK(a["ticks"] == b["ticks"]);
  CHECK(a["feasible"] == b["feasible"]);
  CHECK(a["outcome"] == b["outcome"]);
  CHECK(a["stopped_early"] == b["stopped_early"]);
}

}  // namespace tubeplan::testing
