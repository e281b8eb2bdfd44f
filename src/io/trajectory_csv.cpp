#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <sstream>

#include <tubeplan/io/text_file.hpp>
#include <tubeplan/io/trajectory_csv.hpp>
#include <tubeplan/io/units.hpp>

namespace tubeplan::io {
namespace {

// Enough to show what is wrong with a file; a file with thousands of bad rows is one mistake
// repeated, and ten thousand lines of it would hide the first.
constexpr int kMaxErrors = 50;

constexpr std::array<std::string_view, 8> kPoseColumns = {"t",  "px", "py", "pz",
                                                          "qw", "qx", "qy", "qz"};

struct Field {
  std::string_view text;  // trimmed
  int column = 0;         // 1-based column of the first character
};

std::string_view Trim(std::string_view s, std::size_t& leading) {
  leading = 0;
  while (leading < s.size() && (s[leading] == ' ' || s[leading] == '\t')) ++leading;
  s.remove_prefix(leading);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

std::vector<Field> Split(std::string_view line) {
  std::vector<Field> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    const std::size_t end = comma == std::string_view::npos ? line.size() : comma;
    std::size_t leading = 0;
    const std::string_view text = Trim(line.substr(start, end - start), leading);
    fields.push_back({text, static_cast<int>(start + leading) + 1});
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return fields;
}

class Collector {
 public:
  Collector(const std::string& file, Diagnostics& d) : file_(file), d_(d) {}
  void Error(int line, int column, const std::string& message) {
    ++count_;
    if (count_ <= kMaxErrors) d_.Error(file_, line, column, message);
  }
  void Finish() {
    if (count_ > kMaxErrors)
      d_.Error(file_, 0, 0, "... and " + std::to_string(count_ - kMaxErrors) + " more errors");
  }

 private:
  const std::string& file_;
  Diagnostics& d_;
  int count_ = 0;
};

// YAML's spellings of NaN and infinity (.nan, .NaN, .inf, -.Inf, +.INF), which from_chars
// does not know: worth a message of their own rather than "not a number".
bool IsYamlNonFinite(std::string_view text) {
  if (!text.empty() && (text.front() == '-' || text.front() == '+')) text.remove_prefix(1);
  if (text.size() != 4 || text.front() != '.') return false;
  std::string lower;
  for (const char c : text.substr(1))
    lower += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return lower == "nan" || lower == "inf";
}

std::string Number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

TrajectoryLoadResult LoadTrajectoryText(std::string_view text, const std::string& display_name,
                                        const TrajectoryLoadOptions& options) {
  TrajectoryLoadResult result;
  if (!CheckInputText(text, display_name, "a trajectory CSV (t,px,py,pz,qw,qx,qy,qz)",
                      result.diagnostics))
    return result;
  // A spreadsheet may save CSV with a UTF-8 byte-order mark; editors hide it, so columns are
  // counted after it.
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  Collector errors(display_name, result.diagnostics);
  plan::Trajectory trajectory;
  // At most one sample per line: reserving that bound once avoids the vector's doublings, each
  // of which briefly holds the old and the new array (3x the samples' size at the peak).
  // The shortest row ("0,0,0,0,1,0,0,0\n") is 16 bytes, which bounds a file of blank lines.
  trajectory.samples.reserve(
      std::min(static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) + 1,
               text.size() / 16 + 1));
  double position_scale = 1.0;
  bool have_header = false;
  std::array<std::size_t, 8> pose_index{};
  std::vector<std::size_t> extra_index;
  std::size_t column_count = 0;
  bool have_previous = false;
  double previous_t = 0.0;
  bool rows_ok = true;

  std::size_t start = 0;
  for (int line_number = 1; start <= text.size(); ++line_number) {
    const std::size_t newline = text.find('\n', start);
    const std::size_t end = newline == std::string_view::npos ? text.size() : newline;
    const std::string_view line = text.substr(start, end - start);
    start = end + 1;
    std::size_t leading = 0;
    const std::string_view content = Trim(line, leading);
    if (content.empty()) {
      if (newline == std::string_view::npos) break;
      continue;
    }
    if (content.front() == '#') {
      // "# key: value" metadata; other comments are ignored.
      const std::size_t colon = content.find(':');
      if (colon != std::string_view::npos) {
        std::size_t lead = 0;
        const std::string_view key = Trim(content.substr(1, colon - 1), lead);
        std::size_t value_lead = 0;
        const std::string_view value = Trim(content.substr(colon + 1), value_lead);
        const int value_column = static_cast<int>(leading + colon + 1 + value_lead) + 1;
        if (key == "device") {
          trajectory.device = std::string(value);
        } else if (key == "rate") {
          const QuantityResult rate = ParseQuantityAs(value, dim::kFrequency);
          if (!rate.quantity || !(rate.quantity->value_si > 0.0)) {
            errors.Error(
                line_number, value_column + static_cast<int>(rate.error ? rate.error->offset : 0),
                "rate: " +
                    (rate.error ? rate.error->message : std::string("must be greater than zero")) +
                    " (e.g. \"# rate: 1000 Hz\")");
          } else {
            trajectory.nominal_rate_Hz = rate.quantity->value_si;
          }
        } else if (key == "units") {
          if (value == "m") {
            position_scale = 1.0;
          } else if (value == "mm") {
            position_scale = 1e-3;
          } else {
            errors.Error(line_number, value_column,
                         "units '" + std::string(value) +
                             "' not supported, expected m or mm (for px, py, pz; t is in s)");
          }
        }
      }
      if (newline == std::string_view::npos) break;
      continue;
    }
    const std::vector<Field> fields = Split(line);
    if (!have_header) {
      have_header = true;
      column_count = fields.size();
      std::array<bool, 8> found{};
      for (std::size_t i = 0; i < fields.size(); ++i) {
        bool pose = false;
        for (std::size_t c = 0; c < kPoseColumns.size(); ++c) {
          if (fields[i].text != kPoseColumns[c]) continue;
          pose = true;
          if (found[c]) {
            errors.Error(line_number, fields[i].column,
                         "column '" + Abbreviate(fields[i].text) +
                             "' appears twice, expected each column once");
            rows_ok = false;
          }
          found[c] = true;
          pose_index[c] = i;
        }
        if (!pose) {
          if (fields[i].text.empty()) {
            errors.Error(line_number, fields[i].column, "empty column name in the header");
            rows_ok = false;
          }
          extra_index.push_back(i);
          trajectory.extra_columns.emplace_back(fields[i].text);
        }
      }
      std::string missing;
      for (std::size_t c = 0; c < kPoseColumns.size(); ++c)
        if (!found[c]) missing += (missing.empty() ? "" : ", ") + std::string(kPoseColumns[c]);
      if (!missing.empty()) {
        // A scene or plan given where a trajectory belongs: say so rather than list columns.
        const bool yaml = fields.size() == 1 && content.find(':') != std::string_view::npos;
        errors.Error(line_number, 1,
                     (yaml ? std::string("this looks like YAML (a scene or plan file?), not a "
                                         "trajectory: the header lacks column(s) ")
                           : std::string("the header lacks column(s) ")) +
                         missing +
                         ", expected t,px,py,pz,qw,qx,qy,qz (in any order, more allowed)");
        rows_ok = false;
        break;  // rows cannot be read without their columns
      }
      if (newline == std::string_view::npos) break;
      continue;
    }
    if (fields.size() != column_count) {
      errors.Error(line_number, 1,
                   "row has " + std::to_string(fields.size()) + " fields, expected " +
                       std::to_string(column_count) + " as in the header");
      rows_ok = false;
      if (newline == std::string_view::npos) break;
      continue;
    }
    std::vector<double> values(fields.size(), 0.0);
    bool row_ok = true;
    for (std::size_t i = 0; i < fields.size(); ++i) {
      const Field& f = fields[i];
      double v = 0.0;
      const char* first = f.text.data();
      const char* last = first + f.text.size();
      if (!f.text.empty() && *first == '+') ++first;
      auto [ptr, ec] = std::from_chars(first, last, v);
      if (ec == std::errc::result_out_of_range && ptr == last) {
        // from_chars says out of range for overflow and underflow alike and leaves v unset: an
        // underflow (a negative exponent) is zero, an overflow is not a finite number.
        const std::string_view digits(first, static_cast<std::size_t>(last - first));
        const std::size_t e = digits.find_first_of("eE");
        if (e != std::string_view::npos && e + 1 < digits.size() && digits[e + 1] == '-') {
          v = digits.front() == '-' ? -0.0 : 0.0;
          ec = std::errc();
        } else {
          v = HUGE_VAL;  // reported below as not finite
          ec = std::errc();
        }
      }
      if (IsYamlNonFinite(f.text)) {
        errors.Error(line_number, f.column,
                     "'" + Abbreviate(f.text) +
                         "' is not a finite number, expected a finite decimal number");
        row_ok = false;
      } else if (f.text.empty() || ec != std::errc() || ptr != last) {
        errors.Error(line_number, f.column,
                     "'" + Abbreviate(f.text) + "' is not a number, expected a decimal number");
        row_ok = false;
      } else if (!std::isfinite(v)) {
        errors.Error(line_number, f.column, "the number is not finite, expected a finite number");
        row_ok = false;
      }
      values[i] = v;
    }
    if (!row_ok) {
      rows_ok = false;
      if (newline == std::string_view::npos) break;
      continue;
    }
    plan::HandSample s;
    s.t_s = values[pose_index[0]];
    s.p_WH_m = position_scale *
               Eigen::Vector3d(values[pose_index[1]], values[pose_index[2]], values[pose_index[3]]);
    Eigen::Quaterniond q(values[pose_index[4]], values[pose_index[5]], values[pose_index[6]],
                         values[pose_index[7]]);
    const int t_column = fields[pose_index[0]].column;
    if (have_previous && !(s.t_s > previous_t)) {
      errors.Error(line_number, t_column,
                   "time " + Number(s.t_s) + " s is not after the previous sample's " +
                       Number(previous_t) + " s, expected strictly increasing times");
      rows_ok = false;
    } else if (have_previous && s.t_s - previous_t > options.max_gap_s) {
      errors.Error(line_number, t_column,
                   "gap of " + Number(s.t_s - previous_t) + " s before this sample, more than " +
                       Number(options.max_gap_s) + " s (a dropped recording?)");
      rows_ok = false;
    }
    const double norm = q.norm();
    if (!(std::abs(norm - 1.0) <= options.quaternion_norm_tolerance)) {
      errors.Error(line_number, fields[pose_index[4]].column,
                   "quaternion (qw, qx, qy, qz) has norm " + Number(norm) +
                       ", expected a unit quaternion (within " +
                       Number(options.quaternion_norm_tolerance) + ")");
      rows_ok = false;
    } else {
      s.q_WH = q.normalized();
    }
    have_previous = true;
    previous_t = s.t_s;
    trajectory.samples.push_back(s);
    if (!extra_index.empty()) {
      std::vector<double> extra;
      extra.reserve(extra_index.size());
      for (const std::size_t i : extra_index) extra.push_back(values[i]);
      trajectory.extra_values.push_back(std::move(extra));
    }
    if (newline == std::string_view::npos) break;
  }
  if (!have_header) {
    errors.Error(0, 0, "no header line, expected t,px,py,pz,qw,qx,qy,qz");
  } else if (rows_ok && trajectory.samples.size() < 2) {
    errors.Error(0, 0,
                 "the file has " + std::to_string(trajectory.samples.size()) +
                     " sample(s), expected at least 2");
  }
  errors.Finish();
  if (!result.diagnostics.HasErrors()) result.trajectory = std::move(trajectory);
  return result;
}

TrajectoryLoadResult LoadTrajectoryFile(const std::filesystem::path& path,
                                        const TrajectoryLoadOptions& options) {
  const ReadResult read = ReadInputFile(path);
  if (!read.text) {
    TrajectoryLoadResult result;
    result.diagnostics.Error(
        path.string(), 0, 0,
        "cannot read file (" + read.error + "), expected a readable CSV trajectory");
    return result;
  }
  return LoadTrajectoryText(*read.text, path.string(), options);
}

}  // namespace tubeplan::io
