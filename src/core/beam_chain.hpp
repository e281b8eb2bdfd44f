#pragma once
// Private to the core: the tube as a cantilever from the held end under several point loads on
// its centreline, by the paper's segmented rule or by influence coefficients (physics.md, eq. 6),
// with the linear model or the elastica. Everything in the held-end frame H (= the tube frame O
// of linear_beam.hpp: z along the undeformed axis). Fixed-size storage only.
//
// Both rules are one formula. A load j acts on the cantilever that starts at its clamp c_j: the
// held end (c_j = 0) for the coupled rule; for the segmented rule the cross-section of the
// previous cut, i.e. the previous group of loads (loads closer than a tube radius share a cut).
// A point at arc position s >= c_j moves by infl(s - c_j, s_j - c_j) F_j laterally, where
//     infl(a, b) = a^2 (3 b - a) / (6 E I)  for a <= b,   b^2 (3 a - b) / (6 E I)  for a >= b,
// the textbook influence coefficient; points before c_j do not move. For the segmented rule this
// is exactly the paper's chain: segment k is a cantilever loaded by its own load only, clamped at
// the cross-section where segment k - 1 ended, which carries it along rigidly (a point beyond a
// cantilever's load moves by the load point's deflection plus its rotation times the distance,
// which is the a >= b branch).
//
// A contact acts on the tube's surface, a distance r from the centreline (a rim contact: r = r1).
// Its force F is carried to the centreline as F and the moment M = r x F, and the surface point
// moves with the centre and with the section's rotation omega: dx = dc + omega x r. With
// a = s - c, b = s_j - c, Z = [z]x and P the lateral projection, a load j moves the centre at s by
//     uF(a, b) P F - uM(a, b) Z M,      uM = a^2 / (2 E I) (a <= b),  b (2a - b) / (2 E I) (a >= b)
// and turns its section by
//     omega = thF(a, b) Z F + thM(a, b) P M,   thF = d uF / da,  thM = min(a, b) / (E I),
// so the compliance of surface point i to force j is (Maxwell-Betti: symmetric for one clamp)
//     W_ij = uF P - uM Z [r_j]x - [r_i]x (thF Z + thM P [r_j]x).
// Without the rotation term a rim contact's point would move as the centre does, while the end
// face's rotation moves it by r1 times the tip angle: for the rubber tube of scenes/groove.yaml
// 100 times the penalty spring's compliance, which made a lagged scheme oscillate.

#include <array>
#include <span>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <tubeplan/core/core.hpp>
#include <tubeplan/model/elastica.hpp>
#include <tubeplan/model/rod.hpp>

namespace tubeplan::core {

/// The cross-product matrix: Skew(v) w = v x w.
inline Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

struct BeamLoad {
  double s_m = 0.0;                                 ///< arc position of the load point
  Eigen::Vector3d f_H_N = Eigen::Vector3d::Zero();  ///< force on the tube, frame H
  Eigen::Vector3d r_H_m = Eigen::Vector3d::Zero();  ///< surface point minus centre, frame H
  double clamp_m = 0.0;                             ///< c_j (set by BeamChain::Assign)
  int group = 0;                                    ///< cut group (set by Assign)
  int pc = -1;  ///< loads of one PC (the two ends of a line contact) are never cut apart
};

/// The solved shape of one elastica segment (a group's cantilever).
struct ElasticaSegment {
  model::ElasticaSolution solution;
  Eigen::Vector3d origin_H = Eigen::Vector3d::Zero();   ///< clamp cross-section centre
  Eigen::Matrix3d R_HS = Eigen::Matrix3d::Identity();   ///< clamp frame S (z along the tangent)
  Eigen::Vector3d bend_x_S = Eigen::Vector3d::UnitX();  ///< bending direction in S
  /// Unit tangent at the tip in S: the tip's turn (tip angle about z x bend_x_S) applied to z,
  /// kept from SolveElasticaChain's carry of the clamp frame, which forms that turn anyway (the
  /// tick's tip tangent took another sine and cosine of the same angle).
  Eigen::Vector3d tip_tangent_S = Eigen::Vector3d::UnitZ();
  double clamp_m = 0.0, length_m = 0.0;
};

/// One segment of the rod chain (the large-deflection model where the elastica does not cover the
/// loading): a discrete rod (model/rod.hpp) clamped at the cross-section where the previous one
/// ended, carrying its loads at their own arc positions with their offset moments.
struct RodSegment {
  model::RodSolution solution;  ///< its root moment is the next solve's starting guess
  std::array<model::RodLoad, kMaxLoads> loads_S{};  ///< in the clamp frame S, s from the clamp
  std::array<int, kMaxLoads> index{};               ///< the BeamLoad each came from
  int load_count = 0;
  Eigen::Vector3d origin_H = Eigen::Vector3d::Zero();  ///< clamp cross-section centre
  Eigen::Matrix3d R_HS = Eigen::Matrix3d::Identity();  ///< clamp frame S (z along the tangent)
  double clamp_m = 0.0, end_m = 0.0;                   ///< arc positions of its clamp and end
  /// From its last tangent compliance (Rod::Compliance): the end section's turn per N of each
  /// load's force, frame S, for end_turn_count loads; the next solve's predictor.
  std::array<Eigen::Matrix3d, kMaxLoads> end_turn_per_N{};
  int end_turn_count = 0;
};

class BeamChain {
 public:
  BeamChain(const scene::Scene& scene);

