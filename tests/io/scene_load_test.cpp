// Scene loading: the shipped scenes load, a good file gives exactly its SI values, and broken
// files give exactly the diagnostics a user should read (all of them, at the right line:col).
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include <tubeplan/core/core.hpp>
#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/scene/elements.hpp>
#include <tubeplan/scene/scene.hpp>

#include "../scratch.hpp"
#include "mesh_test_meshes.hpp"

namespace {

using tubeplan::io::LoadSceneFile;
using tubeplan::io::LoadSceneText;

std::string SourcePath(const std::string& relative) {
  return std::string(TUBEPLAN_SOURCE_DIR) + "/" + relative;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// A minimal valid scene; the broken cases below edit one line of it, so the line numbers in the
// expected messages are this text's (line 1 is "tubeplan: 1").
const std::string kMinimal =
    "tubeplan: 1\n"
    "name: t\n"
    "tube: {outer_radius: 5 mm, inner_radius: 4 mm, length: 150 mm, youngs_modulus: 3 MPa, "
    "poisson_ratio: 0.5}\n"
    "friction: {static: 0.7, kinetic: 0.08}\n"
    "parts:\n"
    "  - name: floor\n"
    "    box: {size: [60 mm, 200 mm, 10 mm], position: [0, 0, -5 mm]}\n"
    "  - name: wall\n"
    "    box: {size: [10 mm, 200 mm, 20 mm], position: [15 mm, 0, 10 mm]}\n"
    "start: {position: [0, -90 mm, 40 mm]}\n"
    "goal: \"{Fs - floor.top}\"\n";

// `text` with its line `line` (1-based) replaced.
std::string ReplaceLine(const std::string& text, int line, const std::string& replacement) {
  std::istringstream in(text);
  std::string out, l;
  for (int i = 1; std::getline(in, l); ++i) out += (i == line ? replacement : l) + "\n";
  return out;
}

// kMinimal with its line `line` (1-based) replaced.
std::string WithLine(int line, const std::string& replacement) {
  return ReplaceLine(kMinimal, line, replacement);
}

}  // namespace

TEST_CASE("Every shipped scene loads without a diagnostic", "[scene]") {
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(SourcePath("scenes"))) {
    if (entry.path().extension() != ".yaml") continue;
    CAPTURE(entry.path().string());
    const auto loaded = LoadSceneFile(entry.path());
    CHECK(loaded.diagnostics.FormatAll() == "");
    CHECK(loaded.scene.has_value());
    ++count;
  }
  CHECK(count >= 2);
}

TEST_CASE("The minimal scene of these tests is valid", "[scene]") {
  const auto loaded = LoadSceneText(kMinimal, "t.yaml");
  CHECK(loaded.diagnostics.FormatAll() == "");
  REQUIRE(loaded.scene);
  // No device or model section: the documented defaults.
  CHECK(loaded.scene->device.max_force_N == 8.5);
  CHECK_FALSE(loaded.scene->device.coupling_stiffness_N_per_m.has_value());
  CHECK(loaded.scene->model.tube == tubeplan::scene::TubeModel::kRod);
  CHECK(loaded.scene->model.elements == 0);
  CHECK(loaded.scene->friction.exponent == 1.0);
}

TEST_CASE("A model option that chooses nothing warns and loads", "[scene]") {
  const auto loaded = LoadSceneText(kMinimal + "model: {capsules: 16, elements: 24}\n", "t.yaml");
  REQUIRE(loaded.scene);
  CHECK(loaded.diagnostics.FormatAll() ==
        "t.yaml:12:19: warning: model.capsules has no effect: the core solves the rod and all its "
        "contacts together (model.elements sets the rod's resolution)\n");
  CHECK(loaded.scene->model.elements == 24);
}

TEST_CASE("An element count beyond the tube's length over its radius is said", "[scene]") {
  // 150 mm over 5 mm: at most 30 elements.
  const auto loaded = LoadSceneText(kMinimal + "model: {elements: 48}\n", "t.yaml");
  REQUIRE(loaded.scene);
  CHECK(loaded.diagnostics.FormatAll() ==
        "t.yaml:12:19: warning: model.elements 48 asks for elements shorter than the tube's outer "
        "radius; the core uses 30 (at most length / outer_radius, so that a side's contact stays "
        "off the end face)\n");
  CHECK(tubeplan::core::ElementCount(*loaded.scene) == 30);
}

TEST_CASE("A part too thin for the contact to hold the device's force is said", "[scene]") {
  // The wall 2 mm thick at the default contact (K = 10 N/mm, eps = 1 mm): 10 N/mm x 2 mm = 20 N
  // holds the device's 8.5 N; at eps = 0.1 mm and K = 5 N/mm, 5 x 1.1 = 5.5 N does not.
  const std::string thin =
      WithLine(9, "    box: {size: [2 mm, 200 mm, 20 mm], position: [15 mm, 0, 10 mm]}");
  const auto held = LoadSceneText(thin, "t.yaml");
  REQUIRE(held.scene);
  CHECK(held.diagnostics.FormatAll() == "");
  const auto soft =
      LoadSceneText(thin + "contact: {stiffness: 5 N/mm, threshold: 0.1 mm}\n", "t.yaml");
  REQUIRE(soft.scene);
  CHECK(soft.diagnostics.FormatAll() ==
        "t.yaml:12:10: warning: part wall is 2 mm thin: the contact holds K (eps + half of it) = "
        "5.5 N at its middle, less than the device's 8.5 N, so a full push can carry the tube "
        "through it; expected a thicker part or a stiffer contact\n");
}

