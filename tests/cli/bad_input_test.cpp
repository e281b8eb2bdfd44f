// Bad input through the command line (docs/hardening.md): every case is a file a user or a
// device could hand the tool, with the exact message it must print and exit code 2. The messages
// are the contract: each says where, what is wrong, and what was expected.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

#include <catch2/catch.hpp>

#include "../scratch.hpp"
#include "cli/app.hpp"
#include "run_tool.hpp"

namespace {

using tubeplan::testing::Outcome;
using tubeplan::testing::RunTool;
using tubeplan::testing::SourcePath;

std::filesystem::path Scratch() { return tubeplan::testing::ScratchDir("bad-input"); }

std::string Write(const std::string& name, const std::string& bytes) {
  return tubeplan::testing::WriteScratch("bad-input", name, bytes);
}

// The scene of these tests: line 3 is the tube, so a bad tube value is reported on line 3.
const std::string kScene =
    "tubeplan: 1\n"
    "name: t\n"
    "tube: {outer_radius: 5 mm, inner_radius: 4 mm, length: LENGTH, youngs_modulus: 3 MPa, "
    "poisson_ratio: 0.5}\n"
    "parts:\n"
    "  - name: floor\n"
    "    box: {size: [60 mm, 200 mm, 10 mm], position: [0, 0, -5 mm]}\n"
    "start: {position: [0, -90 mm, 40 mm]}\n"
    "goal: \"{Fs - floor.top}\"\n";
// Where LENGTH starts on line 3 (1-based column).
const int kLengthColumn = static_cast<int>(kScene.find("LENGTH") - kScene.find("tube:")) + 1;

std::string SceneWithLength(const std::string& length) {
  std::string text = kScene;
  return text.replace(text.find("LENGTH"), 6, length);
}

const std::string kHeader = "t,px,py,pz,qw,qx,qy,qz\n";

struct Case {
  const char* name;  // the file name: its extension decides how `check` reads it
  std::string bytes;
  std::string message;  // after "<path>"
};

}  // namespace

TEST_CASE("check: bad files give exactly one clear message each and exit code 2", "[cli][limits]") {
  const std::string long_line = "name: " + std::string(70000, 'x') + "\n";
  const std::vector<Case> cases = {
      {"empty.yaml", "", ": error: the file is empty, expected a YAML scene file"},
      {"blank.yaml", "\n  \n\t\n", ": error: the file is blank, expected a YAML scene file"},
      {"empty.csv", "",
       ": error: the file is empty, expected a trajectory CSV (t,px,py,pz,qw,qx,qy,qz)"},
      {"binary.yaml",
       std::string("\x7f"
                   "ELF\x02\x01\x01\x00\x00\x00",
                   10),
       ":1:8: error: a NUL byte: this is a binary file, expected UTF-8 text: a YAML scene file"},
      {"binary.csv", std::string("t,px\x00", 5) + "\n",
       ":1:5: error: a NUL byte: this is a binary file, expected UTF-8 text: a trajectory CSV "
       "(t,px,py,pz,qw,qx,qy,qz)"},
      {"utf16.yaml", std::string("\xFF\xFEt\x00u\x00", 6),
       ":1:1: error: the file is UTF-16 (it starts with a byte-order mark), expected UTF-8 text: a "
       "YAML scene file"},
      {"utf16be.csv", std::string("\xFE\xFF\x00t", 4),
       ":1:1: error: the file is UTF-16 (it starts with a byte-order mark), expected UTF-8 text: a "
       "trajectory CSV (t,px,py,pz,qw,qx,qy,qz)"},
      {"utf32.yaml", std::string("\xFF\xFE\x00\x00t\x00\x00\x00", 8),
       ":1:1: error: the file is UTF-32 (it starts with a byte-order mark), expected UTF-8 text: a "
       "YAML scene file"},
      // Latin-1 "café": 0xE9 alone is not UTF-8 (it would open a three-byte sequence).
      {"latin1.yaml", "tubeplan: 1\nname: caf\xE9\n",
       ":2:10: error: invalid UTF-8 (byte 0xE9), expected UTF-8 text: a YAML scene file"},
      // An overlong encoding of '/' (0xC0 0xAF) is the classic way past a filter.
      {"overlong.csv", kHeader + "0,\xC0\xAF,0,0,1,0,0,0\n",
       ":2:3: error: invalid UTF-8 (byte 0xC0), expected UTF-8 text: a trajectory CSV "
       "(t,px,py,pz,qw,qx,qy,qz)"},
      {"long.yaml", long_line,
       ":1:1: error: line 1 is 70006 bytes long, expected at most 65536 bytes per line in a YAML "
       "scene file"},
      // A trajectory given where a scene belongs, and a scene where a trajectory belongs.
      {"trajectory.yaml", "# rate: 1 kHz\n" + kHeader + "0,0,0,0,1,0,0,0\n",
       ":2:1: error: a scene file must be a map, found a scalar, expected keys such as tubeplan, "
       "name, tube, parts"},
      {"scene.csv", kScene,
       ":1:1: error: this looks like YAML (a scene or plan file?), not a trajectory: the header "
       "lacks column(s) t, px, py, pz, qw, qx, qy, qz, expected t,px,py,pz,qw,qx,qy,qz (in any "
       "order, more allowed)"},
  };
  for (const Case& c : cases) {
    const std::string path = Write(c.name, c.bytes);
    const Outcome r = RunTool({"check", path});
    INFO(c.name);
    CHECK(r.exit_code == 2);
    CHECK(r.out.empty());
    CHECK(r.err == path + c.message + "\n");
  }
  std::filesystem::remove_all(Scratch());
}

