#pragma once
// Private to the core: the tube as a chain of FCL capsules ending in an FCL cylinder, the parts
// as FCL boxes, a broad phase in each box's frame, and the classification of each close pair into
// a tube element and a part element (contact-states.md, "Surface elements").

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/narrowphase/detail/gjk_solver_indep.h>

#include <tubeplan/core/core.hpp>

namespace tubeplan::core {

/// One close pair: a piece of the tube (capsule or end cylinder) and a part.
struct RawContact {
  states::TubeElement tube = states::TubeElement::kSide;
  int part_element = -1;  ///< index into the core's element list
  std::uint8_t face_mask = 0;
  std::uint32_t part = 0;  ///< index into scene.parts
  double s_m = 0.0;        ///< arc position of the centreline point under the contact
  /// >= 0 when apart; when the shapes overlap (`overlap` set) the signed depth (< 0) of a capsule
  /// whose axis is outside the part, else 0.
  double distance_m = 0.0;
  bool overlap = false;
  /// An end face pressed on a face within its dome's tilt: p_W_m is the dome's lowest point, on
  /// the face plane (collision.cpp; the field keeps the name of the centre of pressure it was).
  bool pressure_centre = false;
  Eigen::Vector3d normal_W = Eigen::Vector3d::UnitZ();  ///< from the part into the tube
  Eigen::Vector3d q_W_m = Eigen::Vector3d::Zero();      ///< nearest point on the part
  Eigen::Vector3d p_W_m = Eigen::Vector3d::Zero();      ///< nearest point on the tube
  /// A capsule over a face: Query marks it `over_face` (its piece and part); Collision::LineEnds,
  /// when asked, sets `line` and the ends of the stretch of its axis over the face, lo nearer the
  /// held end: each a parameter t of the piece's axis (node `piece` at t = 0, the next at 1), the
  /// arc position of the surface point facing the face there (LineSurfacePoint) and its distance
  /// to the face's plane (signed as distance_m). The nearest point is one of the two ends, which
  /// one by the sign of the piece's tilt to the face, so a PC's region runs from the lo end of its
  /// first piece to the hi end of its last (core.cpp); tilted, both ends move towards the nearest
  /// point, reaching it where their distances are eps / 10 apart.
  bool over_face = false;
  bool line = false;
  /// A capsule apart from the part within the band (most contacts: a tube lying in the groove
  /// has a hundred): Query gives its part, elements, piece and distance, enough to form the PCs,
  /// and leaves its points, normal and arc position (normal_W, q_W_m, p_W_m, s_m) to
  /// Collision::Complete, which the core calls only for the few that become loads.
  bool deferred = false;
  int piece = 0;
  int part_slot = 0;  ///< the part among the Collision's
  /// A deferred contact may stand for a strip of them: pieces `piece` .. `piece + strip_pieces -
  /// 1`, consecutive, of one part, each over the same face (a tube lying on a face: tens a part).
  /// Their distances differ, nothing else does: `distance_m` is the least of them, at piece
  /// `strip_deepest` (the first of equals), `strip_farthest_m` the greatest, and
  /// Collision::StripPiece gives any one piece's contact, the one Query would have given alone.
  /// One contact: strip_pieces 1; the other two are read only for a strip (a deferred contact
  /// sets them to its own piece and distance, any other leaves them unset).
  int strip_pieces = 1;
  int strip_deepest = 0;
  double strip_farthest_m = 0.0;
  double t_lo = 0.0, t_hi = 0.0;
  double s_lo_m = 0.0, s_hi_m = 0.0;
  double d_lo_m = 0.0, d_hi_m = 0.0;
};

/// The surface point at parameter t of a line contact's piece (RawContact::line), the nodes being
/// those Query was given, r1 the tube's radius.
inline Eigen::Vector3d LineSurfacePoint(const RawContact& c, double t,
                                        std::span<const Eigen::Vector3d> nodes_W, double r1_m) {
  const Eigen::Vector3d& a_W = nodes_W[std::size_t(c.piece)];
  const Eigen::Vector3d& b_W = nodes_W[std::size_t(c.piece) + 1];
  return a_W + t * (b_W - a_W) - r1_m * c.normal_W;
}

/// Whether a face mask names a face (one bit), not an edge or a vertex. Not std::popcount, which
/// without -mpopcnt is a library call (2 % of a tick in the profile).
inline bool IsFaceMask(std::uint8_t mask) { return mask != 0 && (mask & (mask - 1)) == 0; }

inline constexpr int kMaxRawContacts = 4 * kMaxCapsules;

/// Squared distance from the segment a-b to the box [-half, half] (all in the box's frame), and
/// the segment parameter t in [0, 1] of a nearest point. Exact (convex piecewise quadratic).
double SegmentBoxDistanceSquared(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                 const Eigen::Vector3d& half, double& t_min);

/// Distance from the flat-ended cylinder of radius r on the axis a-b to the box [-half, half]
/// (all in the box's frame) when a face of the box is nearest: the cylinder's lowest point along
/// a face's outward normal (its support point) lies beyond that face's plane, and its foot on the
/// plane lies within the face. The plane bounds the box, so no box point is nearer than the plane
/// distance, and the foot is a box point at exactly that distance: the result is exact. Returns
/// false when no face certifies itself this way (an edge or a vertex is nearest, or the shapes
/// overlap); then a general method is needed. On an exact tie (the end face or a generator
/// parallel to the face) the support point is the end's centre or the axis end nearer the face.
bool CylinderBoxFaceDistance(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius,
                             const Eigen::Vector3d& half, double& distance,
                             Eigen::Vector3d& p_cylinder, Eigen::Vector3d& q_box);

/// How deep the flat-ended cylinder on the axis a-b overlaps the box [-half, half] (box frame):
/// the smallest distance by which its support point lies below a face plane, with that face's
/// outward normal, the support point and its foot. Moving the cylinder out by that depth along
/// the normal separates the two (the plane bounds the box), so the depth is exact when a face
/// is the way out (an end pressed into a face) and an upper bound otherwise. False when the
/// shapes do not overlap or the depth is r1 or more (then no direction is trusted).
bool CylinderBoxPenetration(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius,
                            const Eigen::Vector3d& half, double& depth, Eigen::Vector3d& p_cylinder,
                            Eigen::Vector3d& q_box, Eigen::Vector3d& normal);

/// Parts a Query may leave out whole (the core's, docs/core.md "Idle parts"): a part with no load
/// last tick whose every piece within the band is, by the distances kept from earlier queries,
/// provably farther than `floor_m`. The core then checks each pass of its solve against `gap_m`
/// and asks again with nothing left out where a left-out pair might have closed.
struct IdleParts {
  std::span<const std::uint8_t> may_leave_out;  ///< per scene part index; empty: none
  double floor_m = 0.0;
  // Out: what the left-out parts leave, in groups of pieces. A tube point within a part's slab
  // along one of its axes has its nearest box point at the same coordinate there, so the pair's
  // normal has no component along that axis: a group's normal lies in the span of the part's
  // axes along which one of its pieces reaches out of the slab (`dims` of them: along `axis_W`
  // when 1, across it when 2, anywhere when 3). Its pieces are at least `gap_m` away and no
  // farther along the tube than `s_max_m`; only motion along such a normal, and bending no
  // larger than the bending there, can close one.
  struct Group {
    Eigen::Vector3d axis_W = Eigen::Vector3d::UnitZ();
    int dims = 3;
    double gap_m = 0.0;
    double s_max_m = 0.0;
    /// The first of its parts in the query's order (scene index): their loads would have come
    /// after those of every part before it.
    std::uint32_t first_part = 0;
  };
  static constexpr int kMaxGroups = 8;
  std::array<Group, kMaxGroups> groups{};
  int group_count = 0;
  int left_out = 0;  ///< parts left out
};

class Collision {
 public:
  /// `element_of[part][mask]` is the element index of a face mask of a part.
  Collision(const scene::Scene& scene, std::span<const std::uint32_t> parts, int capsule_count,
            std::vector<std::array<int, 64>> element_of);