TEST_CASE("A contact band as wide as the tube is said", "[scene]") {
  const auto loaded = LoadSceneText(kMinimal + "contact: {threshold: 6 mm}\n", "t.yaml");
  REQUIRE(loaded.scene);
  CHECK(loaded.diagnostics.FormatAll() ==
        "t.yaml:12:10: warning: contact.threshold 6 mm is not below the tube's outer radius (5 "
        "mm): the contact band is wider than the tube, so PCs and forces reach parts the tube "
        "does not touch; expected a threshold well below the radius (the paper's 1 mm)\n");
}

TEST_CASE("A good scene gives exactly its SI values", "[scene]") {
  const auto loaded = LoadSceneFile(SourcePath("tests/data/scenes/good.yaml"));
  REQUIRE(loaded.diagnostics.FormatAll() == "");
  REQUIRE(loaded.scene);
  const tubeplan::scene::Scene& s = *loaded.scene;
  // Each value is one conversion of a short decimal: equal to the double literal, or within an
  // ulp or two where the conversion multiplies by 1e-3 (Approx with 1e-15 relative).
  const auto mm = [](double v) { return Approx(v * 1e-3).epsilon(1e-15); };
  CHECK(s.name == "good");
  CHECK(s.tube.outer_radius_m == mm(5));
  CHECK(s.tube.inner_radius_m == mm(4));
  CHECK(s.tube.length_m == mm(150));
  CHECK(s.tube.youngs_modulus_Pa == 3e6);
  CHECK(s.tube.poisson_ratio == 0.5);
  CHECK(s.contact.stiffness_N_per_m == Approx(1e4).epsilon(1e-15));
  CHECK(s.contact.threshold_m == mm(1));
  CHECK(s.friction.static_coefficient == 0.7);
  CHECK(s.friction.kinetic_coefficient == 0.08);
  CHECK(s.friction.exponent == 0.6667);
  CHECK(s.friction.reference_load_N == 1.0);
  REQUIRE(s.parts.size() == 2);
  CHECK(s.parts[1].name == "wall");
  CHECK(s.parts[1].face_names[3] == "inner");  // xneg renamed
  REQUIRE(s.parts[1].friction);
  CHECK(s.parts[1].friction->static_coefficient == 0.5);
  CHECK_FALSE(s.parts[0].friction);
  // rpy [0, 0, 90 deg]: the wall's x axis along world y, its y axis along world -x.
  const Eigen::Matrix3d R = s.parts[1].X_WP.linear();
  CHECK((R.col(0) - Eigen::Vector3d::UnitY()).norm() < 1e-15);
  CHECK((R.col(1) + Eigen::Vector3d::UnitX()).norm() < 1e-15);
  CHECK(s.parts[1].X_WP.translation().x() == mm(15));
  // Start: roll -90 deg turns the tube's axis (z) onto world +y.
  CHECK((s.X_WH_start.linear().col(2) - Eigen::Vector3d::UnitY()).norm() < 1e-15);
  CHECK(s.X_WH_start.translation().y() == mm(-90));
  CHECK(tubeplan::states::ToString(s.goal) == "{Fs - floor.top, Fs u wall.top_inner}");
  CHECK(s.device.coupling_stiffness_N_per_m == 400.0);
  CHECK(s.device.coupling_damping_Ns_per_m == 2.0);
  CHECK(s.model.tube == tubeplan::scene::TubeModel::kRod);
  CHECK(s.model.time_step_s == 1e-3);
}

