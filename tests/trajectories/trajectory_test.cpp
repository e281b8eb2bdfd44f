// Hand trajectories: resampling onto the core's step, and the CSV loader's values and messages.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <stdexcept>
#include <string>
#include <unistd.h>
#include <vector>

#include <catch2/catch.hpp>

#include <tubeplan/io/plan_file.hpp>
#include <tubeplan/io/trajectory_csv.hpp>
#include <tubeplan/trajectories/trajectory.hpp>

namespace {

using tubeplan::io::LoadTrajectoryFile;
using tubeplan::io::LoadTrajectoryText;
using tubeplan::trajectories::HandSample;
using tubeplan::trajectories::Trajectory;

Eigen::Quaterniond AboutZ(double angle_rad) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle_rad, Eigen::Vector3d::UnitZ()));
}

// Rotation angle between two orientations (either sign of a quaternion is the same rotation).
double AngleBetween(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return a.angularDistance(b);
}

}  // namespace

TEST_CASE("Resampling a constant-velocity line gives the analytic position every tick",
          "[trajectory]") {
  // 250 Hz samples of p(t) = p0 + v t; every 1 ms tick must lie on the line.
  const Eigen::Vector3d p0(0.01, -0.09, 0.04), v(0.05, 0.2, -0.1);  // m, m/s
  Trajectory trajectory;
  for (int i = 0; i <= 250; ++i) {
    const double t = i / 250.0;
    trajectory.samples.push_back({t, p0 + v * t, Eigen::Quaterniond::Identity()});
  }
  const std::vector<HandSample> ticks = tubeplan::trajectories::Resample(trajectory, 1e-3);
  REQUIRE(ticks.size() == 1001);  // 0 .. 1 s inclusive
  for (std::size_t k = 0; k < ticks.size(); ++k) {
    const double t = static_cast<double>(k) * 1e-3;
    CAPTURE(k);
    CHECK(ticks[k].t_s == Approx(t).margin(1e-15));
    // A few roundings of numbers ~0.1 m: 1e-15 m is ~10 ulps.
    CHECK((ticks[k].p_WH_m - (p0 + v * t)).norm() < 1e-15);
  }
  // A tick whose time equals a sample's returns that sample bit for bit (t = 0 here).
  CHECK(ticks.front().p_WH_m == trajectory.samples.front().p_WH_m);
}

TEST_CASE("Orientation is interpolated on the shorter arc", "[trajectory]") {
  Trajectory trajectory;
  trajectory.samples.push_back({0.0, Eigen::Vector3d::Zero(), AboutZ(0.0)});
  trajectory.samples.push_back({0.002, Eigen::Vector3d::Zero(), AboutZ(std::numbers::pi / 2)});
  const auto ticks = tubeplan::trajectories::Resample(trajectory, 1e-3);
  REQUIRE(ticks.size() == 3);
  // Halfway through a 90 degree turn about z is a 45 degree turn (SLERP is uniform in angle).
  CHECK(AngleBetween(ticks[1].q_WH, AboutZ(std::numbers::pi / 4)) < 1e-12);

  // The same end orientation written as -q: still the 90 degree way, not the 270 degree way.
  trajectory.samples[1].q_WH.coeffs() = -trajectory.samples[1].q_WH.coeffs();
  const auto flipped = tubeplan::trajectories::Resample(trajectory, 1e-3);
  CHECK(AngleBetween(flipped[1].q_WH, AboutZ(std::numbers::pi / 4)) < 1e-12);
}

TEST_CASE("PoseAt holds the ends and moves its cursor forward", "[trajectory]") {
  Trajectory trajectory;
  for (int i = 0; i < 5; ++i)
    trajectory.samples.push_back(
        {0.01 * i, Eigen::Vector3d(i, 0, 0), Eigen::Quaterniond::Identity()});
  std::size_t cursor = 0;
  CHECK(tubeplan::trajectories::PoseAt(trajectory, -1.0, cursor).p_WH_m.x() == 0.0);
  CHECK(tubeplan::trajectories::PoseAt(trajectory, 0.025, cursor).p_WH_m.x() == Approx(2.5));
  CHECK(cursor == 2);
  // Going back in time still answers correctly.
  CHECK(tubeplan::trajectories::PoseAt(trajectory, 0.005, cursor).p_WH_m.x() == Approx(0.5));
  CHECK(tubeplan::trajectories::PoseAt(trajectory, 9.0, cursor).p_WH_m.x() == 4.0);
}

