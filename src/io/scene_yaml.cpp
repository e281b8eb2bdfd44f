// Scene files: YAML in, a validated Scene (SI) out, or every problem at once. The format is
// documented for users in docs/scene-format.md; keep the two in step.
//
// The checker never stops at the first problem: each section is read as far as it can be, a bad
// value is reported and replaced by its default so that later checks still run, and checks that
// need a good value (geometry, the goal's elements) run only when their inputs were read cleanly.
#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <map>
#include <numbers>
#include <set>
#include <sstream>
#include <utility>

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/yaml.h>

#include <tubeplan/core/core.hpp>
#include <tubeplan/core/coupling.hpp>
#include <tubeplan/io/mesh_file.hpp>
#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/io/units.hpp>
#include <tubeplan/scene/elements.hpp>
#include <tubeplan/scene/geometry.hpp>

#include "text_file.hpp"
#include "yaml_reader.hpp"

namespace tubeplan::io {
namespace {

bool IsName(std::string_view text, bool allow_underscore) {
  if (text.empty() || !std::isalpha(static_cast<unsigned char>(text[0]))) return false;
  return std::all_of(text.begin(), text.end(), [allow_underscore](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || (allow_underscore && c == '_');
  });
}

Eigen::Isometry3d Pose(const Eigen::Vector3d& position_m, const Eigen::Vector3d& rpy_rad) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = scene::RotationFromRpy(rpy_rad);
  X.translation() = position_m;
  return X;
}

// Roll, pitch and yaw: finite and within a turn either way. A larger angle is a slip of the
// unit or the sign (-1e20 deg turns a part nowhere a person meant), not an orientation.
constexpr double kMaxAngle_rad = 2.0 * std::numbers::pi;

std::optional<Eigen::Vector3d> ReadRpy(Reader& r, const YAML::Node& node, const std::string& what) {
  std::optional<Eigen::Vector3d> rpy = r.Vector(node, what, dim::kAngle);
  if (!rpy) return rpy;
  bool ok = true;
  for (int i = 0; i < 3; ++i) {
    // A turn and a hair: 360 deg written in radians rounds either way.
    if (std::abs((*rpy)[i]) <= kMaxAngle_rad * (1.0 + 1e-12)) continue;
    const YAML::Node item = node[std::size_t(i)];
    r.Error(item, what + "[" + std::to_string(i) + "] " + AsWritten(item, "rad") +
                      " is out of range, expected an angle from -360 deg to 360 deg");
    ok = false;
  }
  return ok ? rpy : std::nullopt;
}

// The friction law's exponent is in [2/3, 1] (docs/models.md, "Friction's load exponent"); files
// write 2/3 as 0.6667 or 0.667, so values down to 2/3 - 1e-3 are accepted (and kept as written:
// the law is smooth in beta).
constexpr double kExponentMin = 2.0 / 3.0 - 1e-3;

std::optional<scene::Friction> ReadFriction(Reader& r, const YAML::Node& node,
                                            const std::string& where) {
  if (!r.ExpectMap(node, where, {"static", "kinetic", "exponent", "reference_load"}))
    return std::nullopt;
  const std::size_t errors = r.error_count();
  scene::Friction f;
  r.Field(node, "static", where, dim::kNone, true, f.static_coefficient);
  r.Field(node, "kinetic", where, dim::kNone, true, f.kinetic_coefficient);
  r.Field(node, "exponent", where, dim::kNone, false, f.exponent);
  r.Field(node, "reference_load", where, dim::kForce, false, f.reference_load_N);
  if (r.error_count() != errors) return std::nullopt;
  bool ok = true;
  auto fail = [&](const std::string& key, const std::string& message) {
    r.Error(r.Get(node, key, where, false), where + "." + key + " " + message);
    ok = false;
  };
  if (f.static_coefficient < 0.0) fail("static", "must be zero or more");
  if (f.kinetic_coefficient < 0.0) {
    fail("kinetic", "must be zero or more");
  } else if (f.static_coefficient >= 0.0 && f.kinetic_coefficient > f.static_coefficient) {
    std::ostringstream m;
    m << "(" << f.kinetic_coefficient << ") must not exceed static (" << f.static_coefficient
      << "): sliding friction is at most the friction that holds";
    fail("kinetic", m.str());
  }
  if (f.exponent < kExponentMin || f.exponent > 1.0) {
    std::ostringstream m;
    m << "(" << f.exponent << ") must be in [2/3, 1] (0.6667 for rubber, 1 for Coulomb)";
    if (r.Get(node, "exponent", where, false).IsDefined()) fail("exponent", m.str());
  }
  if (f.reference_load_N <= 0.0 && r.Get(node, "reference_load", where, false).IsDefined())
    fail("reference_load", "must be greater than zero");
  return ok ? std::optional(f) : std::nullopt;
}

constexpr double kGeometryTolerance_m = 1e-9;

// The most parts a scene may hold (docs/scene-format.md): the core compares the tube with every
// part within its reach each tick, and a scene of a thousand parts is far beyond a task's fixture.
constexpr std::size_t kMaxParts = 1000;

// What the parts of one scene file share: where their mesh files' relative paths start, and
// the meshes read so far, null where reading failed (a file placed twice at one scale is read,
// and reported, once).
struct PartsContext {
  std::filesystem::path base_dir;
  std::map<std::pair<std::string, double>, std::shared_ptr<const scene::PartMesh>> meshes;
};

// A box's `size`.
void ReadBox(Reader& r, const YAML::Node& shape, const std::string& sw, scene::Part& part) {
  if (const YAML::Node n = r.Get(shape, "size", sw, true); n.IsDefined()) {
    if (const auto size = r.Vector(n, sw + ".size", dim::kLength)) {
      part.size_m = *size;
      if ((part.size_m.array() <= 0.0).any())
        r.Error(n, sw + ".size must be greater than zero along every axis");
    }
  }
}

// A cylinder's `radius` and `length`.
void ReadCylinder(Reader& r, const YAML::Node& shape, const std::string& sw, scene::Part& part) {
  double radius_m = 0.0, length_m = 0.0;
  for (const auto& [key, target] : {std::pair<const char*, double*>{"radius", &radius_m},
                                    std::pair<const char*, double*>{"length", &length_m}}) {
    if (!r.Field(shape, key, sw, dim::kLength, true, *target)) continue;
    if (!(*target > 0.0))
      r.Error(r.Get(shape, key, sw, true),
              sw + "." + key + " must be greater than zero, expected a length such as 10 mm");
  }
  part.size_m = Eigen::Vector3d(2.0 * radius_m, 2.0 * radius_m, length_m);
}

// A mesh's `file` (relative to the scene file's directory) and `scale` (the file's unit in
// metres). The mesh file's own problems join the scene's as they are, at their place in it.
void ReadMesh(Reader& r, const YAML::Node& shape, const std::string& sw, scene::Part& part,
              PartsContext& context) {
  std::optional<std::string> file;
  if (const YAML::Node n = r.Get(shape, "file", sw, true); n.IsDefined()) {
    file = r.String(n, sw + ".file");
    if (file && file->empty()) {
      r.Error(n, sw + ".file must not be empty, expected an OBJ or STL file's path");
      file.reset();
    }
  }
  std::optional<double> scale;
  if (const YAML::Node n = r.Get(shape, "scale", sw, false); !n.IsDefined()) {
    r.Error(shape, "missing key 'scale' in '" + sw +
                       "', expected the file's unit in metres, such as 0.001 for millimetres");
  } else if ((scale = r.Quantity(n, sw + ".scale", dim::kLength)) && !(*scale > 0.0)) {
    r.Error(n, sw + ".scale must be greater than zero, expected the file's unit in metres, such "
                    "as 0.001 for millimetres");
    scale.reset();
  }
  if (!file || !scale) return;
  const std::filesystem::path path = context.base_dir / *file;
  // A file read before is not read again; one that failed was reported then.
  const auto [at, first_time] = context.meshes.try_emplace({path.string(), *scale}, nullptr);
  std::shared_ptr<const scene::PartMesh>& mesh = at->second;
  if (first_time) {
    const ReadResult read = ReadInputFile(path, kMaxMeshBytes);
    if (!read.text) {
      r.Error(r.Get(shape, "file", sw, true), sw + ".file: cannot read '" + path.string() + "' (" +
                                                  read.error +
                                                  "), expected a readable OBJ or STL mesh file");
      return;
    }
    MeshLoadResult loaded = LoadMeshBytes(*read.text, path.string(), *scale);
    r.diagnostics().Append(loaded.diagnostics);
    if (!loaded.mesh) return;
    const scene::MeshElements& e = *loaded.elements;
    const std::size_t count = e.faces.size() + e.edges.size() + e.vertices.size();
    if (count > scene::kMaxElements) {
      r.Error(r.Get(shape, "file", sw, true),
              sw + ".file: '" + path.string() + "' has " + std::to_string(count) +
                  " faces, edges and vertices, expected at most " +
                  std::to_string(scene::kMaxElements) +
                  " (export it with fewer sharp features, or smooth curved surfaces finer: "
                  "docs/meshes.md)");
      return;
    }
    mesh = scene::MakePartMesh(*file, std::move(*loaded.mesh), std::move(*loaded.elements));
  }
  if (!mesh) return;
  part.mesh = mesh;
  part.size_m = scene::BoundsInPart(part).sizes();
}

// "a box and a cylinder", "a box, a cylinder and a mesh": the shapes a part names.
std::string ShapeList(const std::vector<std::string>& shapes) {
  std::string list;
  for (std::size_t i = 0; i < shapes.size(); ++i)
    list += (i == 0 ? "" : i + 1 == shapes.size() ? " and " : ", ") + std::string("a ") + shapes[i];
  return list;
}

// A part's shape: exactly one of `box: {size, position, rpy}`, `cylinder: {radius, length,
// position, rpy}` and `mesh: {file, scale, position, rpy}`. Returns the mark of its position,
// for messages about the part.
YAML::Mark ReadShape(Reader& r, const YAML::Node& part_node, const std::string& where,
                     scene::Part& part, PartsContext& context) {
  const std::array<const char*, 3> keys = {"box", "cylinder", "mesh"};
  std::vector<std::string> named;
  for (const char* key : keys)
    if (part_node[key].IsDefined()) named.push_back(key);
  if (named.size() != 1) {
    r.Error(named.empty() ? part_node : part_node[named[1]],
            where +
                (named.empty()       ? " has no shape"
                 : named.size() == 2 ? " has both " + ShapeList(named)
                                     : " has " + ShapeList(named)) +
                ", expected exactly one of 'box', 'cylinder' and 'mesh'");
    return part_node.Mark();
  }
  const std::string& key = named[0];
  const YAML::Node shape = part_node[key];
  const std::string sw = where + "." + key;
  part.shape = key == "box"        ? scene::PartShape::kBox
               : key == "cylinder" ? scene::PartShape::kCylinder
                                   : scene::PartShape::kMesh;
  const std::span<const char* const> ids = scene::FaceIds(part.shape);
  for (std::size_t f = 0; f < ids.size(); ++f) part.face_names[f] = ids[f];
  const std::vector<std::string> size_keys = key == "box" ? std::vector<std::string>{"size"}
                                             : key == "cylinder"
                                                 ? std::vector<std::string>{"radius", "length"}
                                                 : std::vector<std::string>{"file", "scale"};
  std::vector<std::string> allowed = size_keys;
  allowed.insert(allowed.end(), {"position", "rpy"});
  if (!r.ExpectMap(shape, sw, allowed)) return shape.Mark();
  if (part.shape == scene::PartShape::kBox)
    ReadBox(r, shape, sw, part);
  else if (part.shape == scene::PartShape::kCylinder)
    ReadCylinder(r, shape, sw, part);
  else
    ReadMesh(r, shape, sw, part, context);
  Eigen::Vector3d position = Eigen::Vector3d::Zero(), rpy = Eigen::Vector3d::Zero();
  YAML::Mark position_mark = shape.Mark();
  if (const YAML::Node n = r.Get(shape, "position", sw, false); n.IsDefined()) {
    position_mark = n.Mark();
    if (const auto p = r.Vector(n, sw + ".position", dim::kLength)) position = *p;
  }
  if (const YAML::Node n = r.Get(shape, "rpy", sw, false); n.IsDefined())
    if (const auto a = ReadRpy(r, n, sw + ".rpy")) rpy = *a;
  part.X_WP = Pose(position, rpy);
  return position_mark;
}

// A box's or a cylinder's renamed faces; a mesh's faces are named by its file's groups.
void ReadFaceNames(Reader& r, const YAML::Node& faces, const std::string& where,
                   scene::Part& part) {
  const std::string fw = where + ".faces";
  if (part.shape == scene::PartShape::kMesh) {
    r.Error(faces, fw + " cannot rename a mesh's faces, expected the names of the mesh file's "
                        "groups (docs/meshes.md)");
    return;
  }
  const std::span<const char* const> shape_ids = scene::FaceIds(part.shape);
  const std::vector<std::string> ids(shape_ids.begin(), shape_ids.end());
  if (!r.ExpectMap(faces, fw, ids)) return;
  for (const auto& entry : faces) {
    const auto it = std::find(ids.begin(), ids.end(), entry.first.Scalar());
    if (it == ids.end()) continue;  // reported by ExpectMap
    const auto name = r.String(entry.second, fw + "." + *it);
    if (!name) continue;
    // '_' joins face names into edge and vertex names, so a face name cannot hold one.
    if (!IsName(*name, false)) {
      r.Error(entry.second, fw + "." + *it + " '" + *name +
                                "' must start with a letter and hold only letters and "
                                "digits ('_' joins face names into edge names)");
      continue;
    }
    part.face_names[static_cast<std::size_t>(it - ids.begin())] = *name;
  }
  for (std::size_t a = 0; a < ids.size(); ++a)
    for (std::size_t b = a + 1; b < ids.size(); ++b)
      if (part.face_names[a] == part.face_names[b])
        r.Error(faces, fw + ": two faces are named '" + part.face_names[a] +
                           "', expected a distinct name for each face");
}

void ReadParts(Reader& r, const YAML::Node& node, scene::Scene& s, bool& parts_ok,
               const std::filesystem::path& base_dir) {
  PartsContext context{base_dir, {}};
  if (!node.IsSequence() || node.size() == 0) {
    r.Error(node, std::string("'parts' must be a non-empty sequence of parts, found ") +
                      (node.IsSequence() ? "an empty sequence" : KindName(node)));
    parts_ok = false;
    return;
  }
  if (node.size() > kMaxParts) {
    r.Error(node[kMaxParts], "parts[" + std::to_string(kMaxParts) + "] is one part too many: " +
                                 std::to_string(node.size()) + " parts, expected at most " +
                                 std::to_string(kMaxParts) + " (docs/scene-format.md says why)");
    parts_ok = false;
    return;
  }
  // Where each part is, for a message about it; kept as marks: a YAML::Node assigned to another
  // merges the whole document's node set into its own, once a part (quadratic in the parts).
  std::vector<YAML::Mark> position_marks;
  std::set<std::string> names;
  for (std::size_t i = 0; i < node.size(); ++i) {
    const YAML::Node part_node = node[i];
    const std::string where = "parts[" + std::to_string(i) + "]";
    const std::size_t errors = r.error_count();
    if (!r.ExpectMap(part_node, where, {"name", "box", "cylinder", "mesh", "faces", "friction"})) {
      parts_ok = false;
      continue;
    }
    scene::Part part;
    if (const YAML::Node n = r.Get(part_node, "name", where, true); n.IsDefined()) {
      if (const auto name = r.String(n, where + ".name")) {
        part.name = *name;
        if (!IsName(part.name, true)) {
          r.Error(n, where + ".name '" + part.name +
                         "' must start with a letter and hold only letters, digits and '_'");
        }
        if (!names.insert(part.name).second)
          r.Error(n, "part name '" + part.name + "' is used twice, expected unique names");
      }
    }
    YAML::Mark position_mark = ReadShape(r, part_node, where, part, context);
    if (const YAML::Node faces = r.Get(part_node, "faces", where, false); faces.IsDefined())
      ReadFaceNames(r, faces, where, part);
    if (const YAML::Node f = r.Get(part_node, "friction", where, false); f.IsDefined())
      part.friction = ReadFriction(r, f, where + ".friction");
    if (r.error_count() != errors) parts_ok = false;
    s.parts.push_back(part);
    position_marks.push_back(position_mark);
  }
  if (!parts_ok) return;
  for (const auto& [i, j] : scene::OverlappingParts(s.parts, kGeometryTolerance_m)) {
    r.Error(position_marks[i], "part '" + s.parts[i].name + "' overlaps part '" + s.parts[j].name +
                                   "', expected parts that at most touch");
    parts_ok = false;
  }
}

void ReadGoal(Reader& r, const YAML::Node& node, scene::Scene& s, bool parts_ok) {
  const std::vector<scene::PartElement> elements =
      parts_ok ? scene::EnumerateElements(s) : std::vector<scene::PartElement>{};
  if (auto cf = r.Formation(node, "goal", parts_ok ? &elements : nullptr)) s.goal = *cf;
}

void ReadDevice(Reader& r, const YAML::Node& node, scene::Device& d) {
  const std::string w = "device";
  if (!r.ExpectMap(node, w, {"max_force", "max_torque", "max_stiffness", "damping", "coupling"}))
    return;
  auto positive = [&](const std::string& key, Dimension dimension, double& target, bool zero_ok) {
    if (!r.Field(node, key, w, dimension, false, target)) return;
    if (target < 0.0 || (!zero_ok && target == 0.0))
      r.Error(r.Get(node, key, w, false),
              w + "." + key + (zero_ok ? " must be zero or more" : " must be greater than zero"));
  };
  positive("max_force", dim::kForce, d.max_force_N, false);
  positive("max_torque", dim::kTorque, d.max_torque_Nm, false);
  positive("max_stiffness", dim::kStiffness, d.max_stiffness_N_per_m, false);
  positive("damping", dim::kDamping, d.damping_Ns_per_m, true);
  const YAML::Node coupling = r.Get(node, "coupling", w, false);
  if (!coupling.IsDefined()) return;
  const std::string cw = "device.coupling";
  if (!r.ExpectMap(coupling, cw, {"stiffness", "damping"})) return;
  double k = 0.0, b = 0.0;
  if (const YAML::Node n = r.Get(coupling, "stiffness", cw, false); n.IsDefined()) {
    if (const auto v = r.Quantity(n, cw + ".stiffness", dim::kStiffness)) {
      if (*v <= 0.0) {
        r.Error(n, cw + ".stiffness must be greater than zero");
      } else if (*v > d.max_stiffness_N_per_m) {
        std::ostringstream m;
        m << cw << ".stiffness (" << *v << " N/m) exceeds device.max_stiffness ("
          << d.max_stiffness_N_per_m << " N/m), expected at most the device's limit";
        r.Error(n, m.str());
      } else {
        k = *v;
        d.coupling_stiffness_N_per_m = k;
      }
    }
  }
  if (const YAML::Node n = r.Get(coupling, "damping", cw, false); n.IsDefined()) {
    if (const auto v = r.Quantity(n, cw + ".damping", dim::kDamping)) {
      if (*v < 0.0) {
        r.Error(n, cw + ".damping must be zero or more");
      } else {
        b = *v;
        d.coupling_damping_Ns_per_m = b;
      }
    }
  }
}

void ReadModel(Reader& r, const YAML::Node& node, scene::ModelOptions& m) {
  const std::string w = "model";
  if (!r.ExpectMap(node, w, {"beam", "elements", "time_step", "multi_contact", "slip", "capsules"}))
    return;
  // "elastica" is the rod's own limit: the discrete rod converges to it as elements are added.
  if (const YAML::Node n = r.Get(node, "beam", w, false); n.IsDefined())
    if (const auto v = r.Choice<scene::TubeModel>(n, "model.beam",
                                                  {{"rod", scene::TubeModel::kRod},
                                                   {"elastica", scene::TubeModel::kRod},
                                                   {"linear", scene::TubeModel::kLinear}}))
      m.tube = *v;
  // Accepted and ignored with a warning: the rod solves all contacts together, so these choose
  // nothing.
  for (const char* gone : {"multi_contact", "slip", "capsules"})
    if (const YAML::Node n = r.Get(node, gone, w, false); n.IsDefined())
      r.Warning(n, std::string("model.") + gone +
                       " has no effect: the core solves the rod and all its contacts together "
                       "(model.elements sets the rod's resolution)");
  // Up to 10 ms: slower than 100 Hz is not haptics, and the contact spring needs small steps.
  if (r.Field(node, "time_step", w, dim::kTime, false, m.time_step_s) &&
      (m.time_step_s <= 0.0 || m.time_step_s > 0.010))
    r.Error(r.Get(node, "time_step", w, false),
            "model.time_step must be in (0, 10 ms], expected e.g. \"1 ms\" (1 kHz)");
  // The rod's element count: "auto" (the core's default) or a whole number the core supports.
  if (const YAML::Node n = r.Get(node, "elements", w, false); n.IsDefined()) {
    const std::string expected = "expected \"auto\" or a whole number from " +
                                 std::to_string(core::kMinElementCount) + " to " +
                                 std::to_string(core::kMaxElementCount);
    if (n.IsScalar() && n.Scalar() == "auto") {
      m.elements = 0;
    } else if (!n.IsScalar()) {
      r.Error(
          n, "model.elements must be a count, found " + std::string(KindName(n)) + ", " + expected);
    } else if (const auto v = r.Quantity(n, "model.elements", dim::kNone)) {
      if (*v != std::floor(*v) || *v < core::kMinElementCount || *v > core::kMaxElementCount)
        r.Error(n, "model.elements " + Abbreviate(n.Scalar()) +
                       " is not a count the core supports, " + expected);
      else
        m.elements = static_cast<int>(*v);
    }
  }
}

void ReadHeuristics(Reader& r, const YAML::Node& node, scene::Heuristics& h) {
  const std::string w = "heuristics";
  if (!r.ExpectMap(node, w, {"friction", "energy", "distance", "tolerance"})) return;
  for (const auto& [key, target] : {std::pair<const char*, double*>{"friction", &h.friction},
                                    {"energy", &h.energy},
                                    {"distance", &h.distance},
                                    {"tolerance", &h.tolerance}}) {
    if (r.Field(node, key, w, dim::kNone, false, *target) && !(*target >= 0.0 && *target <= 1e6))
      r.Error(r.Get(node, key, w, false),
              w + "." + key + " must be a weight between 0 and 1e6, expected e.g. 1");
  }
}

// The model's message on a tube key, "outer_radius (-0.008) must be ...", with each key's value
// in it as the file wrote it: "outer_radius (-8 mm) must be ...".
std::string TubeValuesAsWritten(Reader& r, const YAML::Node& tube, std::string problem) {
  constexpr std::array<std::pair<const char*, const char*>, 5> kUnits = {{{"outer_radius", "m"},
                                                                          {"inner_radius", "m"},
                                                                          {"length", "m"},
                                                                          {"youngs_modulus", "Pa"},
                                                                          {"poisson_ratio", ""}}};
  for (const auto& [key, unit] : kUnits) {
    const std::string opening = std::string(key) + " (";
    const std::size_t at = problem.find(opening);
    if (at == std::string::npos || (at > 0 && problem[at - 1] != ' ')) continue;
    const std::size_t from = at + opening.size();
    const std::size_t to = problem.find(')', from);
    const YAML::Node value = r.Get(tube, key, "tube", false);
    if (to == std::string::npos || !value.IsScalar()) continue;
    problem.replace(from, to - from, AsWritten(value, unit));
  }
  return problem;
}

// "[1, -90, 40] mm" for a position in metres.
std::string Millimetres(const Eigen::Vector3d& p_m) {
  std::ostringstream text;
  text << std::setprecision(6) << "[" << p_m.x() * 1e3 << ", " << p_m.y() * 1e3 << ", "
       << p_m.z() * 1e3 << "] mm";
  return text.str();
}

// The start the scene gives the tube: the held end inside the workspace, and the tube's body
// (straight from the held end along its +z) clear of every part, as the core takes it at t = 0.
// A part the held end is inside of is reported already.
void CheckStart(Reader& r, const scene::Scene& s, const YAML::Mark& at, bool body_known,
                const std::vector<bool>& held_end_inside) {
  const Eigen::Vector3d p_m = s.X_WH_start.translation();
  if (s.workspace && ((p_m.array() < s.workspace->min_W_m.array()).any() ||
                      (p_m.array() > s.workspace->max_W_m.array()).any())) {
    r.Error(at, "start.position " + Millimetres(p_m) + " is outside the workspace (min " +
                    Millimetres(s.workspace->min_W_m) + ", max " +
                    Millimetres(s.workspace->max_W_m) +
                    "), expected the held end's start inside it");
  }
  if (!body_known) return;
  const model::TubeSpec& tube = s.tube;
  for (std::size_t i = 0; i < s.parts.size(); ++i) {
    if (held_end_inside[i]) continue;
    const std::optional<double> depth_m = scene::StraightTubeOverlap(
        s.X_WH_start, tube.outer_radius_m, tube.length_m, s.parts[i], kGeometryTolerance_m);
    if (!depth_m) continue;
    std::ostringstream m;
    m << std::setprecision(3) << "the tube at its start goes into part '" << s.parts[i].name
      << "' ";
    if (*depth_m >= tube.outer_radius_m)
      m << "across its axis";
    else
      m << "by " << *depth_m * 1e3 << " mm";
    m << " (the straight tube from start.position along its own +z, " << tube.length_m * 1e3
      << " mm long, outer radius " << tube.outer_radius_m * 1e3
      << " mm), expected the tube's body clear of every part at the start";
    r.Error(at, m.str());
  }
}

// The format version and the scene's name.
void ReadHeader(Reader& r, const YAML::Node& root, scene::Scene& s) {
  if (const YAML::Node n = r.Get(root, "tubeplan", "scene", true); n.IsDefined()) {
    if (!n.IsScalar() || n.Scalar() != "1") {
      r.Error(n, "unsupported format version " +
                     (n.IsScalar() ? Abbreviate(n.Scalar()) : std::string(KindName(n))) +
                     ", expected 1");
    }
  }
  if (const YAML::Node n = r.Get(root, "name", "scene", true); n.IsDefined()) {
    if (const auto name = r.String(n, "name")) {
      s.name = *name;
      if (s.name.empty()) r.Error(n, "name must not be empty");
    }
  }
}

// The tube's section; true when every tube key was read and valid: its body can be placed.
bool ReadTube(Reader& r, const YAML::Node& t, model::TubeSpec& spec) {
  const std::string w = "tube";
  if (!r.ExpectMap(t, w,
                   {"outer_radius", "inner_radius", "length", "youngs_modulus", "poisson_ratio"}))
    return false;
  // Keys read cleanly; the model's rules are checked only on those, so that a value that
  // failed to parse is not reported a second time as "must be greater than zero".
  std::set<std::string> read;
  auto field = [&](const char* key, Dimension dimension, double& target) {
    if (r.Field(t, key, w, dimension, true, target) && r.Get(t, key, w, false).IsDefined())
      read.insert(key);
  };
  field("outer_radius", dim::kLength, spec.outer_radius_m);
  field("inner_radius", dim::kLength, spec.inner_radius_m);
  field("length", dim::kLength, spec.length_m);
  field("youngs_modulus", dim::kPressure, spec.youngs_modulus_Pa);
  field("poisson_ratio", dim::kNone, spec.poisson_ratio);
  // The model's own rules, each reported at the key it names ("inner_radius (...) ...").
  const std::vector<std::string> problems = model::ValidateTubeSpec(spec);
  for (const std::string& problem : problems) {
    const std::string key = problem.substr(0, problem.find(' '));
    const YAML::Node at = r.Get(t, key, w, false);
    if (at.IsDefined()) {
      if (read.count(key) == 0) continue;
      // r2 >= r1 is only meaningful when r1 itself was read.
      if (key == "inner_radius" && read.count("outer_radius") == 0) continue;
      r.Error(at, "tube." + TubeValuesAsWritten(r, t, problem));
    } else if (read.size() == 5) {
      r.Error(t, "tube " + problem);  // about the section as a whole
    }
  }
  return read.size() == 5 && problems.empty();
}

void ReadContact(Reader& r, const YAML::Node& c, scene::Contact& contact) {
  const std::string w = "contact";
  if (!r.ExpectMap(c, w, {"stiffness", "threshold", "bend_threshold"})) return;
  auto positive = [&](const std::string& key, Dimension dimension, double& target) {
    if (r.Field(c, key, w, dimension, false, target) && target <= 0.0)
      r.Error(r.Get(c, key, w, false), w + "." + key + " must be greater than zero");
  };
  positive("stiffness", dim::kStiffness, contact.stiffness_N_per_m);
  positive("threshold", dim::kLength, contact.threshold_m);
  positive("bend_threshold", dim::kLength, contact.bend_threshold_m);
}

// The held end's start pose. `start_mark`: where its position is written, once it and its turn
// were read cleanly; `held_end_inside`: per part, whether the held end starts inside it
// (reported here).
void ReadStart(Reader& r, const YAML::Node& st, scene::Scene& s, bool parts_ok,
               std::optional<YAML::Mark>& start_mark, std::vector<bool>& held_end_inside) {
  const std::string w = "start";
  if (!r.ExpectMap(st, w, {"position", "rpy"})) return;
  Eigen::Vector3d rpy = Eigen::Vector3d::Zero();
  bool rpy_ok = true;
  if (const YAML::Node n = r.Get(st, "rpy", w, false); n.IsDefined()) {
    const auto a = ReadRpy(r, n, "start.rpy");
    if (a) rpy = *a;
    rpy_ok = a.has_value();
  }
  const YAML::Node n = r.Get(st, "position", w, true);
  if (!n.IsDefined()) return;
  const auto p = r.Vector(n, "start.position", dim::kLength);
  if (!p) return;
  s.X_WH_start = Pose(*p, rpy);
  if (rpy_ok) start_mark = n.Mark();
  if (!parts_ok) return;
  for (std::size_t i = 0; i < s.parts.size(); ++i) {
    if (!scene::Contains(s.parts[i], *p, kGeometryTolerance_m)) continue;
    held_end_inside[i] = true;
    r.Error(n, "start.position is inside part '" + s.parts[i].name +
                   "', expected the held end outside every part");
  }
}

// The core keeps its elements at least r1 long (docs/core.md, "Contact points"): a count
// beyond that is said, with the count it uses.
void WarnElementCount(Reader& r, const YAML::Node& root, const scene::Scene& s) {
  if (s.model.elements > 0 && s.model.elements != core::ElementCount(s) && s.tube.length_m > 0.0 &&
      s.tube.outer_radius_m > 0.0) {
    const YAML::Node n = r.Get(r.Get(root, "model", "scene", false), "elements", "model", false);
    r.Warning(n, "model.elements " + std::to_string(s.model.elements) +
                     " asks for elements shorter than the tube's outer radius; the core uses " +
                     std::to_string(core::ElementCount(s)) +
                     " (at most length / outer_radius, so that a side's contact stays off the "
                     "end face)");
  }
}

// A contact band as wide as the tube makes every element near a part a PC of it.
void WarnContactBand(Reader& r, const YAML::Node& root, const scene::Scene& s) {
  if (s.tube.outer_radius_m > 0.0 && s.contact.threshold_m >= s.tube.outer_radius_m) {
    std::ostringstream m;
    m << "contact.threshold " << s.contact.threshold_m * 1e3
      << " mm is not below the tube's outer radius (" << s.tube.outer_radius_m * 1e3
      << " mm): the contact band is wider than the tube, so PCs and forces reach parts the tube "
         "does not touch; expected a threshold well below the radius (the paper's 1 mm)";
    r.Warning(r.Get(root, "contact", "scene", false), m.str());
  }
}

// The penalty's force at a part's middle, K (eps + half its thickness): below the device's
// force, a full push can carry the tube out the part's far side. Said for the first such part.
void WarnThinParts(Reader& r, const YAML::Node& root, const scene::Scene& s) {
  for (const scene::Part& part : s.parts) {
    const double hold_N = scene::ContactHoldAtMiddle_N(s, part);
    if (!(hold_N < s.device.max_force_N)) continue;
    const double thinnest_m = scene::ThinnestSize_m(part);
    if (thinnest_m <= 0.0) continue;
    std::ostringstream m;
    m << "part " << part.name << " is " << thinnest_m * 1e3
      << " mm thin: the contact holds K (eps + half of it) = " << hold_N
      << " N at its middle, less than the device's " << s.device.max_force_N
      << " N, so a full push can carry the tube through it; expected a thicker part or a stiffer "
         "contact";
    r.Warning(r.Get(root, "contact", "scene", false), m.str());
    break;
  }
}

// The coupling a scene asks for must be passive on its device at its step (docs/scene-format.md,
// "Device"): an active coupling makes the device oscillate in the operator's hand.
void CheckCouplingPassive(Reader& r, const YAML::Node& root, const scene::Scene& s) {
  const YAML::Node d = r.Get(root, "device", "scene", false);
  if (!d.IsMap()) return;
  const YAML::Node coupling = r.Get(d, "coupling", "device", false);
  const core::Coupling c = core::ResolveCoupling(s.device, s.model.time_step_s);
  if (coupling.IsDefined() && c.stiffness_N_per_m > 0.0 &&
      !core::IsPassive(s.device.damping_Ns_per_m, c, s.model.time_step_s)) {
    std::ostringstream m;
    m << "device.coupling (" << c.stiffness_N_per_m << " N/m, " << c.damping_Ns_per_m
      << " N s/m) is not passive at a " << s.model.time_step_s * 1e3
      << " ms step: the device's damping " << s.device.damping_Ns_per_m
      << " N s/m must exceed K T / 2 + |B| = "
      << c.stiffness_N_per_m * s.model.time_step_s / 2.0 + std::abs(c.damping_Ns_per_m)
      << " N s/m, expected a softer spring or less coupling damping";
    r.Error(coupling, m.str());
  }
}

void ReadWorkspace(Reader& r, const YAML::Node& ws, scene::Scene& s) {
  if (!r.ExpectMap(ws, "workspace", {"min", "max"})) return;
  const YAML::Node lo = r.Get(ws, "min", "workspace", true);
  const YAML::Node hi = r.Get(ws, "max", "workspace", true);
  std::optional<Eigen::Vector3d> min, max;
  if (lo.IsDefined()) min = r.Vector(lo, "workspace.min", dim::kLength);
  if (hi.IsDefined()) max = r.Vector(hi, "workspace.max", dim::kLength);
  if (!min || !max) return;
  if (((*max - *min).array() <= 0.0).any()) {
    r.Error(hi, "workspace.max must exceed workspace.min along every axis");
  } else {
    s.workspace = scene::Workspace{*min, *max};
  }
}

void ReadScene(Reader& r, const YAML::Node& root, scene::Scene& s,
               const std::filesystem::path& base_dir) {
  const std::vector<std::string> top = {"tubeplan", "name",  "tube",      "contact",
                                        "friction", "parts", "start",     "goal",
                                        "device",   "model", "workspace", "heuristics"};
  if (!root.IsMap()) {
    r.Error(root, std::string("a scene file must be a map, found ") + KindName(root) +
                      ", expected keys such as tubeplan, name, tube, parts");
    return;
  }
  r.ExpectMap(root, "scene", top);
  ReadHeader(r, root, s);
  bool tube_ok = false;  // every tube key read and valid: its body can be placed
  if (const YAML::Node t = r.Get(root, "tube", "scene", true); t.IsDefined())
    tube_ok = ReadTube(r, t, s.tube);
  if (const YAML::Node c = r.Get(root, "contact", "scene", false); c.IsDefined())
    ReadContact(r, c, s.contact);
  if (const YAML::Node f = r.Get(root, "friction", "scene", false); f.IsDefined()) {
    if (const auto friction = ReadFriction(r, f, "friction")) s.friction = *friction;
  }
  bool parts_ok = true;
  if (const YAML::Node p = r.Get(root, "parts", "scene", true); p.IsDefined()) {
    ReadParts(r, p, s, parts_ok, base_dir);
  } else {
    parts_ok = false;
  }
  std::optional<YAML::Mark> start_mark;
  std::vector<bool> held_end_inside(s.parts.size(), false);
  if (const YAML::Node st = r.Get(root, "start", "scene", true); st.IsDefined())
    ReadStart(r, st, s, parts_ok, start_mark, held_end_inside);
  if (const YAML::Node g = r.Get(root, "goal", "scene", true); g.IsDefined())
    ReadGoal(r, g, s, parts_ok);
  if (const YAML::Node d = r.Get(root, "device", "scene", false); d.IsDefined())
    ReadDevice(r, d, s.device);
  if (const YAML::Node m = r.Get(root, "model", "scene", false); m.IsDefined())
    ReadModel(r, m, s.model);
  WarnElementCount(r, root, s);
  WarnContactBand(r, root, s);
  WarnThinParts(r, root, s);
  if (const YAML::Node h = r.Get(root, "heuristics", "scene", false); h.IsDefined())
    ReadHeuristics(r, h, s.heuristics);
  CheckCouplingPassive(r, root, s);
  if (const YAML::Node ws = r.Get(root, "workspace", "scene", false); ws.IsDefined())
    ReadWorkspace(r, ws, s);
  if (start_mark) CheckStart(r, s, *start_mark, tube_ok && parts_ok, held_end_inside);
}

}  // namespace