TEST_CASE("Broken scenes get exactly the right diagnostics", "[scene]") {
  struct Case {
    const char* what;
    std::string text;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"YAML syntax",
       WithLine(7, "    box: {size: [60 mm, 200 mm, 10 mm], position: [0, 0, -5 mm]"),
       "t.yaml:8:3: error: illegal block entry, expected valid YAML\n"},
      {"unsupported version", WithLine(1, "tubeplan: 2"),
       "t.yaml:1:11: error: unsupported format version 2, expected 1\n"},
      {"unknown key with a suggestion", WithLine(4, "frction: {static: 0.7, kinetic: 0.08}"),
       "t.yaml:4:1: error: unknown key 'frction' in 'scene', did you mean 'friction'? (expected "
       "one of: tubeplan, name, tube, contact, friction, parts, start, goal, device, model, "
       "workspace, heuristics)\n"},
      {"negative heuristic weight", WithLine(4, "heuristics: {friction: -1, energy: 1}"),
       "t.yaml:4:24: error: heuristics.friction must be a weight between 0 and 1e6, expected "
       "e.g. 1\n"},
      {"missing key",
       WithLine(3,
                "tube: {outer_radius: 5 mm, inner_radius: 4 mm, youngs_modulus: 3 MPa, "
                "poisson_ratio: 0.5}"),
       "t.yaml:3:7: error: missing key 'length' in 'tube'\n"},
      {"wrong dimension",
       WithLine(3,
                "tube: {outer_radius: 5 N, inner_radius: 4 mm, length: 150 mm, "
                "youngs_modulus: 3 MPa, poisson_ratio: 0.5}"),
       "t.yaml:3:24: error: tube.outer_radius: has a unit of force (N), expected a length such "
       "as \"5 mm\"\n"},
      {"wrong type",
       WithLine(3,
                "tube: {outer_radius: [5 mm], inner_radius: 4 mm, length: 150 mm, "
                "youngs_modulus: 3 MPa, poisson_ratio: 0.5}"),
       "t.yaml:3:22: error: tube.outer_radius must be a quantity (a number or a string such as "
       "\"5 mm\"), found a sequence\n"},
      {"inner radius not below the outer",
       WithLine(3,
                "tube: {outer_radius: 5 mm, inner_radius: 5 mm, length: 150 mm, "
                "youngs_modulus: 3 MPa, poisson_ratio: 0.5}"),
       "t.yaml:3:42: error: tube.inner_radius (5 mm) must be smaller than outer_radius (5 mm)\n"},
      {"Poisson's ratio out of range",
       WithLine(3,
                "tube: {outer_radius: 5 mm, inner_radius: 4 mm, length: 150 mm, "
                "youngs_modulus: 3 MPa, poisson_ratio: 0.7}"),
       "t.yaml:3:102: error: tube.poisson_ratio (0.7) must be in [0, 0.5]\n"},
      {"NaN", WithLine(4, "friction: {static: nan, kinetic: 0.08}"),
       "t.yaml:4:20: error: friction.static: the number is not finite, expected a finite "
       "number\n"},
      {"kinetic above static", WithLine(4, "friction: {static: 0.3, kinetic: 0.5}"),
       "t.yaml:4:34: error: friction.kinetic (0.5) must not exceed static (0.3): sliding "
       "friction is at most the friction that holds\n"},
      {"overlapping parts",
       WithLine(9, "    box: {size: [10 mm, 200 mm, 20 mm], position: [15 mm, 0, 9 mm]}"),
       "t.yaml:9:51: error: part 'wall' overlaps part 'floor', expected parts that at most "
       "touch\n"},
      {"start inside a part", WithLine(10, "start: {position: [15 mm, 0, 10 mm]}"),
       "t.yaml:10:19: error: start.position is inside part 'wall', expected the held end "
       "outside every part\n"},
      {"goal names an unknown element", WithLine(11, "goal: \"{Fs - floor.topp}\""),
       "t.yaml:11:14: error: goal: no element 'floor.topp' in this scene, did you mean "
       "'floor.top'? (expected part.face, part.face_face or part.face_face_face)\n"},
      {"goal with a marker an end face cannot take", WithLine(11, "goal: \"{Fe u floor.top}\""),
       "t.yaml:11:"},  // column and message from the CF parser: checked by prefix below
      {"coupling stiffer than the device",
       kMinimal + "device: {max_stiffness: 800 N/m, coupling: {stiffness: 1 kN/m}}\n",
       "t.yaml:12:56: error: device.coupling.stiffness (1000 N/m) exceeds device.max_stiffness "
       "(800 N/m), expected at most the device's limit\n"},
      {"coupling that is not passive",
       kMinimal +
           "device: {damping: 1 N s/m, coupling: {stiffness: 500 N/m, damping: 0.9 N s/m}}\n",
       "t.yaml:12:38: error: device.coupling (500 N/m, 0.9 N s/m) is not passive at a 1 ms step: "
       "the device's damping 1 N s/m must exceed K T / 2 + |B| = 1.15 N s/m, expected a softer "
       "spring or less coupling damping\n"},
      {"unknown model", kMinimal + "model: {beam: timoshenko}\n",
       "t.yaml:12:15: error: model.beam 'timoshenko' is not known (expected one of: rod, "
       "elastica, linear)\n"},
      {"element count beyond the core's", kMinimal + "model: {elements: 200}\n",
       "t.yaml:12:19: error: model.elements 200 is not a count the core supports, expected "
       "\"auto\" or a whole number from 4 to 96\n"},
      {"element count not whole", kMinimal + "model: {elements: 12.5}\n",
       "t.yaml:12:19: error: model.elements 12.5 is not a count the core supports, expected "
       "\"auto\" or a whole number from 4 to 96\n"},
      {"element count not a scalar", kMinimal + "model: {elements: [16]}\n",
       "t.yaml:12:19: error: model.elements must be a count, found a sequence, expected \"auto\" "
       "or a whole number from 4 to 96\n"},
      {"top level not a map", "- 1\n- 2\n",
       "t.yaml:1:1: error: a scene file must be a map, found a sequence, expected keys such as "
       "tubeplan, name, tube, parts\n"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.what, c.text);
    const auto loaded = LoadSceneText(c.text, "t.yaml");
    CHECK_FALSE(loaded.scene);
    const std::string got = loaded.diagnostics.FormatAll();
    if (c.expected.back() == '\n') {
      CHECK(got == c.expected);
    } else {
      CHECK_THAT(got, Catch::StartsWith(c.expected));
      CHECK(std::count(got.begin(), got.end(), '\n') == 1);
    }
  }
}