TEST_CASE("TickStream gives Resample's ticks exactly, one at a time", "[trajectory]") {
  // A recording with jitter and a rate that is not the step's: every tick must be bit for bit
  // what Resample gives (simulate and evaluate stream it; the other callers resample).
  Trajectory trajectory;
  for (int i = 0; i <= 400; ++i) {
    HandSample s;
    s.t_s = 0.25 + i * 4e-3 + (i % 3 == 0 ? 3e-4 : 0.0);
    s.p_WH_m = Eigen::Vector3d(std::sin(i * 0.01), 0.1 * i, -0.002 * i);
    s.q_WH = AboutZ(0.003 * i);
    trajectory.samples.push_back(s);
  }
  const std::vector<HandSample> all = tubeplan::trajectories::Resample(trajectory, 1e-3);
  tubeplan::trajectories::TickStream ticks(trajectory, 1e-3);
  REQUIRE(ticks.count() == all.size());
  for (std::size_t k = 0; k < ticks.count(); ++k) {
    const HandSample s = ticks.Tick(k);
    REQUIRE(s.t_s == all[k].t_s);
    REQUIRE(ticks.TimeOf(k) == all[k].t_s);
    REQUIRE(s.p_WH_m == all[k].p_WH_m);
    REQUIRE(s.q_WH.coeffs() == all[k].q_WH.coeffs());
  }
}

namespace {

// The samples of a trajectory in memory, handed out one at a time as a file's rows are.
class VectorSamples final : public tubeplan::trajectories::SampleSource {
 public:
  explicit VectorSamples(const std::vector<HandSample>& samples) : samples_(samples) {}
  bool Next(HandSample& sample) override {
    if (next_ == samples_.size()) return false;
    sample = samples_[next_++];
    return true;
  }

 private:
  const std::vector<HandSample>& samples_;
  std::size_t next_ = 0;
};

}  // namespace

TEST_CASE("SampleTicks gives TickStream's ticks bit for bit from samples read in order",
          "[trajectory]") {
  // Jittered samples (some on the grid, some between its points), a flip of the quaternion's
  // sign, and steps finer, equal to and coarser than the samples' spacing, with the last sample
  // on the grid and off it: every case of PoseAt.
  Trajectory trajectory;
  for (int i = 0; i <= 300; ++i) {
    HandSample s;
    s.t_s = 0.5 + i * 2e-3 + (i % 4 == 1 ? 7e-4 : 0.0);
    s.p_WH_m = Eigen::Vector3d(std::cos(i * 0.02), 0.05 * i, 0.001 * i * i);
    s.q_WH = AboutZ(0.01 * i);
    if (i % 5 == 0) s.q_WH.coeffs() = -s.q_WH.coeffs();
    trajectory.samples.push_back(s);
  }
  for (const double step_s : {3e-4, 1e-3, 2e-3, 5e-3, 0.6}) {
    CAPTURE(step_s);
    tubeplan::trajectories::TickStream memory(trajectory, step_s);
    VectorSamples samples(trajectory.samples);
    tubeplan::trajectories::SampleTicks streamed(samples, trajectory.samples.front().t_s,
                                                 trajectory.samples.back().t_s, step_s);
    REQUIRE(streamed.count() == memory.count());
    for (std::size_t k = 0; k < memory.count(); ++k) {
      const HandSample a = memory.Tick(k);
      const HandSample b = streamed.Tick(k);
      REQUIRE(b.t_s == a.t_s);
      REQUIRE(b.p_WH_m == a.p_WH_m);
      REQUIRE(b.q_WH.coeffs() == a.q_WH.coeffs());
      // The replays ask for tick 0 twice (the core's reset, then its first step).
      if (k == 0) REQUIRE(streamed.Tick(0).p_WH_m == a.p_WH_m);
    }
  }
}

