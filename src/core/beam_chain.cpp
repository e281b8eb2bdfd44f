#include "beam_chain.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <tubeplan/model/tube.hpp>

namespace tubeplan::core {
namespace {

// The elastica's tip, in the segment's clamp frame, for a load with lateral part fx >= 0 along
// the bending direction and axial part fz; solved from `near`, a solution for a nearby load.
Eigen::Vector2d ElasticaTipXZ(double fx, double fz, double length_m, double EI,
                              const model::ElasticaSolution& near) {
  const double f = std::hypot(fx, fz);
  // The callers stay within the solver's range (ElasticaCovers allows half of it); the clamp
  // only guarantees that a tick can never throw.
  const double alpha = std::min(f * length_m * length_m / EI, model::kMaxElasticaAlpha);
  const double psi = f > 0.0 ? std::atan2(fz, fx) : 0.0;
  const model::ElasticaSolution solution = model::SolveElastica(alpha, psi, &near);
  return {length_m * solution.tip.deflection, length_m * (1.0 - solution.tip.shortening)};
}

// Eigen::AngleAxisd(angle, axis).toRotationMatrix() from the angle's sine and cosine: the same
// operations in the same order (Eigen/src/Geometry/AngleAxis.h), so the same bits, for a caller
// that keeps the sine and cosine.
Eigen::Matrix3d TurnMatrix(const Eigen::Vector3d& axis, double sin_angle, double cos_angle) {
  const Eigen::Vector3d sin_axis = sin_angle * axis;
  const Eigen::Vector3d cos1_axis = (1.0 - cos_angle) * axis;
  Eigen::Matrix3d R;
  double tmp = cos1_axis.x() * axis.y();
  R(0, 1) = tmp - sin_axis.z();
  R(1, 0) = tmp + sin_axis.z();
  tmp = cos1_axis.x() * axis.z();
  R(0, 2) = tmp + sin_axis.y();
  R(2, 0) = tmp - sin_axis.y();
  tmp = cos1_axis.y() * axis.z();
  R(1, 2) = tmp - sin_axis.x();
  R(2, 1) = tmp + sin_axis.x();
  R.diagonal() = cos1_axis.cwiseProduct(axis).array() + cos_angle;
  return R;
}

}  // namespace

BeamChain::BeamChain(const scene::Scene& scene)
    : EI_(model::ComputeSection(scene.tube).bending_stiffness_Nm2),
      length_m_(scene.tube.length_m),
      r1_(scene.tube.outer_radius_m),
      // Loads closer than a tube radius act on the same cross-section as far as the tube's
      // bending can tell: they share a cut (e.g. the end face and a wall at the tip's side).
      group_tolerance_m_(scene.tube.outer_radius_m),
      // The rod's steps: l/48, no longer than the shortest capsule of the chain it draws. Its
      // error is second order in the step (tests/model/rod_test.cpp): at l/48 the tip of the
      // rubber tube at alpha = 5 is within ~0.1 % of l of the exact elastica.
      moments_finite_(std::isfinite(2.0 * length_m_ * length_m_ / EI_) &&
                      std::isfinite(length_m_ / EI_)),
      rod_(EI_, scene.tube.length_m / kMaxCapsules),
      rule_(scene.model.multi_contact) {
  // The nodes' weights on a segment from the held end to the tip, as ElasticaNodes forms them
  // (the same function, so the same bits): with two or three PCs the tick's loaded segment is
  // that one in every tick (the end face's load at the tip), and forming its 49 nodes' weights
  // took 1.85 k instructions a three-PC tick (73.0 k).
  const int count = ChainCapsuleCount(scene) + 1;
  if (count < 2 || count > kMaxCapsules + 1) return;
  const double step_m = length_m_ / double(count - 1);
  const double clamp_m = 0.0, L = length_m_;
  const double h = L / (kElasticaSamples - 1);
  int k = 0;
  for (; k < count && step_m * double(k) <= clamp_m + L; ++k)
    full_hermite_[std::size_t(k)] = Hermite(step_m * double(k), clamp_m, h);
  full_node_count_ = count;
  full_nodes_ = k;
}

int BeamChain::Assign(std::array<BeamLoad, kMaxLoads>& loads, int total,
                      const std::array<bool, kMaxLoads>& member, std::array<int, kMaxLoads>& order,
                      int& members) const {
  int count = 0;
  for (int i = 0; i < total; ++i)
    if (member[std::size_t(i)]) order[std::size_t(count++)] = i;
  members = count;
  std::sort(order.begin(), order.begin() + count, [&](int a, int b) {
    const double sa = loads[std::size_t(a)].s_m, sb = loads[std::size_t(b)].s_m;
    return sa < sb || (sa == sb && a < b);
  });
  int group = -1;
  double group_start_m = -1.0, group_end_m = 0.0, clamp_m = 0.0;
  for (int k = 0; k < count; ++k) {
    BeamLoad& load = loads[std::size_t(order[std::size_t(k)])];
    // A new cut, unless within a tube radius of the group's first load or of the same PC as a
    // load already in the group (a line contact is one PC, one load region).
    bool same_pc = false;
    for (int q = 0; q < k && load.pc >= 0; ++q) {
      const BeamLoad& other = loads[std::size_t(order[std::size_t(q)])];
      if (other.group == group && other.pc == load.pc) same_pc = true;
    }
    if (group < 0 || (load.s_m - group_start_m > group_tolerance_m_ && !same_pc)) {
      ++group;
      clamp_m = group == 0 ? 0.0 : group_end_m;
      group_start_m = load.s_m;
    }
    group_end_m = load.s_m;
    load.group = group;
    load.clamp_m = rule_ == scene::MultiContactRule::kCoupled ? 0.0 : clamp_m;
  }
  return group + 1;
}

double BeamChain::Influence(double s_m, const BeamLoad& load) const {
  const double a = s_m - load.clamp_m, b = load.s_m - load.clamp_m;
  if (a <= 0.0 || b <= 0.0) return 0.0;
  return a <= b ? a * a * (3.0 * b - a) / (6.0 * EI_) : b * b * (3.0 * a - b) / (6.0 * EI_);
}

double BeamChain::InfluenceSlope(double s_m, const BeamLoad& load) const {
  const double a = s_m - load.clamp_m, b = load.s_m - load.clamp_m;
  if (a <= 0.0 || b <= 0.0) return 0.0;
  return a <= b ? a * (2.0 * b - a) / (2.0 * EI_) : b * b / (2.0 * EI_);
}

namespace {
const Eigen::Matrix3d kLateral = Eigen::Vector3d(1.0, 1.0, 0.0).asDiagonal();
const Eigen::Matrix3d kZ = Skew(Eigen::Vector3d::UnitZ());

struct Coefficients {
  double uF = 0.0, thF = 0.0, uM = 0.0, thM = 0.0;
};

// The force's coefficients uF and thF of Coeffs, for a, b > 0.
[[gnu::always_inline]] inline void ForceCoeffs(double a, double b, double EI, double& uF,
                                               double& thF) {
  if (a <= b) {
    uF = a * a * (3.0 * b - a) / (6.0 * EI);
    thF = a * (2.0 * b - a) / (2.0 * EI);
  } else {
    uF = b * b * (3.0 * a - b) / (6.0 * EI);
    thF = b * b / (2.0 * EI);
  }
}

Coefficients Coeffs(double a, double b, double EI) {
  Coefficients c;
  if (a <= 0.0 || b <= 0.0) return c;
  ForceCoeffs(a, b, EI, c.uF, c.thF);
  if (a <= b) {
    c.uM = a * a / (2.0 * EI);
    c.thM = a / EI;
  } else {
    c.uM = b * (2.0 * a - b) / (2.0 * EI);
    c.thM = b / EI;
  }
  return c;
}
}  // namespace

void BeamChain::Compliance(const BeamLoad& i, const BeamLoad& j, bool moments,
                           Eigen::Matrix3d& W) const {
  const double a = i.s_m - j.clamp_m, b = j.s_m - j.clamp_m;
  // The shortcut below needs finite moment coefficients, not their values: with a and b at
  // most l they are at most l^2 / EI and l / EI (rounding is monotonic; a NaN fails the test),
  // finite by moments_finite_. So only uF and thF are formed there, as Coeffs forms them (two
  // divisions of its four, 18 calls a three-PC tick).
  if (!moments && moments_finite_ && a <= length_m_ && b <= length_m_) {
    double uF = 0.0, thF = 0.0;
    if (a > 0.0 && b > 0.0) ForceCoeffs(a, b, EI_, uF, thF);
    // Without the offset moment (Rj = 0: the elastica's ticks, a call per load pair and
    // member) its two products are 3 x 3 products with a zero matrix. With finite coefficients
    // (Coeffs makes them +0 or positive) every entry of both is +0: uM kZ Rj is subtracted
    // from a matrix whose entries it leaves as they are, and thM kLateral Rj added to thF kZ
    // only turns a -0 there into +0, which adding the zero matrix does too. So the result has
    // the same bits without the two products (a third of the elastica's tick in this
    // function).
    // And -[r]x (thF [e_z]x) = thF (r_z I - e_z r^T): each entry of that product is one
    // product thF r_c (or zero) plus exact zeros, so written out it has the same bits but for
    // the sign of a zero, and takes a tenth of the instructions.
    const Eigen::Vector3d& r = i.r_H_m;
    const double t_rz = thF * r.z();
    W << uF + t_rz, 0.0, 0.0,  //
        0.0, uF + t_rz, 0.0,   //
        -thF * r.x(), -thF * r.y(), 0.0;
    return;
  }
  const Coefficients c = Coeffs(a, b, EI_);
  const Eigen::Matrix3d Rj = moments ? Skew(j.r_H_m) : Eigen::Matrix3d::Zero();
  W = c.uF * kLateral - c.uM * kZ * Rj - Skew(i.r_H_m) * (c.thF * kZ + c.thM * kLateral * Rj);
}

double BeamChain::DisplacementBound(const BeamLoad& j, const Eigen::Vector3d& df_H, bool moments,
                                    double r_max_m, double s_max_m, const Eigen::Matrix3d& normal_H,
                                    const Eigen::Matrix3d& turn_H) const {
  // Compliance's terms one by one. The force's lateral part L F bends the centre by uF L F
  // (its direction fixed, its size uF at most its value at s_max: |n . uF L F| <= uF |P L F| for
  // unit n in P's range) and turns the section by theta = thF z x F, which moves the point at
  // offset r_i by r_i x theta: |n . (r x theta)| = |r . (theta x n)| <= r_max |theta x n|, and
  // |theta x n| is |theta| less its part along n when n is one direction. The offset moment
  // r_j x F moves and turns it too (uM, thM) where the model carries it: bounded whole.
  const Coefficients c = Coeffs(s_max_m - j.clamp_m, j.s_m - j.clamp_m, EI_);
  const Eigen::Vector3d lateral(df_H.x(), df_H.y(), 0.0);
  const Eigen::Vector3d turn(-df_H.y(), df_H.x(), 0.0);  // z x F
  double bound = c.uF * (normal_H * lateral).norm() + r_max_m * c.thF * (turn_H * turn).norm();
  if (moments) bound += (c.uM + r_max_m * c.thM) * j.r_H_m.norm() * df_H.norm();
  return bound;
}

double BeamChain::DisplacementChangeBound(const BeamLoad& now, const BeamLoad& then,
                                          const Eigen::Vector3d& f_H, bool moments, double r_max_m,
                                          double s_max_m, const Eigen::Matrix3d& normal_H,
                                          const Eigen::Matrix3d& turn_H) const {
  if (now.clamp_m != then.clamp_m)
    return DisplacementBound(now, f_H, moments, r_max_m, s_max_m, normal_H, turn_H) +
           DisplacementBound(then, f_H, moments, r_max_m, s_max_m, normal_H, turn_H);
  // Each coefficient (Coeffs) is non-decreasing in the load's arc position b at every point a,
  // and for b1 > b2 the difference c(a; b1) - c(a; b2) is non-negative and non-decreasing in a:
  // its value at s_max bounds it at every point up to there. The terms as in DisplacementBound;
  // the offset moment M = r x f changes with r too: u_now M_now - u_then M_then is
  // u_now (M_now - M_then) + (u_now - u_then) M_then.
  const double a = s_max_m - now.clamp_m;
  const Coefficients cn = Coeffs(a, now.s_m - now.clamp_m, EI_);
  const Coefficients ct = Coeffs(a, then.s_m - then.clamp_m, EI_);
  const Eigen::Vector3d lateral(f_H.x(), f_H.y(), 0.0);
  const Eigen::Vector3d turn(-f_H.y(), f_H.x(), 0.0);  // z x F
  double bound = std::abs(cn.uF - ct.uF) * (normal_H * lateral).norm() +
                 r_max_m * std::abs(cn.thF - ct.thF) * (turn_H * turn).norm();
  if (moments) {
    const Eigen::Vector3d M_now = now.r_H_m.cross(f_H), M_then = then.r_H_m.cross(f_H);
    bound += (cn.uM + r_max_m * cn.thM) * (M_now - M_then).norm() +
             (std::abs(cn.uM - ct.uM) + r_max_m * std::abs(cn.thM - ct.thM)) * M_then.norm();
  }
  return bound;
}

Eigen::Vector3d BeamChain::CentreDisplacement(double s_m, const BeamLoad& j) const {
  const Coefficients c = Coeffs(s_m - j.clamp_m, j.s_m - j.clamp_m, EI_);
  const Eigen::Vector3d M = j.r_H_m.cross(j.f_H_N);
  return c.uF * (kLateral * j.f_H_N) - c.uM * (kZ * M);
}

Eigen::Vector3d BeamChain::SectionRotation(double s_m, const BeamLoad& j) const {
  const Coefficients c = Coeffs(s_m - j.clamp_m, j.s_m - j.clamp_m, EI_);
  const Eigen::Vector3d M = j.r_H_m.cross(j.f_H_N);
  return c.thF * (kZ * j.f_H_N) + c.thM * (kLateral * M);
}

Eigen::Matrix3d BeamChain::MomentCompliance(const BeamLoad& i, const BeamLoad& at) const {
  // Compliance's moment terms: a moment M moves the centre by -uM z x M and turns the section
  // by thM M (its lateral part), which moves the surface point by -r_i x that.
  const Coefficients c = Coeffs(i.s_m - at.clamp_m, at.s_m - at.clamp_m, EI_);
  return -c.uM * kZ - c.thM * Skew(i.r_H_m) * kLateral;
}

Eigen::Matrix3d BeamChain::TurnCompliance(double s_m, const BeamLoad& j) const {
  const Coefficients c = Coeffs(s_m - j.clamp_m, j.s_m - j.clamp_m, EI_);
  return c.thF * kZ + c.thM * kLateral * Skew(j.r_H_m);
}

double BeamChain::TurnPerMoment(const BeamLoad& at) const {
  return Coeffs(at.s_m - at.clamp_m, at.s_m - at.clamp_m, EI_).thM;
}

double BeamChain::MomentDisplacementBound(const BeamLoad& at, double moment_Nm, double r_max_m,
                                          double s_max_m) const {
  // Each coefficient grows with the point's arc position (Coeffs): its value at s_max bounds it.
  const Coefficients c = Coeffs(s_max_m - at.clamp_m, at.s_m - at.clamp_m, EI_);
  return (c.uM + r_max_m * c.thM) * std::abs(moment_Nm);
}

bool BeamChain::ElasticaCovers(const std::array<BeamLoad, kMaxLoads>& loads,
                               const std::array<int, kMaxLoads>& order, int count,
                               int groups) const {
  if (rule_ == scene::MultiContactRule::kCoupled && groups > 1) return false;
  // Each segment's resultant must be within the solver's range (and finite).
  // A group's sums start at its first load: Assign numbers the groups 0 to groups - 1 along
  // `order`, each a run of at least one load, so every entry read below is started there, from
  // the same zero the whole arrays were filled with before (the same sums, so the same bits).
  // Filling all kMaxLoads entries of the three took ~40 instructions a three-PC tick more.
  std::array<Eigen::Vector3d, kMaxLoads> resultant;
  std::array<double, kMaxLoads> length;
  std::array<double, kMaxLoads> first;
  for (int k = 0; k < count; ++k) {
    // Groups are runs of `order` (it is sorted by arc position).
    const BeamLoad& load = loads[std::size_t(order[std::size_t(k)])];
    const std::size_t g = std::size_t(load.group);
    if (k == 0 || loads[std::size_t(order[std::size_t(k - 1)])].group != load.group) {
      first[g] = load.s_m;
      resultant[g] = Eigen::Vector3d::Zero();
      length[g] = 0.0;
    }
    resultant[g] += load.f_H_N;
    length[g] = std::max(length[g], load.s_m - load.clamp_m);
    // The elastica takes one load at the segment's end. A region up to a tube diameter long (the
    // end cylinder's side on a face) is taken as that load; a side lying along a face is not.
    if (load.s_m - first[g] > 2.0 * group_tolerance_m_) return false;
  }
  for (int g = 0; g < groups; ++g) {
    const double L = length[std::size_t(g)];
    const double alpha = resultant[std::size_t(g)].norm() * L * L / EI_;
    if (!(alpha <= 0.5 * model::kMaxElasticaAlpha)) return false;
  }
  return true;
}

int BeamChain::SolveElasticaChain(const std::array<BeamLoad, kMaxLoads>& loads, int count,
                                  const std::array<int, kMaxLoads>& order,
                                  std::array<ElasticaSegment, kMaxLoads>& segments) const {
  int segment_count = 0;
  Eigen::Vector3d origin_H = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_HS = Eigen::Matrix3d::Identity();
  double clamp_m = 0.0;
  for (int k = 0; k < count;) {
    // One group: its loads are consecutive in `order`.
    const int group = loads[std::size_t(order[std::size_t(k)])].group;
    Eigen::Vector3d f_H = Eigen::Vector3d::Zero();
    double end_m = clamp_m;
    for (; k < count && loads[std::size_t(order[std::size_t(k)])].group == group; ++k) {
      const BeamLoad& load = loads[std::size_t(order[std::size_t(k)])];
      f_H += load.f_H_N;
      end_m = std::max(end_m, load.s_m);
    }
    ElasticaSegment& seg = segments[std::size_t(segment_count++)];
    seg.origin_H = origin_H;
    seg.R_HS = R_HS;
    seg.clamp_m = clamp_m;
    seg.length_m = end_m - clamp_m;
    const Eigen::Vector3d f_S = R_HS.transpose() * f_H;
    const double fx = std::hypot(f_S.x(), f_S.y());
    // The bending direction: along the lateral load; with none (axial load), the clamp's x.
    seg.bend_x_S =
        fx > 0.0 ? Eigen::Vector3d(f_S.x() / fx, f_S.y() / fx, 0.0) : Eigen::Vector3d::UnitX();
    const double L = seg.length_m;
    if (L > 0.0) {
      const double f = std::hypot(fx, f_S.z());
      // The segment's last solution (last tick's, as a rule) is the solve's starting point. It is
      // read in place: the answer is a temporary until the solve returns.
      seg.solution = model::SolveElastica(std::min(f * L * L / EI_, model::kMaxElasticaAlpha),
                                          f > 0.0 ? std::atan2(f_S.z(), fx) : 0.0, &seg.solution);
    } else {
      seg.solution = model::ElasticaSolution{};
    }
    // A first segment of no length (a load at the held end: three PCs, every tick) carries the
    // clamp nowhere, and its carry changes no bit: it leaves the origin at +0, and its turn by
    // a zero angle is the identity with zeros of either sign off the diagonal, so the identity
    // times it is the identity again (each zero entry a sum with a +0 term) and its z column is
    // z. So it is left out: an axis-angle rotation, a 3 x 3 product and the move, 0.24 k
    // instructions a three-PC tick.
    if (L > 0.0 || segment_count > 1) {
      // Carry the clamp to the segment's tip: there the next segment starts.
      const Eigen::Vector3d y_S = Eigen::Vector3d::UnitZ().cross(seg.bend_x_S);
      const model::ElasticaTip& tip = seg.solution.tip;
      origin_H += R_HS * (L * tip.deflection * seg.bend_x_S +
                          L * (1.0 - tip.shortening) * Eigen::Vector3d::UnitZ());
      // The tip angle's sine and cosine are kept in the solution: the nodes' samples
      // (model::ElasticaSamples) turn their tangents by them too (~70 instructions a tick).
      seg.solution.tip_sin = std::sin(tip.tip_angle_rad);
      seg.solution.tip_cos = std::cos(tip.tip_angle_rad);
      seg.solution.tip_trig_angle_rad = tip.tip_angle_rad;
      const Eigen::Matrix3d tip_R_S = TurnMatrix(y_S, seg.solution.tip_sin, seg.solution.tip_cos);
      seg.tip_tangent_S = tip_R_S * Eigen::Vector3d::UnitZ();
      R_HS = R_HS * tip_R_S;
    } else {
      seg.tip_tangent_S = Eigen::Vector3d::UnitZ();
    }
    clamp_m = end_m;
  }
  return segment_count;
}

namespace {

// The segment of a solved chain whose arc holds s_m, or -1 beyond the last load (or with none).
int ElasticaSegmentAt(const std::array<ElasticaSegment, kMaxLoads>& segments, int segment_count,
                      double s_m) {
  for (int g = 0; g < segment_count; ++g) {
    const ElasticaSegment& seg = segments[std::size_t(g)];
    if (s_m > seg.clamp_m + seg.length_m && g + 1 < segment_count) continue;
    return s_m > seg.clamp_m + seg.length_m ? -1 : g;
  }
  return -1;
}

// A segment's point in H from its dimensionless centreline point (x, z) / L.
Eigen::Vector3d SegmentPoint(const ElasticaSegment& seg, const Eigen::Vector2d& xz) {
  return seg.origin_H +
         seg.R_HS * (seg.length_m * (xz.x() * seg.bend_x_S + xz.y() * Eigen::Vector3d::UnitZ()));
}

// The point of one segment at s_m from its dimensionless centreline at (s_m - clamp) / length.
Eigen::Vector3d SegmentPointAt(const ElasticaSegment& seg, double s_m) {
  const double s_unit = std::clamp((s_m - seg.clamp_m) / seg.length_m, 0.0, 1.0);
  Eigen::Vector2d xz;
  double theta = 0.0;
  model::ElasticaCentreline(seg.solution, std::span<const double>(&s_unit, 1),
                            std::span<Eigen::Vector2d>(&xz, 1), std::span<double>(&theta, 1));
  return SegmentPoint(seg, xz);
}

}  // namespace

void BeamChain::ElasticaEvenPoints(const std::array<ElasticaSegment, kMaxLoads>& segments,
                                   int segment_count, std::span<Eigen::Vector3d> out) const {
  const std::size_t count = out.size();
  const auto s_at = [&](std::size_t k) {
    return count > 1 ? length_m_ * double(k) / double(count - 1) : length_m_;
  };
  // A segment's points in chunks of at most kChunk (no allocation), each walked by
  // ElasticaSamples over its range; a chunk of one point, and the points beyond the chain, one
  // by one.
  constexpr std::size_t kChunk = 64;
  std::array<Eigen::Vector2d, kChunk> xz, tangent;
  for (std::size_t i = 0; i < count;) {
    const int g = ElasticaSegmentAt(segments, segment_count, s_at(i));
    std::size_t n = 1;
    while (i + n < count && n < kChunk &&
           ElasticaSegmentAt(segments, segment_count, s_at(i + n)) == g)
      ++n;
    if (g < 0 || n < 2 || !(segments[std::size_t(g)].length_m > 0.0)) {
      for (std::size_t k = i; k < i + n; ++k)
        out[k] = ElasticaPoint(segments, segment_count, s_at(k));
    } else {
      const ElasticaSegment& seg = segments[std::size_t(g)];
      const auto unit = [&](std::size_t k) {
        return std::clamp((s_at(k) - seg.clamp_m) / seg.length_m, 0.0, 1.0);
      };
      model::ElasticaSamples(seg.solution, unit(i), unit(i + n - 1),
                             std::span<Eigen::Vector2d>(xz.data(), n),
                             std::span<Eigen::Vector2d>(tangent.data(), n));
      for (std::size_t k = 0; k < n; ++k) out[i + k] = SegmentPoint(seg, xz[k]);
    }
    i += n;
  }
}

Eigen::Vector3d BeamChain::ElasticaPoint(const std::array<ElasticaSegment, kMaxLoads>& segments,
                                         int segment_count, double s_m) const {
  const int g = ElasticaSegmentAt(segments, segment_count, s_m);
  if (g >= 0) {
    const ElasticaSegment& seg = segments[std::size_t(g)];
    if (!(seg.length_m > 0.0)) return seg.origin_H;
    return SegmentPointAt(seg, s_m);
  }
  // Beyond the last segment (or no segment): straight along the last tip's tangent.
  if (segment_count == 0) return {0.0, 0.0, s_m};
  const ElasticaSegment& last = segments[std::size_t(segment_count - 1)];
  const double L = last.length_m;
  const model::ElasticaTip& tip = last.solution.tip;
  const Eigen::Vector3d tip_H =
      last.origin_H + last.R_HS * (L * tip.deflection * last.bend_x_S +
                                   L * (1.0 - tip.shortening) * Eigen::Vector3d::UnitZ());
  const Eigen::Vector3d tangent_H = last.R_HS * last.tip_tangent_S;
  return tip_H + (s_m - last.clamp_m - L) * tangent_H;
}

BeamChain::HermiteNode BeamChain::Hermite(double s_m, double clamp_m, double h_m) {
  constexpr int n = kElasticaSamples;
  const double u = std::clamp((s_m - clamp_m) / h_m, 0.0, double(n - 1));
  HermiteNode w;
  w.j = std::min(static_cast<int>(u), n - 2);
  const double t = u - double(w.j), t2 = t * t, t3 = t2 * t;
  w.point0 = 2 * t3 - 3 * t2 + 1;
  w.tangent0_h = (t3 - 2 * t2 + t) * h_m;
  w.point1 = -2 * t3 + 3 * t2;
  w.tangent1_h = (t3 - t2) * h_m;
  return w;
}

void BeamChain::ElasticaNodes(const std::array<ElasticaSegment, kMaxLoads>& segments,
                              int segment_count, std::span<Eigen::Vector3d> nodes) const {
  // Signed indices (the node's and its samples'): each is converted to double in one
  // instruction, where a size_t needs a test and a branch more (two a node: ~150 instructions a
  // three-PC tick).
  const int count = int(nodes.size());
  const double step_m = length_m_ / double(count - 1);
  int k = 0;
  for (int g = 0; g < segment_count; ++g) {
    const ElasticaSegment& seg = segments[std::size_t(g)];
    const double L = seg.length_m;
    if (!(L > 0.0)) continue;
    constexpr int n = kElasticaSamples;
    std::array<Eigen::Vector2d, n> xz{};
    std::array<Eigen::Vector2d, n> tangent_xz{};
    model::ElasticaSamples(seg.solution, xz, tangent_xz);
    const Eigen::Vector3d x_H = seg.R_HS * seg.bend_x_S;
    const Eigen::Vector3d z_H = seg.R_HS.col(2);
    // The samples' points and unit tangents (d/ds of the position), each computed once: every
    // node between two samples needs both samples'. A sample's point and tangent lie side by
    // side, so that a node finds the four vectors it combines at fixed offsets from one address
    // (from two arrays it formed four addresses: ~240 instructions a three-PC tick, 49 nodes).
    // The same sums in the same order, so the same bits.
    struct Sample {
      Eigen::Vector3d point, tangent;
    };
    std::array<Sample, n> sample;
    for (std::size_t j = 0; j < std::size_t(n); ++j) {
      sample[j].point = seg.origin_H + L * (xz[j].x() * x_H + xz[j].y() * z_H);
      sample[j].tangent = tangent_xz[j].x() * x_H + tangent_xz[j].y() * z_H;
    }
    const auto node = [&](const HermiteNode& w) {
      const Sample* const at = &sample[std::size_t(w.j)];
      return Eigen::Vector3d(w.point0 * at[0].point + w.tangent0_h * at[0].tangent +
                             w.point1 * at[1].point + w.tangent1_h * at[1].tangent);
    };
    if (k == 0 && seg.clamp_m == 0.0 && L == length_m_ && count == full_node_count_) {
      for (; k < full_nodes_; ++k) nodes[std::size_t(k)] = node(full_hermite_[std::size_t(k)]);
      continue;
    }
    const double h = L / (n - 1);
    for (; k < count && step_m * double(k) <= seg.clamp_m + L; ++k)
      nodes[std::size_t(k)] = node(Hermite(step_m * double(k), seg.clamp_m, h));
  }
  // Beyond the last load (or with none): straight along the last tangent.
  for (; k < count; ++k)
    nodes[std::size_t(k)] = ElasticaPoint(segments, segment_count, step_m * double(k));
}

Eigen::Vector3d BeamChain::ElasticaTipTangent(
    const std::array<ElasticaSegment, kMaxLoads>& segments, int segment_count) const {
  if (segment_count == 0) return Eigen::Vector3d::UnitZ();
  const ElasticaSegment& last = segments[std::size_t(segment_count - 1)];
  return last.R_HS * last.tip_tangent_S;
}

Eigen::Matrix3d BeamChain::ElasticaCompliance(const ElasticaSegment& segment,
                                              const Eigen::Vector3d& f_H_N) const {
  const double L = segment.length_m;
  if (!(L > 0.0)) return Eigen::Matrix3d::Zero();
  const Eigen::Vector3d f_S = segment.R_HS.transpose() * f_H_N;
  const Eigen::Vector3d& x_S = segment.bend_x_S;
  const double fx = std::max(0.0, f_S.dot(x_S));
  const double fz = f_S.z();
  // Forward differences with a step of 1e-6 of the load scale EI / L^2 (the force at alpha = 1)
  // plus the load itself: the elastica's ~1e-13 relative accuracy leaves ~1e-7 in the slope.
  const double scale = EI_ / (L * L);
  const double h = 1e-6 * (scale + std::hypot(fx, fz));
  // All three from the segment's own solution, a load at most h away.
  const model::ElasticaSolution& near = segment.solution;
  const Eigen::Vector2d base = ElasticaTipXZ(fx, fz, L, EI_, near);
  const Eigen::Vector2d dx = (ElasticaTipXZ(fx + h, fz, L, EI_, near) - base) / h;
  const Eigen::Vector2d dz = (ElasticaTipXZ(fx, fz + h, L, EI_, near) - base) / h;
  // Across the bending plane the response is the in-plane one turned about the axis: a small
  // turn phi of the load turns the deflection X by the same phi, so the compliance is X / fx.
  const double across = fx > 1e-9 * scale ? base.x() / fx : dx.x();
  Eigen::Matrix3d J_local;         // in the basis (bend x, bend y, z) of S
  J_local << dx.x(), 0.0, dz.x(),  //
      0.0, across, 0.0,            //
      dx.y(), 0.0, dz.y();
  Eigen::Matrix3d B;
  B.col(0) = x_S;
  B.col(1) = Eigen::Vector3d::UnitZ().cross(x_S);
  B.col(2) = Eigen::Vector3d::UnitZ();
  const Eigen::Matrix3d basis_H = segment.R_HS * B;
  return basis_H * J_local * basis_H.transpose();
}

}  // namespace tubeplan::core

