// `tubeplan merge`: the report of shards 1..N of one plan set, each once, is the unsharded
// report; anything else (a shard missing or given twice, shards of another split or of another
// plan set) is refused with a message that says which.
#include <filesystem>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "../scratch.hpp"
#include "run_tool.hpp"

namespace {

using namespace tubeplan;
using testing::RunTool;
using testing::SourcePath;

// A shard report as `evaluate --shard I/N --report` writes it, with one feasible plan per file.
std::string Shard(const std::string& name, const std::string& set, long set_plans, int index,
                  int count, const std::vector<std::string>& files, int version = 3) {
  nlohmann::json plans = nlohmann::json::array();
  for (const std::string& f : files)
    plans.push_back(
        {{"plan", f}, {"file", f}, {"feasible", true}, {"transitions", nlohmann::json::array()}});
  nlohmann::json report = {{"tubeplan_evaluate", version},
                           {"plan_set", {{"id", set}, {"plans", set_plans}}},
                           {"shard", {{"index", index}, {"count", count}}},
                           {"plans", plans},
                           {"summary", {{"plans", files.size()}}}};
  return testing::WriteScratch("merge", name, report.dump());
}

}  // namespace

TEST_CASE("merge: exactly shards 1..N of one plan set, each once", "[cli][merge]") {
  const std::string a = Shard("a.json", "set1", 3, 1, 3, {"p1.yaml"});
  const std::string b = Shard("b.json", "set1", 3, 2, 3, {"p2.yaml"});
  const std::string c = Shard("c.json", "set1", 3, 3, 3, {"p3.yaml"});
  SECTION("complete: merged, and the merge is shard 1 of 1 of the same set") {
    const testing::Outcome r = RunTool({"merge", c, a, b, "--json"});
    INFO(r.err);
    REQUIRE(r.exit_code == 0);
    const nlohmann::json merged = nlohmann::json::parse(r.out);
    CHECK(merged["summary"]["plans"] == 3);
    CHECK(merged["plan_set"] == nlohmann::json({{"id", "set1"}, {"plans", 3}}));
    CHECK(merged["shard"] == nlohmann::json({{"index", 1}, {"count", 1}}));
  }
  SECTION("a shard missing") {
    const testing::Outcome r = RunTool({"merge", a, b});
    CHECK(r.exit_code == 2);
    CHECK(r.out.empty());
    CHECK(r.err ==
          "tubeplan merge: error: shard 3/3 of plan set set1 (3 plans) is missing, expected all "
          "3 shards\n");
  }
  SECTION("several missing") {
    const testing::Outcome r = RunTool({"merge", b});
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("shards 1/3 and 3/3 of plan set set1 (3 plans) are missing") !=
          std::string::npos);
  }
  SECTION("a shard twice") {
    const std::string again = Shard("b-again.json", "set1", 3, 2, 3, {"p2.yaml"});
    const testing::Outcome r = RunTool({"merge", a, b, again, c});
    CHECK(r.exit_code == 2);
    CHECK(r.err ==
          again + ": error: shard 2/3 is given twice (also " + b + "), expected each shard once\n");
  }
  SECTION("shards of two splits of the set") {
    const std::string half = Shard("half.json", "set1", 3, 2, 2, {"p2.yaml"});
    const testing::Outcome r = RunTool({"merge", half, c});
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(c +
                     ": error: shard 3/3 of plan set set1 (3 plans) is from a split into 3 "
                     "shards, but " +
                     half + " from one into 2") != std::string::npos);
  }
  SECTION("a shard of another plan set") {
    const std::string other = Shard("other.json", "set2", 3, 3, 3, {"q3.yaml"});
    const testing::Outcome r = RunTool({"merge", a, b, other});
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(other +
                     ": error: shard 3/3 of plan set set2 (3 plans) is from another plan "
                     "set than " +
                     a) != std::string::npos);
  }
  SECTION("shards that do not hold their set's plans") {
    const std::string short_c = Shard("short.json", "set1", 3, 3, 3, {});
    const testing::Outcome r = RunTool({"merge", a, b, short_c});
    CHECK(r.exit_code == 2);
    CHECK(r.err.find("the 3 shards hold 2 plans, but their plan set set1 has 3") !=
          std::string::npos);
  }
  SECTION("a report that does not say its shard") {
    const std::string old = Shard("old.json", "set1", 3, 3, 3, {"p3.yaml"}, 1);
    const testing::Outcome r = RunTool({"merge", a, b, old});
    CHECK(r.exit_code == 2);
    CHECK(r.err.find(old + ": error: a report of version 1, which does not say which shard of "
                           "which plan set it holds") != std::string::npos);
  }
  std::filesystem::remove_all(testing::ScratchDir("merge"));
}

TEST_CASE("evaluate: one plan however it is named, and the same plan set", "[cli][merge]") {
  // The same file by two spellings is one plan; the set named by a directory or its files, in
  // any spelling, has one identity, so shards made either way merge.
  const std::string plan = SourcePath("plans/groove-lay-flat.yaml");
  const std::string dotted = SourcePath("plans/./../plans/groove-lay-flat.yaml");
  const testing::Outcome both = RunTool({"evaluate", plan, dotted, "--json"});
  INFO(both.err);
  REQUIRE(both.exit_code <= 1);
  const nlohmann::json report = nlohmann::json::parse(both.out);
  CHECK(report["summary"]["plans"] == 1);
  CHECK(report["plan_set"]["plans"] == 1);
  const testing::Outcome one = RunTool({"evaluate", dotted, "--json"});
  REQUIRE(one.exit_code <= 1);
  CHECK(nlohmann::json::parse(one.out)["plan_set"] == report["plan_set"]);
}