TEST_CASE("SampleTicks refuses samples that do not reach the times it was promised",
          "[trajectory]") {
  std::vector<HandSample> samples;
  for (int i = 0; i <= 10; ++i) samples.push_back({i * 1e-3, Eigen::Vector3d::Zero(), AboutZ(0)});
  {
    // Promised 20 ms, given 10 ms: the source ends before the last tick.
    VectorSamples source(samples);
    tubeplan::trajectories::SampleTicks ticks(source, 0.0, 0.020, 1e-3);
    CHECK_NOTHROW(ticks.Tick(5));
    CHECK_THROWS_AS(ticks.Tick(15), std::runtime_error);
  }
  {
    // Promised 5 ms as the last: the source goes on past it.
    VectorSamples source(samples);
    tubeplan::trajectories::SampleTicks ticks(source, 0.0, 0.005, 1e-3);
    CHECK_THROWS_AS(ticks.Tick(5), std::runtime_error);
  }
  VectorSamples source(samples);
  CHECK_THROWS_AS(tubeplan::trajectories::SampleTicks(source, 0.0, 0.0, 1e-3),
                  std::invalid_argument);
  CHECK_THROWS_AS(tubeplan::trajectories::SampleTicks(source, 0.0, 0.01, 0.0),
                  std::invalid_argument);
}

TEST_CASE("A good trajectory file loads with exact values and metadata", "[trajectory]") {
  const auto loaded =
      LoadTrajectoryFile(std::string(TUBEPLAN_SOURCE_DIR) + "/tests/data/trajectories/good.csv");
  REQUIRE(loaded.diagnostics.FormatAll() == "");
  REQUIRE(loaded.trajectory);
  const Trajectory& t = *loaded.trajectory;
  CHECK(t.device == "PHANToM Premium 1.5/6DOF");
  CHECK(t.nominal_rate_Hz == 250.0);
  REQUIRE(t.samples.size() == 3);
  CHECK(t.samples[1].t_s == 0.004);
  // "# units: mm": positions are scaled to metres (one multiplication by 1e-3).
  CHECK(t.samples[1].p_WH_m.x() == Approx(1e-3).epsilon(1e-15));
  CHECK(t.samples[2].p_WH_m.y() == Approx(-0.089).epsilon(1e-15));
  // The third quaternion is off unit length by ~5e-7 (rounded digits): normalised, kept.
  CHECK(std::abs(t.samples[2].q_WH.norm() - 1.0) < 1e-15);
  REQUIRE(t.extra_columns == std::vector<std::string>{"button"});
  CHECK(t.extra_values[1][0] == 1.0);
}