  /// Close pairs of the tube whose centreline nodes (capsule_count + 1 of them, equally spaced
  /// in arc length from the held end) are `nodes_W`, with the free end's axis `tip_tangent_W`.
  /// The last intervals (at least r1 of tube) are one straight cylinder along the tip tangent, so
  /// that no capsule's round cap reaches past the flat end face. Writes at most out.size() contacts
  /// and returns how many entries it wrote (the entry past them may be overwritten too); no
  /// allocation. Pairs closer than `band_m` are returned (the core asks for more than epsilon so
  /// that a contact about to close this tick is in its system, and one releasing leaves smoothly).
  /// A strip of deferred contacts takes one entry (RawContact::strip_pieces) and counts as its
  /// pieces towards out.size(): the contacts it stands for are the ones a query writing each alone
  /// would have written, in the same order (StripPiece gives them).
  ///
  /// `idle` (optional) names parts that may be left out; see IdleParts. An end piece within the
  /// band of a part it could face (its axis within the tilt at which an end face presses at its
  /// dome's lowest point, collision.cpp) keeps that part in: such a contact carries its relaxed
  /// point from tick to tick.
  int Query(std::span<const Eigen::Vector3d> nodes_W, const Eigen::Vector3d& tip_tangent_W,
            double band_m, std::span<RawContact> out, IdleParts* idle = nullptr) const;
  /// The end cylinder's length (at least r1): a point of the end piece is within it plus r1 of
  /// the tip.
  double end_length_m() const { return end_m_; }
  /// The radius of the dome that stands for the end face on a part's face (collision.cpp).
  double dome_radius_m() const { return dome_radius_m_; }
  double dome_height_m() const { return dome_height_m_; }
  /// The tolerance's dome (the constructor's): the largest radius set_dome_radius_m takes.
  double tolerance_dome_radius_m() const { return tolerance_dome_radius_m_; }
  /// Sets the dome's radius for the next queries, within [1.25 r1, the tolerance's dome].
  void set_dome_radius_m(double radius_m);

