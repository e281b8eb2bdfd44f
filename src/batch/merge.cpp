#include <map>
#include <set>
#include <sstream>

#include <tubeplan/batch/merge.hpp>
#include <tubeplan/batch/report.hpp>

#include "io/text_file.hpp"

namespace tubeplan::batch {
namespace {

// One shard report as merge reads it.
struct ShardReport {
  std::string path;
  ReportScope scope;
  nlohmann::json plans;
};

// The report at `path`, or nullopt after saying why it is not one merge can take.
std::optional<ShardReport> ReadShardReport(const std::string& path,
                                           std::vector<std::string>& errors) {
  std::ostringstream err;
  const std::optional<std::string> text = io::ReadTextFile(path);
  nlohmann::json report;
  if (text) report = nlohmann::json::parse(*text, nullptr, /*allow_exceptions=*/false);
  if (!text || report.is_discarded() || !report.is_object() ||
      !report.value("tubeplan_evaluate", nlohmann::json()).is_number_integer()) {
    err << path
        << ": error: not a tubeplan evaluate report, expected the JSON that "
           "`tubeplan evaluate --report` writes (version "
        << kEvaluateJsonVersion << ")";
    errors.push_back(err.str());
    return std::nullopt;
  }
  const int version = report["tubeplan_evaluate"].get<int>();
  if (version != kEvaluateJsonVersion) {
    err << path << ": error: a report of version " << version
        << (version < 2 ? ", which does not say which shard of which plan set it holds; expected "
                          "version "
            : version < kEvaluateJsonVersion ? ", made by an earlier core; expected version "
                                             : ", expected version ")
        << kEvaluateJsonVersion << ": evaluate the shard again with this tubeplan";
    errors.push_back(err.str());
    return std::nullopt;
  }
  const nlohmann::json set = report.value("plan_set", nlohmann::json());
  const nlohmann::json shard = report.value("shard", nlohmann::json());
  const bool scoped = set.is_object() && set.value("id", nlohmann::json()).is_string() &&
                      set.value("plans", nlohmann::json()).is_number_integer() &&
                      set["plans"].get<long>() >= 0 && shard.is_object() &&
                      shard.value("index", nlohmann::json()).is_number_integer() &&
                      shard.value("count", nlohmann::json()).is_number_integer() &&
                      shard["count"].get<long>() >= 1 && shard["index"].get<long>() >= 1 &&
                      shard["index"].get<long>() <= shard["count"].get<long>() &&
                      shard["count"].get<long>() <= 1000000;
  if (!scoped || !report.contains("plans") || !report["plans"].is_array()) {
    err << path
        << ": error: a report without a readable \"plan_set\" {id, plans}, \"shard\" {index, "
           "count} or \"plans\", expected the JSON that `tubeplan evaluate --report` writes";
    errors.push_back(err.str());
    return std::nullopt;
  }
  ShardReport r;
  r.path = path;
  r.scope.plan_set_id = set["id"].get<std::string>();
  r.scope.plan_set_plans = set["plans"].get<long>();
  r.scope.shard_index = shard["index"].get<int>();
  r.scope.shard_count = shard["count"].get<int>();
  r.plans = report["plans"];
  return r;
}

std::string ShardText(const ReportScope& s) {
  return std::to_string(s.shard_index) + "/" + std::to_string(s.shard_count);
}

// "3/8" or "3/8, 5/8 and 6/8".
std::string ShardList(const std::vector<int>& indices, int count) {
  std::string text;
  for (std::size_t i = 0; i < indices.size(); ++i) {
    if (i > 0) text += i + 1 == indices.size() ? " and " : ", ";
    text += std::to_string(indices[i]) + "/" + std::to_string(count);
  }
  return text;
}

// Shards 1..N of one plan set, each once (the first report names the set and N); says every
// report that is not one of them.
bool OneSplit(const std::vector<ShardReport>& shards, std::map<int, const ShardReport*>& by_index,
              std::vector<std::string>& errors) {
  const ShardReport& first = shards.front();
  bool ok = true;
  for (const ShardReport& r : shards) {
    const std::string what = "shard " + ShardText(r.scope) + " of plan set " + r.scope.plan_set_id +
                             " (" + std::to_string(r.scope.plan_set_plans) + " plans)";
    std::ostringstream err;
    if (r.scope.plan_set_id != first.scope.plan_set_id ||
        r.scope.plan_set_plans != first.scope.plan_set_plans) {
      err << r.path << ": error: " << what << " is from another plan set than " << first.path
          << " (plan set " << first.scope.plan_set_id << ", " << first.scope.plan_set_plans
          << " plans), expected the shards of one `tubeplan evaluate` plan set";
    } else if (r.scope.shard_count != first.scope.shard_count) {
      err << r.path << ": error: " << what << " is from a split into " << r.scope.shard_count
          << " shards, but " << first.path << " from one into " << first.scope.shard_count
          << ", expected the shards of one split (--shard I/" << first.scope.shard_count << ")";
    } else if (const auto [it, inserted] = by_index.emplace(r.scope.shard_index, &r); !inserted) {
      err << r.path << ": error: shard " << ShardText(r.scope) << " is given twice (also "
          << it->second->path << "), expected each shard once";
    }
    if (err.tellp() > 0) {
      errors.push_back(err.str());
      ok = false;
    }
  }
  if (!ok) return false;
  const int count = first.scope.shard_count;
  std::vector<int> missing;
  for (int i = 1; i <= count; ++i)
    if (!by_index.contains(i)) missing.push_back(i);
  if (missing.empty()) return true;
  std::ostringstream err;
  err << "tubeplan merge: error: shard" << (missing.size() == 1 ? " " : "s ")
      << ShardList(missing, count) << " of plan set " << first.scope.plan_set_id << " ("
      << first.scope.plan_set_plans << " plans) " << (missing.size() == 1 ? "is" : "are")
      << " missing, expected all " << count << " shards";
  errors.push_back(err.str());
  return false;
}

// The shards' plans, each plan once and every plan of the set; says every one that is not.
bool CollectPlans(const std::map<int, const ShardReport*>& by_index, nlohmann::json& plans,
                  std::vector<std::string>& errors) {
  const ReportScope& scope = by_index.begin()->second->scope;
  bool ok = true;
  std::set<std::string> files;
  for (const auto& [index, r] : by_index) {
    for (const nlohmann::json& p : r->plans) {
      if (!p.is_object() || !p.contains("file") || !p["file"].is_string() ||
          !p.contains("feasible") || !p["feasible"].is_boolean()) {
        errors.push_back(r->path +
                         ": error: a plan without \"file\" or \"feasible\", expected the "
                         "entries `tubeplan evaluate` writes");
        ok = false;
        continue;
      }
      if (!files.insert(p["file"].get<std::string>()).second) {
        errors.push_back(r->path + ": error: plan " + p["file"].dump() +
                         " is in two reports, expected disjoint shards");
        ok = false;
      }
      plans.push_back(p);
    }
  }
  if (ok && static_cast<long>(plans.size()) != scope.plan_set_plans) {
    std::ostringstream err;
    err << "tubeplan merge: error: the " << scope.shard_count << " shards hold " << plans.size()
        << " plans, but their plan set " << scope.plan_set_id << " has " << scope.plan_set_plans
        << ", expected reports as `tubeplan evaluate` wrote them";
    errors.push_back(err.str());
    ok = false;
  }
  return ok;
}

}  // namespace

std::optional<nlohmann::json> MergeShardReports(const std::vector<std::string>& paths,
                                                std::vector<std::string>& errors) {
  // Every report is read and checked first; every problem is said, then nothing is merged.
  std::vector<ShardReport> shards;
  for (const std::string& path : paths)
    if (std::optional<ShardReport> r = ReadShardReport(path, errors))
      shards.push_back(std::move(*r));
  if (shards.size() != paths.size() || shards.empty()) return std::nullopt;
  std::map<int, const ShardReport*> by_index;
  if (!OneSplit(shards, by_index, errors)) return std::nullopt;
  nlohmann::json plans = nlohmann::json::array();
  if (!CollectPlans(by_index, plans, errors)) return std::nullopt;
  ReportScope whole = shards.front().scope;
  whole.shard_index = whole.shard_count = 1;
  return Report(std::move(plans), whole);
}

}  // namespace tubeplan::batch