TEST_CASE("Broken trajectory files get exactly the right diagnostics", "[trajectory]") {
  const std::string header = "t,px,py,pz,qw,qx,qy,qz\n";
  const std::string row0 = "0.000,0,0,0,1,0,0,0\n";
  struct Case {
    const char* what;
    std::string text;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"not a number", header + row0 + "0.001,0,abc,0,1,0,0,0\n",
       "t.csv:3:9: error: 'abc' is not a number, expected a decimal number\n"},
      {"nan", header + row0 + "0.001,nan,0,0,1,0,0,0\n",
       "t.csv:3:7: error: the number is not finite, expected a finite number\n"},
      {"time not increasing", header + row0 + "0.000,0,0,0,1,0,0,0\n",
       "t.csv:3:1: error: time 0 s is not after the previous sample's 0 s, expected strictly "
       "increasing times\n"},
      {"gap", header + row0 + "0.2,0,0,0,1,0,0,0\n",
       "t.csv:3:1: error: gap of 0.2 s before this sample, more than 0.05 s (a dropped "
       "recording?)\n"},
      {"quaternion not unit", header + row0 + "0.001,0,0,0,0.5,0,0,0\n",
       "t.csv:3:13: error: quaternion (qw, qx, qy, qz) has norm 0.5, expected a unit quaternion "
       "(within 0.001)\n"},
      {"missing columns", "t,px,py,pz,qx,qy\n" + row0,
       "t.csv:1:1: error: the header lacks column(s) qw, qz, expected t,px,py,pz,qw,qx,qy,qz (in "
       "any order, more allowed)\n"},
      {"duplicate column", "t,px,py,pz,qw,qx,qy,qz,px\n",
       "t.csv:1:24: error: column 'px' appears twice, expected each column once\n"},
      {"wrong field count", header + row0 + "0.001,0,0,0,1,0,0\n",
       "t.csv:3:1: error: row has 7 fields, expected 8 as in the header\n"},
      {"one sample", header + row0,
       "t.csv: error: the file has 1 sample(s), expected at least 2\n"},
      {"empty", "# only a comment\n",
       "t.csv: error: no header line, expected t,px,py,pz,qw,qx,qy,qz\n"},
      {"bad units", "# units: inch\n" + header + row0 + "0.001,0,0,0,1,0,0,0\n",
       "t.csv:1:10: error: units 'inch' not supported, expected m or mm (for px, py, pz; t is in "
       "s)\n"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.what, c.text);
    const auto loaded = LoadTrajectoryText(c.text, "t.csv");
    CHECK_FALSE(loaded.trajectory);
    CHECK(loaded.diagnostics.FormatAll() == c.expected);
  }
}

TEST_CASE("Trajectory errors are all reported, then capped", "[trajectory]") {
  std::string text = "t,px,py,pz,qw,qx,qy,qz\r\n0,0,0,0,1,0,0,0\r\n";  // CRLF is fine
  for (int i = 1; i <= 60; ++i) text += std::to_string(i * 1e-3) + ",x,0,0,1,0,0,0\r\n";
  const auto loaded = LoadTrajectoryText(text, "t.csv");
  CHECK_FALSE(loaded.trajectory);
  // 60 bad rows: the first 50 are listed, then one line says how many more.
  REQUIRE(loaded.diagnostics.all().size() == 51);
  CHECK(loaded.diagnostics.all()[0].line == 3);
  CHECK(loaded.diagnostics.all()[0].column == 10);
  CHECK(loaded.diagnostics.all()[50].message == "... and 10 more errors");
  // Printed after the errors it counts, not first (its line 0 would sort it there).
  const std::string all = loaded.diagnostics.FormatAll();
  CHECK_THAT(all, Catch::StartsWith("t.csv:3:10: error: 'x' is not a number"));
  CHECK_THAT(all, Catch::EndsWith("t.csv: error: ... and 10 more errors\n"));
}

TEST_CASE("A 20 Hz file sits at the gap limit on every row, not over it on some", "[trajectory]") {
  // Times as decimals: 0.35 - 0.30 and 0.40 - 0.35 round to either side of 0.05.
  std::string text = "t,px,py,pz,qw,qx,qy,qz\n";
  char row[64];
  for (int k = 0; k <= 200; ++k) {
    std::snprintf(row, sizeof row, "%.2f,0,0,0,1,0,0,0\n", k * 0.05);
    text += row;
  }
  const auto loaded = LoadTrajectoryText(text, "t.csv");
  CHECK(loaded.diagnostics.FormatAll() == "");
  CHECK(loaded.trajectory);
  // A gap beyond 50 ms is still one (51 ms).
  const auto gap =
      LoadTrajectoryText("t,px,py,pz,qw,qx,qy,qz\n0,0,0,0,1,0,0,0\n0.051,0,0,0,1,0,0,0\n", "t.csv");
  CHECK(gap.diagnostics.FormatAll() ==
        "t.csv:3:1: error: gap of 0.051 s before this sample, more than 0.05 s (a dropped "
        "recording?)\n");
}

