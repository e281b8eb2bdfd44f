#include "collision.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tubeplan::core {
namespace {

// Bit of BoxFace for the positive / negative side of each box axis (x, y, z).
constexpr std::array<int, 3> kPositiveFace = {2, 4, 0};
constexpr std::array<int, 3> kNegativeFace = {3, 5, 1};

Eigen::Isometry3d SegmentPose(const Eigen::Vector3d& a_W, const Eigen::Vector3d& b_W) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = 0.5 * (a_W + b_W);
  const Eigen::Vector3d axis = b_W - a_W;
  // Pieces have the tube's length over N, far from zero; FromTwoVectors handles antiparallel.
  X.linear() =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis).toRotationMatrix();
  return X;
}

// A capsule's round cap reaches r1 past its end node: the capsules stop at least r1 before the
// free end, and a flat-ended cylinder of a whole number of node intervals covers the rest.
int EndPieceCount(const scene::Scene& scene, int capsule_count) {
  const double piece_m = scene.tube.length_m / capsule_count;
  return std::clamp(static_cast<int>(std::ceil(scene.tube.outer_radius_m / piece_m - 1e-9)), 1,
                    capsule_count);
}
double EndCylinderLength(const scene::Scene& scene, int capsule_count) {
  return EndPieceCount(scene, capsule_count) * scene.tube.length_m / capsule_count;
}

}  // namespace

Collision::Collision(const scene::Scene& scene, std::span<const std::uint32_t> parts,
                     int capsule_count, std::vector<std::array<int, 64>> element_of)
    : element_of_(std::move(element_of)),
      capsule_(scene.tube.outer_radius_m, scene.tube.length_m / capsule_count),
      end_(scene.tube.outer_radius_m, EndCylinderLength(scene, capsule_count)),
      radius_m_(scene.tube.outer_radius_m),
      length_m_(scene.tube.length_m),
      piece_m_(scene.tube.length_m / capsule_count),
      end_pieces_(EndPieceCount(scene, capsule_count)),
      end_m_(EndCylinderLength(scene, capsule_count)),
      // A part point within 1 % of epsilon of a second face plane lies on their edge: far above
      // GJK's error (gjk_tolerance below), far below any distance that changes a force.
      part_tolerance_m_(0.01 * scene.contact.threshold_m),
      // The end face counts as flat on a face, or the last piece's side as flat on it, when its
      // far side is within a tenth of epsilon of its near side.
      tube_tolerance_m_(0.1 * scene.contact.threshold_m),
      eps_m_(scene.contact.threshold_m),
      parallel_per_m_(10.0 / scene.contact.threshold_m) {
  {
    const double r1 = scene.tube.outer_radius_m;
    // The dome's height is the tube's geometric tolerance (the capsules' chord error has the
    // same bound, ChainCapsuleCount): the cap over the rim circle with it has
    // R = (r1^2 + h^2) / (2 h).
    const double h = std::min(tube_tolerance_m_, 0.5 * r1);
    tolerance_dome_height_m_ = h;
    tolerance_dome_radius_m_ = (r1 * r1 + h * h) / (2.0 * h);
    set_dome_radius_m(tolerance_dome_radius_m_);
  }
  // FCL's default 1e-6 leaves micrometres of error in d, i.e. 1e-2 N at K = 1e4 N/m.
  solver_.gjk_tolerance = 1e-12;
  solver_.gjk_max_iterations = 128;
  for (const std::uint32_t p : parts) {
    const scene::BoxPart& box = scene.parts[p];
    Part part;
    part.index = p;
    part.box = fcl::Boxd(box.size_m);
    part.X_WP = box.X_WP;
    part.X_PW = box.X_WP.inverse();
    part.R_WP = box.X_WP.linear();
    part.p_WP = box.X_WP.translation();
    part.R_PW = part.R_WP.transpose();
    part.p_PW = -(part.R_PW * part.p_WP);
    part.half_m = 0.5 * box.size_m;
    part.minus_half_m = -part.half_m;
    for (int a = 0; a < 3; ++a) {
      part.edge_above_m[a] = part.half_m[a] - part_tolerance_m_;
      part.edge_below_m[a] = -part.half_m[a] + part_tolerance_m_;
    }
    part.aligned = part.R_WP == Eigen::Matrix3d::Identity();
    for (int a = 0; a < 3; ++a) {
      Eigen::Vector3d on_face_P = Eigen::Vector3d::Zero();
      on_face_P[a] = part.minus_half_m[a];
      part.face_mask_of_face[std::size_t(2 * a)] = FaceMask(part, on_face_P);
      on_face_P[a] = part.half_m[a];
      part.face_mask_of_face[std::size_t(2 * a + 1)] = FaceMask(part, on_face_P);
    }
    parts_.push_back(part);
  }
  kept_.resize(parts_.size() * std::size_t(kMaxCapsules));
  summaries_.resize(parts_.size());
  anchors_.resize(parts_.size() * std::size_t(kMaxCapsules + 2));
}

void Collision::set_dome_radius_m(double radius_m) {
  // At least 1.25 r1: a cap of height r1 / 2 at most, as the tolerance's is (the constructor).
  // At the tolerance's radius its own height, bit for bit: a tick whose end pressed no face
  // through (N <= K eps, no overlapping face) is the same bits as before the bed of springs.
  // h = r1^2 / (R + sqrt(R^2 - r1^2)), not R - sqrt(R^2 - r1^2), which cancels at large R.
  const double r1 = radius_m_;
  const double R = std::clamp(radius_m, 1.25 * r1, tolerance_dome_radius_m_);
  dome_radius_m_ = R;
  dome_height_m_ = R < tolerance_dome_radius_m_ ? r1 * r1 / (R + std::sqrt(R * R - r1 * r1))
                                                : tolerance_dome_height_m_;
  dome_sin_max_ = r1 / R;
  facing_axis_sq_ = 1.0 - dome_sin_max_ * dome_sin_max_;
}

void Collision::ForgetDistances() {
  std::fill(kept_.begin(), kept_.end(), KeptDistance{});
  std::fill(summaries_.begin(), summaries_.end(), IdleSummary{});
}

// Inlined where Query calls it (twice a piece of a tube lying in the groove): most calls end at its
// first test.
[[gnu::always_inline]] inline bool Collision::KeptBeyondBand(const KeptDistance& kept,
                                                             const Eigen::Vector3d& a_W,
                                                             const Eigen::Vector3d& b_W,
                                                             double band_m) const {
  // The distance from a capsule to a fixed box is 1-Lipschitz in the motion of its axis's ends:
  // if each end moved by at most delta, every axis point a + t (b - a) moved by at most
  // (1 - t) |da| + t |db| <= delta, and a point's distance to the box is 1-Lipschitz. So a pair
  // kept at d_m is now at least d_m - delta away. The kept and the new distance are both
  // computed, each off by the rounding of the part-frame transform and the closed form: a few
  // units in the last place of the coordinates, ~1e-15 m in a scene a few metres across. The
  // margin of 1 nm is six orders above that and far below any distance that matters (epsilon is
  // a millimetre): a pair skipped here is beyond the band (and beyond 0 when the band is not, so
  // the axis is outside the box) in the narrow phase too, which would discard it. A pair within
  // 1 nm + delta of the band is evaluated. Squared: no root; their rounding is relative 1e-16.
  // Nothing kept (-infinity) or a NaN anywhere compares false: evaluated.
  // No slack (a pair in the band, a hundred a tick for a tube lying in the groove) decides it
  // before the motions are formed.
  if (!(kept.d_m - (std::max(band_m, 0.0) + kCoherenceMargin_m) > 0.0)) return false;
  return KeptBeyondBand(kept, (a_W - kept.a_W_m()).squaredNorm(),
                        (b_W - kept.b_W_m()).squaredNorm(), band_m);
}

[[gnu::always_inline]] inline bool Collision::KeptBeyondBand(const KeptDistance& kept,
                                                             double moved_a_sq, double moved_b_sq,
                                                             double band_m) const {
  const double slack_m = kept.d_m - (std::max(band_m, 0.0) + kCoherenceMargin_m);
  const double slack_sq = slack_m * slack_m;
  return slack_m > 0.0 && moved_a_sq <= slack_sq && moved_b_sq <= slack_sq;
}

[[gnu::always_inline]] inline void Collision::Keep(KeptDistance& kept, const Eigen::Vector3d& a_W,
                                                   const Eigen::Vector3d& b_W, double d_m) const {
  // Only a finite distance: one from infinite coordinates would make every later motion look
  // small against it.
  kept.d_m = std::isfinite(d_m) ? d_m : -std::numeric_limits<double>::infinity();
  kept.ends_W_m.col(0) = a_W;
  kept.ends_W_m.col(1) = b_W;
}