  /// Narrow-phase evaluations (closed form or GJK) of the last Query, for the benchmarks'
  /// figures; pairs settled by an earlier query's distance (below) are not among them.
  int last_narrow_phase_calls() const { return narrow_calls_; }
  /// Pairs of the last Query that passed the broad phase and were settled as farther than the
  /// band by a distance an earlier Query computed (temporal coherence, collision.cpp).
  int last_coherent_skips() const { return coherent_skips_; }

  /// Whether the centreline `nodes_H` (held-end frame H), placed by (R_WH, p_WH), goes through a
  /// part: a node lies deeper than `depth_m` inside it (past every face plane by more than
  /// that), or, for a part no thicker than 2 depth_m along one axis (a sheet, which has no such
  /// inside), the centreline crosses it from beyond one face to beyond the opposite one, more
  /// than `depth_m` inside its other faces. The core keeps the tube from going there
  /// (docs/core.md, "Through a part"). The nodes' bounding box is tried against each part
  /// first, so a tube nowhere near it costs a box test a part. `spacing_m` > 0 promises that
  /// consecutive nodes are at most that far apart (a shape that keeps its length: the elastica's,
  /// the rod's); the box is then taken over every fourth node and grown by twice it, a quarter of
  /// the work.
  bool AxisThrough(std::span<const Eigen::Vector3d> nodes_H, const Eigen::Matrix3d& R_WH,
                   const Eigen::Vector3d& p_WH, double depth_m, double spacing_m = 0.0) const;

  /// For a contact Query marked `over_face` (a capsule over a face), the ends of the stretch of
  /// its axis over the face, drawn towards its nearest point as the piece tilts to the face
  /// (RawContact::line); `nodes_W` are the nodes Query was given. Nothing for other contacts.
  void LineEnds(RawContact& c, std::span<const Eigen::Vector3d> nodes_W) const;

  /// Makes a `deferred` contact whole: its nearest points, normal and arc position, the same bits
  /// Query would have given (the same closed form on the same nodes); `nodes_W` are the nodes
  /// Query was given. Nothing for a contact that is not deferred.
  void Complete(RawContact& c, std::span<const Eigen::Vector3d> nodes_W) const;

  /// The contact of piece `piece` of the strip `strip` the last Query wrote
  /// (RawContact::strip_pieces): the same bits as Query writing it alone. Its distance is the one
  /// Query kept for the piece; so only until the next Query.
  RawContact StripPiece(const RawContact& strip, int piece) const;
  /// The distance of piece `piece` of the strip `strip` the last Query wrote: StripPiece's, without
  /// the rest of the contact.
  double StripPieceDistance(const RawContact& strip, int piece) const {
    return kept_[std::size_t(strip.part_slot) * std::size_t(kMaxCapsules) + std::size_t(piece)].d_m;
  }

  /// Forgets the distances kept from earlier queries. Query's results never depend on them, only
  /// its narrow-phase count does: the core forgets them when it is reset or restored, so that
  /// its figures depend on the ticks since then alone.
  void ForgetDistances();