  /// Takes the loads whose `member` flag is set (the first `count`), writes their indices
  /// sorted by arc position to `order` and sets their group and clamp; returns how many there
  /// are in `members` and the number of groups.
  int Assign(std::array<BeamLoad, kMaxLoads>& loads, int count,
             const std::array<bool, kMaxLoads>& member, std::array<int, kMaxLoads>& order,
             int& members) const;

  /// Lateral influence coefficient [m/N] of load j on the point at arc position s_m.
  double Influence(double s_m, const BeamLoad& load) const;
  /// d/ds of Influence [1/N]: the rotation of the tangent per newton.
  double InfluenceSlope(double s_m, const BeamLoad& load) const;

  /// W_ij above [m/N], frame H: displacement of load i's surface point per force of load j.
  /// Without `moments` the offset moment r_j x F_j is left out (the elastica carries tip forces
  /// only, and the compliance must describe the shape the model will produce).
  Eigen::Matrix3d Compliance(const BeamLoad& i, const BeamLoad& j, bool moments = true) const {
    Eigen::Matrix3d W;
    Compliance(i, j, moments, W);
    return W;
  }
  /// The same, written into W (the tick's 18 a three-PC tick: a returned block copied into place
  /// is read right after the callee wrote it, and such a load waits for the stores to reach the
  /// cache; `perf` had a fifth of build_compliance's time there).
  void Compliance(const BeamLoad& i, const BeamLoad& j, bool moments, Eigen::Matrix3d& W) const;
  /// An upper bound [m] of |Compliance(i, j, moments) df_H| over every point i of the tube (any
  /// arc position, its offset from the centreline at most r_max_m): how far a change df_H [N]
  /// of load j's force moves any surface point. Each coefficient grows with the point's arc
  /// position, so a point at s_max_m bounds all those up to there. `normal_H` projects onto the
  /// directions the bound is for (a part's possible normals: the bound of |n . displacement|
  /// for unit n among them), `turn_H` is what a turn's cross product with such an n can keep
  /// (the identity, or the projection across n when n is one direction).
  double DisplacementBound(const BeamLoad& j, const Eigen::Vector3d& df_H, bool moments,
                           double r_max_m, double s_max_m, const Eigen::Matrix3d& normal_H,
                           const Eigen::Matrix3d& turn_H) const;
  /// The same for the change (Compliance(i, now) - Compliance(i, then)) f_H of one force f_H
  /// moved from `then` to `now` (another arc position or offset). With one clamp each term's
  /// coefficient grows with the load's arc position at every point, and so does the difference
  /// with the point's: its value at s_max bounds it. With two clamps, the two bounds added.
  double DisplacementChangeBound(const BeamLoad& now, const BeamLoad& then,
                                 const Eigen::Vector3d& f_H, bool moments, double r_max_m,
                                 double s_max_m, const Eigen::Matrix3d& normal_H,
                                 const Eigen::Matrix3d& turn_H) const;
  /// Displacement of the centre at s_m [m] and rotation of its section [rad], frame H, under
  /// load j (force and the moment of its offset).
  Eigen::Vector3d CentreDisplacement(double s_m, const BeamLoad& j) const;
  Eigen::Vector3d SectionRotation(double s_m, const BeamLoad& j) const;

