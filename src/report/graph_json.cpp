#include <cmath>
#include <vector>

#include <tubeplan/report/graph_json.hpp>

namespace tubeplan::report {
namespace {

nlohmann::json Pose(const Eigen::Isometry3d& X) {
  const Eigen::Quaterniond q(X.linear());
  const Eigen::Vector3d p = X.translation();
  return {{"p", {p.x(), p.y(), p.z()}}, {"q", {q.w(), q.x(), q.y(), q.z()}}};
}

nlohmann::json Ref(const graph::TickRef& r, double step_s) {
  nlohmann::json j = {{"motion", r.motion}, {"tick", r.tick}};
  if (r.substeps > 0) j["substeps"] = r.substeps, j["substep"] = r.substep;
  j["t_s"] = step_s * (r.substeps > 0 ? r.tick - 1 + r.substep : r.tick);
  return j;
}

}  // namespace

nlohmann::json GraphToJson(const graph::ContactGraph& g, const scene::Scene& s,
                           const std::string& scene_path, const graph::ExploreOptions& explore,
                           const graph::PruneWeights& weights) {
  const double T = s.model.time_step_s;
  nlohmann::json j;
  j["tubeplan_graph"] = kGraphJsonVersion;
  j["scene"] = scene_path;
  j["parameters"] = {
      {"seed", explore.seed},
      {"random_motions", explore.random_motions},
      {"closing_motions", explore.closing_motions},
      {"replay_copies", explore.replay_copies},
      {"replay_paths", explore.replay_paths},
      {"replay_offset_m", explore.replay_offset_m},
      {"budget", explore.max_motions},
      {"time_limit_s",
       explore.time_limit_s > 0.0 ? nlohmann::json(explore.time_limit_s) : nlohmann::json(nullptr)},
      {"probe_step_m", explore.probe_step_m},
      {"probe_turn_rad", explore.probe_turn_rad},
      {"push_N", explore.push_N},
      {"speed_m_per_s", explore.speed_m_per_s},
      {"substeps", explore.substeps},
      {"weights",
       {{"friction", weights.friction},
        {"energy", weights.energy},
        {"distance", weights.distance}}},
      {"tolerance", weights.tolerance}};
  j["start"] = g.start >= 0 ? nlohmann::json(g.nodes[std::size_t(g.start)].cf) : nullptr;
  j["goal"] = g.goal >= 0 ? nlohmann::json(g.nodes[std::size_t(g.goal)].cf) : nullptr;
  nlohmann::json nodes = nlohmann::json::array();
  for (const graph::Node& n : g.nodes) {
    nlohmann::json w = Ref(n.witness, T);
    w["hand"] = Pose(n.X_W_hand);
    w["held"] = Pose(n.X_WH);
    const nlohmann::json least =
        std::isfinite(n.min_force_N)
            ? nlohmann::json{{"hand", Pose(n.X_W_hand_least)}, {"held", Pose(n.X_WH_least)}}
            : nlohmann::json(nullptr);
    nodes.push_back({{"cf", n.cf},
                     {"pcs", n.pcs},
                     {"start", n.start},
                     {"goal", n.goal},
                     {"energy_J", n.energy_J},
                     {"friction_N", n.friction_N},
                     {"friction_limit_N", n.friction_limit_N},
                     {"force_N", n.force_N},
                     {"min_force_N", std::isfinite(n.min_force_N) ? nlohmann::json(n.min_force_N)
                                                                  : nlohmann::json(nullptr)},
                     {"least_force", least},
                     {"distance_m", n.distance_m >= 0.0 ? nlohmann::json(n.distance_m) : nullptr},
                     {"ticks", n.ticks},
                     {"from_replay", n.from_replay},
                     {"witness", w}});
  }
  j["nodes"] = nodes;
  nlohmann::json arcs = nlohmann::json::array();
  for (const graph::Arc& a : g.arcs) {
    arcs.push_back({{"from", g.nodes[std::size_t(a.from)].cf},
                    {"to", g.nodes[std::size_t(a.to)].cf},
                    {"kept", a.kept},
                    {"reason", a.reason},
                    {"count", a.count},
                    {"simultaneous", a.simultaneous},
                    {"batch", a.batch == graph::BatchResult::kFeasible     ? "feasible"
                              : a.batch == graph::BatchResult::kInfeasible ? "infeasible"
                                                                           : "untried"},
                    {"from_replay", a.from_replay},
                    {"witness", Ref(a.witness, T)}});
  }
  j["arcs"] = arcs;
  nlohmann::json curve = nlohmann::json::array();
  for (const graph::SaturationPoint& p : g.saturation)
    curve.push_back({p.motions, p.nodes, p.arcs});
  j["saturation"] = curve;
  j["elements"] = {{"reached", g.reached_elements}, {"unreached", g.unreached_elements}};
  // The moves of the motions a witness lies in, so that it can be replayed; of the others, the
  // kind (most closing rounds' motions found nothing new and would double the file).
  // (A state or transition seen only in an evaluate report's replays has no witness motion.)
  std::vector<bool> witnessed(g.motions.size(), false);
  const auto witness = [&](bool from_replay, const graph::TickRef& r) {
    if (!from_replay && r.motion >= 0 && std::size_t(r.motion) < witnessed.size())
      witnessed[std::size_t(r.motion)] = true;
  };
  for (const graph::Node& n : g.nodes) witness(n.from_replay, n.witness);
  for (const graph::Arc& a : g.arcs) witness(a.from_replay, a.witness);
  nlohmann::json motions = nlohmann::json::array();
  for (std::size_t i = 0; i < g.motions.size(); ++i) {
    const graph::Motion& m = g.motions[i];
    if (!witnessed[i]) {
      motions.push_back({{"kind", m.kind}});
      continue;
    }
    nlohmann::json moves = nlohmann::json::array();
    for (const graph::Move& mv : m.moves) {
      moves.push_back({{"p", {mv.p_W_m.x(), mv.p_W_m.y(), mv.p_W_m.z()}},
                       {"q", {mv.q_W.w(), mv.q_W.x(), mv.q_W.y(), mv.q_W.z()}},
                       {"speed_m_per_s", mv.speed_m_per_s},
                       {"turn_rad_per_s", mv.turn_rad_per_s}});
      if (mv.guard_N > 0.0) {
        moves.back()["guard_dir"] = {mv.guard_dir_W.x(), mv.guard_dir_W.y(), mv.guard_dir_W.z()};
        moves.back()["guard_N"] = mv.guard_N;
      }
      if (mv.relative) moves.back()["relative"] = true;
      if (mv.force_limit_N > 0.0) moves.back()["force_limit_N"] = mv.force_limit_N;
      if (mv.min_ticks > 0) moves.back()["min_ticks"] = mv.min_ticks;
      if (mv.max_ticks > 0) moves.back()["max_ticks"] = mv.max_ticks;
    }
    motions.push_back({{"kind", m.kind}, {"moves", moves}});
    if (m.prefix_ticks > 0) motions.back()["prefix_ticks"] = m.prefix_ticks;
  }
  j["motions"] = motions;
  j["stats"] = {{"motions", g.motions.size()},
                {"ticks", g.ticks},
                {"refinements", g.refinements},
                {"held_back", g.held_back},
                {"probed", g.probed},
                {"closing_rounds", g.closing_rounds},
                {"saturated", g.saturated},
                {"ended_by", g.end == graph::ExploreEnd::kSaturated ? "saturation"
                             : g.end == graph::ExploreEnd::kBudget  ? "budget"
                                                                    : "time_limit"},
                {"seconds", g.seconds},
                {"jobs", explore.jobs}};
  return j;
}

}  // namespace tubeplan::report
