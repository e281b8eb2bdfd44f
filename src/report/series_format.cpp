#include <array>
#include <cstdio>

#include <nlohmann/json.hpp>

#include <tubeplan/report/series_format.hpp>

#include "io/text_file.hpp"

namespace tubeplan::report {
namespace {

// The series' text held before it is written to the file.
constexpr std::size_t kSeriesChunkBytes = std::size_t{1} << 20;

// 17 significant digits: a double read back is the double written (the series is for analysis,
// and the determinism check compares bits).
void AppendNumber(std::string& s, double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.17g", v);
  s += buffer;
}

std::string FlagsText(std::uint32_t flags) {
  std::string text;
  for (int b = 0; b < core::kStepFlagCount; ++b) {
    if ((flags & (1u << b)) == 0) continue;
    if (!text.empty()) text += '|';
    text += FlagName(1u << b);
  }
  return text;
}

std::string PcText(const core::Core& core, const core::ContactState& pc) {
  return std::string(states::ToString(pc.tube)) + " " + std::string(states::ToString(pc.marker)) +
         " " + core.elements()[std::size_t(pc.part_element)].name;
}

// A PC's friction: none where nothing can hold it (a frictionless part: its limit is 0).
const char* FrictionState(const core::ContactState& pc) {
  if (!(pc.friction_limit_N > 0.0)) return "none";
  return pc.sliding ? "sliding" : "stuck";
}

void AppendPose(std::string& s, const Eigen::Isometry3d& X) {
  const Eigen::Quaterniond q(X.linear());
  for (double v : {X.translation().x(), X.translation().y(), X.translation().z(), q.w(), q.x(),
                   q.y(), q.z()}) {
    s += ',';
    AppendNumber(s, v);
  }
}

}  // namespace

std::optional<SeriesFormat> SeriesFormatOf(const std::string& path, std::string& error) {
  if (path.empty()) return SeriesFormat::kNone;
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".csv") return SeriesFormat::kCsv;
  if (ext == ".jsonl") return SeriesFormat::kJsonLines;
  error = "unknown output format \"" + ext + "\", expected a file name ending in .csv or .jsonl";
  return std::nullopt;
}

std::string_view FlagName(std::uint32_t bit) {
  switch (bit) {
    case core::kForceClamped:
      return "clamped";
    case core::kPenetration:
      return "penetration";
    case core::kProxySeparated:
      return "separated";
    case core::kContactsTruncated:
      return "truncated";
    case core::kNotConverged:
      return "unconverged";
    case core::kSolverFault:
      return "fault";
    case core::kBeyondLinearRange:
      return "beyond_linear";
    case core::kBuckled:
      return "buckled";
    default:
      return "unknown";
  }
}

SeriesWriter::SeriesWriter(SeriesFormat format, bool mesh) : format_(format), mesh_(mesh) {
  if (format_ != SeriesFormat::kCsv) return;
  text_ =
      "t,hand_px,hand_py,hand_pz,hand_qw,hand_qx,hand_qy,hand_qz,held_px,held_py,held_pz,held_qw,"
      "held_qx,held_qy,held_qz,fx,fy,fz,tx,ty,tz,cf,energy,strain,tip_deflection,flags,n_pc";
  for (int k = 1; k <= core::kMaxContacts; ++k) {
    const std::string p = "pc" + std::to_string(k);
    text_ += "," + p + "," + p + "_s," + p + "_depth," + p + "_normal," + p + "_friction," + p +
             "_limit," + p + "_state," + p + "_work";
  }
  if (mesh_)
    for (int k = 0; k < kMeshPoints; ++k) {
      const std::string c = "c" + std::to_string(k);
      text_ += "," + c + "_x," + c + "_y," + c + "_z";
    }
  text_ += '\n';
}

