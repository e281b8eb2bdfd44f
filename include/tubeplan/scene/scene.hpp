#pragma once
// A scene: one task of inserting the tube into rigid parts. Plain data in SI units, built by the
// loader (io/scene_yaml.hpp) or in code (tests); defaults in member initialisers.

#include <array>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <tubeplan/model/tip_response.hpp>
#include <tubeplan/model/tube.hpp>
#include <tubeplan/scene/mesh.hpp>
#include <tubeplan/scene/mesh_distance.hpp>
#include <tubeplan/states/contact_formation.hpp>

namespace tubeplan::scene {

/// Coulomb friction with a load exponent (docs/models.md, "Friction's load exponent"):
/// f_max = static_coefficient * reference_load_N * (N / reference_load_N)^exponent.
struct Friction {
  double static_coefficient = 0.0;   ///< mu_s [-], >= 0
  double kinetic_coefficient = 0.0;  ///< mu_k (the paper's mu_D) [-], 0 <= mu_k <= mu_s
  double exponent = 1.0;             ///< beta [-], in [2/3, 1]
  double reference_load_N = 1.0;     ///< N0 [N], > 0
  bool IsFrictionless() const { return static_coefficient == 0.0 && kinetic_coefficient == 0.0; }
};

/// Penalty contact (paper eq. 4) and the threshold that decides "the tube bends".
struct Contact {
  double stiffness_N_per_m = 1.0e4;  ///< K [N/m]
  double threshold_m = 1.0e-3;       ///< epsilon [m]: a PC is active when d < epsilon
  double bend_threshold_m = 1.0e-4;  ///< tip deflection above which the tube "bends" [m]
};

/// Faces of a box in its own frame; the order is the order used to name edges and vertices.
enum class BoxFace : int { kTop = 0, kBottom, kXPos, kXNeg, kYPos, kYNeg };
inline constexpr std::array<const char*, 6> kBoxFaceIds = {"top",  "bottom", "xpos",
                                                           "xneg", "ypos",   "yneg"};

/// Faces of a cylinder: its two flat ends (normals +z and -z of its frame) and its round side.
enum class CylinderFace : int { kTop = 0, kBottom, kSide };
inline constexpr std::array<const char*, 3> kCylinderFaceIds = {"top", "bottom", "side"};

/// The shape of a rigid part.
enum class PartShape {
  kBox,       ///< six flat faces, twelve edges, eight vertices
  kCylinder,  ///< along its frame's z: a flat top and bottom, a round side, two rims
  kMesh,      ///< a closed triangle mesh read from a file, cut into faces, edges and vertices
};

/// A mesh part's surface: the welded, checked mesh in the part's frame P [m], its elements
/// (io::LoadMeshFile makes both) and its distance queries in P (MakePartMesh builds them).
struct PartMesh {
  std::string file;  ///< the file as the scene names it
  TriangleMesh mesh;
  MeshElements elements;
  MeshGeometry distance_P;  ///< placed at the identity: query it with points in P
  double thinnest_m = 0.0;  ///< its thinnest wall (ThinnestSize_m), measured once [m]
};

/// A PartMesh of a sound mesh (CheckMesh found nothing) and its elements, its queries built
/// and its thinnest wall measured. Throws std::invalid_argument for more than kMaxElements
/// elements.
std::shared_ptr<const PartMesh> MakePartMesh(std::string file, TriangleMesh mesh,
                                             MeshElements elements);

struct Part {
  std::string name;  ///< [A-Za-z][A-Za-z0-9_]*
  PartShape shape = PartShape::kBox;
  /// Full extents along the part frame's x, y, z [m]: a box's sides; a cylinder's diameter twice,
  /// then its length; a mesh's bounding box in P (which need not be centred on P's origin).
  Eigen::Vector3d size_m = Eigen::Vector3d::Zero();
  Eigen::Isometry3d X_WP = Eigen::Isometry3d::Identity();  ///< part centre frame P in world W
  std::optional<Friction> friction;  ///< overrides the scene's friction if set
  /// Name of each face, indexed by BoxFace or CylinderFace: the shape's face ids unless the
  /// scene renames them (a cylinder uses the first three).
  std::array<std::string, 6> face_names = {"top", "bottom", "xpos", "xneg", "ypos", "yneg"};
  /// A mesh part's surface, shared by copies of the scene; null for the other shapes.
  std::shared_ptr<const PartMesh> mesh;
};

/// The part's bounding box in its own frame P: centred on P's origin for a box or a cylinder.
Eigen::AlignedBox3d BoundsInPart(const Part& part);

/// A mesh part named `name` placed at X_WP: its size is its bounding box's.
Part MakeMeshPart(std::string name, std::shared_ptr<const PartMesh> mesh,
                  const Eigen::Isometry3d& X_WP);

/// The ids of a shape's faces, in the order of BoxFace or CylinderFace.
std::span<const char* const> FaceIds(PartShape shape);

/// A cylinder of `radius_m` and `length_m` along z of X_WP, its faces named by their ids.
Part MakeCylinder(std::string name, double radius_m, double length_m,
                  const Eigen::Isometry3d& X_WP);

/// How the core models the tube's bending.
enum class TubeModel {
  kRod,     ///< a discrete Kirchhoff rod: large deflections, the elastica in the limit
  kLinear,  ///< the paper's small-deflection beam (for comparison with the paper)
};

/// "rod" or "linear".
const char* ToString(TubeModel model);

struct ModelOptions {
  TubeModel tube = TubeModel::kRod;
  double time_step_s = 1.0e-3;  ///< the core's fixed step [s]
  /// The rod's elements; 0: the core's default (core::ElementCount). More elements are more
  /// accurate and slower (docs/accuracy.md).
  int elements = 0;
};

/// The haptic device and the virtual coupling of the hand to the held end (docs/scene-format.md,
/// "Device").
struct Device {
  double max_force_N = 8.5;  ///< PHANToM Premium 1.5/6DOF
  double max_torque_Nm = 0.188;
  double max_stiffness_N_per_m = 800.0;
  double damping_Ns_per_m = 5.0;                     ///< the device's own physical damping b
  std::optional<double> coupling_stiffness_N_per_m;  ///< K_c; unset: a passive default
  std::optional<double> coupling_damping_Ns_per_m;   ///< unset: a default from the device
};

/// Axis-aligned box in world the hand may move in.
struct Workspace {
  Eigen::Vector3d min_W_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d max_W_m = Eigen::Vector3d::Zero();
};

/// Weights of the graph's pruning heuristics (paper V-B; graph::PruneWeights has the meaning).
struct Heuristics {
  double friction = 1.0;    ///< [-], >= 0
  double energy = 1.0;      ///< [-], >= 0
  double distance = 1.0;    ///< [-], >= 0
  double tolerance = 0.05;  ///< [-], >= 0: how far above the best score an arc is still kept
};

struct Scene {
  std::string name;
  model::TubeSpec tube;
  Contact contact;
  Friction friction;
  std::vector<Part> parts;
  Eigen::Isometry3d X_WH_start = Eigen::Isometry3d::Identity();  ///< held end at the start
  states::ContactFormation goal;
  Device device;
  ModelOptions model;
  std::optional<Workspace> workspace;  ///< unset: the parts' bounding box grown by the tube length
  Heuristics heuristics;
};

/// Friction that applies at a part: its own if set, the scene's otherwise.
const Friction& FrictionAt(const Scene& scene, std::size_t part_index);

/// How thin a part is [m]: a box's or a cylinder's least extent; a mesh's thinnest wall, the
/// least distance from a triangle straight through the solid to its other side (at most 4096
/// triangles, evenly spread, are measured).
double ThinnestSize_m(const Part& part);

/// The force the contact law pushes back with when a point reaches a part's middle,
/// K (eps + half the part's ThinnestSize_m) [N]: below the device's force, a full push can carry
/// the tube through the part.
double ContactHoldAtMiddle_N(const Scene& scene, const Part& part);

/// Rotation from roll-pitch-yaw [rad], applied as R = Rz(yaw) Ry(pitch) Rx(roll) (extrinsic
/// x-y-z, the ROS/URDF convention).
Eigen::Matrix3d RotationFromRpy(const Eigen::Vector3d& rpy_rad);

}  // namespace tubeplan::scene
