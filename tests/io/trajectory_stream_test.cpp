// Streamed trajectory files (docs/hardening.md, "Long recordings: memory"): the chunked input
// checks, the validating pass and the row-by-row replay must say and give exactly what the
// in-memory loader says and gives, on the shipped trajectories and on every bad input we test.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>
#include <vector>

#include <catch2/catch.hpp>

#include <tubeplan/io/trajectory_csv.hpp>
#include <tubeplan/trajectories/trajectory.hpp>

#include "../scratch.hpp"
#include "io/text_file.hpp"

namespace {

namespace io = tubeplan::io;
namespace trajectories = tubeplan::trajectories;

std::filesystem::path Scratch() { return tubeplan::testing::ScratchDir("trajectory-stream"); }

std::string Write(const std::string& name, const std::string& bytes) {
  return tubeplan::testing::WriteScratch("trajectory-stream", name, bytes);
}

std::string Source(const std::string& relative) {
  return std::string(TUBEPLAN_SOURCE_DIR) + "/" + relative;
}

constexpr std::string_view kExpected = "a trajectory CSV (t,px,py,pz,qw,qx,qy,qz)";

// CheckInputText on the whole text, and InputTextCheck fed the text cut at `cuts`.
std::string Whole(std::string_view text) {
  io::Diagnostics d;
  io::CheckInputText(text, "f", kExpected, d);
  return d.FormatAll();
}
std::string Pieces(std::string_view text, const std::vector<std::size_t>& cuts) {
  io::InputTextCheck check;
  std::size_t from = 0;
  for (const std::size_t cut : cuts) {
    check.Feed(text.substr(from, cut - from));
    from = cut;
  }
  check.Feed(text.substr(from));
  io::Diagnostics d;
  check.Finish("f", kExpected, d);
  return d.FormatAll();
}

// The bad inputs of the trajectory loader's and the command line's tests, and cases where a
// chunk's end falls inside what is checked (a UTF-8 sequence, a byte-order mark, a long line).
std::vector<std::pair<std::string, std::string>> BadTexts() {
  const std::string header = "t,px,py,pz,qw,qx,qy,qz\n";
  const std::string row0 = "0.000,0,0,0,1,0,0,0\n";
  std::vector<std::pair<std::string, std::string>> cases = {
      {"not a number", header + row0 + "0.001,0,abc,0,1,0,0,0\n"},
      {"nan", header + row0 + "0.001,nan,0,0,1,0,0,0\n"},
      {".nan", header + row0 + "0.001,.nan,0,0,1,0,0,0\n"},
      {"1e400", header + row0 + "0.001,1e400,0,0,1,0,0,0\n"},
      {"underflow", header + row0 + "0.001,1e-400,0,0,1,0,0,0\n"},
      {"time not increasing", header + row0 + "0.000,0,0,0,1,0,0,0\n"},
      {"gap", header + row0 + "0.2,0,0,0,1,0,0,0\n"},
      {"quaternion not unit", header + row0 + "0.001,0,0,0,0.5,0,0,0\n"},
      {"missing columns", "t,px,py,pz,qx,qy\n" + row0},
      {"duplicate column", "t,px,py,pz,qw,qx,qy,qz,px\n"},
      {"empty column name", "t,px,py,pz,qw,qx,qy,qz,\n" + row0},
      {"wrong field count", header + row0 + "0.001,0,0,0,1,0,0\n"},
      {"one sample", header + row0},
      {"no header", "# only a comment\n"},
      {"bad units", "# units: inch\n" + header + row0 + "0.001,0,0,0,1,0,0,0\n"},
      {"bad rate", "# rate: fast\n" + header + row0 + "0.001,0,0,0,1,0,0,0\n"},
      {"empty", ""},
      {"blank", "\n  \n\t\r\n"},
      {"binary", std::string("t,px\x00", 5) + "\n"},
      {"utf16le", std::string("\xFF\xFEt\x00,\x00", 6)},
      {"utf16be", std::string("\xFE\xFF\x00t", 4)},
      {"utf32", std::string("\xFF\xFE\x00\x00t\x00\x00\x00", 8)},
      {"utf-8 bom", "\xEF\xBB\xBF" + header + row0 + "0.001,0,0,0,1,0,0,0\n"},
      {"latin-1", header + row0 + "0.001,0,0,0,1,0,0,0 # caf\xE9\n"},
      {"overlong", header + "0,\xC0\xAF,0,0,1,0,0,0\n"},
      {"cut sequence at the end", header + row0 + "0.001,0,0,0,1,0,0,0\n\xE2\x82"},
      {"surrogate", header + "\xED\xA0\x80\n"},
      {"scene", "tubeplan: 1\nname: t\n"},
      {"no newline at the end", header + row0 + "0.001,0,0,0,1,0,0,0"},
      {"crlf", "t,px,py,pz,qw,qx,qy,qz\r\n0,0,0,0,1,0,0,0\r\n0.001,0,0,0,1,0,0,0\r\n"},
  };
  std::string capped = header + row0;
  for (int i = 1; i <= 60; ++i) capped += std::to_string(i * 1e-3) + ",x,0,0,1,0,0,0\n";
  cases.emplace_back("60 bad rows", capped);
  // Over several 64 KiB chunks, with the problems after the first chunk's end.
  std::string rows = header;
  for (int i = 0; i < 4000; ++i) rows += std::to_string(i * 1e-3) + ",0.1,0.2,0.3,1,0,0,0\n";
  cases.emplace_back("long and good", rows);
  cases.emplace_back("long line", rows + "0," + std::string(70000, '1') + ",0,0,1,0,0,0\n" + rows);
  cases.emplace_back("long blank line", std::string(70000, ' ') + "\n\n");
  cases.emplace_back("long then NUL", rows + std::string(70000, 'x') + std::string("\x00", 1));
  cases.emplace_back("NUL late", rows + std::string("4,0,0,0,1,0,0,\x00\n", 16));
  for (const std::size_t at : {std::size_t{65535}, std::size_t{65534}, std::size_t{65533}}) {
    // A three-byte character (U+20AC) across the first chunk's end, valid and broken.
    std::string valid = rows;
    valid.insert(at, "\xE2\x82\xAC");
    cases.emplace_back("euro at " + std::to_string(at), valid);
    std::string broken = rows;
    broken.insert(at,
                  "\xE2\x82"
                  "A");
    cases.emplace_back("broken euro at " + std::to_string(at), broken);
  }
  return cases;
}

// Every tick of the file at `step_s`, from the in-memory loader and TickStream.
std::vector<trajectories::HandSample> MemoryTicks(const std::string& path, double step_s) {
  const io::TrajectoryLoadResult loaded = io::LoadTrajectoryFile(path);
  REQUIRE(loaded.trajectory);
  trajectories::TickStream ticks(*loaded.trajectory, step_s);
  std::vector<trajectories::HandSample> out;
  for (std::size_t k = 0; k < ticks.count(); ++k) out.push_back(ticks.Tick(k));
  return out;
}

// The same from the streamed passes: ScanTrajectoryFile, then the rows again.
std::vector<trajectories::HandSample> StreamedTicks(const std::string& path, double step_s) {
  const io::TrajectoryScanResult scanned = io::ScanTrajectoryFile(path);
  REQUIRE(scanned.info);
  io::TrajectoryFileSamples samples(*scanned.info);
  trajectories::SampleTicks ticks(samples, scanned.info->t_first_s, scanned.info->t_last_s, step_s);
  std::vector<trajectories::HandSample> out;
  for (std::size_t k = 0; k < ticks.count(); ++k) out.push_back(ticks.Tick(k));
  return out;
}

}  // namespace