void SeriesWriter::Add(const core::Core& core, const core::StepOutput& out,
                       const std::string& cf_text) {
  if (format_ == SeriesFormat::kNone) return;
  const double eps = core.scene().contact.threshold_m;
  std::array<Eigen::Vector3d, kMeshPoints> centreline;
  if (mesh_) core.Centreline(centreline);
  if (format_ == SeriesFormat::kCsv) {
    std::string& s = text_;
    AppendNumber(s, out.t_s);
    AppendPose(s, out.X_W_hand);
    AppendPose(s, out.X_WH);
    for (double v : {out.force_W_N.x(), out.force_W_N.y(), out.force_W_N.z(), out.torque_W_Nm.x(),
                     out.torque_W_Nm.y(), out.torque_W_Nm.z()}) {
      s += ',';
      AppendNumber(s, v);
    }
    s += ",\"" + cf_text + "\",";  // the CF has commas: quoted (RFC 4180)
    AppendNumber(s, out.energy_J);
    s += ',';
    AppendNumber(s, out.max_strain);
    s += ',';
    AppendNumber(s, out.tip_deflection_m);
    s += ',' + FlagsText(out.flags) + ',' + std::to_string(out.contact_count);
    for (int k = 0; k < core::kMaxContacts; ++k) {
      if (k >= out.contact_count) {
        s += ",,,,,,,,";
        continue;
      }
      const core::ContactState& pc = out.contacts[std::size_t(k)];
      s += ',' + PcText(core, pc);
      for (double v : {pc.s_m, eps - pc.distance_m, pc.normal_force_N, pc.friction_W_N.norm(),
                       pc.friction_limit_N}) {
        s += ',';
        AppendNumber(s, v);
      }
      s += ',';
      s += FrictionState(pc);
      s += ',';
      AppendNumber(s, pc.friction_work_J);
    }
    if (mesh_)
      for (const Eigen::Vector3d& p : centreline)
        for (int a = 0; a < 3; ++a) {
          s += ',';
          AppendNumber(s, p[a]);
        }
    s += '\n';
    return;
  }
  const auto pose = [](const Eigen::Isometry3d& X) {
    const Eigen::Quaterniond q(X.linear());
    return nlohmann::json{{"p", {X.translation().x(), X.translation().y(), X.translation().z()}},
                          {"q", {q.w(), q.x(), q.y(), q.z()}}};
  };
  nlohmann::json j;
  j["t"] = out.t_s;
  j["hand"] = pose(out.X_W_hand);
  j["held"] = pose(out.X_WH);
  j["force"] = {out.force_W_N.x(), out.force_W_N.y(), out.force_W_N.z()};
  j["torque"] = {out.torque_W_Nm.x(), out.torque_W_Nm.y(), out.torque_W_Nm.z()};
  j["cf"] = cf_text;
  j["energy"] = out.energy_J;
  j["strain"] = out.max_strain;
  j["tip_deflection"] = out.tip_deflection_m;
  nlohmann::json flags = nlohmann::json::array();
  for (int b = 0; b < core::kStepFlagCount; ++b)
    if (out.flags & (1u << b)) flags.push_back(FlagName(1u << b));
  j["flags"] = flags;
  nlohmann::json pcs = nlohmann::json::array();
  for (const core::ContactState& pc : out.Contacts()) {
    pcs.push_back({{"pc", PcText(core, pc)},
                   {"s", pc.s_m},
                   {"depth", eps - pc.distance_m},
                   {"normal", pc.normal_force_N},
                   {"friction", pc.friction_W_N.norm()},
                   {"limit", pc.friction_limit_N},
                   {"state", FrictionState(pc)},
                   {"work", pc.friction_work_J},
                   {"n", {pc.normal_W.x(), pc.normal_W.y(), pc.normal_W.z()}},
                   {"point", {pc.p_WC_m.x(), pc.p_WC_m.y(), pc.p_WC_m.z()}}});
  }
  j["contacts"] = pcs;
  if (mesh_) {
    nlohmann::json c = nlohmann::json::array();
    for (const Eigen::Vector3d& p : centreline) c.push_back({p.x(), p.y(), p.z()});
    j["centreline"] = c;
  }
  text_ += j.dump();
  text_ += '\n';
}

SeriesFile::SeriesFile(const std::filesystem::path& path, SeriesFormat format, bool mesh)
    : writer_(format, mesh), file_(std::make_unique<io::AtomicFile>(path)) {}

SeriesFile::~SeriesFile() = default;

std::string SeriesFile::OpenError() { return file_->error().empty() ? "" : file_->Commit(); }

void SeriesFile::Add(const core::Core& core, const core::StepOutput& out,
                     const std::string& cf_text) {
  writer_.Add(core, out, cf_text);
  if (writer_.text().size() >= kSeriesChunkBytes) {
    file_->Write(writer_.text());
    writer_.Clear();
  }
}

std::string SeriesFile::Commit() {
  file_->Write(writer_.text());
  writer_.Clear();
  return file_->Commit();
}

}  // namespace tubeplan::report