namespace tubeplan::core {

int BeamChain::SolveRodChain(const std::array<BeamLoad, kMaxLoads>& loads, int count,
                             const std::array<int, kMaxLoads>& order,
                             std::array<RodSegment, kMaxLoads>& segments,
                             std::span<Eigen::Vector3d> nodes) const {
  const bool coupled = rule_ == scene::MultiContactRule::kCoupled;
  int segment_count = 0;
  Eigen::Vector3d origin_H = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_HS = Eigen::Matrix3d::Identity();
  double clamp_m = 0.0;
  // The nodes are shared out as RodNodes does: a segment's up to its end, the last one's all
  // that are left (straight beyond its last load).
  const std::size_t node_count = nodes.size();
  if (node_count == 1 || node_count > std::size_t(kMaxCapsules) + 1)
    throw std::invalid_argument("BeamChain::SolveRodChain: 2 to kMaxCapsules + 1 nodes expected");
  std::array<double, kMaxCapsules + 1> node_s_S{};
  std::size_t next_node = 0;
  for (int k = 0; k < count;) {
    // One segment: a group's loads (consecutive in `order`), or every load under the coupled rule.
    const int group = loads[std::size_t(order[std::size_t(k)])].group;
    RodSegment& seg = segments[std::size_t(segment_count++)];
    // The loads of its last solve, for the predictor below.
    const std::array<model::RodLoad, kMaxLoads> last_loads_S = seg.loads_S;
    const int last_count = seg.load_count;
    seg.origin_H = origin_H;
    seg.R_HS = R_HS;
    seg.clamp_m = clamp_m;
    seg.load_count = 0;
    for (; k < count && (coupled || loads[std::size_t(order[std::size_t(k)])].group == group);
         ++k) {
      const int i = order[std::size_t(k)];
      const BeamLoad& load = loads[std::size_t(i)];
      const std::size_t q = std::size_t(seg.load_count++);
      seg.index[q] = i;
      seg.loads_S[q] = model::RodLoad{std::max(load.s_m - clamp_m, 0.0),
                                      R_HS.transpose() * load.f_H_N, R_HS.transpose() * load.r_H_m};
    }
    const std::span<const model::RodLoad> seg_loads(seg.loads_S.data(),
                                                    std::size_t(seg.load_count));
    // The solve starts from the last solution's end, turned by the change of the forces since
    // that solve times the end's turn per force from the last tangent (a first-order predictor:
    // a tick's forces change by up to ~0.1 N, which turns the rubber tube's end by ~0.1 rad,
    // and the shooting from the old end alone then took three chord iterations or more). Only
    // for the same loads at the same places (within 1 % of l), and a predicted turn below
    // 0.25 rad: the solve takes no solution more than 0.5 rad from where it started.
    model::RodSolution start = seg.solution;
    if (seg.end_turn_count == seg.load_count && last_count == seg.load_count) {
      Eigen::Vector3d turn = Eigen::Vector3d::Zero();
      bool same = true;
      for (int q = 0; q < seg.load_count && same; ++q) {
        const model::RodLoad& now = seg.loads_S[std::size_t(q)];
        const model::RodLoad& before = last_loads_S[std::size_t(q)];
        same = std::abs(now.s_m - before.s_m) <= 0.01 * length_m_;
        turn += seg.end_turn_per_N[std::size_t(q)] * (now.f_N - before.f_N);
      }
      const double angle = turn.norm();
      if (same && angle > 0.0 && angle <= 0.25)
        start.end_R = Eigen::AngleAxisd(angle, turn / angle).toRotationMatrix() * start.end_R;
    }
    if (node_count == 0) {
      seg.solution = rod_.Solve(seg_loads, start);
    } else {
      double end_S = 0.0;
      for (const model::RodLoad& load : seg_loads) end_S = std::max(end_S, load.s_m);
      const bool last = k == count;
      const std::size_t first = next_node;
      for (; next_node < node_count; ++next_node) {
        const double s = length_m_ * double(next_node) / double(node_count - 1);
        if (!last && s > clamp_m + end_S) break;
        node_s_S[next_node - first] = std::max(s - clamp_m, 0.0);
      }
      const std::size_t n = next_node - first;
      const std::span<Eigen::Vector3d> seg_nodes = nodes.subspan(first, n);
      seg.solution =
          rod_.Solve(seg_loads, start,
                     model::RodSamples{std::span<const double>(node_s_S.data(), n), seg_nodes, {}});
      for (Eigen::Vector3d& p : seg_nodes) p = origin_H + R_HS * p;
    }
    if (!seg.solution.converged) return 0;
    seg.end_m = clamp_m + seg.solution.end_m;
    // Carry the clamp to the segment's end: there the next segment starts.
    origin_H += R_HS * seg.solution.end_p_m;
    R_HS = R_HS * seg.solution.end_R;
    clamp_m = seg.end_m;
  }
  return segment_count;
}

bool BeamChain::SolveRodPinned(std::array<BeamLoad, kMaxLoads>& loads, int count,
                               const std::array<int, kMaxLoads>& order,
                               std::array<RodSegment, kMaxLoads>& segments,
                               const Eigen::Matrix3d& start_end_R,
                               const std::array<Eigen::Vector3d, kMaxLoads>& pinned_H,
                               std::span<Eigen::Vector3d> nodes) const {
  const std::size_t node_count = nodes.size();
  if (count <= 0 || node_count < 2 || node_count > std::size_t(kMaxCapsules) + 1) return false;
  const bool coupled = rule_ == scene::MultiContactRule::kCoupled;
  const int group = loads[std::size_t(order[0])].group;
  for (int k = 1; k < count && !coupled; ++k)
    if (loads[std::size_t(order[std::size_t(k)])].group != group) return false;
  // One segment clamped at the held end: its frame S is H.
  std::array<model::RodLoad, kMaxLoads> loads_S{};
  std::array<Eigen::Vector2d, kMaxLoads> pinned_xy;
  for (int q = 0; q < count; ++q) {
    const BeamLoad& load = loads[std::size_t(order[std::size_t(q)])];
    loads_S[std::size_t(q)] = model::RodLoad{std::max(load.s_m, 0.0), load.f_H_N, load.r_H_m};
    pinned_xy[std::size_t(q)] = pinned_H[std::size_t(order[std::size_t(q)])].head<2>();
  }
  std::array<double, kMaxCapsules + 1> node_s{};
  for (std::size_t k = 0; k < node_count; ++k)
    node_s[k] = length_m_ * double(k) / double(node_count - 1);
  model::RodSolution start;
  start.end_R = start_end_R;
  const model::RodSolution solution = rod_.SolvePinned(
      std::span<model::RodLoad>(loads_S.data(), std::size_t(count)), start,
      std::span<const Eigen::Vector2d>(pinned_xy.data(), std::size_t(count)),
      model::RodSamples{std::span<const double>(node_s.data(), node_count), nodes, {}});
  if (!solution.converged) return false;
  RodSegment& seg = segments[0];
  seg.solution = solution;
  seg.load_count = count;
  seg.end_turn_count = 0;
  seg.origin_H.setZero();
  seg.R_HS.setIdentity();
  seg.clamp_m = 0.0;
  seg.end_m = solution.end_m;
  for (int q = 0; q < count; ++q) {
    seg.index[std::size_t(q)] = order[std::size_t(q)];
    seg.loads_S[std::size_t(q)] = loads_S[std::size_t(q)];
    loads[std::size_t(order[std::size_t(q)])].f_H_N = loads_S[std::size_t(q)].f_N;
  }
  return true;
}

bool BeamChain::RodCompliance(RodSegment& segment,
                              std::array<std::array<Eigen::Matrix3d, kMaxLoads>, kMaxLoads>& w,
                              model::RodEndMoment* moment) const {
  const int n = segment.load_count;
  std::array<Eigen::Matrix3d, kMaxLoads * kMaxLoads> w_S;
  model::RodEndMoment moment_S;
  segment.end_turn_count = 0;
  if (!rod_.Compliance(std::span<const model::RodLoad>(segment.loads_S.data(), std::size_t(n)),
                       segment.solution, std::span<Eigen::Matrix3d>(w_S.data(), std::size_t(n * n)),
                       std::span<Eigen::Matrix3d>(segment.end_turn_per_N.data(), std::size_t(n)),
                       moment != nullptr ? &moment_S : nullptr))
    return false;
  segment.end_turn_count = n;
  const Eigen::Matrix3d& R = segment.R_HS;
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b)
      w[std::size_t(segment.index[std::size_t(a)])][std::size_t(segment.index[std::size_t(b)])] =
          R * w_S[std::size_t(a * n + b)] * R.transpose();
  if (moment != nullptr) {
    moment->turn_per_Nm = R * moment_S.turn_per_Nm * R.transpose();
    for (int a = 0; a < n; ++a)
      moment->w_per_Nm[std::size_t(segment.index[std::size_t(a)])] =
          R * moment_S.w_per_Nm[std::size_t(a)] * R.transpose();
  }
  return true;
}