TEST_CASE("Every problem in a file is reported at once", "[scene]") {
  std::string text = WithLine(3,
                              "tube: {outer_radius: 5 mm, inner_radius: 6 mm, length: 5 N, "
                              "youngs_modulus: -3 MPa, poisson_ratio: 0.5}");
  text = text + "colour: red\n";
  const auto loaded = LoadSceneText(text, "t.yaml");
  CHECK_FALSE(loaded.scene);
  // r2 >= r1, length with a force unit, negative E, unknown key: four, in file order.
  CHECK(loaded.diagnostics.FormatAll() ==
        "t.yaml:3:42: error: tube.inner_radius (6 mm) must be smaller than outer_radius (5 mm)\n"
        "t.yaml:3:58: error: tube.length: has a unit of force (N), expected a length such as "
        "\"5 mm\"\n"
        "t.yaml:3:77: error: tube.youngs_modulus (-3 MPa) must be a finite number greater than "
        "zero\n"
        "t.yaml:12:1: error: unknown key 'colour' in 'scene' (expected one of: tubeplan, name, "
        "tube, contact, friction, parts, start, goal, device, model, workspace, heuristics)\n");
}

TEST_CASE("An unreadable file is one error for the whole file", "[scene]") {
  const auto loaded = LoadSceneFile("no/such/scene.yaml");
  CHECK_FALSE(loaded.scene);
  CHECK(loaded.diagnostics.FormatAll() ==
        "no/such/scene.yaml: error: cannot read file (no such file), expected a readable YAML "
        "scene file\n");
}

TEST_CASE("Damaged scenes never throw and never load half-checked", "[scene]") {
  // Every one-byte deletion and duplication of a good file: the loader must return either a
  // scene with no error or at least one error, and never throw or crash (ASan build included).
  const std::string good = ReadText(SourcePath("tests/data/scenes/good.yaml"));
  REQUIRE(good.size() > 100);
  int loaded_count = 0, rejected = 0;
  for (std::size_t i = 0; i < good.size(); ++i) {
    for (const std::string& text :
         {good.substr(0, i) + good.substr(i + 1), good.substr(0, i + 1) + good.substr(i)}) {
      tubeplan::io::SceneLoadResult result;
      REQUIRE_NOTHROW(result = LoadSceneText(text, "fuzz.yaml"));
      CHECK(result.scene.has_value() != result.diagnostics.HasErrors());
      (result.scene ? loaded_count : rejected) += 1;
    }
  }
  // Most damage must be caught (comments and spaces are harmless, most other bytes are not).
  CHECK(rejected > loaded_count);
}

TEST_CASE("The tube's body at the start must be clear of every part", "[scene]") {
  const auto load = [](const std::string& start) {
    return LoadSceneText(WithLine(10, start), "t.yaml").diagnostics.FormatAll();
  };
  const std::string body =
      " (the straight tube from start.position along its own +z, 150 mm long, outer radius 5 mm), "
      "expected the tube's body clear of every part at the start\n";
  // Along +y, 3 mm above the floor: its lower side 2 mm into it (only the held end was checked).
  CHECK(load("start: {position: [0, -90 mm, 3 mm], rpy: [-90 deg, 0, 0]}") ==
        "t.yaml:10:19: error: the tube at its start goes into part 'floor' by 2 mm" + body);
  // Resting on the floor (touching) is fine.
  CHECK(load("start: {position: [0, -90 mm, 5 mm], rpy: [-90 deg, 0, 0]}") == "");
  // Pushed end first into the wall's near face: across the axis; its flat tip exactly on the
  // face is fine (a capsule's round end would be 5 mm into the wall).
  CHECK(load("start: {position: [15 mm, -249 mm, 10 mm], rpy: [-90 deg, 0, 0]}") ==
        "t.yaml:10:19: error: the tube at its start goes into part 'wall' across its axis" + body);
  CHECK(load("start: {position: [15 mm, -250 mm, 10 mm], rpy: [-90 deg, 0, 0]}") == "");
  // The held end inside a part is said once, as before, not again for the body.
  CHECK(load("start: {position: [15 mm, 0, 10 mm], rpy: [-90 deg, 0, 0]}") ==
        "t.yaml:10:19: error: start.position is inside part 'wall', expected the held end outside "
        "every part\n");
}

