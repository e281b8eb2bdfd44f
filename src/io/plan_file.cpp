#include <charconv>
#include <cstdio>
#include <sstream>

#include <tubeplan/io/plan_file.hpp>

namespace tubeplan::io {

namespace {

// A YAML double-quoted scalar (CF texts contain braces and commas).
std::string Quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string Number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", value);
  return buffer;
}

}  // namespace

std::string FormatPlanYaml(const plan::Plan& p) {
  std::ostringstream out;
  std::istringstream comment(p.comment);
  for (std::string line; std::getline(comment, line);) out << "# " << line << "\n";
  out << "tubeplan: 1\n";
  out << "plan: " << Quoted(p.name) << "\n";
  out << "scene: " << Quoted(p.scene) << "\n";
  out << "trajectory: " << Quoted(p.trajectory) << "\n";
  out << "states:\n";
  for (const std::string& s : p.states) out << "  - " << Quoted(s) << "\n";
  const plan::Limits& l = p.limits;
  out << "limits: {max_force: " << Number(l.max_force_N)
      << " N, max_strain: " << Number(l.max_strain)
      << ", max_penetration: " << Number(l.max_penetration_m * 1e3)
      << " mm, dwell: " << Number(l.dwell_s * 1e3) << " ms, stall: " << Number(l.stall_s)
      << " s}\n";
  return out.str();
}

std::string TrajectoryCsvHeader(const std::string& device, double nominal_rate_Hz,
                                const std::vector<std::string>& extra_columns) {
  std::string out;
  if (!device.empty()) out += "# device: " + device + "\n";
  if (nominal_rate_Hz > 0.0) out += "# rate: " + Number(nominal_rate_Hz) + " Hz\n";
  out += "# units: m\n";
  out += "t,px,py,pz,qw,qx,qy,qz";
  for (const std::string& c : extra_columns) out += "," + c;
  out += "\n";
  return out;
}

std::string TrajectoryCsvStopped(const std::string& stopped_early) {
  return "# stopped: " + stopped_early + "\n";
}

void AppendTrajectoryCsvRow(std::string& out, const trajectories::HandSample& s,
                            std::string_view extra_fields) {
  char t[32];
  const auto [end, ec] = std::to_chars(t, t + sizeof t, s.t_s);  // shortest round trip
  out.append(t, ec == std::errc() ? end : t);
  char row[192];
  std::snprintf(row, sizeof row, ",%.9f,%.9f,%.9f,%.9f,%.9f,%.9f,%.9f", s.p_WH_m.x(), s.p_WH_m.y(),
                s.p_WH_m.z(), s.q_WH.w(), s.q_WH.x(), s.q_WH.y(), s.q_WH.z());
  out += row;
  if (!extra_fields.empty()) out.append(",").append(extra_fields);
  out += '\n';
}

std::optional<trajectories::Trajectory> TrajectoryAsWritten(
    const trajectories::Trajectory& trajectory) {
  TrajectoryLoadResult read = LoadTrajectoryText(FormatTrajectoryCsv(trajectory), "candidate");
  return std::move(read.trajectory);
}

std::string FormatTrajectoryCsv(const trajectories::Trajectory& t) {
  std::string out = TrajectoryCsvHeader(t.device, t.nominal_rate_Hz);
  char row[192];
  for (const trajectories::HandSample& s : t.samples) {
    std::snprintf(row, sizeof row, "%.6f,%.9f,%.9f,%.9f,%.9f,%.9f,%.9f,%.9f\n", s.t_s, s.p_WH_m.x(),
                  s.p_WH_m.y(), s.p_WH_m.z(), s.q_WH.w(), s.q_WH.x(), s.q_WH.y(), s.q_WH.z());
    out += row;
  }
  if (!t.stopped_early.empty()) out += TrajectoryCsvStopped(t.stopped_early);
  return out;
}

}  // namespace tubeplan::io
