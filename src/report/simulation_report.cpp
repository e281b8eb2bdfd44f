#include <algorithm>
#include <iomanip>
#include <sstream>

#include <tubeplan/report/series_format.hpp>
#include <tubeplan/report/simulation_report.hpp>
#include <tubeplan/states/contact_formation.hpp>

namespace tubeplan::report {

nlohmann::json SimulationJson(const batch::SimulationInput& input,
                              const batch::Simulated& simulated, const std::string& out_path) {
  const scene::Scene& s = *input.scene;
  const plan::Simulation& sum = simulated.run;
  nlohmann::json j;
  j["scene"] = input.scene_path;
  j["trajectory"] = input.trajectory_path;
  j["ticks"] = sum.tick_count;
  j["time_step_s"] = s.model.time_step_s;
  j["duration_s"] = sum.duration_s;
  j["elements"] = simulated.element_count;
  nlohmann::json v = nlohmann::json::array();
  for (const plan::Visit& visit : sum.visits) {
    v.push_back({{"t", visit.t_s}, {"cf", visit.cf}});
    if (visit.fault) v.back()["fault"] = true;
  }
  j["visits"] = v;
  j["final_cf"] = sum.final_cf;
  j["goal"] = states::ToString(s.goal);
  j["goal_reached"] = sum.final_cf == states::ToString(s.goal);
  j["peak_force_N"] = sum.peak_force_N;
  j["peak_force_t"] = sum.peak_force_t_s;
  j["peak_torque_Nm"] = sum.peak_torque_Nm;
  j["peak_strain"] = sum.peak_strain;
  j["peak_strain_t"] = sum.peak_strain_t_s;
  j["peak_energy_J"] = sum.peak_energy_J;
  j["warnings"] = simulated.strain_warning.empty()
                      ? nlohmann::json::array()
                      : nlohmann::json::array({simulated.strain_warning});
  nlohmann::json flags;
  for (int b = 0; b < core::kStepFlagCount; ++b)
    flags[std::string(FlagName(1u << b))] = sum.flag_ticks[std::size_t(b)];
  j["flag_ticks"] = flags;
  j["run_time_s"] = sum.core_s;
  j["mean_tick_us"] = 1e6 * sum.core_s / static_cast<double>(sum.tick_count);
  j["worst_tick_us"] = 1e6 * sum.worst_tick_s;
  if (!out_path.empty()) j["out"] = out_path;
  return j;
}

void PrintSimulation(std::ostream& out, const batch::SimulationInput& input,
                     const batch::Simulated& simulated, const std::string& out_path) {
  const scene::Scene& s = *input.scene;
  const plan::Simulation& sum = simulated.run;
  const std::vector<plan::Visit>& visits = sum.visits;
  std::ostringstream text;
  text << std::setprecision(4);
  text << input.scene_path << " + " << input.trajectory_path << ": " << sum.tick_count
       << " ticks of " << s.model.time_step_s * 1e3 << " ms (" << sum.duration_s << " s), "
       << simulated.element_count << " rod elements\n";
  text << "contact formations, in order (t = entry time):\n";
  const std::size_t shown = std::min<std::size_t>(visits.size(), 40);
  for (std::size_t i = 0; i < shown; ++i)
    text << "  t = " << std::setw(7) << visits[i].t_s << " s  " << visits[i].cf
         << (visits[i].fault ? "  (solver fault: the core held the tube still; not its state)" : "")
         << "\n";
  if (visits.size() > shown)
    text << "  ... " << visits.size() - shown << " more changes (the series in --out has all)\n";
  text << "final: " << sum.final_cf
       << (sum.final_cf == states::ToString(s.goal) ? " (the goal)" : "") << "\n";
  text << "peak force " << sum.peak_force_N << " N at t = " << sum.peak_force_t_s
       << " s; peak torque " << sum.peak_torque_Nm << " N m; peak strain " << sum.peak_strain
       << " at t = " << sum.peak_strain_t_s << " s; peak bending energy " << sum.peak_energy_J
       << " J\n";
  if (!simulated.strain_warning.empty()) text << "warning: " << simulated.strain_warning << "\n";
  text << "ticks flagged:";
  bool any = false;
  for (int b = 0; b < core::kStepFlagCount; ++b)
    if (sum.flag_ticks[std::size_t(b)] > 0) {
      text << " " << FlagName(1u << b) << " " << sum.flag_ticks[std::size_t(b)];
      any = true;
    }
  text << (any ? "" : " none") << "\n";
  text << "core run time " << sum.core_s * 1e3 << " ms: mean "
       << 1e6 * sum.core_s / static_cast<double>(sum.tick_count) << " us per tick, worst "
       << 1e6 * sum.worst_tick_s << " us\n";
  if (!out_path.empty()) text << "series written to " << out_path << "\n";
  out << text.str();
}

}  // namespace tubeplan::report