TEST_CASE("The input checks fed in pieces say exactly what they say of the whole text",
          "[trajectory][stream]") {
  for (const auto& [what, text] : BadTexts()) {
    CAPTURE(what);
    const std::string whole = Whole(text);
    // Every cut of short texts; one byte at a time; cuts around the chunk size.
    if (text.size() < 200) {
      for (std::size_t cut = 0; cut <= text.size(); ++cut) REQUIRE(Pieces(text, {cut}) == whole);
      std::vector<std::size_t> bytes;
      for (std::size_t i = 1; i < text.size(); ++i) bytes.push_back(i);
      REQUIRE(Pieces(text, bytes) == whole);
    } else {
      for (std::size_t cut = 65530; cut <= 65540 && cut <= text.size(); ++cut)
        REQUIRE(Pieces(text, {cut}) == whole);
      REQUIRE(Pieces(text, {1, 2, 3, std::min<std::size_t>(text.size(), 70001)}) == whole);
    }
  }
}

TEST_CASE("The streamed check of a trajectory file gives the in-memory loader's diagnostics",
          "[trajectory][stream]") {
  for (const auto& [what, text] : BadTexts()) {
    CAPTURE(what);
    const std::string path = Write("t.csv", text);
    const io::TrajectoryLoadResult loaded = io::LoadTrajectoryFile(path);
    const io::TrajectoryScanResult scanned = io::ScanTrajectoryFile(path);
    CHECK(scanned.diagnostics.FormatAll() == loaded.diagnostics.FormatAll());
    REQUIRE(scanned.info.has_value() == loaded.trajectory.has_value());
    if (!loaded.trajectory) continue;
    const trajectories::Trajectory& t = *loaded.trajectory;
    CHECK(scanned.info->sample_count == t.samples.size());
    CHECK(scanned.info->t_first_s == t.samples.front().t_s);
    CHECK(scanned.info->t_last_s == t.samples.back().t_s);
    CHECK(scanned.info->device == t.device);
    CHECK(scanned.info->nominal_rate_Hz == t.nominal_rate_Hz);
    CHECK(scanned.info->extra_columns == t.extra_columns);
  }
  // Files that cannot be read at all: the same words, and the reason apart for plan messages.
  for (const std::string& path :
       {Scratch().string(), std::string("/dev/zero"), (Scratch() / "missing.csv").string()}) {
    CAPTURE(path);
    const io::TrajectoryScanResult scanned = io::ScanTrajectoryFile(path);
    CHECK(scanned.diagnostics.FormatAll() == io::LoadTrajectoryFile(path).diagnostics.FormatAll());
    CHECK_FALSE(scanned.read_error.empty());
    CHECK_FALSE(scanned.info);
  }
  std::filesystem::remove_all(Scratch());
}

