#pragma once
// Judging a set of plan files as `tubeplan evaluate` does (docs/evaluate.md): the set named by
// files and directories, in one order on every machine, cut into shards; each plan replayed
// through the judge on a pool of threads, with its Monte Carlo replicates.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <tubeplan/io/plan_file.hpp>
#include <tubeplan/plan/judge.hpp>
#include <tubeplan/plan/plan.hpp>

namespace tubeplan::batch {

/// One judged plan.
struct Evaluated {
  std::string file;
  plan::Plan plan;
  plan::Judgement judgement;
  int runs = 0;             ///< Monte Carlo replicates
  std::vector<int> robust;  ///< per transition: replicates in which it was feasible
  double replayed_s = 0.0;  ///< trajectory time replayed, replicates included
  double run_s = 0.0;       ///< wall time of those replays
};

/// A set of plan files: one per file however it is named (`plans/x.yaml`, `./plans/x.yaml`, a
/// link to it; the first spelling given is kept), in the order of their canonical paths.
struct PlanSet {
  std::vector<std::string> files;      ///< as given
  std::vector<std::string> canonical;  ///< CanonicalPlanPath of each
  std::string id;                      ///< PlanSetId of the whole set
  long size = 0;                       ///< plans in the whole set (before SelectShard)
  int shard_index = 1, shard_count = 1;
};

/// The plan set named by `inputs`: files as given, directories' *.yaml files. A directory without
/// one is an error in `errors` ("DIR: error: ..."), and the others are still taken.
PlanSet CollectPlanSet(const std::vector<std::string>& inputs, std::vector<std::string>& errors);

/// Keeps shard `text` ("I/N", 1 <= I <= N) of `set`: the plans whose place in its order is I-1
/// modulo N, so that every machine splits a set alike. False with `error` for another text.
bool SelectShard(const std::string& text, PlanSet& set, std::string& error);

/// The identity of a plan set: 16 hex digits of FNV-1a over its plans' canonical paths (absolute,
/// symbolic links and "." resolved), sorted, each ended by a newline. Two spellings of one file
/// give one path, so the same set named another way has the same identity.
std::string PlanSetId(std::vector<std::string> canonical_paths);
/// The canonical path of a plan file as PlanSetId takes it (weakly canonical, absolute).
std::string CanonicalPlanPath(const std::string& path);

struct BatchOptions {
  int jobs = 1;  ///< threads, each with its own core
  /// Perturbed replicates per plan (trajectories::Perturb); needs trajectories loaded.
  int monte_carlo = 0;
  std::uint64_t seed = 1;
  /// The watcher of plan i's judged replay (an HTML report records it), or none.
  std::function<plan::TickWatcher(std::size_t)> watch;
  /// Called after each plan is judged, with how many are, from the thread that judged it.
  std::function<void(std::size_t)> judged;
};

struct BatchResult {
  std::vector<Evaluated> results;  ///< per plan, in order; those not judged are empty
  std::size_t judged = 0;          ///< plans judged, Monte Carlo included
  /// "FILE: error: ..." for each trajectory file rewritten during its replay (then no result).
  std::vector<std::string> changed;
  double wall_s = 0.0;
};

/// Judges the plans of `files` (each loaded, in `loaded`, without errors) on `options.jobs`
/// threads. A SIGINT or SIGTERM (io/interrupt.hpp) lets the plans under way finish and starts no
/// other: `judged` then falls short of the plans' count. The results are the same for any jobs.
BatchResult JudgeBatch(const std::vector<std::string>& files,
                       const std::vector<io::PlanLoadResult>& loaded, const BatchOptions& options);

}  // namespace tubeplan::batch
