#include <algorithm>
#include <iomanip>
#include <sstream>

#include <tubeplan/report/plans_report.hpp>

namespace tubeplan::report {
namespace {

// The candidates' first line: how many, of how many asked, through which graph, written where.
void PrintHeader(std::ostream& t, const batch::PlansRequest& request, const std::string& scene_name,
                 const graph::ContactGraph& g, const batch::Plans& plans) {
  const std::size_t paths = plans.paths.size();
  const bool motion = std::any_of(plans.candidates.begin(), plans.candidates.end(),
                                  [](const plan::Candidate& c) { return c.from_motion; });
  t << paths << " candidate plan" << (paths == 1 ? "" : "s") << " (of " << request.k
    << " asked) through the pruned graph of " << scene_name << " (" << g.nodes.size() << " CFs, "
    << std::count_if(g.arcs.begin(), g.arcs.end(), [](const auto& a) { return a.kept; })
    << " kept arcs)" << (motion ? " and the explorer's own motion to the goal" : "")
    << ", each replayed as `evaluate` would: " << plans.feasible << " feasible"
    << (request.all || plans.feasible == 0 || plans.feasible == long(plans.candidates.size())
            ? ""
            : " (the others are not written; --all writes them, marked)")
    << (request.all || plans.feasible > 0 ? "; written to " + plans.out_dir.string()
                                          : std::string("; none written"))
    << ":\n";
  // Fewer than asked: the pruned graph holds no more loopless paths to the goal.
  const std::string more = batch::ExploreMoreHint(g);
  if (static_cast<int>(paths) < request.k)
    t << "  (the pruned graph has no other loopless path from the start to the goal: a larger "
         "--tolerance keeps more arcs"
      << (more.empty() ? "" : ", " + more + " explores more states") << ")\n";
}

// One candidate's line: its name (or "(not written)"), cost, length, states and verdict.
void PrintCandidate(std::ostream& t, const plan::Candidate& c) {
  t << "  " << (c.plan.name.empty() ? "(not written)" : c.plan.name) << ": ";
  if (c.from_motion)
    t << "the explorer's motion to the goal";
  else
    t << "cost " << c.path.cost;
  const std::size_t transitions = c.plan.states.empty() ? 0 : c.plan.states.size() - 1;
  t << ", " << transitions << (transitions == 1 ? " transition, " : " transitions, ")
    << c.duration_s << " s:";
  for (const std::string& state : c.plan.states)
    t << " " << state << (&state == &c.plan.states.back() ? "" : " ->");
  t << "; " << plan::VerdictText(c) << "\n";
}

}  // namespace

void PrintPlans(std::ostream& out, const batch::PlansRequest& request,
                const std::string& scene_name, const graph::ContactGraph& graph,
                const batch::Plans& plans) {
  std::ostringstream t;
  t << std::setprecision(3);
  PrintHeader(t, request, scene_name, graph, plans);
  for (const plan::Candidate& c : plans.candidates) PrintCandidate(t, c);
  if (plans.feasible == 0) {
    const std::string more = batch::ExploreMoreHint(graph);
    t << "  no candidate replays feasible, each also tried at 1/2 and 1/4 of --speed: "
      << (more.empty() ? "" : more + " or ") << "a larger --tolerance may give one; --all writes "
      << "them for inspection\n";
  }
  out << t.str();
}

}  // namespace tubeplan::report