TEST_CASE("check: NaN and infinity in every spelling, and numbers too large, are refused",
          "[cli][limits]") {
  // YAML's own spellings (.nan, .inf) and C's (nan, inf, infinity) in any case, with a sign, a
  // unit, or as an overflow: none of them may reach the core as a number.
  const std::string not_finite = "the number is not finite, expected a finite number";
  const std::string too_large = "the number is too large, expected a finite number";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"nan", not_finite},      {"NaN", not_finite},    {".nan", not_finite},
      {".NaN", not_finite},     {".NAN", not_finite},   {"-nan", not_finite},
      {"inf", not_finite},      {"-Inf", not_finite},   {"+INF", not_finite},
      {".inf", not_finite},     {"-.inf", not_finite},  {"+.Inf", not_finite},
      {"infinity", not_finite}, {"nan mm", not_finite}, {"1e400", too_large},
      {"1e999 mm", too_large},  {"-1e400", too_large},
  };
  for (const auto& [value, message] : cases) {
    const std::string path = Write("nan.yaml", SceneWithLength(value));
    const Outcome r = RunTool({"check", path});
    INFO(value);
    CHECK(r.exit_code == 2);
    CHECK(r.err ==
          path + ":3:" + std::to_string(kLengthColumn) + ": error: tube.length: " + message + "\n");
  }
  // A quantity too large only in SI (1e300 GPa) overflows after the unit is applied.
  const std::string path = Write("nan.yaml", SceneWithLength("1e300 Gm"));
  const Outcome r = RunTool({"check", path});
  CHECK(r.exit_code == 2);
  CHECK(r.err == path + ":3:" + std::to_string(kLengthColumn) +
                     ": error: tube.length: the quantity overflows in SI units, expected a finite "
                     "number\n");
  std::filesystem::remove_all(Scratch());
}

TEST_CASE("check: NaN and infinity in a trajectory, in every spelling", "[cli][limits]") {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"nan", "the number is not finite, expected a finite number"},
      {"NaN", "the number is not finite, expected a finite number"},
      {"-inf", "the number is not finite, expected a finite number"},
      {"Infinity", "the number is not finite, expected a finite number"},
      {"1e400", "the number is not finite, expected a finite number"},
      {".nan", "'.nan' is not a finite number, expected a finite decimal number"},
      {"-.Inf", "'-.Inf' is not a finite number, expected a finite decimal number"},
      {"0x1p3", "'0x1p3' is not a number, expected a decimal number"},
  };
  for (const auto& [value, message] : cases) {
    const std::string path =
        Write("nan.csv", kHeader + "0,0,0,0,1,0,0,0\n0.001," + value + ",0,0,1,0,0,0\n");
    const Outcome r = RunTool({"check", path});
    INFO(value);
    CHECK(r.exit_code == 2);
    CHECK(r.err == path + ":3:7: error: " + message + "\n");
  }
  // An underflow is zero, not an error: 1e-400 m is no distance at all.
  const std::string path =
      Write("tiny.csv", kHeader + "0,1e-400,0,0,1,0,0,0\n0.001,0,0,0,1,0,0,0\n");
  const Outcome r = RunTool({"check", path});
  CHECK(r.exit_code == 0);
  std::filesystem::remove_all(Scratch());
}