 private:
  struct Part {
    std::uint32_t index = 0;
    fcl::Boxd box;
    Eigen::Isometry3d X_WP = Eigen::Isometry3d::Identity();
    Eigen::Isometry3d X_PW = Eigen::Isometry3d::Identity();
    // The same poses as plain rotation and translation: Isometry3d's products go through 4x4
    // matrices, which cost a tenth of a tick here.
    Eigen::Matrix3d R_PW = Eigen::Matrix3d::Identity(), R_WP = Eigen::Matrix3d::Identity();
    Eigen::Vector3d p_PW = Eigen::Vector3d::Zero(), p_WP = Eigen::Vector3d::Zero();
    Eigen::Vector3d half_m = Eigen::Vector3d::Zero(), minus_half_m = Eigen::Vector3d::Zero();
    // FaceMask's planes per axis, half_m - part_tolerance_m_ and -half_m + part_tolerance_m_: a
    // point at or above the first lies on the face at +half_m, at or below the second on the one
    // at -half_m. Made once: FaceMask runs once a contact.
    std::array<double, 3> edge_above_m{}, edge_below_m{};
    // FaceMask of a point on the face at -half_m (index 2 a) or +half_m (2 a + 1) along axis a,
    // within the edges' planes of the other two axes: the face's bits alone (two for a part
    // thinner than the tolerance). Query's runs over a face take it (collision.cpp).
    std::array<std::uint8_t, 6> face_mask_of_face{};
    // Parts set square to the world (most scenes' floors and walls) skip the rotation: a
    // product with the identity gives the same numbers, so nothing else changes.
    bool aligned = false;
    Eigen::Vector3d ToPart(const Eigen::Vector3d& p_W) const {
      return aligned ? Eigen::Vector3d(p_W + p_PW) : Eigen::Vector3d(R_PW * p_W + p_PW);
    }
    Eigen::Vector3d ToWorld(const Eigen::Vector3d& p_P) const {
      return aligned ? Eigen::Vector3d(p_P + p_WP) : Eigen::Vector3d(R_WP * p_P + p_WP);
    }
    Eigen::Vector3d DirectionToWorld(const Eigen::Vector3d& v_P) const {
      return aligned ? v_P : Eigen::Vector3d(R_WP * v_P);
    }
  };
  // Classifies the part point q (part frame) into a face mask of the box.
  std::uint8_t FaceMask(const Part& part, const Eigen::Vector3d& q_P) const;
  // Points in the part's frame from here on.
  bool PassesBroadPhase(const Part& part, const Eigen::Vector3d& a_P, const Eigen::Vector3d& b_P,
                        double band_m) const;
  // Capsule (segment a-b swept by r1) against the box, in closed form: the signed distance
  // (negative when the capsule dips into the box with its axis outside; then exact too), the
  // deepest or nearest tube point, the nearest box point, and the axis point nearest the box and
  // its distance from it, whose difference over that distance is the normal from the part into
  // the tube (formed by the caller where it is read), all in the part's frame (most pieces that
  // pass the broad phase turn out farther than the band and need nothing in the world frame).
  // False only when the axis reaches into the box (no defined direction).
  bool CapsuleBoxDistance(const Part& part, const Eigen::Vector3d& a_P, const Eigen::Vector3d& b_P,
                          double& distance_m, Eigen::Vector3d& p_tube_P, Eigen::Vector3d& q_part_P,
                          Eigen::Vector3d& c_P, double& axis_m) const;
  struct KeptDistance;
  // Whether the idle part parts_[part_i], left out by its last evaluation (valid summary), still
  // is: every node has moved too little since for it to matter (world frame only). Then it adds
  // its groups to idle's and counts it.
  bool StillLeftOut(std::size_t part_i, std::span<const Eigen::Vector3d> nodes_W,
                    const Eigen::Vector3d& end_start_W, double band_m, IdleParts& idle) const;
  // Evaluates the idle part parts_[part_i] afresh: whether it can be left out of this query
  // (IdleParts); then it adds its groups to idle's and counts it. Reads the part-frame nodes Query
  // has just made.
  bool LeaveOut(std::size_t part_i, const KeptDistance* kept,
                std::span<const Eigen::Vector3d> nodes_W, const Eigen::Vector3d& end_start_W,
                const Eigen::Vector3d& end_start_P, double band_m, IdleParts& idle) const;
  // Whether the distance kept for a piece, now that its axis runs a_W-b_W, proves the pair
  // farther than the band.
  bool KeptBeyondBand(const KeptDistance& kept, const Eigen::Vector3d& a_W,
                      const Eigen::Vector3d& b_W, double band_m) const;
  // The same with the squared motions of the axis's ends since the distance was kept.
  bool KeptBeyondBand(const KeptDistance& kept, double moved_a_sq, double moved_b_sq,
                      double band_m) const;
  // Keeps the capsule distance d_m of the piece on a_W-b_W (beyond the band, or in it: an idle
  // part is left out by the kept distances of its pieces in the band).
  void Keep(KeptDistance& kept, const Eigen::Vector3d& a_W, const Eigen::Vector3d& b_W,
            double d_m) const;
  // Returns the contact's part point in the part's frame.
  Eigen::Vector3d Overlapping(const Part& part, const Eigen::Vector3d& a_W,
                              const Eigen::Vector3d& b_W, RawContact& c) const;