namespace {

// A segment beyond one face along that face's axis only (ends a and b on the axis, the face at
// half): the nearer end's excess over the face, and its parameter t (the first on a tie).
[[gnu::always_inline]] inline double NearerEndExcess(double a, double b, double half,
                                                     double& t_min) {
  const double excess_a = std::abs(a) - half;
  const double excess_b = std::abs(b) - half;
  t_min = excess_b < excess_a ? 1.0 : 0.0;
  return std::min(excess_a, excess_b);
}

// The common case of SegmentBoxDistanceSquared, inlined into the capsule's distance: both ends
// beyond the same face and within the other two slabs (a capsule lying over a face). Then only
// that axis is outside along the whole segment, its excess is linear in t, and the nearer end is
// nearest (the first on a tie, as in the general case). False when it is not the case.
[[gnu::always_inline]] inline bool OneFaceDistanceSquared(const Eigen::Vector3d& a,
                                                          const Eigen::Vector3d& b,
                                                          const Eigen::Vector3d& half,
                                                          double& f_min, double& t_min) {
  int outside = -1;
  bool one_face = true;
  for (int k = 0; k < 3 && one_face; ++k) {
    const bool a_out = std::abs(a[k]) > half[k], b_out = std::abs(b[k]) > half[k];
    if (!a_out && !b_out) continue;
    one_face = a_out && b_out && (a[k] > 0.0) == (b[k] > 0.0) && outside < 0;
    outside = k;
  }
  if (!one_face || outside < 0) return false;
  const double e = NearerEndExcess(a[outside], b[outside], half[outside], t_min);
  f_min = e * e;
  return true;
}

// SegmentBoxDistanceSquared when OneFaceDistanceSquared is not the case.
double SegmentBoxDistanceSquaredAnyFace(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                        const Eigen::Vector3d& half, double& t_min) {
  // f(t) = sum over axes of max(0, |a + t (b - a)| - h)^2 is convex and, between the parameters
  // where a coordinate crosses a face plane (at most six), quadratic in t: minimise it exactly on
  // each piece. All points in the box's frame.
  const Eigen::Vector3d d = b - a;
  std::array<double, 8> cuts{};
  int n = 0;
  cuts[std::size_t(n++)] = 0.0;
  cuts[std::size_t(n++)] = 1.0;
  for (int k = 0; k < 3; ++k) {
    if (d[k] == 0.0) continue;
    for (const double side : {-1.0, 1.0}) {
      // Only a crossing within (0, 1) is a cut: one whose quotient is not (a sign against the
      // step's, or a numerator beyond it, whose quotient rounds to 1 or more) is passed over
      // before its division.
      const double num = side * half[k] - a[k];
      if (!((d[k] > 0.0 ? num > 0.0 : num < 0.0) && std::abs(num) <= std::abs(d[k]))) continue;
      const double t = num / d[k];
      if (t > 0.0 && t < 1.0) cuts[std::size_t(n++)] = t;
    }
  }
  for (int i = 1; i < n; ++i)  // insertion sort: at most 8
    for (int j = i; j > 0 && cuts[std::size_t(j - 1)] > cuts[std::size_t(j)]; --j)
      std::swap(cuts[std::size_t(j - 1)], cuts[std::size_t(j)]);
  double best = std::numeric_limits<double>::infinity();
  t_min = 0.0;
  for (int i = 0; i + 1 < n; ++i) {
    const double t0 = cuts[std::size_t(i)], t1 = cuts[std::size_t(i) + 1];
    const double tm = 0.5 * (t0 + t1);
    // On this piece each axis is below, inside or above the box: f = A t^2 + B t + C.
    double A = 0.0, B = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double x = a[k] + tm * d[k];
      if (std::abs(x) <= half[k]) continue;
      const double offset = a[k] - (x > 0.0 ? half[k] : -half[k]);  // (offset + t d)^2
      A += d[k] * d[k];
      B += 2.0 * offset * d[k];
    }
    double t = A > 0.0 ? std::clamp(-B / (2.0 * A), t0, t1) : t0;
    // Evaluate f directly (not from A, B, C) so that the value carries no cancellation.
    double f = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double excess = std::abs(a[k] + t * d[k]) - half[k];
      if (excess > 0.0) f += excess * excess;
    }
    if (f < best) best = f, t_min = t;
  }
  return best;
}

}  // namespace

double SegmentBoxDistanceSquared(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                 const Eigen::Vector3d& half, double& t_min) {
  double f = 0.0;
  if (OneFaceDistanceSquared(a, b, half, f, t_min)) return f;
  return SegmentBoxDistanceSquaredAnyFace(a, b, half, t_min);
}

bool CylinderBoxFaceDistance(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius,
                             const Eigen::Vector3d& half, double& distance,
                             Eigen::Vector3d& p_cylinder, Eigen::Vector3d& q_box) {
  const Eigen::Vector3d axis = b - a;
  const double length = axis.norm();
  if (!(length > 0.0)) return false;
  const Eigen::Vector3d u = axis / length;
  for (int k = 0; k < 3; ++k) {
    for (const double side : {-1.0, 1.0}) {
      // Outward normal n = side e_k. The support point in -n: the axis end with the smaller
      // n.x, then the rim point farthest along -n within the end's plane.
      const double n_u = side * u[k];
      const Eigen::Vector3d& end = n_u > 0.0 ? a : b;
      // The support point lies within r of that end: a face whose plane the end is more than r
      // inside of (and a margin for the rounding of the point, a few ulp of r and of the
      // coordinate) is passed over before its root and quotient, as it would be below (most of
      // the six: an end over one face of a part lies within the other five's planes). Before
      // the end is copied into the support point, too (~30 instructions a tick, tip on the floor).
      if (side * end[k] + radius + 1e-9 * (radius + std::abs(end[k])) < half[k]) continue;
      Eigen::Vector3d s = end;
      Eigen::Vector3d radial = n_u * u;  // -(n - (n.u) u): the part of -n across the axis
      radial[k] -= side;
      const double radial_norm = radial.norm();
      if (radial_norm > 1e-12) s += (radius / radial_norm) * radial;
      const double beyond = side * s[k] - half[k];
      if (!(beyond > 0.0)) continue;
      const int i = (k + 1) % 3, j = (k + 2) % 3;
      if (std::abs(s[i]) > half[i] || std::abs(s[j]) > half[j]) continue;
      distance = beyond;
      p_cylinder = s;
      q_box = s;
      q_box[k] = side * half[k];
      return true;
    }
  }
  return false;
}

bool CylinderBoxPenetration(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius,
                            const Eigen::Vector3d& half, double& depth, Eigen::Vector3d& p_cylinder,
                            Eigen::Vector3d& q_box, Eigen::Vector3d& normal) {
  const Eigen::Vector3d axis = b - a;
  const double length = axis.norm();
  if (!(length > 0.0)) return false;
  const Eigen::Vector3d u = axis / length;
  depth = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    for (const double side : {-1.0, 1.0}) {
      // The support point along -n (as in CylinderBoxFaceDistance); moving the cylinder out by
      // how far it lies below the face's plane separates the two, since the plane bounds the box.
      const double n_u = side * u[k];
      Eigen::Vector3d s = n_u > 0.0 ? a : b;
      Eigen::Vector3d radial = n_u * u;
      radial[k] -= side;
      const double radial_norm = radial.norm();
      if (radial_norm > 1e-12) s += (radius / radial_norm) * radial;
      const double below = half[k] - side * s[k];
      if (below < depth) {
        depth = below;
        p_cylinder = s;
        q_box = s;
        q_box[k] = side * half[k];
        normal = side * Eigen::Vector3d::Unit(k);
      }
    }
  }
  return depth >= 0.0 && depth < radius;
}

// Inlined into Query, which calls it for every pair in the band (a hundred a tick for a tube
// lying in the groove): as a call, its outputs went through memory and its one-face case through
// a second call, an eighth of the query's instructions.
[[gnu::always_inline]] inline bool Collision::CapsuleBoxDistance(
    const Part& part, const Eigen::Vector3d& a_P, const Eigen::Vector3d& b_P, double& distance_m,
    Eigen::Vector3d& p_tube_P, Eigen::Vector3d& q_part_P, Eigen::Vector3d& c_P,
    double& axis_m) const {
  double t = 0.0, axis_sq = 0.0;
  if (!OneFaceDistanceSquared(a_P, b_P, part.half_m, axis_sq, t))
    axis_sq = SegmentBoxDistanceSquaredAnyFace(a_P, b_P, part.half_m, t);
  axis_m = std::sqrt(axis_sq);
  c_P = a_P + t * (b_P - a_P);  // on the capsule's axis
  q_part_P = c_P.cwiseMax(-part.half_m).cwiseMin(part.half_m);
  // Below a micrometre the direction from the box to the axis is not defined well enough: that
  // is the axis inside the box, for which no signed distance is given.
  if (!(axis_m > 1e-6 * radius_m_)) return false;
  // Signed: with the axis outside the box the capsule's surface may still dip into it; the
  // depth r1 - |c - q| is then exact (the nearest box point q is the foot of the deepest point's
  // normal), so the penalty keeps growing past K eps instead of saturating at the surface.
  distance_m = axis_m - radius_m_;
  p_tube_P = c_P + (q_part_P - c_P) * (radius_m_ / axis_m);
  return true;
}

void Collision::LineEnds(RawContact& c, std::span<const Eigen::Vector3d> nodes_W) const {
  if (!c.over_face) return;
  const Part& part = parts_[std::size_t(c.part_slot)];
  const Eigen::Vector3d a_P = part.ToPart(nodes_W[std::size_t(c.piece)]);
  const Eigen::Vector3d b_P = part.ToPart(nodes_W[std::size_t(c.piece) + 1]);
  // The face: the one bit of the mask, its axis and side.
  int k = 0;
  double side = 1.0;
  for (int a = 0; a < 3; ++a) {
    if (c.face_mask & (1u << kPositiveFace[a])) k = a, side = 1.0;
    if (c.face_mask & (1u << kNegativeFace[a])) k = a, side = -1.0;
  }
  // The stretch of the axis within the face's two other slabs (the whole axis for a piece lying
  // over the face, most of them).
  const Eigen::Vector3d d_P = b_P - a_P;
  double t_lo = 0.0, t_hi = 1.0;
  for (int i = 0; i < 3; ++i) {
    const double h = part.half_m[i];
    if (i == k || (std::abs(a_P[i]) <= h && std::abs(b_P[i]) <= h)) continue;
    if (d_P[i] == 0.0) return;  // beside the face (the mask's tolerance): no stretch
    const double t1 = (-h - a_P[i]) / d_P[i], t2 = (h - a_P[i]) / d_P[i];
    t_lo = std::max(t_lo, std::min(t1, t2));
    t_hi = std::min(t_hi, std::max(t1, t2));
  }
  if (!(t_hi > t_lo)) return;
  // Parallel to the face, the piece spans its whole stretch; tilted, its nearest end. The ends
  // move from the stretch's towards the nearest as the ends' distances to the face's plane come
  // apart, there by eps / 10 (the capsule chain's tolerance): continuous in the tube's pose, and
  // a piece crossing a face at an angle (a tube wrapped round an edge) keeps its nearest point,
  // where it presses, for both ends (its region ending there as before).
  const double d0 = side * a_P[k] - part.half_m[k] - radius_m_, slope = side * d_P[k];
  const double d_lo = d0 + t_lo * slope, d_hi = d0 + t_hi * slope;
  const double t_near = d_lo <= d_hi ? t_lo : t_hi;
  const double w = std::max(0.0, 1.0 - std::abs(d_hi - d_lo) * parallel_per_m_);
  c.line = true;
  c.t_lo = t_near + w * (t_lo - t_near);
  c.t_hi = t_near + w * (t_hi - t_near);
  c.d_lo_m = d0 + c.t_lo * slope;
  c.d_hi_m = d0 + c.t_hi * slope;
  // The arc positions as the nearest point's is taken (Query): the surface point's foot on the
  // chord, (t - 1/2) L less r1 times the axis's component along the face's normal.
  const double length_m = d_P.norm();
  const double half_m = 0.5 * piece_m_;
  const double offset_m = radius_m_ * slope / length_m;
  const double s0_m = piece_m_ * c.piece + half_m;
  c.s_lo_m =
      std::max(0.0, s0_m + std::clamp((c.t_lo - 0.5) * length_m - offset_m, -half_m, half_m));
  c.s_hi_m =
      std::max(0.0, s0_m + std::clamp((c.t_hi - 0.5) * length_m - offset_m, -half_m, half_m));
}