TEST_CASE("check: deeply nested and aliased YAML are refused before they are walked",
          "[cli][limits]") {
  // 100 levels: yaml-cpp parses it; our bound (64) refuses it at the 65th level.
  const std::string deep = "tubeplan: " + std::string(100, '[') + std::string(100, ']') + "\n";
  std::string path = Write("deep.yaml", deep);
  Outcome r = RunTool({"check", path});
  CHECK(r.exit_code == 2);
  CHECK(r.err == path +
                     ":1:75: error: nesting deeper than 64 levels, expected a scene file (a few "
                     "levels deep)\n");
  // 10000 levels: yaml-cpp's own guard (500 levels) stops its recursive parser first; the
  // message is the same, at the place yaml-cpp's scanner had reached (the end of the line: it
  // reads a flow collection's tokens before parsing them).
  const std::string deeper = "tubeplan: " + std::string(10000, '[') + std::string(10000, ']');
  path = Write("deeper.yaml", deeper);
  r = RunTool({"check", path});
  CHECK(r.exit_code == 2);
  CHECK(r.err == path +
                     ":1:20011: error: nesting deeper than 64 levels, expected a scene file (a few "
                     "levels deep)\n");
  // A billion laughs: nine levels of ten aliases each, 1e9 nodes to anything that walks them.
  std::string laughs = "a0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol, lol]\n";
  for (int i = 1; i <= 9; ++i) {
    const std::string prev = "*a" + std::to_string(i - 1);
    laughs += "a" + std::to_string(i) + ": &a" + std::to_string(i) + " [";
    for (int k = 0; k < 10; ++k) laughs += prev + (k < 9 ? ", " : "]\n");
  }
  path = Write("laughs.yaml", laughs);
  r = RunTool({"check", path});
  CHECK(r.exit_code == 2);
  CHECK(r.err.rfind(path + ":", 0) == 0);
  CHECK(r.err.find("error: the document expands to more than 100000 nodes (aliases repeat what "
                   "they name: a 'billion laughs'?), expected a scene file of ordinary size\n") !=
        std::string::npos);
  std::filesystem::remove_all(Scratch());
}

TEST_CASE("check: plans naming missing files, directories and devices", "[cli][limits]") {
  const std::string scene = SourcePath("scenes/groove.yaml");
  const std::string trajectory = SourcePath("plans/groove-insert.csv");
  auto plan = [](const std::string& scene_path, const std::string& trajectory_path) {
    return "tubeplan: 1\nplan: p\nscene: \"" + scene_path + "\"\ntrajectory: \"" + trajectory_path +
           "\"\nstates: [\"{}\", goal]\n";
  };
  // Paths are relative to the plan's directory; absolute ones are taken as they are.
  const std::string dir = Scratch().string();
  const std::vector<std::tuple<std::string, std::string, std::string>> cases = {
      {"missing.yaml", plan(dir + "/no-such.yaml", trajectory),
       ":3:8: error: scene: cannot read '" + dir +
           "/no-such.yaml' (no such file), expected a "
           "scene file path relative to the plan file"},
      {"directory.yaml", plan(scene, dir),
       ":4:13: error: trajectory: cannot read '" + dir +
           "' (it is a directory), expected a "
           "trajectory CSV path relative to the plan file"},
      // /dev/zero never ends: read, it would fill the memory; it is refused unread.
      {"device.yaml", plan(scene, "/dev/zero"),
       ":4:13: error: trajectory: cannot read '/dev/zero' (it is not a regular file (a device, "
       "FIFO or socket)), expected a trajectory CSV path relative to the plan file"},
  };
  for (const auto& [name, text, message] : cases) {
    const std::string path = Write(name, text);
    const Outcome r = RunTool({"check", path});
    INFO(name);
    CHECK(r.exit_code == 2);
    CHECK(r.err == path + message + "\n");
  }
  // A file without read permission (root reads it anyway, so only checked for other users).
  if (::geteuid() != 0) {
    const std::string locked = Write("locked.csv", "t\n");
    std::filesystem::permissions(locked, std::filesystem::perms::none);
    const Outcome r = RunTool({"check", locked});
    CHECK(r.exit_code == 2);
    CHECK(r.err == locked +
                       ": error: cannot read file (Permission denied), expected a readable CSV "
                       "trajectory\n");
  }
  std::filesystem::remove_all(Scratch());
}

TEST_CASE("graph --verdicts: a report it cannot read says which versions it reads",
          "[cli][limits]") {
  // A report of a later format: refused before the exploration, naming the versions graph reads
  // (1 to the version evaluate writes now).
  const std::string path = Write("later.json", "{\"tubeplan_evaluate\": 99, \"plans\": []}");
  const Outcome r =
      RunTool({"graph", SourcePath("scenes/shelf.yaml"), "--verdicts", path, "--budget", "1"});
  CHECK(r.exit_code == 2);
  CHECK(r.err == path +
                     ": error: not a readable tubeplan evaluate report, expected the JSON that "
                     "`tubeplan evaluate --report` writes (version 1 to 3)\n");
}