TEST_CASE("A start outside the workspace is an error", "[scene]") {
  const std::string text =
      kMinimal + "workspace: {min: [-100 mm, -100 mm, -10 mm], max: [100 mm, 100 mm, 30 mm]}\n";
  CHECK(LoadSceneText(text, "t.yaml").diagnostics.FormatAll() ==
        "t.yaml:10:19: error: start.position [0, -90, 40] mm is outside the workspace (min [-100, "
        "-100, -10] mm, max [100, 100, 30] mm), expected the held end's start inside it\n");
  const std::string inside =
      kMinimal + "workspace: {min: [-100 mm, -100 mm, -10 mm], max: [100 mm, 100 mm, 50 mm]}\n";
  CHECK(LoadSceneText(inside, "t.yaml").diagnostics.FormatAll() == "");
}

TEST_CASE("A second YAML document and YAML tags are errors, not ignored", "[scene]") {
  CHECK(LoadSceneText(kMinimal + "---\nname: other\n", "t.yaml").diagnostics.FormatAll() ==
        "t.yaml:12:1: error: a second YAML document starts here, expected a scene file as one "
        "document (no '---' after its start)\n");
  // An invalid later document is reported, not skipped.
  const auto broken = LoadSceneText(kMinimal + "---\nname: [\n", "t.yaml");
  CHECK_FALSE(broken.scene);
  CHECK_THAT(broken.diagnostics.FormatAll(), Catch::Contains("expected valid YAML"));
  CHECK(LoadSceneText(WithLine(2, "name: !custom t"), "t.yaml").diagnostics.FormatAll() ==
        "t.yaml:2:7: error: unknown tag '!custom', expected a scene file without tags (plain "
        "values such as 5 mm or \"5 mm\")\n");
  CHECK_FALSE(LoadSceneText(WithLine(2, "name: !!str t"), "t.yaml").scene);
}

TEST_CASE("Angles are finite and within a turn either way", "[scene]") {
  CHECK(LoadSceneText(WithLine(10, "start: {position: [0, -90 mm, 40 mm], rpy: [-1e20 deg, 0, 7]}"),
                      "t.yaml")
            .diagnostics.FormatAll() ==
        "t.yaml:10:45: error: start.rpy[0] -1e20 deg is out of range, expected an angle from "
        "-360 deg to 360 deg\n"
        "t.yaml:10:59: error: start.rpy[2] 7 rad is out of range, expected an angle from -360 deg "
        "to 360 deg\n");
  CHECK(LoadSceneText(WithLine(10, "start: {position: [0, -90 mm, 40 mm], rpy: [360 deg, 0, 0]}"),
                      "t.yaml")
            .scene);
  CHECK(LoadSceneText(WithLine(9,
                               "    box: {size: [10 mm, 200 mm, 20 mm], position: [15 mm, 0, "
                               "10 mm], rpy: [0, 0, 361 deg]}"),
                      "t.yaml")
            .diagnostics.FormatAll() ==
        "t.yaml:9:82: error: parts[1].box.rpy[2] 361 deg is out of range, expected an angle from "
        "-360 deg to 360 deg\n");
}

TEST_CASE("Friction and tube messages say one thing each, with the values as written", "[scene]") {
  // A negative static friction is one error, with no follow-on about the kinetic one.
  CHECK(LoadSceneText(WithLine(4, "friction: {static: -0.1, kinetic: 0.08}"), "t.yaml")
            .diagnostics.FormatAll() ==
        "t.yaml:4:20: error: friction.static must be zero or more\n");
  // Values as the file wrote them, a plain number with its SI unit.
  CHECK(LoadSceneText(WithLine(3,
                               "tube: {outer_radius: -0.008, inner_radius: 4 mm, length: "
                               "-150 mm, youngs_modulus: 3 MPa, poisson_ratio: 0.5}"),
                      "t.yaml")
            .diagnostics.FormatAll() ==
        "t.yaml:3:22: error: tube.outer_radius (-0.008 m) must be a finite number greater than "
        "zero\n"
        "t.yaml:3:58: error: tube.length (-150 mm) must be a finite number greater than zero\n");
}

TEST_CASE("A scene of more than 1000 parts is refused at the part too many", "[scene]") {
  std::string parts;
  for (int i = 0; i < 1001; ++i)
    parts += "  - {name: p" + std::to_string(i) + ", box: {size: [1 mm, 1 mm, 1 mm], position: [" +
             std::to_string(2 * (i % 40)) + " mm, " + std::to_string(2 * (i / 40)) +
             " mm, 100 mm]}}\n";
  const std::string head = kMinimal.substr(0, kMinimal.find("start:"));
  const std::string tail = kMinimal.substr(kMinimal.find("start:"));
  CHECK(LoadSceneText(head + parts + tail, "t.yaml").diagnostics.FormatAll() ==
        "t.yaml:1008:5: error: parts[1000] is one part too many: 1003 parts, expected at most "
        "1000 (docs/scene-format.md says why)\n");
  // A thousand load, and one overlapping pair among them is found and named.
  std::string overlapping = parts.substr(0, parts.find("  - {name: p997,"));
  overlapping += "  - {name: q, box: {size: [1 mm, 1 mm, 1 mm], position: [0.5 mm, 0, 100 mm]}}\n";
  const auto loaded = LoadSceneText(head + overlapping + tail, "t.yaml");
  CHECK(loaded.diagnostics.FormatAll() ==
        "t.yaml:1007:57: error: part 'q' overlaps part 'p0', expected parts that at most touch\n");
}