  std::vector<Part> parts_;
  std::vector<std::array<int, 64>> element_of_;
  fcl::Capsuled capsule_;
  fcl::Cylinderd end_;
  mutable fcl::detail::GJKSolver_indep<double> solver_;
  double radius_m_ = 0.0;
  double length_m_ = 0.0;
  double piece_m_ = 0.0;  // arc length of one capsule, l / N
  int end_pieces_ = 1;    // node intervals the end cylinder covers
  double end_m_ = 0.0;    // its length, end_pieces_ * piece_m_ >= r1
  double part_tolerance_m_ = 0.0;
  double tube_tolerance_m_ = 0.0;
  double eps_m_ = 0.0;           // the contact threshold epsilon
  double parallel_per_m_ = 0.0;  // 1 / (eps / 10): LineEnds' tilt scale
  // The end face on a part's face is a spherical cap over the rim, of height dome_height_m_ and
  // radius dome_radius_m_; it is the lowest point while sin(tilt) < dome_sin_max_ = r1 / R.
  double dome_height_m_ = 0.0;
  double dome_radius_m_ = 0.0;
  double tolerance_dome_radius_m_ = 0.0;
  double tolerance_dome_height_m_ = 0.0;
  double dome_sin_max_ = 0.0;
  // An end face presses at its dome's lowest point only while sin(tilt) < dome_sin_max_ from a
  // face (collision.cpp): 1 - that squared, the least square of the end's axis component along a
  // face normal at which it can.
  double facing_axis_sq_ = 0.0;
  mutable int narrow_calls_ = 0;
  mutable int coherent_skips_ = 0;
  mutable std::array<Eigen::Vector3d, kMaxCapsules + 1> nodes_P_{};  // scratch
  // Query's boxes of runs of kGroup capsules, world frame (scratch).
  static constexpr int kGroup = 8;
  mutable std::array<Eigen::Vector3d, (kMaxCapsules + kGroup - 1) / kGroup> group_lo_W_{},
      group_hi_W_{};
  // A lower bound on the distance from a piece's capsule (its axis a-b swept by r1; for the end
  // piece the capsule that contains its cylinder) to a part, with the axis's ends when it was
  // computed. Per part, kMaxCapsules pieces; sized at construction, so Query allocates nothing.
  static constexpr double kCoherenceMargin_m = 1e-9;  // collision.cpp, KeptBeyondBand
  struct KeptDistance {
    // The axis's ends a and b, the columns of one 3 x 2 block: two consecutive nodes, contiguous
    // in the query's span, are kept with three 16-byte copies (Query's capsules over a face).
    Eigen::Matrix<double, 3, 2> ends_W_m = Eigen::Matrix<double, 3, 2>::Zero();
    double d_m = -std::numeric_limits<double>::infinity();  // none: never skips
    Eigen::Vector3d a_W_m() const { return ends_W_m.col(0); }
    Eigen::Vector3d b_W_m() const { return ends_W_m.col(1); }
  };
  mutable std::vector<KeptDistance> kept_;
  // A part's last evaluation as idle (LeaveOut), per part, and where the tube's nodes and its end
  // piece's start were then ((kMaxCapsules + 2) points a part): it holds for later queries while
  // the tube has moved less than its slacks (along each axis, a piece crossing no slab; the end
  // turning onto no face), the band has not widened past the one it was taken at, and every gap
  // less the motion stays above the floor. Forgotten with the distances, and when the part is
  // queried.
  struct IdleSummary {
    bool valid = false;
    double band_m = 0.0;
    double slack_m = 0.0;  // how far the end may move before it could face a face
    // The dome's range it was made with (facing_axis_sq_): a wider range since (a smaller dome
    // radius) may let the end face a face sooner than slack_m says.
    double facing_axis_sq = 0.0;
    Eigen::Vector3d slab_slack_m = Eigen::Vector3d::Zero();  // per axis: before a slab is crossed
    std::array<IdleParts::Group, IdleParts::kMaxGroups> groups{};
    int group_count = 0;
  };
  mutable std::vector<IdleSummary> summaries_;
  mutable std::vector<Eigen::Vector3d> anchors_;
};

}  // namespace tubeplan::core