TEST_CASE("Extra columns hold any text and are kept by name", "[trajectory]") {
  const auto loaded = LoadTrajectoryText(
      "t,px,py,pz,qw,qx,qy,qz,button,note\n0,0,0,0,1,0,0,0,1,start\n"
      "0.001,0,0,0,1,0,0,0,pressed,2026-11-24T10:00:00\n",
      "t.csv");
  CHECK(loaded.diagnostics.FormatAll() == "");
  REQUIRE(loaded.trajectory);
  CHECK(loaded.trajectory->extra_columns == std::vector<std::string>{"button", "note"});
  CHECK(loaded.trajectory->extra_values[0][0] == 1.0);
  CHECK(std::isnan(loaded.trajectory->extra_values[0][1]));
  CHECK(std::isnan(loaded.trajectory->extra_values[1][0]));
  // The pose columns are still numbers.
  CHECK(LoadTrajectoryText("t,px,py,pz,qw,qx,qy,qz,note\n0,0,0,0,1,0,0,0,a\n"
                           "0.001,zero,0,0,1,0,0,0,b\n",
                           "t.csv")
            .diagnostics.FormatAll() ==
        "t.csv:3:7: error: 'zero' is not a number, expected a decimal number\n");
}

TEST_CASE("A live recording's marks read back: stalled ticks and where the run stopped",
          "[trajectory]") {
  std::string csv = tubeplan::io::TrajectoryCsvHeader("emulator", 1000.0, {"stalled"});
  HandSample s;
  for (int k = 0; k < 3; ++k) {
    s.t_s = 1e-3 * k;
    s.p_WH_m.x() = 1e-4 * k;
    tubeplan::io::AppendTrajectoryCsvRow(csv, s, k == 1 ? "1" : "0");
  }
  csv += tubeplan::io::TrajectoryCsvStopped("missed deadlines at t = 0.002 s");
  const auto loaded = LoadTrajectoryText(csv, "live.csv");
  REQUIRE(loaded.diagnostics.FormatAll() == "");
  const Trajectory& t = *loaded.trajectory;
  CHECK(t.stopped_early == "missed deadlines at t = 0.002 s");
  REQUIRE(t.extra_columns == std::vector<std::string>{"stalled"});
  CHECK(t.extra_values[0][0] == 0.0);
  CHECK(t.extra_values[1][0] == 1.0);
  CHECK(t.samples[2].p_WH_m.x() == 2e-4);
  // The streamed check of a file learns it too, and a trajectory written out keeps it.
  const std::string path = std::string(std::getenv("TMPDIR") ? std::getenv("TMPDIR") : "/tmp") +
                           "/tubeplan-stopped-" + std::to_string(::getpid()) + ".csv";
  std::FILE* f = std::fopen(path.c_str(), "wb");
  REQUIRE(f);
  std::fwrite(csv.data(), 1, csv.size(), f);
  std::fclose(f);
  const auto scanned = tubeplan::io::ScanTrajectoryFile(path);
  std::remove(path.c_str());
  REQUIRE(scanned.info);
  CHECK(scanned.info->stopped_early == t.stopped_early);
  const std::string written = tubeplan::io::FormatTrajectoryCsv(t);
  CHECK_THAT(written, Catch::EndsWith("\n# stopped: missed deadlines at t = 0.002 s\n"));
  const auto again = LoadTrajectoryText(written, "again.csv");
  REQUIRE(again.trajectory);
  CHECK(again.trajectory->stopped_early == t.stopped_early);
}

TEST_CASE("Damaged trajectory files never throw", "[trajectory]") {
  const std::string good =
      "# rate: 1 kHz\nt,px,py,pz,qw,qx,qy,qz\n0,0.1,0.2,0.3,1,0,0,0\n0.001,0.1,0.2,0.3,1,0,0,0\n";
  REQUIRE(LoadTrajectoryText(good, "g.csv").trajectory);
  for (std::size_t i = 0; i < good.size(); ++i) {
    for (const std::string& text :
         {good.substr(0, i) + good.substr(i + 1), good.substr(0, i + 1) + good.substr(i)}) {
      tubeplan::io::TrajectoryLoadResult r;
      REQUIRE_NOTHROW(r = LoadTrajectoryText(text, "f.csv"));
      CHECK(r.trajectory.has_value() != r.diagnostics.HasErrors());
    }
  }
}