RawContact Collision::StripPiece(const RawContact& strip, int piece) const {
  // A strip's entry is its first piece's contact as Query wrote it, but for the strip's figures:
  // every other field is the same for each of its pieces.
  RawContact c = strip;
  c.piece = piece;
  c.distance_m = StripPieceDistance(strip, piece);
  c.strip_pieces = 1;
  c.strip_deepest = piece;
  c.strip_farthest_m = c.distance_m;
  return c;
}

void Collision::Complete(RawContact& c, std::span<const Eigen::Vector3d> nodes_W) const {
  if (!c.deferred) return;
  // Query's steps for a capsule apart from the part, on the same nodes: the same bits.
  const Part& part = parts_[std::size_t(c.part_slot)];
  const Eigen::Vector3d& a_W = nodes_W[std::size_t(c.piece)];
  const Eigen::Vector3d& b_W = nodes_W[std::size_t(c.piece) + 1];
  double d = 0.0, axis_m = 0.0;
  // (Set only so that the compiler sees them set: Query found the pair apart, so
  // CapsuleBoxDistance sets them all again.)
  Eigen::Vector3d p_P = Eigen::Vector3d::Zero(), q_P = p_P, c_P = p_P;
  CapsuleBoxDistance(part, part.ToPart(a_W), part.ToPart(b_W), d, p_P, q_P, c_P, axis_m);
  const Eigen::Vector3d p_tube_W = part.ToWorld(p_P);
  const Eigen::Vector3d q_part_W = part.ToWorld(q_P);
  c.q_W_m = q_part_W;
  c.normal_W = (p_tube_W - q_part_W) / d;
  c.p_W_m = p_tube_W;
  const Eigen::Vector3d axis_W = (b_W - a_W).normalized();
  const Eigen::Vector3d centre_W = 0.5 * (a_W + b_W);
  const double half_m = 0.5 * piece_m_;
  const double along = std::clamp((p_tube_W - centre_W).dot(axis_W), -half_m, half_m);
  c.s_m = std::max(0.0, piece_m_ * c.piece + half_m + along);
  c.deferred = false;
}

// Inlined for the same reason as CapsuleBoxDistance: once a contact.
[[gnu::always_inline]] inline std::uint8_t Collision::FaceMask(const Part& part,
                                                               const Eigen::Vector3d& q_P) const {
  std::uint8_t mask = 0;
  for (int a = 0; a < 3; ++a) {
    mask |= std::uint8_t(unsigned(q_P[a] >= part.edge_above_m[a]) << kPositiveFace[a]);
    mask |= std::uint8_t(unsigned(q_P[a] <= part.edge_below_m[a]) << kNegativeFace[a]);
  }
  if (mask != 0) return mask;
  // Not on the surface (only when the shapes overlap): the face nearest to the point.
  int best = 0;
  for (int a = 1; a < 3; ++a)
    if (part.half_m[a] - std::abs(q_P[a]) < part.half_m[best] - std::abs(q_P[best])) best = a;
  return std::uint8_t(1u << (q_P[best] >= 0.0 ? kPositiveFace[best] : kNegativeFace[best]));
}

bool Collision::PassesBroadPhase(const Part& part, const Eigen::Vector3d& a_P,
                                 const Eigen::Vector3d& b_P, double band_m) const {
  // The piece's bounding box in the part's frame, grown by its radius and the band, against the
  // part: exact for the box's own axes, so rotated parts cull as well as aligned ones.
  const double grow = radius_m_ + band_m;
  for (int k = 0; k < 3; ++k) {
    const double lo = std::min(a_P[k], b_P[k]) - grow;
    const double hi = std::max(a_P[k], b_P[k]) + grow;
    if (lo > part.half_m[k] || hi < part.minus_half_m[k]) return false;
  }
  return true;
}

Eigen::Vector3d Collision::Overlapping(const Part& part, const Eigen::Vector3d& a_W,
                                       const Eigen::Vector3d& b_W, RawContact& c) const {
  // GJK reports overlap without a depth. The contact is taken at the piece's midpoint, pushed out
  // through the face of the part nearest to it, at distance 0: the largest penalty force, K eps,
  // and a defined normal. The tick is flagged kPenetration by the caller.
  const Eigen::Vector3d m_P = part.ToPart(0.5 * (a_W + b_W));
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (part.half_m[a] - std::abs(m_P[a]) < part.half_m[axis] - std::abs(m_P[axis])) axis = a;
  const double side = m_P[axis] >= 0.0 ? 1.0 : -1.0;
  Eigen::Vector3d q_P = m_P.cwiseMax(-part.half_m).cwiseMin(part.half_m);
  q_P[axis] = side * part.half_m[axis];
  c.q_W_m = part.ToWorld(q_P);
  c.normal_W = part.DirectionToWorld(side * Eigen::Vector3d::Unit(axis));
  c.distance_m = 0.0;
  c.overlap = true;
  return q_P;
}

namespace {
// Adds a part's group to the query's, merging it with one of the same span (the least gap, the
// farthest s_max, the first part).
void AddGroup(IdleParts& idle, const IdleParts::Group& group) {
  int at = 0;
  while (at < idle.group_count && !(idle.groups[std::size_t(at)].dims == group.dims &&
                                    idle.groups[std::size_t(at)].axis_W == group.axis_W))
    ++at;
  if (at == IdleParts::kMaxGroups) {
    // Full: the last group takes this one in, as a group of any normal.
    at = IdleParts::kMaxGroups - 1;
    idle.groups[std::size_t(at)].dims = 3;
  }
  if (at == idle.group_count) {
    idle.groups[std::size_t(idle.group_count++)] = group;
    return;
  }
  IdleParts::Group& into = idle.groups[std::size_t(at)];
  into.gap_m = std::min(into.gap_m, group.gap_m);
  into.s_max_m = std::max(into.s_max_m, group.s_max_m);
  into.first_part = std::min(into.first_part, group.first_part);
}
}  // namespace

bool Collision::StillLeftOut(std::size_t part_i, std::span<const Eigen::Vector3d> nodes_W,
                             const Eigen::Vector3d& end_start_W, double band_m,
                             IdleParts& idle) const {
  const Part& part = parts_[part_i];
  const IdleSummary& summary = summaries_[part_i];
  const Eigen::Vector3d* const anchor = &anchors_[part_i * std::size_t(kMaxCapsules + 2)];
  const std::size_t node_count = nodes_W.size();
  // Last tick's evaluation, while it still holds: every point of the tube has moved at most
  // delta since it (a piece's axis ends did, so all of it), so each group's pieces are at least
  // its gap less delta away; no piece has crossed a slab it was inside by more than delta, nor
  // turned the end onto a face it was `slack` from facing; and a piece beyond the band it was
  // evaluated at is beyond this tick's band if that is delta narrower.
  // A slab is crossed by motion along its own axis only: that is bounded axis by axis (a tube
  // sliding along a wall keeps its height, however far it slides).
  if (summary.valid) {
    // The largest motion along each world axis; every node's motion is within its norm.
    Eigen::Vector3d along_W = Eigen::Vector3d::Zero();
    // (The motion first: its max with along_W keeps along_W's coordinate on a tie, so along_W is
    // updated in its registers, not through a copy, two instructions a node; every value is an
    // absolute value or the starting +0, so a tie is of the same bits, and the nodes are finite.)
    for (std::size_t i = 0; i < node_count; ++i)
      along_W = (nodes_W[i] - anchor[i]).cwiseAbs().cwiseMax(along_W);
    along_W = along_W.cwiseMax((end_start_W - anchor[node_count]).cwiseAbs());
    const double delta_m = along_W.norm();
    // A part turned to the world: its own axes see at most delta.
    const Eigen::Vector3d along_P = part.aligned ? along_W : Eigen::Vector3d::Constant(delta_m);
    bool holds = band_m + delta_m <= summary.band_m && delta_m < summary.slack_m &&
                 facing_axis_sq_ >= summary.facing_axis_sq &&
                 (along_P.array() < summary.slab_slack_m.array()).all();
    for (int g = 0; g < summary.group_count && holds; ++g)
      holds = summary.groups[std::size_t(g)].gap_m - delta_m > idle.floor_m;
    if (holds) {
      ++idle.left_out;
      for (int g = 0; g < summary.group_count; ++g) {
        IdleParts::Group group = summary.groups[std::size_t(g)];
        group.gap_m -= delta_m;
        AddGroup(idle, group);
      }
      return true;
    }
  }
  return false;
}