TEST_CASE("A cylinder part loads with its size, pose, faces and elements", "[scene]") {
  // A round post on the floor in place of the wall, its side renamed.
  const std::string text =
      WithLine(9,
               "    cylinder: {radius: 6 mm, length: 20 mm, position: [15 mm, 0, 10 mm], "
               "rpy: [0, 90 deg, 0]}\n    faces: {side: barrel}");
  const auto loaded = LoadSceneText(text, "t.yaml");
  CHECK(loaded.diagnostics.FormatAll() == "");
  REQUIRE(loaded.scene);
  const tubeplan::scene::Part& post = loaded.scene->parts[1];
  CHECK(post.shape == tubeplan::scene::PartShape::kCylinder);
  CHECK(post.size_m.isApprox(Eigen::Vector3d(12e-3, 12e-3, 20e-3), 1e-12));
  // Turned 90 deg about y: the post's axis (its z) along world x.
  CHECK((post.X_WP.linear().col(2) - Eigen::Vector3d::UnitX()).norm() < 1e-12);
  std::vector<std::string> names;
  for (const auto& e : tubeplan::scene::EnumerateElements(*loaded.scene))
    if (e.part_index == 1) names.push_back(e.name);
  CHECK(names == std::vector<std::string>{"wall.top", "wall.bottom", "wall.barrel",
                                          "wall.top_barrel", "wall.bottom_barrel"});
}

TEST_CASE("A part's shape is exactly one box or one cylinder of positive size", "[scene]") {
  struct Case {
    const char* what;
    std::string text;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"both shapes",
       WithLine(9,
                "    box: {size: [10 mm, 200 mm, 20 mm]}\n"
                "    cylinder: {radius: 6 mm, length: 20 mm}"),
       "t.yaml:10:15: error: parts[1] has both a box and a cylinder, expected exactly one of "
       "'box', 'cylinder' and 'mesh'\n"},
      {"no shape", WithLine(9, "    friction: {static: 0.7, kinetic: 0.08}"),
       "t.yaml:8:5: error: parts[1] has no shape, expected exactly one of 'box', 'cylinder' and "
       "'mesh'\n"},
      {"zero radius",
       WithLine(9, "    cylinder: {radius: 0 mm, length: 20 mm, position: [15 mm, 0, 10 mm]}"),
       "t.yaml:9:24: error: parts[1].cylinder.radius must be greater than zero, expected a length "
       "such as 10 mm\n"},
      {"a box's key on a cylinder",
       WithLine(9, "    cylinder: {size: [1 mm, 1 mm, 1 mm], radius: 6 mm, length: 20 mm}"),
       "t.yaml:9:16: error: unknown key 'size' in 'parts[1].cylinder'"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.what, c.text);
    const auto loaded = LoadSceneText(c.text, "t.yaml");
    CHECK_FALSE(loaded.scene);
    const std::string got = loaded.diagnostics.FormatAll();
    if (c.expected.back() == '\n')
      CHECK(got == c.expected);
    else
      CHECK_THAT(got, Catch::StartsWith(c.expected));
  }
}

TEST_CASE("The held end is inside a cylinder by its round side, not by its box", "[scene]") {
  // A post standing along z, 10 mm round, in place of the wall; the held end beside it, within
  // its bounding box's corner but 13 mm from its axis, the tube pointing away along +x: valid.
  // 3.6 mm from the axis instead: inside the post.
  const auto with_start = [](const std::string& position) {
    std::string text =
        WithLine(9, "    cylinder: {radius: 10 mm, length: 20 mm, position: [15 mm, 0, 50 mm]}");
    text.erase(text.find("start:"));
    return text + "start: {position: " + position + ", rpy: [0, 90 deg, 0]}\n" +
           "goal: \"{Fs - floor.top}\"\n";
  };
  const auto beside = LoadSceneText(with_start("[24 mm, 9.5 mm, 45 mm]"), "t.yaml");
  CHECK(beside.diagnostics.FormatAll() == "");
  CHECK(beside.scene.has_value());
  const auto inside = LoadSceneText(with_start("[17 mm, 3 mm, 45 mm]"), "t.yaml");
  CHECK_THAT(inside.diagnostics.FormatAll(),
             Catch::Contains("start.position is inside part 'wall', expected the held end "
                             "outside every part"));
}

