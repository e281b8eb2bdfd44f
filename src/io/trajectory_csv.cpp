#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>

#include <tubeplan/io/trajectory_csv.hpp>
#include <tubeplan/io/units.hpp>

#include "text_file.hpp"

namespace tubeplan::io {
namespace {

// Enough to show what is wrong with a file; a file with thousands of bad rows is one mistake
// repeated, and ten thousand lines of it would hide the first.
constexpr int kMaxErrors = 50;

// Times differ from what the file wrote by their decimal rounding (0.35 - 0.30 is 0.04999...96,
// 0.40 - 0.35 is 0.05000...03): a gap is compared with a nanosecond to spare, so a 20 Hz file
// sits at the 50 ms limit on every row, not over it on some.
constexpr double kTimeRounding_s = 1e-9;

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

// The line's comma-separated fields into `fields` (reused from row to row: no allocation a row).
void Split(std::string_view line, std::vector<Field>& fields) {
  fields.clear();
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
}

class Collector {
 public:
  Collector(const std::string& file, Diagnostics& d) : file_(file), d_(d) {}
  void Error(int line, int column, const std::string& message) {
    ++count_;
    if (count_ <= kMaxErrors) d_.Error(file_, line, column, message);
  }
  void Warning(int line, int column, const std::string& message) {
    d_.Warning(file_, line, column, message);
  }
  void Finish() {
    if (count_ > kMaxErrors)
      d_.ErrorAfterAll(file_, "... and " + std::to_string(count_ - kMaxErrors) +
                                  (count_ - kMaxErrors == 1 ? " more error" : " more errors"));
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

// One row after another, as LoadTrajectoryText and the streamed passes read them: the header,
// metadata and every check of a row, with the diagnostics in the order of the file. Holds one
// row's fields and values, never the samples.
class RowParser {
 public:
  RowParser(const std::string& file, const TrajectoryLoadOptions& options, Diagnostics& d)
      : options_(options), errors_(file, d) {}

  /// One line without its '\n' (a UTF-8 byte-order mark already removed from the first); true
  /// when it gave a sample, in `sample`, with its extra columns' values in extra_values().
  bool Line(std::string_view line, int line_number, trajectories::HandSample& sample);
  /// True after a header without the pose columns: the rows cannot be read.
  bool stopped() const { return stopped_; }
  /// The whole-file checks (a header, two samples) and the count of errors beyond the cap.
  void Finish();

  std::size_t sample_count() const { return sample_count_; }
  const std::vector<double>& extra_values() const { return extra_; }
  std::string device;
  double nominal_rate_Hz = 0.0;
  std::string stopped_early;
  std::vector<std::string> extra_columns;

 private:
  void Metadata(std::string_view content, std::size_t leading, int line_number);
  void Header(std::string_view content, int line_number);

  const TrajectoryLoadOptions options_;
  Collector errors_;
  std::vector<Field> fields_;
  std::vector<double> values_, extra_;
  double position_scale_ = 1.0;
  bool have_header_ = false;
  std::array<std::size_t, 8> pose_index_{};
  std::vector<std::size_t> extra_index_;
  std::vector<bool> is_pose_;  // per column of the header
  std::size_t column_count_ = 0;
  bool have_previous_ = false;
  double previous_t_ = 0.0;
  Eigen::Vector3d previous_p_ = Eigen::Vector3d::Zero();
  bool speed_warned_ = false;
  bool rows_ok_ = true;
  bool stopped_ = false;
  std::size_t sample_count_ = 0;
};

void RowParser::Metadata(std::string_view content, std::size_t leading, int line_number) {
  // "# key: value" metadata; other comments are ignored.
  const std::size_t colon = content.find(':');
  if (colon == std::string_view::npos) return;
  std::size_t lead = 0;
  const std::string_view key = Trim(content.substr(1, colon - 1), lead);
  std::size_t value_lead = 0;
  const std::string_view value = Trim(content.substr(colon + 1), value_lead);
  const int value_column = static_cast<int>(leading + colon + 1 + value_lead) + 1;
  if (key == "device") {
    device = std::string(value);
  } else if (key == "stopped") {
    stopped_early = std::string(value);
  } else if (key == "rate") {
    const QuantityResult rate = ParseQuantityAs(value, dim::kFrequency);
    if (!rate.quantity || !(rate.quantity->value_si > 0.0)) {
      errors_.Error(
          line_number, value_column + static_cast<int>(rate.error ? rate.error->offset : 0),
          "rate: " + (rate.error ? rate.error->message : std::string("must be greater than zero")) +
              " (e.g. \"# rate: 1000 Hz\")");
    } else {
      nominal_rate_Hz = rate.quantity->value_si;
    }
  } else if (key == "units") {
    if (value == "m") {
      position_scale_ = 1.0;
    } else if (value == "mm") {
      position_scale_ = 1e-3;
    } else {
      errors_.Error(line_number, value_column,
                    "units '" + std::string(value) +
                        "' not supported, expected m or mm (for px, py, pz; t is in s)");
    }
  }
}

void RowParser::Header(std::string_view content, int line_number) {
  have_header_ = true;
  column_count_ = fields_.size();
  is_pose_.assign(fields_.size(), false);
  std::array<bool, 8> found{};
  for (std::size_t i = 0; i < fields_.size(); ++i) {
    bool pose = false;
    for (std::size_t c = 0; c < kPoseColumns.size(); ++c) {
      if (fields_[i].text != kPoseColumns[c]) continue;
      pose = true;
      is_pose_[i] = true;
      if (found[c]) {
        errors_.Error(line_number, fields_[i].column,
                      "column '" + Abbreviate(fields_[i].text) +
                          "' appears twice, expected each column once");
        rows_ok_ = false;
      }
      found[c] = true;
      pose_index_[c] = i;
    }
    if (!pose) {
      if (fields_[i].text.empty()) {
        errors_.Error(line_number, fields_[i].column, "empty column name in the header");
        rows_ok_ = false;
      }
      extra_index_.push_back(i);
      extra_columns.emplace_back(fields_[i].text);
    }
  }
  std::string missing;
  for (std::size_t c = 0; c < kPoseColumns.size(); ++c)
    if (!found[c]) missing += (missing.empty() ? "" : ", ") + std::string(kPoseColumns[c]);
  if (!missing.empty()) {
    // A scene or plan given where a trajectory belongs: say so rather than list columns.
    const bool yaml = fields_.size() == 1 && content.find(':') != std::string_view::npos;
    errors_.Error(line_number, 1,
                  (yaml ? std::string("this looks like YAML (a scene or plan file?), not a "
                                      "trajectory: the header lacks column(s) ")
                        : std::string("the header lacks column(s) ")) +
                      missing + ", expected t,px,py,pz,qw,qx,qy,qz (in any order, more allowed)");
    rows_ok_ = false;
    stopped_ = true;  // rows cannot be read without their columns
  }
}

bool RowParser::Line(std::string_view line, int line_number, trajectories::HandSample& sample) {
  if (stopped_) return false;
  std::size_t leading = 0;
  const std::string_view content = Trim(line, leading);
  if (content.empty()) return false;
  if (content.front() == '#') {
    Metadata(content, leading, line_number);
    return false;
  }
  Split(line, fields_);
  if (!have_header_) {
    Header(content, line_number);
    return false;
  }
  if (fields_.size() != column_count_) {
    errors_.Error(line_number, 1,
                  "row has " + std::to_string(fields_.size()) + " fields, expected " +
                      std::to_string(column_count_) + " as in the header");
    rows_ok_ = false;
    return false;
  }
  values_.assign(fields_.size(), 0.0);
  bool row_ok = true;
  for (std::size_t i = 0; i < fields_.size(); ++i) {
    const Field& f = fields_[i];
    // A column beyond the pose holds any text (a button's state, a label): its value is the
    // number it spells, else NaN; nothing here reads it.
    if (!is_pose_[i]) {
      double v = std::numeric_limits<double>::quiet_NaN();
      const char* first = f.text.data();
      const char* last = first + f.text.size();
      if (!f.text.empty() && *first == '+') ++first;
      if (const auto [ptr, ec] = std::from_chars(first, last, v); ec != std::errc() || ptr != last)
        v = std::numeric_limits<double>::quiet_NaN();
      values_[i] = v;
      continue;
    }
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
      errors_.Error(
          line_number, f.column,
          "'" + Abbreviate(f.text) + "' is not a finite number, expected a finite decimal number");
      row_ok = false;
    } else if (f.text.empty() || ec != std::errc() || ptr != last) {
      errors_.Error(line_number, f.column,
                    "'" + Abbreviate(f.text) + "' is not a number, expected a decimal number");
      row_ok = false;
    } else if (!std::isfinite(v)) {
      errors_.Error(line_number, f.column, "the number is not finite, expected a finite number");
      row_ok = false;
    }
    values_[i] = v;
  }
  if (!row_ok) {
    rows_ok_ = false;
    return false;
  }
  trajectories::HandSample s;
  s.t_s = values_[pose_index_[0]];
  s.p_WH_m = position_scale_ * Eigen::Vector3d(values_[pose_index_[1]], values_[pose_index_[2]],
                                               values_[pose_index_[3]]);
  Eigen::Quaterniond q(values_[pose_index_[4]], values_[pose_index_[5]], values_[pose_index_[6]],
                       values_[pose_index_[7]]);
  const int t_column = fields_[pose_index_[0]].column;
  if (have_previous_ && !(s.t_s > previous_t_)) {
    errors_.Error(line_number, t_column,
                  "time " + Number(s.t_s) + " s is not after the previous sample's " +
                      Number(previous_t_) + " s, expected strictly increasing times");
    rows_ok_ = false;
  } else if (have_previous_ && s.t_s - previous_t_ > options_.max_gap_s + kTimeRounding_s) {
    errors_.Error(line_number, t_column,
                  "gap of " + Number(s.t_s - previous_t_) + " s before this sample, more than " +
                      Number(options_.max_gap_s) + " s (a dropped recording?)");
    rows_ok_ = false;
  }
  // A hand faster than a haptic device follows: said once, at its first sample (the core keeps
  // the tube out of parts whatever the hand does, but such a recording is not a hand's).
  if (have_previous_ && rows_ok_ && !speed_warned_ && s.t_s > previous_t_) {
    const double speed = (s.p_WH_m - previous_p_).norm() / (s.t_s - previous_t_);
    if (speed > options_.max_hand_speed_m_per_s) {
      errors_.Warning(line_number, fields_[pose_index_[1]].column,
                      "the hand moves at " + Number(speed) + " m/s before this sample, faster " +
                          "than the " + Number(options_.max_hand_speed_m_per_s) +
                          " m/s a hand moves a haptic device (a jump in the recording?)");
      speed_warned_ = true;
    }
  }
  previous_p_ = s.p_WH_m;
  const double norm = q.norm();
  if (!(std::abs(norm - 1.0) <= options_.quaternion_norm_tolerance)) {
    errors_.Error(line_number, fields_[pose_index_[4]].column,
                  "quaternion (qw, qx, qy, qz) has norm " + Number(norm) +
                      ", expected a unit quaternion (within " +
                      Number(options_.quaternion_norm_tolerance) + ")");
    rows_ok_ = false;
  } else {
    s.q_WH = q.normalized();
  }
  have_previous_ = true;
  previous_t_ = s.t_s;
  ++sample_count_;
  extra_.clear();
  for (const std::size_t i : extra_index_) extra_.push_back(values_[i]);
  sample = s;
  return true;
}

void RowParser::Finish() {
  if (!have_header_) {
    errors_.Error(0, 0, "no header line, expected t,px,py,pz,qw,qx,qy,qz");
  } else if (rows_ok_ && sample_count_ < 2) {
    errors_.Error(
        0, 0, "the file has " + std::to_string(sample_count_) + " sample(s), expected at least 2");
  }
  errors_.Finish();
}

constexpr std::string_view kExpected = "a trajectory CSV (t,px,py,pz,qw,qx,qy,qz)";
constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";

// A spreadsheet may save CSV with a UTF-8 byte-order mark; editors hide it, so columns are
// counted after it.
std::string_view WithoutBom(std::string_view text) {
  if (text.substr(0, 3) == kUtf8Bom) text.remove_prefix(3);
  return text;
}

std::string CannotRead(const std::string& why) {
  return "cannot read file (" + why + "), expected a readable CSV trajectory";
}

}  // namespace

TrajectoryLoadResult LoadTrajectoryText(std::string_view text, const std::string& display_name,
                                        const TrajectoryLoadOptions& options) {
  TrajectoryLoadResult result;
  if (!CheckInputText(text, display_name, kExpected, result.diagnostics)) return result;
  text = WithoutBom(text);
  trajectories::Trajectory trajectory;
  // At most one sample per line: reserving that bound once avoids the vector's doublings, each
  // of which briefly holds the old and the new array (3x the samples' size at the peak).
  // The shortest row ("0,0,0,0,1,0,0,0\n") is 16 bytes, which bounds a file of blank lines.
  trajectory.samples.reserve(
      std::min(static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) + 1,
               text.size() / 16 + 1));
  RowParser rows(display_name, options, result.diagnostics);
  trajectories::HandSample sample;
  std::size_t start = 0;
  for (int line_number = 1; start <= text.size() && !rows.stopped(); ++line_number) {
    const std::size_t newline = text.find('\n', start);
    const std::size_t end = newline == std::string_view::npos ? text.size() : newline;
    if (rows.Line(text.substr(start, end - start), line_number, sample)) {
      trajectory.samples.push_back(sample);
      // No per-row vector when there are no extra columns (24 bytes a sample).
      if (!rows.extra_columns.empty()) trajectory.extra_values.push_back(rows.extra_values());
    }
    if (newline == std::string_view::npos) break;
    start = end + 1;
  }
  rows.Finish();
  trajectory.device = rows.device;
  trajectory.nominal_rate_Hz = rows.nominal_rate_Hz;
  trajectory.stopped_early = rows.stopped_early;
  trajectory.extra_columns = rows.extra_columns;
  if (!result.diagnostics.HasErrors()) result.trajectory = std::move(trajectory);
  return result;
}

TrajectoryLoadResult LoadTrajectoryFile(const std::filesystem::path& path,
                                        const TrajectoryLoadOptions& options) {
  const ReadResult read = ReadInputFile(path);
  if (!read.text) {
    TrajectoryLoadResult result;
    result.diagnostics.Error(path.string(), 0, 0, CannotRead(read.error));
    return result;
  }
  return LoadTrajectoryText(*read.text, path.string(), options);
}

TrajectoryScanResult ScanTrajectoryFile(const std::filesystem::path& path,
                                        const TrajectoryLoadOptions& options) {
  TrajectoryScanResult result;
  const std::string name = path.string();
  InputLineReader in;
  result.read_error = in.Open(path);
  // The rows' diagnostics are kept apart: they count only when the text passes its checks (as
  // in LoadTrajectoryText, which parses only then).
  Diagnostics row_diagnostics;
  RowParser rows(name, options, row_diagnostics);
  TrajectoryInfo info;
  trajectories::HandSample sample;
  std::string_view line;
  for (int line_number = 1; result.read_error.empty() && in.Next(line); ++line_number) {
    // Rows are not parsed once the text fails (a binary file): only its checks go on.
    if (rows.stopped() || in.check_failing()) continue;
    if (!rows.Line(line_number == 1 ? WithoutBom(line) : line, line_number, sample)) continue;
    if (rows.sample_count() == 1) info.t_first_s = sample.t_s;
    info.t_last_s = sample.t_s;
  }
  if (result.read_error.empty()) result.read_error = in.error();
  if (!result.read_error.empty()) {
    result.diagnostics.Error(name, 0, 0, CannotRead(result.read_error));
    return result;
  }
  if (!in.FinishCheck(name, kExpected, result.diagnostics)) return result;
  rows.Finish();
  result.diagnostics.Append(row_diagnostics);
  if (result.diagnostics.HasErrors()) return result;
  info.path = path;
  info.sample_count = rows.sample_count();
  info.device = rows.device;
  info.nominal_rate_Hz = rows.nominal_rate_Hz;
  info.stopped_early = rows.stopped_early;
  info.extra_columns = rows.extra_columns;
  info.file_bytes = in.file().size();
  info.modified_ns = in.file().modified_ns();
  result.info = std::move(info);
  return result;
}

struct TrajectoryFileSamples::Rows {
  Rows(std::string file, const TrajectoryLoadOptions& options)
      : name(std::move(file)), parser(name, options, diagnostics) {}
  std::string name;  // before parser, which refers to it
  InputLineReader in;
  Diagnostics diagnostics;
  RowParser parser;
  int line_number = 0;
  std::size_t count = 0;
};

TrajectoryFileSamples::TrajectoryFileSamples(const TrajectoryInfo& info,
                                             const TrajectoryLoadOptions& options)
    : info_(info), rows_(std::make_unique<Rows>(info.path.string(), options)) {
  const std::string error = rows_->in.Open(info.path);
  if (!error.empty()) Changed("cannot read it again (" + error + ")");
  if (rows_->in.file().size() != info.file_bytes ||
      rows_->in.file().modified_ns() != info.modified_ns)
    Changed("it was modified after it was checked");
}

TrajectoryFileSamples::~TrajectoryFileSamples() = default;

[[noreturn]] void TrajectoryFileSamples::Changed(const std::string& what) const {
  throw InputChanged(info_.path.string() + ": error: " + what +
                     ", expected the trajectory file to stay as it was while it is replayed");
}

bool TrajectoryFileSamples::Next(trajectories::HandSample& sample) {
  Rows& r = *rows_;
  std::string_view line;
  while (r.in.Next(line)) {
    ++r.line_number;
    if (!r.parser.Line(r.line_number == 1 ? WithoutBom(line) : line, r.line_number, sample))
      continue;
    if (r.diagnostics.HasErrors() || ++r.count > info_.sample_count) break;
    return true;
  }
  if (!r.in.error().empty()) Changed("cannot read it again (" + r.in.error() + ")");
  if (r.diagnostics.HasErrors() || r.count != info_.sample_count)
    Changed("its rows differ from those checked");
  return false;
}

}  // namespace tubeplan::io