bool Collision::LeaveOut(std::size_t part_i, const KeptDistance* kept,
                         std::span<const Eigen::Vector3d> nodes_W,
                         const Eigen::Vector3d& end_start_W, const Eigen::Vector3d& end_start_P,
                         double band_m, IdleParts& idle) const {
  const Part& part = parts_[part_i];
  IdleSummary& summary = summaries_[part_i];
  Eigen::Vector3d* const anchor = &anchors_[part_i * std::size_t(kMaxCapsules + 2)];
  const std::size_t node_count = nodes_W.size();
  summary.valid = false;
  // The pieces the band would take are those the broad phase passes and no kept distance
  // settles beyond the band (the loop in Query), here a band half an epsilon wider so that
  // the evaluation holds for ticks after it. Each has a kept distance, less how far it has
  // moved since: a lower bound of its distance now (KeptBeyondBand). The part is left out when
  // the least of them is above the floor; a piece with none, or an end that could face the
  // part, keeps it in. Pieces are grouped by the axes their normals may have (IdleParts).
  const double wide_band_m = band_m + 0.5 * eps_m_;
  const int pieces = static_cast<int>(node_count) - end_pieces_;
  std::array<double, 8> lowest_m, s_max_m;
  lowest_m.fill(std::numeric_limits<double>::infinity());
  s_max_m.fill(-1.0);  // no piece
  double slack_m = std::numeric_limits<double>::infinity();
  Eigen::Vector3d slab_slack_m = Eigen::Vector3d::Constant(slack_m);
  for (int k = 0; k < pieces; ++k) {
    const bool is_end = k == pieces - 1;
    const Eigen::Vector3d& a_W = is_end ? end_start_W : nodes_W[std::size_t(k)];
    const Eigen::Vector3d& b_W = is_end ? nodes_W.back() : nodes_W[std::size_t(k) + 1];
    const Eigen::Vector3d& a_P = is_end ? end_start_P : nodes_P_[std::size_t(k)];
    const Eigen::Vector3d& b_P = is_end ? nodes_P_[node_count - 1] : nodes_P_[std::size_t(k) + 1];
    // The broad phase's own bound: how far the piece's axis box, grown by r1, is from the part's
    // along one of its axes (the broad phase passes a piece where this is within the band). A
    // piece the wider band takes that the query's band never did has no kept distance; this
    // bounds it. Only there: taken within the band too, it left parts out in ticks whose full
    // query truncated its contacts, and the graph's exploration went elsewhere (249 CFs against
    // 251), the case docs/core.md names.
    double apart_m = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < 3; ++i)
      apart_m = std::max({apart_m, std::min(a_P[i], b_P[i]) - part.half_m[i],
                          -part.half_m[i] - std::max(a_P[i], b_P[i])});
    apart_m -= radius_m_;
    if (apart_m > wide_band_m) continue;
    const KeptDistance& kept_k = kept[k];
    const double moved_a_sq = (a_W - kept_k.a_W_m()).squaredNorm();
    const double moved_b_sq = (b_W - kept_k.b_W_m()).squaredNorm();
    if (KeptBeyondBand(kept_k, moved_a_sq, moved_b_sq, wide_band_m)) continue;
    // A capsule's nearest point to the box lies on the line from its axis's nearest point c to
    // that point's clamp into the box: the normal has a component only along the axes on which
    // c is out of the slab, so only where the axis reaches out. The end cylinder's rim reaches
    // r1 beyond its axis. The face mask's tolerance is the margin for rounding.
    const double reach_out_m = is_end ? radius_m_ : 0.0;
    int outside = 0;
    for (int i = 0; i < 3; ++i) {
      const double inside_by_m = part.half_m[i] - 2.0 * part_tolerance_m_ -
                                 (std::max(std::abs(a_P[i]), std::abs(b_P[i])) + reach_out_m);
      // Within a tenth of epsilon of the slab's side counts as out: the tube's jitter would cross
      // it tick after tick and void the evaluation (a piece at a wall's top, the tip sliding).
      if (inside_by_m <= 0.1 * eps_m_)
        outside |= 1 << i;
      else
        slab_slack_m[i] = std::min(slab_slack_m[i], inside_by_m);
    }
    if (is_end) {
      // A face of the part the end nearly faces keeps it in, if the end cylinder reaches that
      // face's plane (else no nearest point can lie on it). The end's axis u turns by at most
      // 4 delta / |b - a| when its ends move by delta.
      const Eigen::Vector3d axis_P = b_P - a_P;
      const double length_m = axis_P.norm();
      for (int i = 0; i < 3; ++i) {
        if ((outside & (1 << i)) == 0) continue;
        const double u = std::abs(axis_P[i]) / length_m;
        if (!(u * u < facing_axis_sq_)) return false;
        slack_m = std::min(slack_m, (std::sqrt(facing_axis_sq_) - u) * length_m / 4.0);
      }
    }
    // The same margin as KeptBeyondBand's, for the same rounding. Nothing kept (-infinity) or a
    // NaN leaves the broad phase's bound.
    const double kept_m =
        kept_k.d_m - std::sqrt(std::max(moved_a_sq, moved_b_sq)) - kCoherenceMargin_m;
    const std::size_t g = std::size_t(outside);
    lowest_m[g] = std::min(lowest_m[g], apart_m > band_m ? std::max(kept_m, apart_m) : kept_m);
    // A load's arc position lies within its piece.
    s_max_m[g] = is_end ? length_m_ : piece_m_ * (k + 1);
  }
  // A NaN compares false: kept in.
  for (std::size_t g = 0; g < 8; ++g)
    if (s_max_m[g] >= 0.0 && !(lowest_m[g] > idle.floor_m)) return false;
  const std::array<double, 8>& gap_m = lowest_m;
  ++idle.left_out;
  summary.group_count = 0;
  for (int outside = 0; outside < 8; ++outside) {
    const std::size_t g = std::size_t(outside);
    if (s_max_m[g] < 0.0) continue;
    IdleParts::Group group;
    group.dims = (outside & 1) + ((outside >> 1) & 1) + ((outside >> 2) & 1);
    const int axis = group.dims == 1 ? (outside == 1   ? 0
                                        : outside == 2 ? 1
                                                       : 2)
                                     : (outside == 6   ? 0
                                        : outside == 5 ? 1
                                                       : 2);
    if (group.dims == 0) group.dims = 3;  // no axis out: inside the box (overlap), any normal
    group.axis_W = group.dims == 3 ? Eigen::Vector3d::UnitZ().eval()
                                   : part.DirectionToWorld(Eigen::Vector3d::Unit(axis));
    group.gap_m = gap_m[g];
    group.s_max_m = s_max_m[g];
    group.first_part = part.index;
    AddGroup(idle, group);
    summary.groups[std::size_t(summary.group_count++)] = group;
  }
  summary.valid = true;
  summary.band_m = wide_band_m;
  summary.slack_m = slack_m;
  summary.facing_axis_sq = facing_axis_sq_;
  summary.slab_slack_m = slab_slack_m;
  for (std::size_t i = 0; i < node_count; ++i) anchor[i] = nodes_W[i];
  anchor[node_count] = end_start_W;
  return true;
}

bool Collision::AxisThrough(std::span<const Eigen::Vector3d> nodes_H, const Eigen::Matrix3d& R_WH,
                            const Eigen::Vector3d& p_WH, double depth_m, double spacing_m) const {
  // The nodes' bounding box in frame H, then per part the box that contains it in the part's
  // frame; only a part that box reaches deep enough into is tried node by node. With nodes at
  // most spacing_m apart, every node lies within two spacings of one of every fourth node (and
  // the last): their box grown by that contains them all.
  // (x and y as one SSE pair, z alone: a third of the instructions of Eigen's 3-vector min/max.)
  constexpr double kInf = std::numeric_limits<double>::infinity();
  Eigen::Vector2d lo_xy(kInf, kInf), hi_xy(-kInf, -kInf);
  double lo_z = kInf, hi_z = -kInf;
  const std::size_t stride = spacing_m > 0.0 ? 4 : 1;
  const auto take = [&](const Eigen::Vector3d& x) {
    lo_xy = lo_xy.cwiseMin(x.head<2>());
    hi_xy = hi_xy.cwiseMax(x.head<2>());
    lo_z = x.z() < lo_z ? x.z() : lo_z;
    hi_z = x.z() > hi_z ? x.z() : hi_z;
  };
  for (std::size_t k = 0; k < nodes_H.size(); k += stride) take(nodes_H[k]);
  if (!nodes_H.empty()) take(nodes_H.back());
  const double grow_m = stride > 1 ? 2.0 * spacing_m : 0.0;
  const Eigen::Vector3d lo(lo_xy.x() - grow_m, lo_xy.y() - grow_m, lo_z - grow_m);
  const Eigen::Vector3d hi(hi_xy.x() + grow_m, hi_xy.y() + grow_m, hi_z + grow_m);
  const Eigen::Vector3d centre_H = 0.5 * (lo + hi), half_H = 0.5 * (hi - lo);
  const bool finite_pose = R_WH.allFinite() && p_WH.allFinite();
  // The box turned by the pose (below) is the same for every part set square to the world: made
  // at the first such part only (~45 instructions a tick, the groove's three parts square).
  bool turned = false;
  Eigen::Vector3d turned_centre_m, turned_reach_m;
  for (const Part& part : parts_) {
    // A node deeper than depth_m has |q| < half - depth_m along every axis of the part.
    const Eigen::Vector3d inner_m = part.half_m - Eigen::Vector3d::Constant(depth_m);
    // A part no deeper than that along one axis (a sheet) has no such inside: the axis goes
    // through it where it crosses from beyond one of its faces to beyond the opposite one, more
    // than depth_m inside its other faces (a tube folded round the sheet's edge does not).
    int thin_axis = -1, thin_count = 0;
    for (int a = 0; a < 3; ++a)
      if (!(inner_m[a] > 0.0)) thin_axis = a, ++thin_count;
    if (thin_count > 1) continue;  // a rod or a speck: no face to cross through
    const bool sheet = thin_count == 1;
    const Eigen::Vector3d reject_m = sheet ? part.half_m : inner_m;
    // A part set square to the world takes the pose as it is: the product with the identity
    // differs from it at most in the sign of a zero, which no test below tells apart, when the
    // pose is finite (0 times a NaN or an infinity would spread it through the product). The
    // products were a fifth of the check's instructions, three parts in the groove.
    Eigen::Matrix3d R_PH_turned;
    if (!(part.aligned && finite_pose)) R_PH_turned = part.R_PW * R_WH;
    const Eigen::Matrix3d& R_PH = part.aligned && finite_pose ? R_WH : R_PH_turned;
    const Eigen::Vector3d p_PH = part.aligned && finite_pose
                                     ? Eigen::Vector3d(p_WH + part.p_PW)
                                     : Eigen::Vector3d(part.R_PW * p_WH + part.p_PW);
    // (Each product formed on its own, as Eigen forms a small product within an expression:
    // the same sums in the same order, so the same bits kept or made afresh.)
    if (part.aligned && finite_pose && !turned) {
      turned_centre_m = R_WH * centre_H;
      turned_reach_m = R_WH.cwiseAbs() * half_H;
      turned = true;
    }
    const Eigen::Vector3d centre_P =
        part.aligned && finite_pose ? turned_centre_m : Eigen::Vector3d(R_PH * centre_H);
    const Eigen::Vector3d reach_P =
        part.aligned && finite_pose ? turned_reach_m : Eigen::Vector3d(R_PH.cwiseAbs() * half_H);
    if ((((centre_P + p_PH).cwiseAbs() - reach_P).array() >= reject_m.array()).any()) continue;
    if (!sheet) {
      for (const Eigen::Vector3d& x : nodes_H) {
        const Eigen::Vector3d q = R_PH * x + p_PH;
        if (std::abs(q.x()) < inner_m.x() && std::abs(q.y()) < inner_m.y() &&
            std::abs(q.z()) < inner_m.z())
          return true;
      }
      continue;
    }
    // The sheet: walking the nodes, the side of the last node beyond a face (0 before any), and
    // whether the centreline has crossed the mid-plane inside the other faces since it.
    if (nodes_H.empty()) continue;
    const int a = thin_axis, b = (a + 1) % 3, c = (a + 2) % 3;
    const double half_a = part.half_m[a];
    int side = 0;
    bool crossed = false;
    Eigen::Vector3d q_prev = R_PH * nodes_H[0] + p_PH;
    for (std::size_t k = 0; k < nodes_H.size(); ++k) {
      const Eigen::Vector3d q = k == 0 ? q_prev : (R_PH * nodes_H[k] + p_PH).eval();
      if (k > 0 && (q_prev[a] < 0.0) != (q[a] < 0.0)) {
        const double t = q_prev[a] / (q_prev[a] - q[a]);  // in [0, 1]: the signs differ
        const Eigen::Vector3d at = q_prev + t * (q - q_prev);
        if (std::abs(at[b]) < inner_m[b] && std::abs(at[c]) < inner_m[c]) crossed = true;
      }
      const int here = q[a] >= half_a ? 1 : (q[a] <= -half_a ? -1 : 0);
      if (here != 0) {
        if (crossed && side == -here) return true;
        side = here;  // the same side again: back out where it came in, not through
        crossed = false;
      }
      q_prev = q;
    }
  }
  return false;
}