namespace {

// The shipped clip (scenes/clip.obj, millimetres) on a floor of two slabs with a 10 mm gap for
// its post (radius 3 mm, 5 mm under its base); its channel runs along y from 20 to 40 mm. Line
// numbers in the messages below are this text's.
const std::string kClipScene =
    "tubeplan: 1\n"
    "name: t\n"
    "tube: {outer_radius: 5 mm, inner_radius: 4 mm, length: 150 mm, youngs_modulus: 3 MPa, "
    "poisson_ratio: 0.5}\n"
    "friction: {static: 0.7, kinetic: 0.08}\n"
    "parts:\n"
    "  - name: floor\n"
    "    box: {size: [25 mm, 200 mm, 10 mm], position: [-17.5 mm, 0, -5 mm]}\n"
    "  - name: right\n"
    "    box: {size: [25 mm, 200 mm, 10 mm], position: [17.5 mm, 0, -5 mm]}\n"
    "  - name: clip\n"
    "    mesh: {file: clip.obj, scale: 0.001, position: [0, 20 mm, 0]}\n"
    "start: {position: [0, -90 mm, 40 mm]}\n"
    "goal: \"{Fs - clip.floor}\"\n";

std::string ClipSceneWith(int line, const std::string& replacement) {
  return ReplaceLine(kClipScene, line, replacement);
}

}  // namespace

TEST_CASE("A mesh part loads from its file with its elements named by the file", "[scene]") {
  const auto loaded = LoadSceneText(kClipScene, "t.yaml", SourcePath("scenes"));
  CHECK(loaded.diagnostics.FormatAll() == "");
  REQUIRE(loaded.scene);
  const tubeplan::scene::Part& clip = loaded.scene->parts[2];
  CHECK(clip.shape == tubeplan::scene::PartShape::kMesh);
  REQUIRE(clip.mesh);
  CHECK(clip.mesh->file == "clip.obj");
  // 21 x 20 x 27 mm (post included) in millimetres scaled to metres, placed 20 mm along y.
  CHECK(clip.size_m.isApprox(Eigen::Vector3d(0.021, 0.020, 0.027), 1e-12));
  CHECK(clip.X_WP.translation().isApprox(Eigen::Vector3d(0, 0.020, 0), 1e-12));
  // Its 16 faces, 38 edges and 24 vertices (tests/io/clip_mesh_test.cpp), as "clip.<name>".
  std::vector<std::string> names;
  for (const auto& e : tubeplan::scene::EnumerateElements(*loaded.scene))
    if (e.part_index == 2) names.push_back(e.name);
  REQUIRE(names.size() == 16 + 38 + 24);
  CHECK(names.front() == "clip.bottom");
  CHECK(std::count(names.begin(), names.end(), "clip.right_lip_right_inner") == 1);
  // The same file as a length, "1 mm": the same part.
  const auto as_length = LoadSceneText(
      ClipSceneWith(11, "    mesh: {file: clip.obj, scale: 1 mm, position: [0, 20 mm, 0]}"),
      "t.yaml", SourcePath("scenes"));
  REQUIRE(as_length.scene);
  CHECK(as_length.scene->parts[2].size_m == clip.size_m);
}

TEST_CASE("A scene file's mesh is read relative to the scene file's directory", "[scene]") {
  // The scene and a cube (1 m, scale 0.01: 10 mm) in a scratch directory, read from elsewhere.
  const std::string scene_path = tubeplan::testing::WriteScratch(
      "mesh-scene", "cube-scene.yaml",
      WithLine(9, "    mesh: {file: cube.obj, scale: 0.01, position: [15 mm, 0, 0]}"));
  tubeplan::testing::WriteScratch("mesh-scene", "cube.obj", tubeplan::testing::CubeObj());
  const auto loaded = LoadSceneFile(scene_path);
  CHECK(loaded.diagnostics.FormatAll() == "");
  REQUIRE(loaded.scene);
  CHECK(loaded.scene->parts[1].size_m.isApprox(Eigen::Vector3d::Constant(0.01), 1e-12));
  // The cube's faces are named by its groups.
  CHECK(tubeplan::scene::FindElement(tubeplan::scene::EnumerateElements(*loaded.scene),
                                     "wall.top_xpos_ypos") >= 0);
}

TEST_CASE("A mesh of more elements than the core can number is refused at its file", "[scene]") {
  // 14^3 separate cubes in one file: 2,744 closed bodies of 26 elements each, 71,344 in all.
  std::ostringstream obj;
  for (int c = 0; c < 14 * 14 * 14; ++c) {
    const Eigen::Vector3d at(2.0 * (c % 14), 2.0 * (c / 14 % 14), 2.0 * (c / 196));
    for (int i = 0; i < 8; ++i) {
      const Eigen::Vector3d p = tubeplan::testing::CubeCorner(i) + at;
      obj << "v " << p.x() << " " << p.y() << " " << p.z() << "\n";
    }
    for (const std::array<int, 4>& f : tubeplan::testing::kCubeFaces)
      obj << "f " << f[0] - 8 << " " << f[1] - 8 << " " << f[2] - 8 << " " << f[3] - 8 << "\n";
  }
  const std::string scene_path = tubeplan::testing::WriteScratch(
      "mesh-many", "many-scene.yaml",
      WithLine(9, "    mesh: {file: many.obj, scale: 0.0005, position: [15 mm, 0, 0]}"));
  tubeplan::testing::WriteScratch("mesh-many", "many.obj", obj.str());
  const auto loaded = LoadSceneFile(scene_path);
  CHECK_FALSE(loaded.scene);
  CHECK(loaded.diagnostics.FormatAll().find(
            "has 71344 faces, edges and vertices, expected at most 65534") != std::string::npos);
}