  /// The linear model's response to a moment at a section (an end face's dome, docs/core.md):
  /// displacement [m/(N m)] of load i's surface point per moment [N m] on the section of
  /// `at` (its arc position and clamp), frame H; the section's turn [rad/N] at s_m per force of
  /// load j (force and the moment of its offset), frame H; and the section's own turn per moment
  /// about a lateral axis [rad/(N m)]. The first is the second's transpose where i's clamp is
  /// at's (Maxwell-Betti).
  Eigen::Matrix3d MomentCompliance(const BeamLoad& i, const BeamLoad& at) const;
  Eigen::Matrix3d TurnCompliance(double s_m, const BeamLoad& j) const;
  double TurnPerMoment(const BeamLoad& at) const;
  /// An upper bound [m] of |MomentCompliance(i, at) M| over every point i as in
  /// DisplacementBound (arc position up to s_max_m, offset at most r_max_m).
  double MomentDisplacementBound(const BeamLoad& at, double moment_Nm, double r_max_m,
                                 double s_max_m) const;

  /// Whether the elastica can carry these loads: one group per cantilever (segmented), or a
  /// single group (coupled), and every segment's load parameter within the solver's range.
  /// `order` and `count` as Assign left them.
  bool ElasticaCovers(const std::array<BeamLoad, kMaxLoads>& loads,
                      const std::array<int, kMaxLoads>& order, int count, int groups) const;

  /// Solves the elastica chain: one segment per group, each loaded by its group's resultant at
  /// the group's last load point, clamped where the previous one ended. Loads must be Assigned.
  /// Returns the number of segments.
  int SolveElasticaChain(const std::array<BeamLoad, kMaxLoads>& loads, int count,
                         const std::array<int, kMaxLoads>& order,
                         std::array<ElasticaSegment, kMaxLoads>& segments) const;

  /// Position in H of the centreline at s_m of a solved elastica chain.
  Eigen::Vector3d ElasticaPoint(const std::array<ElasticaSegment, kMaxLoads>& segments,
                                int segment_count, double s_m) const;
  /// The centreline of a solved chain at s = k l / (out.size() - 1), frame H, as ElasticaPoint
  /// to 1e-12 of l (tests/core/beam_chain_test.cpp): a segment's points are walked by
  /// model::ElasticaSamples over their range (the Jacobi functions carried from point to point
  /// by their addition theorems), about a third of ElasticaPoint's cost a point (21 points:
  /// 8.0 k instructions against 21.8 k; Core::Centreline, the shape a consumer asks for).
  void ElasticaEvenPoints(const std::array<ElasticaSegment, kMaxLoads>& segments, int segment_count,
                          std::span<Eigen::Vector3d> out) const;
  /// The centreline of a solved chain at s = k l / (nodes.size() - 1), frame H: exact at
  /// kElasticaSamples points per segment and cubic Hermite (positions and tangents) between
  /// them: within 2 um of the exact shape up to alpha = 10 (tests/core/beam_chain_test.cpp),
  /// i.e. K x 2 um = 0.02 N of penalty force, at a third of the cost of every node exactly.
  void ElasticaNodes(const std::array<ElasticaSegment, kMaxLoads>& segments, int segment_count,
                     std::span<Eigen::Vector3d> nodes) const;
  static constexpr int kElasticaSamples = 17;

  /// Unit tangent in H at the free end of a solved elastica chain.
  Eigen::Vector3d ElasticaTipTangent(const std::array<ElasticaSegment, kMaxLoads>& segments,
                                     int segment_count) const;
  /// 3x3 tangent compliance [m/N] of a segment's tip to its own load, frame H (finite
  /// differences of the elastica in the bending plane; rotational symmetry across it).
  Eigen::Matrix3d ElasticaCompliance(const ElasticaSegment& segment,
                                     const Eigen::Vector3d& f_H_N) const;