SceneLoadResult LoadSceneText(std::string_view yaml_text, const std::string& display_name,
                              const std::filesystem::path& base_dir) {
  SceneLoadResult result;
  Reader reader(display_name, result.diagnostics);
  scene::Scene s;
  if (yaml_text.size() > kMaxYamlBytes) {
    result.diagnostics.Error(display_name, 0, 0,
                             "the file is " + std::to_string(yaml_text.size() >> 20) +
                                 " MiB, expected a YAML scene file of at most " +
                                 std::to_string(kMaxYamlBytes >> 20) + " MiB");
    return result;
  }
  if (!CheckInputText(yaml_text, display_name, "a YAML scene file", result.diagnostics))
    return result;
  try {
    const YAML::Node root = LoadOneDocument(reader, std::string(yaml_text), "a scene file");
    if (CheckYamlShape(reader, root, "a scene file")) ReadScene(reader, root, s, base_dir);
  } catch (const YAML::DeepRecursion& e) {
    // yaml-cpp's own guard of its recursive parser (500 levels); its message is "bad file".
    reader.Error(e.mark, "nesting deeper than " + std::to_string(kMaxYamlDepth) +
                             " levels, expected a scene file (a few levels deep)");
  } catch (const YAML::Exception& e) {
    reader.Error(e.mark, e.msg + ", expected valid YAML");
  } catch (const std::exception& e) {
    // Not expected: the reader checks every node's type before converting it. Still a file
    // problem for the user, never a crash.
    result.diagnostics.Error(display_name, 0, 0,
                             std::string("could not read the scene: ") + e.what());
  }
  if (!result.diagnostics.HasErrors()) result.scene = std::move(s);
  return result;
}

SceneLoadResult LoadSceneFile(const std::filesystem::path& path) {
  const ReadResult read = ReadInputFile(path, kMaxYamlBytes);
  if (!read.text) {
    SceneLoadResult result;
    result.diagnostics.Error(
        path.string(), 0, 0,
        "cannot read file (" + read.error + "), expected a readable YAML scene file");
    return result;
  }
  return LoadSceneText(*read.text, path.string(), path.parent_path());
}

}  // namespace tubeplan::io