TEST_CASE("Damaged trajectory files get the same diagnostics streamed and in memory",
          "[trajectory][stream]") {
  // Every byte of a good file deleted or doubled in turn (the loader's own robustness test).
  const std::string good =
      "# rate: 1 kHz\n# units: mm\nt,px,py,pz,qw,qx,qy,qz,button\n0,0.1,0.2,0.3,1,0,0,0,0\n"
      "0.001,0.1,0.2,0.3,1,0,0,0,1\n";
  for (std::size_t i = 0; i < good.size(); ++i) {
    for (const std::string& text :
         {good.substr(0, i) + good.substr(i + 1), good.substr(0, i + 1) + good.substr(i)}) {
      CAPTURE(text);
      const std::string path = Write("d.csv", text);
      CHECK(io::ScanTrajectoryFile(path).diagnostics.FormatAll() ==
            io::LoadTrajectoryFile(path).diagnostics.FormatAll());
    }
  }
  std::filesystem::remove_all(Scratch());
}

TEST_CASE("A streamed replay of the shipped trajectories gives the in-memory ticks bit for bit",
          "[trajectory][stream]") {
  // groove-insert.csv is 450 KB: its rows cross several 64 KiB chunks. Steps: the scenes' 1 ms,
  // a finer and a coarser one that fall between the samples.
  for (const std::string file : {"plans/groove-insert.csv", "plans/groove-lay-flat.csv",
                                 "tests/data/trajectories/good.csv"}) {
    for (const double step_s : {1e-3, 3.7e-4, 2.5e-3}) {
      CAPTURE(file, step_s);
      const std::vector<trajectories::HandSample> memory = MemoryTicks(Source(file), step_s);
      const std::vector<trajectories::HandSample> streamed = StreamedTicks(Source(file), step_s);
      REQUIRE(streamed.size() == memory.size());
      for (std::size_t k = 0; k < memory.size(); ++k) {
        REQUIRE(streamed[k].t_s == memory[k].t_s);
        REQUIRE(streamed[k].p_WH_m == memory[k].p_WH_m);
        REQUIRE(streamed[k].q_WH.coeffs() == memory[k].q_WH.coeffs());
      }
    }
  }
}