  /// Solves the rod chain for the Assigned loads: the paper's segmented rule cuts it at each
  /// group (a segment per group, clamped where the previous ended); the coupled rule is one rod
  /// from the held end carrying every load. Each segment starts from the root moment its slot in
  /// `segments` holds (last tick's). Returns the number of segments, or 0 if one did not
  /// converge (the caller falls back to the linear model). When `nodes` is not empty (at least
  /// 2 and at most kMaxCapsules + 1 of them) it also writes the chain's centreline there, as
  /// RodNodes would for the solved segments: each segment's solve draws its nodes on its way
  /// (model::Rod::Solve with samples), so no integration is added for the shape.
  int SolveRodChain(const std::array<BeamLoad, kMaxLoads>& loads, int count,
                    const std::array<int, kMaxLoads>& order,
                    std::array<RodSegment, kMaxLoads>& segments,
                    std::span<Eigen::Vector3d> nodes = {}) const;
  /// The rod chain of one segment (the coupled rule, or the segmented rule with every load in
  /// one group) solved with its loads' forces across the held end's axis (x, y of H) unknown:
  /// those that put the centre at each load's arc position at (x, y) of `pinned_H` (indexed as
  /// `loads`), model::Rod::SolvePinned, started from the end frame `start_end_R`. On success
  /// the loads' x, y forces, the segment (as SolveRodChain leaves it) and the centreline at
  /// `nodes` are the solution's, and it returns true; otherwise nothing is written.
  bool SolveRodPinned(std::array<BeamLoad, kMaxLoads>& loads, int count,
                      const std::array<int, kMaxLoads>& order,
                      std::array<RodSegment, kMaxLoads>& segments,
                      const Eigen::Matrix3d& start_end_R,
                      const std::array<Eigen::Vector3d, kMaxLoads>& pinned_H,
                      std::span<Eigen::Vector3d> nodes) const;
  /// Tangent compliance of a solved segment's loads to each other, frame H, written to
  /// w[i][j] for the BeamLoad indices i, j of the segment. False if singular. With `moment`,
  /// also what a moment on the segment's end section (at its last load) does, frame H: the end's
  /// turn per moment, and moment->w_per_Nm[i] for the segment's BeamLoad indices i.
  bool RodCompliance(RodSegment& segment,
                     std::array<std::array<Eigen::Matrix3d, kMaxLoads>, kMaxLoads>& w,
                     model::RodEndMoment* moment = nullptr) const;
  /// The centreline of a solved rod chain at s = k l / (nodes.size() - 1), frame H (straight
  /// beyond the last segment), and its tangent at the free end. The tick draws its nodes with
  /// the solve (SolveRodChain given the nodes), which spares this integration; this one is
  /// what tests/core/beam_chain_test.cpp holds that to.
  void RodNodes(const std::array<RodSegment, kMaxLoads>& segments, int segment_count,
                std::span<Eigen::Vector3d> nodes) const;
  Eigen::Vector3d RodTipTangent(const std::array<RodSegment, kMaxLoads>& segments,
                                int segment_count) const;

  double bending_stiffness_Nm2() const { return EI_; }
  double length_m() const { return length_m_; }
  double outer_radius_m() const { return r1_; }
  double group_tolerance_m() const { return group_tolerance_m_; }

 private:
  double EI_ = 0.0;
  double length_m_ = 0.0;
  double r1_ = 0.0;
  double group_tolerance_m_ = 0.0;
  // Whether the moment coefficients (uM <= l^2 / EI, thM <= l / EI) are finite for arc lengths
  // within the tube's (Compliance).
  bool moments_finite_ = false;
  model::Rod rod_;
  scene::MultiContactRule rule_ = scene::MultiContactRule::kSegmented;
  /// A centreline node's cubic Hermite weights (ElasticaNodes): the samples j and j + 1 it lies
  /// between, and the weights of their points and of their tangents (the latter times the
  /// samples' spacing h).
  struct HermiteNode {
    int j = 0;
    double point0 = 0.0, tangent0_h = 0.0, point1 = 0.0, tangent1_h = 0.0;
  };
  static HermiteNode Hermite(double s_m, double clamp_m, double h_m);
  /// The weights of the nodes of a segment clamped at the held end and as long as the tube
  /// (clamp 0, length l: the tip loaded, one segment), for the tick's node count (the core's
  /// ChainCapsuleCount + 1), the first `full_nodes_` of them on that segment: the same numbers
  /// every tick, made once here. ElasticaNodes forms them per node otherwise.
  std::array<HermiteNode, kMaxCapsules + 1> full_hermite_{};
  int full_node_count_ = 0;  ///< the node count they are for (0: none)
  int full_nodes_ = 0;
};

}  // namespace tubeplan::core