int Collision::Query(std::span<const Eigen::Vector3d> nodes_W, const Eigen::Vector3d& tip_tangent_W,
                     double band_m, std::span<RawContact> out, IdleParts* idle) const {
  // Capsules 0 .. pieces - 2, then the end cylinder as piece pieces - 1.
  const int pieces = static_cast<int>(nodes_W.size()) - end_pieces_;
  int count = 0;  // entries written
  int stood = 0;  // contacts they stand for (a strip, its pieces): at most out.size()
  narrow_calls_ = 0;
  coherent_skips_ = 0;
  const Eigen::Vector3d tip_W = nodes_W.back();
  const Eigen::Vector3d end_start_W = tip_W - end_m_ * tip_tangent_W;
  const std::size_t node_count = nodes_W.size();
  // The box of each run of kGroup capsules (their nodes), made every query: a run whose box is
  // out of an aligned part's grown box has every capsule out of it in the broad phase (each
  // capsule's coordinates lie within its run's, and rounding is monotonic, so its grown extent
  // lies beyond the run's), and is passed over whole. Two places ask: before the loop over the
  // pieces, the leading runs of a part the tube's box (below) reaches into by less than half its
  // extent along some axis (a tube reaching it with its end only: the tip on the floor); in the
  // loop, each later run, where its box in the part's frame is made anyway. The runs' boxes also
  // give the tube's box.
  const int capsules = pieces - 1;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  Eigen::Vector3d lo_W = Eigen::Vector3d::Constant(kInf), hi_W = -lo_W;  // the tube's (below)
  for (int g = 0; g * kGroup < capsules; ++g) {
    const std::size_t first = std::size_t(g * kGroup);
    const std::size_t last = std::size_t(std::min((g + 1) * kGroup, capsules));  // last node
    Eigen::Vector3d lo_g = nodes_W[first], hi_g = nodes_W[first];
    // The node first: its min / max with the box keeps the box's coordinate on a tie, so the box
    // is updated in its registers (lo_g.cwiseMin(node) kept the node's, through a copy each: four
    // instructions a node). A tie of two values differs only for +0 and -0, where the box may now
    // hold the other zero: the boxes are only compared (shifted by the part's position at most),
    // and the zeros compare equal; the nodes are finite (the core commits only a finite shape).
    // A whole run (all but the last) in a loop of kGroup steps known when compiled, unrolled:
    // without a count and a test a node (~150 instructions a tick); the same steps in the same
    // order as the general loop's.
    if (last - first == std::size_t(kGroup)) {
      for (std::size_t j = 1; j <= std::size_t(kGroup); ++j) {
        lo_g = nodes_W[first + j].cwiseMin(lo_g);
        hi_g = nodes_W[first + j].cwiseMax(hi_g);
      }
    } else {
      for (std::size_t i = first + 1; i <= last; ++i) {
        lo_g = nodes_W[i].cwiseMin(lo_g);
        hi_g = nodes_W[i].cwiseMax(hi_g);
      }
    }
    group_lo_W_[std::size_t(g)] = lo_g;
    group_hi_W_[std::size_t(g)] = hi_g;
    lo_W = lo_W.cwiseMin(lo_g);
    hi_W = hi_W.cwiseMax(hi_g);
  }
  // The whole tube's bounding box: most parts are nowhere near it. In the world frame once, for
  // the parts aligned with it (their frame is a shift of the world's, and rounding is monotonic,
  // so the shifted box is the box of the shifted nodes, bit for bit). From the runs' boxes and
  // the nodes past them, not every node again (a run's box is its nodes' least and greatest
  // coordinates, so the same box for the finite nodes the core commits; a thousand
  // instructions of a three-PC tick). The runs' boxes as each is made (above), in the same order,
  // not read back in a loop of their own (~50 instructions a tick).
  for (std::size_t i = capsules > 0 ? std::size_t(capsules) + 1 : 0; i < node_count; ++i) {
    lo_W = lo_W.cwiseMin(nodes_W[i]);
    hi_W = hi_W.cwiseMax(nodes_W[i]);
  }
  // The radius, as the runs over a face below take it: read from the member, it was loaded again
  // for each capsule (the query's writes could alias it). They ask no more of a capsule's axis
  // distance than that it exceeds r1 (d > 0): CapsuleBoxDistance's least axis distance, 1e-6 r1,
  // then holds too (for r1 > 0 it is below r1, for r1 <= 0 not above 0 <= |e|, equal only to a
  // zero distance, which d > 0 refuses; a NaN fails both), so that test was always passed.
  const double r1_m = radius_m_;
  for (std::size_t part_i = 0; part_i < parts_.size(); ++part_i) {
    const Part& part = parts_[part_i];
    KeptDistance* const kept = &kept_[part_i * std::size_t(kMaxCapsules)];
    // The nodes in the part's frame, made only for a part the tube may reach and that is not
    // still left out (most of the groove's ticks leave out both walls); an aligned part's only
    // for its evaluation as idle (LeaveOut), its pieces take theirs where they read them.
    bool in_part_frame = false;
    const auto to_part_frame = [&] {
      if (in_part_frame) return;
      for (std::size_t i = 0; i < node_count; ++i) nodes_P_[i] = part.ToPart(nodes_W[i]);
      in_part_frame = true;
    };
    Eigen::Vector3d lo, hi;
    if (part.aligned) {
      lo = lo_W + part.p_PW;
      hi = hi_W + part.p_PW;
    } else {
      to_part_frame();
      lo = Eigen::Vector3d::Constant(kInf);
      hi = -lo;
      for (std::size_t i = 0; i < node_count; ++i) {
        lo = lo.cwiseMin(nodes_P_[i]);
        hi = hi.cwiseMax(nodes_P_[i]);
      }
    }
    const double grow = radius_m_ + band_m;
    if (((lo.array() - grow) > part.half_m.array()).any() ||
        ((hi.array() + grow) < -part.half_m.array()).any())
      continue;
    const bool may_leave_out = idle != nullptr && part.index < idle->may_leave_out.size() &&
                               idle->may_leave_out[part.index] != 0;
    if (may_leave_out && StillLeftOut(part_i, nodes_W, end_start_W, band_m, *idle)) continue;
    const Eigen::Vector3d end_start_P = part.ToPart(end_start_W);
    if (may_leave_out) {
      to_part_frame();
      if (LeaveOut(part_i, kept, nodes_W, end_start_W, end_start_P, band_m, *idle)) continue;
    } else {
      summaries_[part_i].valid = false;
    }
    bool by_group = false;
    if (part.aligned) {
      const Eigen::Array3d reach = (hi.array().min(part.half_m.array() + grow) -
                                    lo.array().max(part.minus_half_m.array() - grow));
      by_group = (2.0 * reach < hi.array() - lo.array()).any();
    }
    int k_begin = 0;
    if (by_group) {
      for (; k_begin < capsules; k_begin += kGroup) {
        const Eigen::Vector3d lo_g = group_lo_W_[std::size_t(k_begin / kGroup)] + part.p_PW;
        const Eigen::Vector3d hi_g = group_hi_W_[std::size_t(k_begin / kGroup)] + part.p_PW;
        if (!(((lo_g.array() - grow) > part.half_m.array()).any() ||
              ((hi_g.array() + grow) < part.minus_half_m.array()).any()))
          break;
      }
      k_begin = std::min(k_begin, capsules);
    }
    // An aligned part's pieces take their nodes into its frame where they read them: its runs
    // beyond one face only their face's axis (a hundred nodes a tick for a tube lying in the
    // groove), its other pieces, a few a part, both nodes. The same sums as ToPart's, not made
    // for every node first.
    if (!part.aligned) to_part_frame();
    // A capsule apart from the part within the band: what forms the PCs now, the points only if
    // it becomes a load (Complete; made here, they were a third of the query's instructions for
    // a tube lying in the groove, a hundred contacts of which six become loads).
    // One over a face, next to the piece before it over the same face, joins that one's strip
    // (RawContact::strip_pieces): the core forms PCs from strips, and needs a piece of one only
    // where it becomes a load (StripPiece); written one by one, they made a third of its contact
    // work and most of the query's writes. Its distance is the one kept for its piece (Keep,
    // before each call here). `strip_entry`: the last strip, `strip_next` the piece that would
    // extend it, which finds the strip the last entry: the pieces come in order, each writing its
    // entries (a deferred one, or others) in its own turn, so an entry after the strip's would be
    // that of strip_next or a later piece, whose turn has then come or passed.
    // (The strip's entry as a pointer, not an index: its address is not formed again for each
    // piece that joins it.)
    RawContact* strip_entry = nullptr;
    int strip_next = -1;
    std::uint8_t strip_mask = 0;
    const auto emit_deferred = [&](int k, double d, std::uint8_t face_mask)
        __attribute__((always_inline)) {
      ++stood;
      if (strip_next == k && strip_mask == face_mask) {
        RawContact& strip = *strip_entry;
        ++strip.strip_pieces;
        if (d < strip.distance_m) {
          strip.distance_m = d;
          strip.strip_deepest = k;
        }
        strip.strip_farthest_m = std::max(strip.strip_farthest_m, d);
        ++strip_next;
        return;
      }
      if (IsFaceMask(face_mask)) {
        strip_entry = &out[std::size_t(count)];
        strip_next = k + 1;
        strip_mask = face_mask;
      }
      RawContact& c = out[std::size_t(count++)];
      c.tube = states::TubeElement::kSide;
      c.part = part.index;
      c.distance_m = d;
      c.overlap = false;
      c.pressure_centre = false;
      c.face_mask = face_mask;
      c.part_element = element_of_[part.index][face_mask];
      c.over_face = IsFaceMask(face_mask);
      c.line = false;
      c.piece = k;
      c.part_slot = static_cast<int>(part_i);
      c.deferred = true;
      c.strip_pieces = 1;
      c.strip_deepest = k;
      c.strip_farthest_m = d;
#ifndef NDEBUG
      // Unmade until Complete: NaN in the debug (sanitizer) build, where a read before it
      // reaches the core's checks of its outputs instead of last tick's values.
      constexpr double kUnmade = std::numeric_limits<double>::quiet_NaN();
      c.normal_W.setConstant(kUnmade);
      c.q_W_m.setConstant(kUnmade);
      c.p_W_m.setConstant(kUnmade);
      c.s_m = kUnmade;
#endif
    };
    // The face a box (part frame) lies beyond, within the other two slabs, or -1.
    const auto face_beyond = [&part](const Eigen::Vector3d& lo_b, const Eigen::Vector3d& hi_b) {
      int axis = -1, beyond = 0;
      for (int j = 0; j < 3; ++j) {
        if (lo_b[j] > part.half_m[j] || hi_b[j] < part.minus_half_m[j]) {
          axis = j;
          ++beyond;
        } else if (hi_b[j] > part.half_m[j] || lo_b[j] < part.minus_half_m[j]) {
          beyond = 2;  // astride a face's plane
        }
      }
      return beyond == 1 ? axis : -1;
    };
    // Whether a box beyond the face along axis o lies clear of the face's edges by more than the
    // rounding of a point between its nodes (below).
    const auto clear_of_edges = [&part](const Eigen::Vector3d& lo_b, const Eigen::Vector3d& hi_b,
                                        int o) {
      bool clear = true;
      for (int j = 0; j < 3; ++j) {
        const double margin_m =
            8.0 * std::numeric_limits<double>::epsilon() * std::max(-lo_b[j], hi_b[j]);
        clear = clear && (j == o ? (lo_b[j] - margin_m > part.half_m[j] ||
                                    hi_b[j] + margin_m < part.minus_half_m[j])
                                 : (lo_b[j] - margin_m > part.edge_below_m[j] &&
                                    hi_b[j] + margin_m < part.edge_above_m[j]));
      }
      return clear;
    };
    // A run of kGroup capsules of an aligned part whose box lies beyond one face and within the
    // other two slabs: each node of it does (the box is its nodes' box, bit for bit, above), so
    // each capsule of it is the case OneFaceDistanceSquared settles (a tube lying on a part: a
    // hundred pieces a tick). Their face's axis, or -1. The nodes are finite (the core commits
    // only a finite shape); a NaN could drop out of the box.
    // The run's face mask too (else 0), when its nodes lie clear of the face's edges by more than
    // the rounding of the nearest point a + t (b - a) (t = 0 or 1, each coordinate within
    // 2 DBL_EPSILON max(|a|, |b|) of a node's; 8 taken): FaceMask of any such point then has
    // only the face's own bits, which it has for the point beyond the face at the run's lower
    // corner.
    // The run's capsules before the last (whose cap the steps below look at) all pass the broad
    // phase when the run's box does on the face's axis (each capsule's coordinates lie within
    // the run's, and rounding is monotonic): `all_pass`. Pieces before `fast_end` take that path;
    // the next run starts at `next_run`.
    // A tube lying on a part has its whole box beyond the face and clear of its edges: then so is
    // every run's box, which lies within it (its margins are no larger, and rounding is
    // monotonic), with the same face and mask, found here once a part rather than once a run
    // (eighteen runs a tick with three PCs). Not for a part the tube reaches with its end only
    // (by_group): few of its runs are asked (the two-PC tick's floor).
    int tube_face_axis = -1;
    std::uint8_t tube_face_mask = 0;
    if (part.aligned && !by_group) {
      const int o = face_beyond(lo, hi);
      if (o >= 0 && clear_of_edges(lo, hi, o)) {
        tube_face_axis = o;
        tube_face_mask = part.face_mask_of_face[std::size_t(2 * o + (lo[o] > 0.0 ? 1 : 0))];
      }
    }
    // A run's box on the axis o of a face it lies beyond (its bounds shifted into the part):
    // whether it is out of the part's grown box there, and whether every capsule in it passes
    // that face's broad phase (the run's step and the strip's loop over runs ask both).
    // (The part's half sizes on o are passed in: the strip's loop holds them in registers.)
    const auto run_out_of_reach = [&](double lo_o, double hi_o, double half_o,
                                      double minus_half_o) {
      return lo_o > 0.0 ? lo_o - grow > half_o : hi_o + grow < minus_half_o;
    };
    const auto run_all_pass = [&](double lo_o, double hi_o, double half_o, double minus_half_o) {
      return lo_o > 0.0 ? !(hi_o - grow > half_o) : !(lo_o + grow < minus_half_o);
    };
    int face_axis = -1, fast_end = -1, next_run = part.aligned ? k_begin : pieces;
    bool all_pass = false;
    std::uint8_t group_mask = 0;
    for (int k = k_begin; k < pieces; ++k) {
      if (k == next_run && k < capsules) {
        next_run = (k / kGroup + 1) * kGroup;
        const std::size_t g = std::size_t(k / kGroup);
        group_mask = tube_face_mask;
        // A run out of the part's grown box has every capsule out of it in the broad phase, as
        // the leading runs above: passed over whole. Its box at hand, that is a few comparisons
        // (the two-PC tick had forty capsules fail the broad phase one by one). Beyond one face,
        // within the other two slabs, only that face's axis can take it out.
        bool out_of_reach = false;
        if (tube_face_axis >= 0) {
          // The tube's face is every run's (above): only the run's bounds on its axis are read,
          // so only they are taken into the part (the same sums; ~40 instructions a three-PC tick).
          const int o = tube_face_axis;
          const double lo_o = group_lo_W_[g][o] + part.p_PW[o];
          const double hi_o = group_hi_W_[g][o] + part.p_PW[o];
          face_axis = o;
          fast_end = std::min(next_run, pieces - 2);
          out_of_reach = run_out_of_reach(lo_o, hi_o, part.half_m[o], part.minus_half_m[o]);
          if (!out_of_reach)
            all_pass = run_all_pass(lo_o, hi_o, part.half_m[o], part.minus_half_m[o]);
        } else {
          const Eigen::Vector3d lo_g = group_lo_W_[g] + part.p_PW;
          const Eigen::Vector3d hi_g = group_hi_W_[g] + part.p_PW;
          face_axis = face_beyond(lo_g, hi_g);
          fast_end = face_axis >= 0 ? std::min(next_run, pieces - 2) : -1;
          out_of_reach =
              face_axis >= 0
                  ? run_out_of_reach(lo_g[face_axis], hi_g[face_axis], part.half_m[face_axis],
                                     part.minus_half_m[face_axis])
                  : (((lo_g.array() - grow) > part.half_m.array()).any() ||
                     ((hi_g.array() + grow) < part.minus_half_m.array()).any());
          if (!out_of_reach && face_axis >= 0) {
            const int o = face_axis;
            all_pass = run_all_pass(lo_g[o], hi_g[o], part.half_m[o], part.minus_half_m[o]);
            // That point's mask, kept with the part: clamped onto the part, the run's lower
            // corner lies on the face's plane (+half_m[o] when beyond it, where lo_g[o] >
            // half_m[o] >= 0; else -half_m[o]) and, along the other two axes, at lo_g, strictly
            // between their edges' planes (clear), as 0 is (the planes are at +-(half_m -
            // tolerance)): FaceMask gives it the bits of Part::face_mask_of_face's point.
            if (clear_of_edges(lo_g, hi_g, o))
              group_mask = part.face_mask_of_face[std::size_t(2 * o + (lo_g[o] > 0.0 ? 1 : 0))];
          }
        }
        if (out_of_reach) {
          k = std::min(next_run, capsules) - 1;  // on to the next run, or the end piece
          continue;
        }
      }
      if (k < fast_end) {
        if (all_pass && strip_next == k && strip_mask == group_mask) {
          // The run's capsules in the band that extend the strip (a tube lying in the groove:
          // nearly all of its hundred), in a loop of their own: the steps below for each, the
          // same operations on the same values, with the strip's figures in registers, its
          // counts and the narrow phase's added once for the capsules taken, and a node's excess
          // over the face carried to the next capsule, whose first end it is (the same sum), not
          // through memory and the general loop's state (~40 instructions a capsule). The first
          // capsule that is not such a one, or that would find `out` full, is left to the steps
          // below, everything written back as they would have left it. (strip_next == k is a
          // strip of a face mask: group_mask is that mask.)
          const int o = face_axis;
          const double half_o_m = part.half_m[o], minus_half_o_m = part.minus_half_m[o];
          const double p_o_m = part.p_PW[o];
          const int k_first = k;
          const int k_room = k + (static_cast<int>(out.size()) - stood);
          int k_stop = std::min(fast_end, k_room);
          RawContact& strip = *strip_entry;
          int strip_deepest = strip.strip_deepest;
          double least_m = strip.distance_m, farthest_m = strip.strip_farthest_m;
          double excess_a = std::abs(nodes_W[std::size_t(k)][o] + p_o_m) - half_o_m;
          for (;; ++k) {
            if (k == k_stop) {
              // The run's end. A tube whose box lies beyond the face (tube_face_axis) gives the
              // next run the same face and mask: the strip goes on into it when the run's steps
              // above, done here, find it within reach with all its capsules passing the broad
              // phase (its new bounds set as they set them); else they are left to do it.
              if (k != fast_end || k != next_run || tube_face_axis < 0 || !(k < capsules)) break;
              const double lo_o = group_lo_W_[std::size_t(k / kGroup)][o] + p_o_m;
              const double hi_o = group_hi_W_[std::size_t(k / kGroup)][o] + p_o_m;
              if (run_out_of_reach(lo_o, hi_o, half_o_m, minus_half_o_m) ||
                  !run_all_pass(lo_o, hi_o, half_o_m, minus_half_o_m))
                break;
              next_run = (k / kGroup + 1) * kGroup;
              fast_end = std::min(next_run, pieces - 2);
              k_stop = std::min(fast_end, k_room);
              if (k == k_stop) break;
            }
            // NearerEndExcess's sums and choice.
            const double excess_b = std::abs(nodes_W[std::size_t(k) + 1][o] + p_o_m) - half_o_m;
            // The least, the greatest and the deepest with their operands ordered so that each
            // result is formed in the register of the value it replaces, not through copies (five
            // instructions a capsule, ~430 a three-PC tick). Each order differs from std::min's /
            // std::max's only where neither operand is less: a NaN, which none is (the nodes and
            // the part's bounds are finite; d passed 0 < d < band_m, and the strip's figures are
            // such d), or equal values, the same bits but for +0 and -0 (the excesses' least is
            // taken its absolute value; the figures are d > 0).
            const double axis_m = std::abs(excess_a < excess_b ? excess_a : excess_b);
            const double d = axis_m - r1_m;
            if (!(d > 0.0 && d < band_m)) break;
            KeptDistance& kept_k = kept[k];
            kept_k.d_m = d;
            // Nodes k and k + 1, contiguous in the span (a Vector3d is its three coordinates):
            // one 3 x 2 block, three 16-byte copies, not four copies of 16 and 8 bytes
            // (KeptDistance; ~170 instructions a three-PC tick).
            static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double));
            kept_k.ends_W_m =
                Eigen::Map<const Eigen::Matrix<double, 3, 2>>(nodes_W[std::size_t(k)].data());
            strip_deepest = d < least_m ? k : strip_deepest;
            least_m = least_m < d ? least_m : d;
            farthest_m = std::max(d, farthest_m);
            excess_a = excess_b;
          }
          const int joined = k - k_first;
          stood += joined;
          narrow_calls_ += joined;
          strip.strip_pieces += joined;
          strip.strip_deepest = strip_deepest;
          strip.distance_m = least_m;
          strip.strip_farthest_m = farthest_m;
          strip_next = k;
          if (k == fast_end) {
            --k;  // on to the next run's first capsule, or the last one
            continue;
          }
        }
        // Such a capsule: the steps below for it, the same operations on the same values,
        // without their general cases (they were a third of the query's instructions). Only its
        // axis across the face can fail the broad phase (within the other two slabs, an end's
        // grown extent reaches the part), and the distance is the nearer end's excess over the
        // face, as in OneFaceDistanceSquared. A pair whose distance the steps below would not
        // sign goes through them; nothing here has changed state by then.
        const Eigen::Vector3d& a_W = nodes_W[std::size_t(k)];
        const Eigen::Vector3d& b_W = nodes_W[std::size_t(k) + 1];
        const int o = face_axis;
        // The face's axis of the nodes in the part's frame, ToPart's sum (the part is aligned).
        const double a_o = a_W[o] + part.p_PW[o], b_o = b_W[o] + part.p_PW[o];
        if (!all_pass && (a_o > 0.0 ? std::min(a_o, b_o) - grow > part.half_m[o]
                                    : std::max(a_o, b_o) + grow < part.minus_half_m[o]))
          continue;  // PassesBroadPhase's answer
        double t = 0.0;
        const double e = NearerEndExcess(a_o, b_o, part.half_m[o], t);
        // |e|: the root of e's rounded square, which the general steps take, is |e| itself in
        // binary floating point (barring underflow, below 1e-154 m, which the test after it
        // sends to the general steps either way); without the root's latency in each capsule's
        // chain of dependent operations.
        const double axis_m = std::abs(e);
        const double d = axis_m - r1_m;
        if (d > 0.0) {
          if (stood == static_cast<int>(out.size())) return count;
          KeptDistance& kept_k = kept[k];
          // A pair in the band is not one the kept distance settles beyond it (KeptBeyondBand:
          // one it settles is beyond the band in the steps below too), so that is asked only of
          // a pair beyond the band (a hundred a tick are in it for a tube lying in the groove).
          if (!(d < band_m)) {
            if (KeptBeyondBand(kept_k, a_W, b_W, band_m)) {
              ++coherent_skips_;
            } else {
              ++narrow_calls_;
              Keep(kept_k, a_W, b_W, d);
            }
            continue;
          }
          ++narrow_calls_;
          // Kept as Keep would, without its finiteness test: 0 < d < band_m is finite (the test
          // and a second comparison with the band were a tenth of each such capsule's steps).
          kept_k.d_m = d;
          // a_W and b_W are nodes k and k + 1 of the span, contiguous: one 3 x 2 block, as in
          // the strip's loop.
          kept_k.ends_W_m = Eigen::Map<const Eigen::Matrix<double, 3, 2>>(a_W.data());
          if (group_mask != 0) {
            emit_deferred(k, d, group_mask);
          } else {
            const Eigen::Vector3d a_P = part.ToPart(a_W), b_P = part.ToPart(b_W);
            const Eigen::Vector3d c_P = a_P + t * (b_P - a_P);
            emit_deferred(k, d, FaceMask(part, c_P.cwiseMax(-part.half_m).cwiseMin(part.half_m)));
          }
          continue;
        }
      }
      const bool is_end = k == pieces - 1;
      const Eigen::Vector3d& a_W = is_end ? end_start_W : nodes_W[std::size_t(k)];
      const Eigen::Vector3d& b_W = is_end ? tip_W : nodes_W[std::size_t(k) + 1];
      const Eigen::Vector3d a_P = is_end         ? end_start_P
                                  : part.aligned ? part.ToPart(a_W)
                                                 : nodes_P_[std::size_t(k)];
      const Eigen::Vector3d b_P = part.aligned ? part.ToPart(b_W)
                                  : is_end     ? nodes_P_[node_count - 1]
                                               : nodes_P_[std::size_t(k) + 1];
      if (!PassesBroadPhase(part, a_P, b_P, band_m)) continue;
      if (stood == static_cast<int>(out.size())) return count;
      // Most pieces that pass the broad phase lie beside a part, farther than the band, and
      // move micrometres a tick: the distance computed some ticks ago, less how far the piece
      // has moved since, still says so (KeptBeyondBand), and the narrow phase below would
      // discard the pair.
      KeptDistance& kept_k = kept[k];
      if (KeptBeyondBand(kept_k, a_W, b_W, band_m)) {
        ++coherent_skips_;
        continue;
      }
      if (is_end) {
        // The capsule on the end piece's axis contains the cylinder: if it is farther than the
        // band, so is the cylinder, and FCL's GJK (microseconds) is not needed. It is the
        // distance kept for the end piece.
        double bound_m = 0.0, unused_axis_m = 0.0;
        Eigen::Vector3d unused_p, unused_q, unused_c;
        if (CapsuleBoxDistance(part, a_P, b_P, bound_m, unused_p, unused_q, unused_c,
                               unused_axis_m)) {
          Keep(kept_k, a_W, b_W, bound_m);
          if (bound_m >= band_m) continue;
        }
      }

      double d = 0.0;
      // The tube's and the part's points and the normal, in the part's frame until the pair is
      // known to be in the band (GJK's answer comes in the world frame). p_P is set only so that
      // the compiler sees it set: a pair CapsuleBoxDistance leaves it unset for takes its point
      // from Overlapping.
      Eigen::Vector3d p_P = Eigen::Vector3d::Zero(), q_P, n_P, p_gjk_W, q_gjk_W;
      ++narrow_calls_;
      bool separated = false;
      bool signed_depth = false;  // overlapping with a trusted depth: d < 0, normal given
      bool from_gjk = false;
      if (!is_end) {
        Eigen::Vector3d c_P;
        double axis_m = 0.0;
        separated = CapsuleBoxDistance(part, a_P, b_P, d, p_P, q_P, c_P, axis_m);
        signed_depth = separated && d <= 0.0;
        if (separated) Keep(kept_k, a_W, b_W, d);
        if (separated && d >= band_m) continue;
        if (separated && !signed_depth && k != pieces - 2) {
          // Apart, within the band: deferred. Not the last capsule, whose point is needed below
          // to tell its cap inside the end cylinder.
          emit_deferred(k, d, FaceMask(part, q_P));
          continue;
        }
        // The normal from the box to the axis, read only with a signed depth (a pair apart
        // takes its normal in the world frame, below).
        if (signed_depth) n_P = (c_P - q_P) / axis_m;
      } else if (CylinderBoxFaceDistance(a_P, b_P, radius_m_, part.half_m, d, p_P, q_P)) {
        // The end piece nearest to a face (the usual case: the tip on the floor, the end against
        // a wall) in closed form; FCL's GJK only for an edge or a vertex nearest, or overlap.
        separated = true;
      } else {
        separated = solver_.shapeDistance(end_, SegmentPose(a_W, b_W), part.box, part.X_WP, &d,
                                          &p_gjk_W, &q_gjk_W);
        from_gjk = true;
        // Overlapping: the shallowest way out through a face of the part (exact for an end
        // pressed into a face, an upper bound of the depth elsewhere), while less than r1.
        if ((!separated || !(d > 0.0)) &&
            CylinderBoxPenetration(a_P, b_P, radius_m_, part.half_m, d, p_P, q_P, n_P)) {
          signed_depth = true;
          from_gjk = false;
          d = -d;
        }
      }
      if (separated && d >= band_m) continue;
      Eigen::Vector3d p_tube_W, q_part_W;
      if (from_gjk) {
        p_tube_W = p_gjk_W;
        q_part_W = q_gjk_W;
        q_P = part.ToPart(q_gjk_W);
      } else {
        p_tube_W = part.ToWorld(p_P);
        q_part_W = part.ToWorld(q_P);
      }
      // The last capsule's round cap past its end node lies inside the end cylinder, which starts
      // there: a point of it within the cylinder is not the tube's surface. The end face pressed
      // on a wall had such a side contact on the axis 1.4 mm behind it (the rubber tube's last
      // node l / 16 from the end, its cap r1 long), which came within epsilon when the face was
      // pressed 0.4 mm in (13.8 N, a coupling's pull before the device's limit): a second PC
      // whose cut, l / 16 from the end, took the end's segment off the rest of the tube (the
      // segmented rule) for the tick, and the fast pass 0.1 mm off its plane snapped
      // (`stability --only "fast pass off-plane"`). Only the cap's part within r1 / 2 of the axis,
      // which faces where the end face does: a part reaching it reaches into the end first. Taken
      // out up to the cylinder's side too, a side contact at the end's start went to the end
      // cylinder's generator, and a soft two-PC run of `tubeplan accuracy` (K = 1e4 N/m, eps =
      // 0.1 mm) drew its tip 1e27 lengths away (docs/accuracy.md).
      // (A capsule whose axis is inside the part has no point here yet: Overlapping's, below.)
      if (!is_end && separated && k == pieces - 2) {
        const Eigen::Vector3d from_end_W = p_tube_W - end_start_W;
        const double along_end_m = from_end_W.dot(tip_tangent_W);
        if (along_end_m > tube_tolerance_m_ && along_end_m < end_m_ &&
            (from_end_W - along_end_m * tip_tangent_W).norm() < 0.5 * radius_m_)
          continue;
      }
      // Made in place, not copied there (out has room: checked above); a pair that yields no
      // contact leaves it past count.
      RawContact& c = out[std::size_t(count)];
      c = RawContact{};
      c.part = part.index;
      const Eigen::Vector3d axis_W = (b_W - a_W).normalized();
      if (signed_depth) {
        c.distance_m = d;
        c.q_W_m = q_part_W;
        c.normal_W = part.DirectionToWorld(n_P);
        c.overlap = true;
      } else if (separated && d > 0.0) {
        c.distance_m = d;
        c.q_W_m = q_part_W;
        c.normal_W = (p_tube_W - q_part_W) / d;
      } else {
        q_P = Overlapping(part, a_W, b_W, c);
        p_tube_W = c.q_W_m;
      }
      c.p_W_m = p_tube_W;
      c.face_mask = FaceMask(part, q_P);
      c.part_element = element_of_[part.index][c.face_mask];
      // A capsule over a face: its stretch (LineEnds) is worked out only for the pieces that
      // end a PC's region (core.cpp), two of the hundred of a tube lying in the groove.
      if (!is_end && separated && IsFaceMask(c.face_mask)) {
        c.over_face = true;
        c.piece = k;
        c.part_slot = static_cast<int>(part_i);
      }

      // The centreline point under the contact, and which element of the tube touches.
      const Eigen::Vector3d centre_W = 0.5 * (a_W + b_W);
      const double half_m = 0.5 * (is_end ? end_m_ : piece_m_);
      const double along = std::clamp((p_tube_W - centre_W).dot(axis_W), -half_m, half_m);
      const double s0 = is_end ? length_m_ - end_m_ : piece_m_ * k;
      c.s_m = std::max(0.0, s0 + half_m + along);
      c.tube = states::TubeElement::kSide;
      if (is_end && along >= half_m - tube_tolerance_m_) {
        const Eigen::Vector3d radial_W = p_tube_W - centre_W - along * axis_W;
        const double tilt = axis_W.cross(c.normal_W).norm();  // sin of end face to contact plane
        const bool side_flat = std::abs(axis_W.dot(c.normal_W)) * end_m_ < tube_tolerance_m_;
        // The end face pressed on a face of the part, slightly tilted. A flat disc's contact
        // point jumps by r1 as the tilt changes sign; the centre of pressure the core used before
        // stop 36 (the force of the centre's distance, placed (r1^2 + r2^2) / (4 (eps -
        // d_centre)) per radian from the centre) is not the gradient of any energy: a tilting
        // face made energy (docs/accuracy.md). The face is a spherical cap over the rim circle
        // instead, of height h and radius R, and the whole end is moved back along its axis by
        // h, so that its apex is the face's centre: a convex body, whose lowest point
        //     e = R sin(tilt) from the centre,  d = d_centre - R (1 - cos(tilt))
        // moves continuously from the centre to the rim, where it meets the rim's point (its
        // distance d_rim + h cos(tilt)) at sin(tilt) = r1 / R with the same distance and
        // normal. K (eps - d)^2 / 2 of the lowest point is then a potential of the end's pose
        // for the tick's R (set_dome_radius_m): the tolerance's (h the tube's geometric
        // tolerance), or, for a face pressed through the part's surface, the bed of springs'
        // radius at last tick's depth (core.cpp), which changes from tick to tick with the force
        // (conservative within a tick; across ticks the stability sweep's passivity check is
        // the evidence). The overlapping face takes it too: it took no dome until stop 43, and
        // its flat law's range (2 r1 sin(tilt) < eps / 10) was passed in one tick of a slide with
        // eps = 1e-5 m.
        const double radial_m = radial_W.norm();
        const double cos_tilt = std::sqrt(std::max(0.0, 1.0 - tilt * tilt));
        const double centre_m = c.distance_m + radius_m_ * tilt;
        // Overlapping, only with the exact depth of a face pressed in (CylinderBoxPenetration):
        // Overlapping()'s point, for an axis inside the part, is not the rim's lowest.
        const bool on_face = !side_flat && IsFaceMask(c.face_mask) && (!c.overlap || signed_depth);
        bool at_pressure_centre = false;
        if (radial_m < radius_m_ - tube_tolerance_m_) {
          c.tube = states::TubeElement::kEndFace;
        } else if (on_face && tilt < dome_sin_max_) {
          c.tube = states::TubeElement::kEndFace;
          at_pressure_centre = c.pressure_centre = true;
          const double e_m = dome_radius_m_ * tilt;
          p_tube_W =
              centre_W + half_m * axis_W +
              (radial_m > 0.0 ? (e_m / radial_m) * radial_W : Eigen::Vector3d::Zero().eval());
          c.distance_m = centre_m - dome_radius_m_ * (1.0 - cos_tilt);
        } else if (!side_flat && 2.0 * radius_m_ * tilt < tube_tolerance_m_) {
          c.tube = states::TubeElement::kEndFace;
        } else if (!side_flat) {
          c.tube = states::TubeElement::kEndRim;
          if (on_face) c.distance_m += dome_height_m_ * cos_tilt;
        }
        if (c.tube == states::TubeElement::kEndFace && !at_pressure_centre)
          p_tube_W = centre_W + half_m * axis_W;  // lying flat, or on an edge: the face's centre
        c.p_W_m = p_tube_W;
        if (c.tube != states::TubeElement::kSide) c.s_m = length_m_;
      }
      if (is_end && c.tube == states::TubeElement::kSide && !c.overlap && IsFaceMask(c.face_mask)) {
        // The end cylinder's side on a face is a line contact along its nearest generator: GJK
        // returns one point of it, at either end depending on the sign of a tiny tilt, which
        // would make the load jump by the cylinder's length from tick to tick. Both ends of the
        // generator go out instead, each with its own distance to the face's plane.
        const Eigen::Vector3d radial_W = p_tube_W - centre_W - along * axis_W;
        const RawContact side = c;  // out[count] may take the first end
        for (const double end : {-half_m, half_m}) {
          if (stood == static_cast<int>(out.size())) return count;
          RawContact e = side;
          e.p_W_m = centre_W + radial_W + end * axis_W;
          e.distance_m = side.distance_m + side.normal_W.dot(e.p_W_m - p_tube_W);
          e.s_m = std::max(0.0, s0 + half_m + end);
          if (e.distance_m < band_m && e.distance_m > 0.0) {
            out[std::size_t(count++)] = e;
            ++stood;
          }
        }
        continue;
      }
      ++count;
      ++stood;
    }
  }
  return count;
}

}  // namespace tubeplan::core