void BeamChain::RodNodes(const std::array<RodSegment, kMaxLoads>& segments, int segment_count,
                         std::span<Eigen::Vector3d> nodes) const {
  const std::size_t count = nodes.size();
  std::array<double, kMaxCapsules + 1> s_S{};
  std::size_t k = 0;
  for (int g = 0; g < segment_count && k < count; ++g) {
    const RodSegment& seg = segments[std::size_t(g)];
    const bool last = g + 1 == segment_count;
    // This segment's nodes: up to its end, or all that are left for the last one (straight
    // beyond its last load).
    const std::size_t first = k;
    for (; k < count; ++k) {
      const double s = count > 1 ? length_m_ * double(k) / double(count - 1) : length_m_;
      if (!last && s > seg.end_m) break;
      s_S[k - first] = std::max(s - seg.clamp_m, 0.0);
    }
    const std::size_t n = k - first;
    if (n == 0) continue;
    rod_.Shape(
        std::span<const model::RodLoad>(seg.loads_S.data(), std::size_t(seg.load_count)),
        seg.solution,
        model::RodSamples{std::span<const double>(s_S.data(), n), nodes.subspan(first, n), {}});
    for (std::size_t q = first; q < k; ++q) nodes[q] = seg.origin_H + seg.R_HS * nodes[q];
  }
  for (; k < count; ++k)  // no segment: the straight tube
    nodes[k] = Eigen::Vector3d(0.0, 0.0,
                               count > 1 ? length_m_ * double(k) / double(count - 1) : length_m_);
}

Eigen::Vector3d BeamChain::RodTipTangent(const std::array<RodSegment, kMaxLoads>& segments,
                                         int segment_count) const {
  if (segment_count == 0) return Eigen::Vector3d::UnitZ();
  const RodSegment& seg = segments[std::size_t(segment_count - 1)];
  return (seg.R_HS * seg.solution.end_R).col(2);
}

}  // namespace tubeplan::core