TEST_CASE("A trajectory file changed between its check and its replay is an error",
          "[trajectory][stream]") {
  const std::string text = "t,px,py,pz,qw,qx,qy,qz\n0,0,0,0,1,0,0,0\n0.001,0,0,0,1,0,0,0\n";
  const std::string path = Write("c.csv", text);
  const io::TrajectoryScanResult scanned = io::ScanTrajectoryFile(path);
  REQUIRE(scanned.info);
  // A recorder that appended a row after the check.
  Write("c.csv", text + "0.002,0,0,0,1,0,0,0\n");
  CHECK_THROWS_WITH(io::TrajectoryFileSamples(*scanned.info),
                    path +
                        ": error: it was modified after it was checked, expected the trajectory "
                        "file to stay as it was while it is replayed");
  std::filesystem::remove(path);
  CHECK_THROWS_AS(io::TrajectoryFileSamples(*scanned.info), io::InputChanged);
  std::filesystem::remove_all(Scratch());
}

TEST_CASE("A line reader hands out every line, across chunks, whatever their length",
          "[files][stream]") {
  std::string text;
  std::vector<std::string> lines;
  for (int i = 0; i < 3000; ++i) {
    // Lengths from 0 to 299 bytes, so that lines start and end at every offset of a chunk.
    lines.push_back(
        std::string(static_cast<std::size_t>(i % 300), static_cast<char>('a' + i % 26)));
    text += lines.back() + "\n";
  }
  lines.push_back("last, without a newline");
  text += lines.back();
  const std::string path = Write("lines.txt", text);
  io::InputLineReader in;
  REQUIRE(in.Open(path).empty());
  std::string_view line;
  std::size_t n = 0;
  while (in.Next(line)) {
    REQUIRE(n < lines.size());
    REQUIRE(line == lines[n]);
    ++n;
  }
  CHECK(n == lines.size());
  CHECK(in.error().empty());
  io::Diagnostics d;
  CHECK(in.FinishCheck(path, "text", d));
  std::filesystem::remove_all(Scratch());
}

TEST_CASE("A hand faster than a haptic device is warned about once, at its sample", "[io]") {
  // 1 kHz; the hand still, then 10 mm in one sample (10 m/s) at line 5, then 6 mm (6 m/s).
  const std::string csv =
      "t,px,py,pz,qw,qx,qy,qz\n"
      "0.000,0,0,0.05,1,0,0,0\n"
      "0.001,0,0,0.05,1,0,0,0\n"
      "0.002,0,0.0019,0.05,1,0,0,0\n"
      "0.003,0,0.0119,0.05,1,0,0,0\n"
      "0.004,0,0.0179,0.05,1,0,0,0\n";
  const tubeplan::io::TrajectoryLoadResult loaded =
      tubeplan::io::LoadTrajectoryText(csv, "jump.csv");
  REQUIRE(loaded.trajectory);  // a warning, not an error: the replay still runs
  CHECK(loaded.diagnostics.FormatAll() ==
        "jump.csv:5:7: warning: the hand moves at 10 m/s before this sample, faster than the 2 "
        "m/s a hand moves a haptic device (a jump in the recording?)\n");
  // 1.9 m/s (the third row) is within what a hand does.
  const std::string slow = csv.substr(0, csv.find("0.003"));
  CHECK(tubeplan::io::LoadTrajectoryText(slow, "slow.csv").diagnostics.FormatAll() == "");
}
