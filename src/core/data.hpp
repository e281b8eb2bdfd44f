#pragma once
// The core's changing data: the state a tick carries to the next (what a snapshot saves) and the
// scratch it works in, all sized once from the model. Nothing here allocates during a tick.

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <tubeplan/core/core.hpp>

#include "core/banded.hpp"
#include "core/model.hpp"
#include "core/rod.hpp"

namespace tubeplan::core {

/// Where on the tube a contact point is.
enum class SampleKind : std::uint8_t {
  kNode,     ///< the side surface at an inner node (the capsule chain's sphere there)
  kRim,      ///< the free end's rim
  kSide,     ///< the side surface of an end's half element, against a part's edge
  kCurve,    ///< the side surface about an inner node (its smooth centreline), against an edge
  kEndFace,  ///< the free end's face, against a part's vertex
};

/// One contact point between the tube's surface and a part. The point is a material point of the
/// section at `node` (kNode, kRim, kEndFace), of the element from `node` (kSide) or of the
/// smooth centreline's piece about `node` (kCurve), offset
/// from the centreline by `offset_W`; its distance moves with the material point whose offset
/// was `moving_offset_W` (Material), whose derivatives the assembly takes.
struct Sample {
  SampleKind kind = SampleKind::kNode;
  ElementIndex element = kNoElement;  ///< the part's element the nearest point lies on
  int part = 0;                       ///< index into Model::parts
  int node = 0;                       ///< the section's node, or the segment's first node
  int feature = 0;      ///< ring position (kRim), edge (kSide, kCurve) or vertex (kEndFace)
  double theta = 0.0;   ///< position along the segment (kSide) or the piece (kCurve), 0..1
  double weight = 1.0;  ///< share of K it carries
  /// d weight / d nodes from weight_first on (two or three): a share that fades moves with them.
  Eigen::Matrix<double, 9, 1> weight_gradient = Eigen::Matrix<double, 9, 1>::Zero();
  int weight_first = 0;
  int weight_nodes = 0;
  /// The leading part of the share's curvature, c g g^T (g over the same nodes): the bend of the
  /// smooth step it fades by along the coordinate it fades with, where that bend is convex.
  double weight_curve = 0.0;
  Eigen::Matrix<double, 9, 1> weight_curve_gradient = Eigen::Matrix<double, 9, 1>::Zero();
  double distance_m = 0.0;  ///< signed distance d of the point to the part
  /// The distance its contact presses by: its own, or for the rim's points on one part their
  /// smooth minimum (Assemble), so that every contact's force is K (eps - this).
  double contact_distance_m = 0.0;
  Eigen::Vector3d normal_W = Eigen::Vector3d::UnitZ();        ///< from the part into the tube
  Eigen::Matrix3d curvature_per_m = Eigen::Matrix3d::Zero();  ///< d2 distance / d point2
  Eigen::Vector3d point_W = Eigen::Vector3d::Zero();          ///< on the tube's surface
  Eigen::Vector3d offset_W = Eigen::Vector3d::Zero();         ///< from the centreline to the point
  Eigen::Vector3d moving_offset_W = Eigen::Vector3d::Zero();
  double normal_force_N = 0.0;
  Eigen::Vector3d friction_W_N = Eigen::Vector3d::Zero();  ///< on the tube
  double friction_ratio = 0.0;                             ///< |friction| / its static limit
  double static_limit_N = 0.0;
  double friction_work_J = 0.0;  ///< dissipated this tick
  bool sliding = false;
  int friction_point = -1;  ///< the friction point it carries, -1 for none
};

/// The rod carrier of a contact point of this kind.
inline Carrier CarrierOf(SampleKind kind) {
  switch (kind) {
    case SampleKind::kNode:
      return Carrier::kInnerNode;
    case SampleKind::kSide:
      return Carrier::kElement;
    case SampleKind::kCurve:
      return Carrier::kCurve;
    case SampleKind::kRim:
    case SampleKind::kEndFace:
      break;
  }
  return Carrier::kEndNode;
}

/// Friction carried by one contact point: its anchor on the part and whether it sticks.
struct FrictionPoint {
  SampleKind kind = SampleKind::kNode;
  int part = 0;
  int node = 0;
  int feature = 0;
  double theta = 0.0;
  Eigen::Vector3d offset_W = Eigen::Vector3d::Zero();   ///< material offset at the tick's start
  Eigen::Vector3d anchor_W = Eigen::Vector3d::Zero();   ///< where the spring holds the point
  Eigen::Vector3d normal_W = Eigen::Vector3d::UnitZ();  ///< tangent plane of the tick
  double limit_N = 0.0;   ///< the force its spring carries at most this pass (static or kinetic)
  double normal_N = 0.0;  ///< its normal force when the limit was set
  bool sliding = false;
  int sample = -1;  ///< the contact point that carries it this pass, -1 for none
};

inline constexpr int kMaxSamples = 512;
/// The feature of the held end's section's contact point (a kSide at node 0).
inline constexpr int kHeldFeature = -1;
/// Parts the side can press on at once as one contact each (SideGroup); the side's sections
/// on any more press each on their own.
inline constexpr int kMaxSideGroups = 16;

/// Whether a contact point is one of the side's sections that press on a part together as one
/// contact: the spheres at the inner nodes and the held end's section.
inline bool IsSideSection(const Sample& s) {
  return s.kind == SampleKind::kNode || (s.kind == SampleKind::kSide && s.feature == kHeldFeature);
}

/// Whether a contact point lies on the tube's surface, so that it names a PC and its depth is a
/// penetration: all but a point that bears alone (not one of the side's sections, which share
/// their contact's force by their softmin whatever their share) whose share of K has faded below
/// a thousandth. A share fades where the part lies off the surface the point stands for (a
/// vertex in the bore, for the end face; a part past the tube's end, for the side's end pieces):
/// such a point bears at most a thousandth of K (eps - d), and its depth is not the tube's (a
/// block's corner passing a rubber tube's end plane inside the bore, 4.4 mm deep in the capsule).
inline constexpr double kLeastShare = 1e-3;
inline bool OnSurface(const Sample& s) { return IsSideSection(s) || s.weight >= kLeastShare; }

/// The side's sections on one part: samples side_members[first, first + count).
struct SideGroup {
  int first = 0;
  int count = 0;
};
inline constexpr int kMaxFrictionPoints = 256;

/// The Hessian is the band B plus sum_k c_k u_k u_k^T over the side groups whose sections span
/// more than the band (one term each). Its factors: B's LDL^T, B^-1 u_k, and the factors of the
/// capacitance C^-1 + U^T B^-1 U (Woodbury's identity).
struct HessianFactors {
  BandLdlt band;
  std::array<Eigen::VectorXd, kMaxSideGroups> low_rank_u, low_rank_z;
  std::array<double, kMaxSideGroups> low_rank_c{};
  int low_rank_count = 0;
  using Capacitance =
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxSideGroups, kMaxSideGroups>;
  Eigen::LDLT<Capacitance> capacitance;
};

/// The factors of the last Hessian a converged, stable solve factored, kept for the solves after
/// it: one that starts with the same contacts takes its first step with them (SolveEquilibrium).
struct KeptFactors {
  HessianFactors factors;
  std::uint64_t contacts = 0;  ///< the contact set where the solve that kept them ended
  int solves = 0;              ///< the solves that have stepped with them since
  bool valid = false;
};

/// What a tick carries to the next: the rod, the held end, the hand, friction, kept factors.
struct CarriedState {
  std::vector<Eigen::Vector3d> x_W;                    ///< nodes 0..N [m]
  std::vector<Eigen::Vector3d> x_prev_W;               ///< the nodes a tick before [m]
  Eigen::Matrix3d R_WH = Eigen::Matrix3d::Identity();  ///< the held end's orientation
  Eigen::Vector3d p_hand_prev_W = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_held_prev_W = Eigen::Vector3d::Zero();
  std::array<FrictionPoint, kMaxFrictionPoints> friction{};
  int friction_count = 0;
  bool bends = false;  ///< the tube was bending (the markers' threshold has hysteresis)
  /// Per (part, node): the direction from the node's section centre to its point nearest the
  /// part, as the last tick found it (a section facing a part squarely keeps it).
  std::vector<Eigen::Vector3d> section_direction_W;
  /// Per contact point of the last tick: the element it was pressed on, per (node, part), so
  /// that a point pushed inside a part keeps being pushed back out the way it came in.
  std::vector<ElementIndex> entry_element;
  KeptFactors kept;
};

/// The tick's working memory.
struct Scratch {
  std::vector<Eigen::Vector3d> x_trial_W;
  std::vector<Eigen::Vector3d> x_start_W;  ///< the nodes at the tick's start
  std::array<Sample, kMaxSamples> samples{};
  int sample_count = 0;
  bool samples_truncated = false;
  Eigen::VectorXd unknowns, unknowns_trial;
  Eigen::VectorXd gradient, step, direction, work;
  BandMatrix hessian;
  HessianFactors factors;
  /// `factors` are an unshifted factorisation of the Hessian at this or the last iterate (it
  /// was positive definite), with its rank-one terms.
  bool factors_current = false;
  std::vector<std::uint8_t> parts_near;  ///< per part: within reach this iteration
  /// Per node: the distance from its section's surface to the nearest part (a lower bound) [m],
  /// and that bound for the parts not near.
  std::vector<double> clearance_m;
  double far_clearance_m = 0.0;
  std::vector<std::uint8_t> entry_seen;  ///< per (part, node): a contact point there this tick
  /// Where the rim's points sit on a part with friction is chosen once a tick, when the rim first
  /// meets the part, and kept for the tick's iterations, so that the potential they minimise
  /// does not change under them (on a frictionless part they are found at every iterate and
  /// these are not read): per (part, node), whether its direction is this tick's, and tangent x
  /// direction then.
  std::vector<std::uint8_t> section_chosen;
  std::vector<Eigen::Vector3d> section_side_W;
  /// Choices a trial point of the line search made, kept if the point is taken.
  struct SectionChoice {
    std::size_t index = 0;
    Eigen::Vector3d direction_W = Eigen::Vector3d::Zero(), side_W = Eigen::Vector3d::Zero();
  };
  std::array<SectionChoice, 128> section_pending{};
  int section_pending_count = 0;
  /// The side's sections grouped by the part element they press on (Assemble).
  std::array<int, kMaxSamples> side_members{};
  std::array<SideGroup, kMaxSideGroups> side_groups{};
  int side_group_count = 0;
  /// The inner nodes' tangents, kept while their nodes stay the same (Material).
  NodeTangents tangents;
  /// The loads of the part elements the contact points press on, and their friction limits,
  /// summed once for a friction pass: element_loads[element_of[k]] is contact point k's.
  struct ElementLoad {
    int part = 0;
    ElementIndex element = kNoElement;
    double group_N = 0.0;  ///< the normal force of its points within epsilon
    /// Of the side's sections on its part (IsSideSection), which press as one contact: their
    /// normal force and their depths eps - d, summed.
    double side_N = 0.0;
    double side_depth_m = 0.0;
    double static_N = 0.0, kinetic_N = 0.0;  ///< FrictionLimit at group_N
  };
  std::array<ElementLoad, kMaxSamples> element_loads{};
  /// The edges of one part near the tube (contacts.cpp), as many as the part with the most has.
  std::vector<int> edges_near;
  std::array<int, kMaxSamples> element_of{};
  /// Friction points made at the tick's end, before they replace the carried ones.
  std::array<FrictionPoint, kMaxFrictionPoints> friction_next{};
};

/// The tick's input and the quantities every stage reads.
struct TickInput {
  double t_s = 0.0;
  Eigen::Isometry3d X_W_hand = Eigen::Isometry3d::Identity();
  Eigen::Vector3d p_hand_W = Eigen::Vector3d::Zero();
  Eigen::Vector3d tangent_held_W = Eigen::Vector3d::UnitZ();  ///< the held end's axis
  bool hand_valid = true;
};

/// How the tick's solve went.
struct SolveReport {
  int iterations = 0;  ///< Newton iterations over all friction passes
  int friction_passes = 0;
  double residual_N = 0.0;
  bool converged = false;
  bool indefinite = false;  ///< a direction of negative curvature was followed (buckling)
};

struct Data {
  CarriedState state;
  Scratch scratch;
  TickInput input;
  SolveReport solve;
  StepOutput out;
};

/// What a snapshot keeps: the carried state and the last output.
struct SnapshotData {
  CarriedState state;
  StepOutput out;
  Eigen::Vector3d p_hand_W = Eigen::Vector3d::Zero();
  int sample_count = 0;  ///< the last tick's contact points (0: the tube was free)
};

/// Sizes every buffer of `data` for `model` and puts the tube straight at the held pose X_WH.
void InitData(const Model& model, const Eigen::Isometry3d& X_WH, Data& data);

}  // namespace tubeplan::core
