#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <sstream>
#include <utility>

#include <tubeplan/report/accuracy_report.hpp>
#include <tubeplan/report/svg_plot.hpp>

namespace tubeplan::report {
namespace {

// A figure, or null when it is not finite.
nlohmann::json Number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

// A relative error or time in two-digit scientific notation, "n/a" when it is not finite.
std::string Sci(double v) {
  if (!std::isfinite(v)) return "n/a";
  std::ostringstream s;
  s << std::setprecision(2) << std::scientific << v;
  return s.str();
}

}  // namespace

nlohmann::json AccuracyJson(const study::AccuracyReport& r) {
  nlohmann::json rows = nlohmann::json::array();
  for (const study::AccuracyRow& row : r.rows)
    rows.push_back({{"setting", row.setting},
                    {"scenario", row.scenario},
                    {"error", Number(row.error)},
                    {"time_us", Number(row.time_us)},
                    {"metric", row.metric},
                    {"detail", row.detail},
                    {"default", row.is_default}});
  nlohmann::json convergence = nlohmann::json::array();
  for (const study::ConvergenceStudy& c : r.convergence)
    convergence.push_back({{"problem", c.problem},
                           {"quantity", c.quantity},
                           {"against", c.against},
                           {"segments", c.segments},
                           {"value", c.value},
                           {"error", c.error},
                           {"order", c.order},
                           {"time_ms", c.time_ms}});
  nlohmann::json scenarios = nlohmann::json::array();
  for (const study::ScenarioReference& s : r.references)
    scenarios.push_back({{"scenario", s.scenario},
                         {"contact", s.contact},
                         {"segments", s.segments},
                         {"hand_m", s.step},
                         {"force_x_N", s.force_x_N},
                         {"force_z_N", s.force_z_N},
                         {"tip_x_m", s.tip_x_m},
                         {"tip_z_m", s.tip_z_m},
                         {"uncertainty", s.uncertainty},
                         {"time_ms_per_solve", s.time_ms}});
  return {{"scene", r.scene},
          {"elements", r.elements},
          {"rows", rows},
          {"references",
           {{"tip_loads",
             "exact elastica (closed form, model/elastica) for the linear model; "
             "the reference rod (Richardson, N/2 and N) for the elastica"},
            {"contact_scenarios", scenarios},
            {"convergence", convergence}}},
          {"notes", r.notes}};
}

void PrintAccuracy(std::ostream& out, const study::AccuracyReport& r) {
  out << "accuracy of " << r.scene << " (the tube as " << r.elements << " rod elements)\n\n";
  out << "reference rod convergence:\n";
  for (const study::ConvergenceStudy& c : r.convergence) {
    out << "  " << c.problem << ", " << c.quantity << ", error against " << c.against << ":\n";
    for (std::size_t i = 0; i < c.segments.size(); ++i) {
      out << "    N=" << std::setw(4) << c.segments[i] << "  " << std::setprecision(10)
          << c.value[i] << "  error " << Sci(c.error[i]);
      if (i >= 1 && i - 1 < c.order.size())
        out << "  order " << std::fixed << std::setprecision(2) << c.order[i - 1]
            << std::defaultfloat;
      out << "  " << std::setprecision(3) << c.time_ms[i] << " ms\n";
    }
  }
  out << "\n";
  std::size_t w_setting = 7, w_scenario = 8;
  for (const study::AccuracyRow& row : r.rows) {
    w_setting = std::max(w_setting, row.setting.size() + 2);
    w_scenario = std::max(w_scenario, row.scenario.size());
  }
  out << std::left << std::setw(int(w_setting)) << "setting"
      << "  " << std::setw(int(w_scenario)) << "scenario"
      << "  " << std::right << std::setw(9) << "error"
      << "  " << std::setw(9) << "time_us"
      << "  detail\n";
  for (const study::AccuracyRow& row : r.rows) {
    out << std::left << std::setw(int(w_setting)) << (row.setting + (row.is_default ? " *" : ""))
        << "  " << std::setw(int(w_scenario)) << row.scenario << "  " << std::right << std::setw(9)
        << Sci(row.error) << "  " << std::setw(9) << std::setprecision(3) << row.time_us << "  "
        << row.detail << "\n";
  }
  out << "\n* the scene's own setting. error: tip loads, relative tip displacement; contact "
         "scenarios, largest operator-force error over the load steps relative to the largest "
         "reference force. time: per solve (tip loads) or per core tick (contact scenarios).\n";
  for (const std::string& n : r.notes) out << "note: " << n << "\n";
}

std::string AccuracySvg(const study::AccuracyReport& r) {
  // One marker per setting: its worst error over the contact scenarios against its mean tick time
  // (the tip-load rows are per solve, a different unit of time, so they are not mixed in).
  std::map<std::string, std::pair<double, double>> by_setting;  // worst error, summed time
  std::map<std::string, int> count;
  for (const study::AccuracyRow& row : r.rows) {
    if (row.scenario.rfind("tip load", 0) == 0) continue;
    auto& [err, time] = by_setting[row.setting];
    err = std::max(err, std::isfinite(row.error) ? row.error : 0.0);
    time += row.time_us;
    ++count[row.setting];
  }
  ScatterPlot plot;
  plot.title = "tubeplan accuracy: " + r.scene + " (worst error over the contact scenarios)";
  plot.x_label = "core tick, mean over the scenarios [us]";
  plot.y_label = "relative error of the operator force";
  PlotSeries same{"vs same contact law", "", {}};
  PlotSeries rigid{"vs hard contact", "", {}};
  for (const auto& [setting, v] : by_setting) {
    const bool is_rigid =
        setting.find("K=") != std::string::npos && setting.find("eps=") != std::string::npos;
    (is_rigid ? rigid : same).points.push_back({v.second / count[setting], v.first, setting});
  }
  plot.series = {same, rigid};
  return RenderSvg(plot);
}

}  // namespace tubeplan::report