TEST_CASE("A mesh part's problems are reported where they are", "[scene]") {
  const std::string scenes = SourcePath("scenes");
  struct Case {
    const char* what;
    std::string text;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"no such file", ClipSceneWith(11, "    mesh: {file: nope.obj, scale: 0.001}"),
       "t.yaml:11:18: error: parts[2].mesh.file: cannot read '" + scenes +
           "/nope.obj' (no such file), expected a readable OBJ or STL mesh file\n"},
      {"no scale", ClipSceneWith(11, "    mesh: {file: clip.obj}"),
       "t.yaml:11:11: error: missing key 'scale' in 'parts[2].mesh', expected the file's unit in "
       "metres, such as 0.001 for millimetres\n"},
      {"zero scale", ClipSceneWith(11, "    mesh: {file: clip.obj, scale: 0}"),
       "t.yaml:11:35: error: parts[2].mesh.scale must be greater than zero, expected the file's "
       "unit in metres, such as 0.001 for millimetres\n"},
      {"negative scale", ClipSceneWith(11, "    mesh: {file: clip.obj, scale: -1 mm}"),
       "t.yaml:11:35: error: parts[2].mesh.scale must be greater than zero, expected the file's "
       "unit in metres, such as 0.001 for millimetres\n"},
      {"faces on a mesh",
       ClipSceneWith(11,
                     "    mesh: {file: clip.obj, scale: 0.001, position: [0, 20 mm, 0]}\n"
                     "    faces: {top: lid}"),
       "t.yaml:12:12: error: parts[2].faces cannot rename a mesh's faces, expected the names of "
       "the mesh file's groups (docs/meshes.md)\n"},
      {"a box and a mesh",
       ClipSceneWith(11,
                     "    box: {size: [1 mm, 1 mm, 1 mm]}\n"
                     "    mesh: {file: clip.obj, scale: 0.001}"),
       "t.yaml:12:11: error: parts[2] has both a box and a mesh, expected exactly one of 'box', "
       "'cylinder' and 'mesh'\n"},
      {"a cylinder's key on a mesh",
       ClipSceneWith(11, "    mesh: {file: clip.obj, scale: 0.001, radius: 1 mm}"),
       "t.yaml:11:42: error: unknown key 'radius' in 'parts[2].mesh'"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.what, c.text);
    const auto loaded = LoadSceneText(c.text, "t.yaml", scenes);
    CHECK_FALSE(loaded.scene);
    const std::string got = loaded.diagnostics.FormatAll();
    if (c.expected.back() == '\n')
      CHECK(got == c.expected);
    else
      CHECK_THAT(got, Catch::StartsWith(c.expected));
  }
}

TEST_CASE("A clip on a whole floor overlaps it by its post", "[scene]") {
  // The floor in one piece under the clip: the post (5 mm under the base) goes into it.
  std::string text =
      ClipSceneWith(7, "    box: {size: [60 mm, 200 mm, 10 mm], position: [0, 0, -5 mm]}");
  // The other slab moved out of the way, 20 mm under the floor.
  text.replace(text.find("[17.5 mm, 0, -5 mm]"), std::string("[17.5 mm, 0, -5 mm]").size(),
               "[17.5 mm, 0, -25 mm]");
  const auto loaded = LoadSceneText(text, "t.yaml", SourcePath("scenes"));
  CHECK_FALSE(loaded.scene);
  CHECK(loaded.diagnostics.FormatAll() ==
        "t.yaml:11:52: error: part 'clip' overlaps part 'floor', expected parts that at most "
        "touch\n");
}

TEST_CASE("A broken mesh file's problems join the scene's, at the mesh file's lines", "[scene]") {
  // A cube with its ypos face left out (tests/io/mesh_test_meshes.hpp): four edges of one
  // triangle each, on the lines of top, bottom, xpos and xneg (11, 13, 15, 17), once though two
  // parts name the file. And a scene problem of its own in the same file: all at once.
  const auto dir = tubeplan::testing::ScratchDir("mesh-broken");
  tubeplan::testing::WriteScratch("mesh-broken", "open.obj", tubeplan::testing::CubeObj(4));
  const std::string text =
      WithLine(9,
               "    mesh: {file: open.obj, scale: 0.01, position: [15 mm, 0, 0]}\n"
               "  - name: again\n"
               "    mesh: {file: open.obj, scale: 0.01, position: [40 mm, 0, 0]}")
          .replace(0, std::string("tubeplan: 1").size(), "tubeplan: 2");
  const auto loaded = LoadSceneText(text, "t.yaml", dir);
  CHECK_FALSE(loaded.scene);
  const std::string got = loaded.diagnostics.FormatAll();
  CHECK_THAT(got, Catch::Contains("t.yaml:1:11: error: unsupported format version 2"));
  for (int line : {11, 13, 15, 17})
    CHECK_THAT(got, Catch::Contains((dir / "open.obj").string() + ":" + std::to_string(line) +
                                    ":1: error: the edge from"));
  CHECK(std::count(got.begin(), got.end(), '\n') == 5);
}
