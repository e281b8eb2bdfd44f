#pragma once
// What `tubeplan evaluate` does to a plan set before its report (docs/evaluate.md): every plan
// read and checked first (any problem: nothing is judged), then all judged on a pool of threads
// with SIGINT and SIGTERM deferred, so that a report covers the whole set or is not written.
#include <ostream>
#include <string>
#include <vector>

#include <tubeplan/batch/evaluate.hpp>
#include <tubeplan/batch/report.hpp>

namespace tubeplan::batch {

/// What an evaluation is asked.
struct EvaluationRequest {
  std::vector<std::string> inputs;  ///< plan files and directories of them
  std::string shard;                ///< "I/N", empty for all
  int jobs = 0;                     ///< threads, 0: the machine's cores
  int monte_carlo = 0;              ///< perturbed replicates per plan
  std::uint64_t seed = 1;
  std::string report_path;  ///< the JSON report's file, empty for none
  std::string html_path;    ///< the HTML report's file, empty for none
  bool progress = false;    ///< "[judged/plans]" on the error stream as plans are judged
};

/// The plan set, read, then judged.
struct Evaluation {
  PlanSet set;
  std::vector<io::PlanLoadResult> loaded;  ///< per plan of the set
  int jobs = 1;                            ///< threads (no more than plans)
  BatchResult judged;
};

/// Reads every plan of the set `request.inputs` names (its shard), and checks that no output
/// replaces an input. False after printing every problem found on `err`.
bool LoadEvaluation(const EvaluationRequest& request, Evaluation& evaluation, std::ostream& err);

enum class JudgedEnd {
  kAll,          ///< every plan judged
  kChanged,      ///< a trajectory file changed while it was replayed
  kInterrupted,  ///< a signal stopped the batch
};

/// Judges the plans read (each replay watched by `watch` when given) with SIGINT and SIGTERM
/// deferred; after it a signal ends the process, saying that no report was written. Unless every
/// plan was judged, says on `err` why no report is written.
JudgedEnd JudgeEvaluation(const EvaluationRequest& request, Evaluation& evaluation,
                          const std::function<plan::TickWatcher(std::size_t)>& watch,
                          std::ostream& err);

/// The JSON report's scope of a plan set (its identity, size and shard).
ReportScope ScopeOf(const PlanSet& set);

}  // namespace tubeplan::batch
