#include "core/contacts.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/rod.hpp"

namespace tubeplan::core {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

// Closest points of segments [p0, p1] and [q0, q1]: parameters (s, u) in [0, 1] (Ericson,
// Real-Time Collision Detection, 5.1.9).
void ClosestSegmentPoints(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1, double& s,
                          double& u) {
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  const double c = d1.dot(r), b = d1.dot(d2);
  const double denom = a * e - b * b;
  // Parallel segments: any s; 0.5 keeps the point inside (and such a point is rejected below
  // unless it is the only one).
  s = denom > 1e-12 * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.5;
  u = (b * s + f) / e;
  if (u < 0.0) {
    u = 0.0;
    s = std::clamp(-c / a, 0.0, 1.0);
  } else if (u > 1.0) {
    u = 1.0;
    s = std::clamp((b - c) / a, 0.0, 1.0);
  }
}

// Where a node's sphere stops standing for the side: |n.t| from kCapStart, over kCapFade.
constexpr double kCapStart = 0.3, kCapFade = 0.2;
// A section's nearest direction is kept while it is within this fraction of epsilon of the
// nearest point's distance.
constexpr double kKeepDirection = 0.01;
// The fraction of a curve piece at either end over which its node's sphere takes back the share
// it yields to the piece (YieldNode).
constexpr double kPieceEnd = 0.1;

// Smooth step from 0 at a = 0 to 1 at a = 1.
double SmoothStep(double a) {
  a = std::clamp(a, 0.0, 1.0);
  return a * a * (3.0 - 2.0 * a);
}

// The smooth step's first and second derivatives (0 outside (0, 1)).
double SmoothStepSlope(double a) { return a > 0.0 && a < 1.0 ? 6.0 * a * (1.0 - a) : 0.0; }
double SmoothStepBend(double a) { return a > 0.0 && a < 1.0 ? 6.0 - 12.0 * a : 0.0; }

// A lower bound on the distance from segment [p0, p1] to the edge: the edge lies in its faces'
// planes, so no point is nearer the edge than it is to either plane, and a segment wholly on one
// side of a plane is no nearer than its nearer end. 0 for a round side's axis (it has no faces).
// Less a picometre, far above the rounding of these sums and of the closest points' distance at
// a part's size: the bound stays below the distance the exact test computes.
double FacePlaneBound(const PartEdge& edge, const Vec3& p0, const Vec3& p1) {
  constexpr double kRounding_m = 1e-12;
  double bound = 0.0;
  for (const Vec3& n : edge.face_normals_W) {
    const double d0 = (p0 - edge.a_W).dot(n), d1 = (p1 - edge.a_W).dot(n);
    if (d0 * d1 > 0.0) bound = std::max(bound, std::min(std::abs(d0), std::abs(d1)));
  }
  return bound - kRounding_m;
}

// How far point c lies in front of both the edge's face planes (where the edge is the part's
// nearest feature): 1 there, fading to 0 over ramp_m behind either plane; and its gradient.
double InFrontOfFaces(const PartEdge& edge, const Vec3& c, double ramp_m, Vec3& gradient) {
  double front = 1.0;
  gradient.setZero();
  for (int k = 0; k < 2; ++k) {
    const Vec3& n = edge.face_normals_W[std::size_t(k)];
    const Vec3& n_other = edge.face_normals_W[std::size_t(1 - k)];
    const double x = 1.0 + (c - edge.a_W).dot(n) / ramp_m;
    const double x_other = 1.0 + (c - edge.a_W).dot(n_other) / ramp_m;
    front *= SmoothStep(x);
    if (x > 0.0 && x < 1.0) gradient += SmoothStep(x_other) * 6.0 * x * (1.0 - x) / ramp_m * n;
  }
  return front;
}

// How square the tube's direction v (any length) crosses the edge's unit direction: 0 up to 5
// degrees, s((sin^2 phi - sin^2 5 deg) / (sin^2 20 deg - sin^2 5 deg)) between, 1 from 20
// degrees on; and its gradient in v. Below 20 degrees, the node spheres bear the edge as a line
// along the tube. Below 5 the share is none: there the point of the side nearest the edge runs
// along the tube faster than the nodes move, and its share's curvature, left out of the
// Hessian, stalled Newton (docs/core.md, "Contact points").
double Across(const Vec3& v, const Vec3& unit, Vec3& gradient) {
  constexpr double kSin2Fade = 0.116977778440511;    // sin^2 20 deg
  constexpr double kSin2None = 0.00759612349389597;  // sin^2 5 deg
  const Vec3 cross = v.cross(unit);
  const double v2 = v.squaredNorm();
  const double sin2 = cross.squaredNorm() / v2;
  const double x = std::clamp((sin2 - kSin2None) / (kSin2Fade - kSin2None), 0.0, 1.0);
  const Vec3 d_sin2_dv = 2.0 * unit.cross(cross) / v2 - 2.0 * cross.squaredNorm() * v / (v2 * v2);
  gradient = 6.0 * x * (1.0 - x) / (kSin2Fade - kSin2None) * d_sin2_dv;
  return SmoothStep(x);
}

// The parameter in [0, 1] of a curve piece's point (nodes x0, x1, x2; CurveWeights) nearest the
// line through `from` along unit `dir` (zero: the point `from`), by Newton's method from `theta`
// on the squared distance. Also its first and second derivatives there (halved): a minimum inside
// the piece has slope 0 and curvature > 0; at an end, a slope that is not 0 says it was clamped.
double NearestOnPiece(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& from,
                      const Vec3& dir, double theta, double& slope, double& curvature) {
  const Mat3 Q = Mat3::Identity() - dir * dir.transpose();
  const Vec3 second = Q * (x0 - 2.0 * x1 + x2);
  curvature = 0.0;
  for (int k = 0; k < 16; ++k) {
    const std::array<double, 3> w = CurveWeights(theta), dw = CurveSlopes(theta);
    const Vec3 r = Q * (w[0] * x0 + w[1] * x1 + w[2] * x2 - from);
    const Vec3 t = Q * (dw[0] * x0 + dw[1] * x1 + dw[2] * x2);
    slope = r.dot(t);
    curvature = t.squaredNorm() + r.dot(second);
    if (std::abs(slope) <= 1e-12 * r.norm() * t.norm()) slope = 0.0;
    // Where the distance curves the wrong way, a step towards the nearer end.
    const double step =
        curvature > 1e-12 * t.squaredNorm() ? -slope / curvature : (slope > 0.0 ? -0.25 : 0.25);
    const double next = std::clamp(theta + step, 0.0, 1.0);
    const bool done = std::abs(next - theta) < 1e-12;
    theta = next;
    if (done) break;
  }
  return theta;
}

// Whether the piece's point nearest the target (NearestOnPiece from `guess`) is a minimum that
// belongs to the piece: inside it, or at its start where the piece before ends (so that a point
// where two pieces meet is borne once); its parameter and the distance's curvature there.
bool InsidePiece(const Vec3& x0, const Vec3& x1, const Vec3& x2, const Vec3& from, const Vec3& dir,
                 double guess, double& theta, double& curvature) {
  double slope = 0.0;
  theta = NearestOnPiece(x0, x1, x2, from, dir, guess, slope, curvature);
  return theta >= 0.0 && theta < 1.0 && !(theta == 0.0 && slope != 0.0) && curvature > 0.0;
}

class Finder {
 public:
  Finder(const Model& model, std::span<const Vec3> x_W, Data& data, Choices choices)
      : m_(model), x_(x_W), d_(data), n_(model.rod.elements), keep_(choices == Choices::kKeep) {}

  void Run() {
    Scratch& s = d_.scratch;
    s.sample_count = 0;
    s.samples_truncated = false;
    std::fill(s.clearance_m.begin(), s.clearance_m.end(), s.far_clearance_m);
    for (int p = 0; p < int(m_.parts.size()); ++p) {
      if (!s.parts_near[std::size_t(p)]) continue;
      const PartModel& part = m_.parts[std::size_t(p)];
      // The held end's section, the spheres at the inner nodes, the end elements' outer halves
      // and the smooth side between them against edges, the free end's rim and end face; each
      // notes its node's clearance for the solve's step.
      HeldNode(p, part);
      for (int i = 1; i < n_; ++i) Node(p, part, i);
      Side(p, part, 0);
      if (n_ > 1) Side(p, part, n_ - 1);
      for (int i = 1; i < n_; ++i) Curve(p, part, i);
      Rim(p, part);
      EndFace(p, part);
    }
  }

 private:
  // The part's edges whose boxes meet the box lo..hi of a piece of the tube, in order: the only
  // ones Side and Curve can find near it. (The tree's leaves hold several edges: each edge's own
  // box is tested too.)
  void FindEdgesNear(const PartModel& part, const Vec3& lo, const Vec3& hi) {
    edge_count_ = 0;
    const auto& edges = part.geometry.edges();
    part.geometry.EdgesOverlapping(lo, hi, [&](int e) {
      const PartEdge& edge = edges[std::size_t(e)];
      if ((edge.min_W.array() <= hi.array()).all() && (edge.max_W.array() >= lo.array()).all())
        d_.scratch.edges_near[std::size_t(edge_count_++)] = e;
    });
    std::sort(d_.scratch.edges_near.begin(), d_.scratch.edges_near.begin() + edge_count_);
  }

  std::span<const int> EdgesNear() const {
    return {d_.scratch.edges_near.data(), std::size_t(edge_count_)};
  }

  // Of each curved face's ridges near the segment p0..p1 (a piece of the tube's axis), the one
  // nearest it: the only one of that face to bear on the piece (PartEdge::ridge).
  void FindNearestRidges(const PartModel& part, const Vec3& p0, const Vec3& p1) {
    ridge_count_ = 0;
    const auto& edges = part.geometry.edges();
    for (const int e : EdgesNear()) {
      const PartEdge& edge = edges[std::size_t(e)];
      if (!edge.ridge) continue;
      double theta = 0.0, u = 0.0;
      ClosestSegmentPoints(p0, p1, edge.a_W, edge.b_W, theta, u);
      // An end the ridge does not bear is the bearer's nearest point too: the bearer stands.
      if ((u == 0.0 && !edge.a_bears) || (u == 1.0 && !edge.b_bears)) continue;
      const double gap_m = (p0 + theta * (p1 - p0) - edge.a_W - u * (edge.b_W - edge.a_W)).norm();
      int k = 0;
      while (k < ridge_count_ && nearest_ridges_[std::size_t(k)].element != edge.element) ++k;
      if (k == ridge_count_) {
        // More curved faces near one piece than the table holds: their ridges all bear.
        if (k == int(nearest_ridges_.size())) continue;
        nearest_ridges_[std::size_t(ridge_count_++)] = {edge.element, e, gap_m};
      } else if (gap_m < nearest_ridges_[std::size_t(k)].gap_m) {
        nearest_ridges_[std::size_t(k)] = {edge.element, e, gap_m};
      }
    }
  }

  // Whether edge e may bear on the piece FindNearestRidges looked at.
  bool Bears(const PartEdge& edge, int e) const {
    if (!edge.ridge) return true;
    for (int k = 0; k < ridge_count_; ++k)
      if (nearest_ridges_[std::size_t(k)].element == edge.element)
        return nearest_ridges_[std::size_t(k)].edge == e;
    return true;
  }

  // Notes node i's clearance: its centre's distance to a part, less the radius.
  void Clear(int i, double centre_m) {
    double& c = d_.scratch.clearance_m[std::size_t(i)];
    c = std::min(c, centre_m - m_.rod.outer_radius_m);
  }

  ElementIndex Entry(int part, int node) const {
    return d_.state.entry_element[std::size_t(part * (n_ + 1) + node)];
  }

  Sample* Add() {
    Scratch& s = d_.scratch;
    if (s.sample_count == kMaxSamples) {
      s.samples_truncated = true;
      return nullptr;
    }
    return &s.samples[std::size_t(s.sample_count++)];
  }

  Sample* Record(SampleKind kind, int part, int node, int feature, double theta, double weight,
                 const PartDistance& dist, const MaterialPoint& mp, const Vec3& moving_offset_W) {
    Sample* smp = Add();
    if (smp == nullptr) return nullptr;
    // Every field from this tick's values: nothing of the slot's last use may reach the solve.
    *smp = Sample{};
    smp->kind = kind;
    smp->part = part;
    smp->node = node;
    smp->feature = feature;
    smp->theta = theta;
    smp->weight = weight;
    smp->distance_m = dist.distance_m;
    smp->normal_W = dist.normal_W;
    smp->curvature_per_m = dist.curvature_per_m;
    smp->element = dist.element;
    smp->point_W = mp.point_W;
    smp->offset_W = mp.offset_W;
    smp->moving_offset_W = moving_offset_W;
    return smp;
  }

  // The point of a section circle (centre c, unit axis t, radius r) nearest the part: where the
  // part's distance gradient, seen in the section's plane, points back at the centre. Starts
  // from `guess` (any direction in the plane); a section parallel to a face keeps the guess.
  Vec3 NearestOnCircle(const PartModel& part, const Vec3& c, const Vec3& t, double r,
                       const Vec3& guess, ElementIndex entry) const {
    Vec3 rho = guess - guess.dot(t) * t;
    if (rho.norm() < 1e-12) rho = t.unitOrthogonal();
    rho.normalize();
    PartDistance at = part.geometry.Distance(c, entry);
    for (int k = 0; k < 16; ++k) {
      Vec3 g = -(at.normal_W - at.normal_W.dot(t) * t);
      const double lg = g.norm();
      if (lg < 1e-9) break;  // the section faces the part squarely: every point is as near
      g /= lg;
      const bool settled = (g - rho).norm() < 1e-12;
      rho = g;
      if (settled) break;
      at = part.geometry.Distance(c + r * rho, entry);
    }
    return rho;
  }

  // The direction of a section's point nearest the part, and the direction a quarter turn on
  // (tangent x direction): on a part with friction fixed on the section for the tick from where
  // it first meets the part (Material turns them with it), on a frictionless part found at every
  // iterate (docs/core.md, "The end rim").
  void SectionFrame(const PartModel& part, int p, int node, const Vec3& c, const Vec3& t,
                    ElementIndex entry, Vec3& rho, Vec3& side) {
    Scratch& s = d_.scratch;
    const double r1 = m_.rod.outer_radius_m;
    const std::size_t k = std::size_t(p * (n_ + 1) + node);
    Vec3& kept = d_.state.section_direction_W[k];
    const bool held = !part.friction.IsFrictionless();
    if (held && s.section_chosen[k]) {
      rho = kept;
      side = s.section_side_W[k];
      return;
    }
    rho = NearestOnCircle(part, c, t, r1, kept, entry);
    // A section nearly square to a part with friction keeps last tick's direction: its points
    // are then as near within a hundredth of epsilon, and a direction chosen afresh would swing
    // with every small tilt (carrying the friction anchors of the rim's points with it).
    Vec3 last = kept - kept.dot(t) * t;
    if (held && last.norm() > 1e-12) {
      last.normalize();
      const double gain_m = part.geometry.Distance(c + r1 * last, entry).distance_m -
                            part.geometry.Distance(c + r1 * rho, entry).distance_m;
      if (gain_m < kKeepDirection * m_.contact.threshold_m) rho = last;
    }
    side = t.cross(rho);
    if (keep_) {
      kept = rho;
      s.section_side_W[k] = side;
      s.section_chosen[k] = 1;
    } else if (s.section_pending_count < int(s.section_pending.size())) {
      s.section_pending[std::size_t(s.section_pending_count++)] = {k, rho, side};
    }
  }

  // The side surface at inner node i: the sphere of radius r1 about the node, the capsule
  // chain's surface there. It stands for the side where the part lies across the tube (the
  // distance's gradient n about square to the tangent t); where n turns towards the tangent, the
  // sphere's cap is within the neighbouring elements or past the tube's end, and its share of K
  // fades out between |n.t| = 0.3 and 0.5 (past a bend of 35 deg at one node). A side along a
  // face or an edge bears on every node near it.
  void Node(int p, const PartModel& part, int i) {
    const double r1 = m_.rod.outer_radius_m, eps = m_.contact.threshold_m;
    const Vec3& c = x_[std::size_t(i)];
    // Beyond reach of the part's bounding box, the gap to the box is the node's clearance.
    const double gap_m =
        (part.geometry.min_W() - c).cwiseMax(c - part.geometry.max_W()).cwiseMax(0.0).norm();
    if (gap_m - r1 >= eps) {
      Clear(i, gap_m);
      return;
    }
    PartDistance at = part.geometry.Distance(c, Entry(p, i));
    Clear(i, at.distance_m);
    if (at.distance_m - r1 >= eps) return;
    MaterialPoint mp = Material(Carrier::kInnerNode, x_, i, 0.0, Vec3::Zero(), false);
    mp.tangent_W = d_.scratch.tangents.Tangent(x_, i);
    const double along = at.normal_W.dot(mp.tangent_W);
    const double x = (std::abs(along) - kCapStart) / kCapFade;
    const double weight = 1.0 - SmoothStep(x);
    if (weight <= 0.0) return;
    at.distance_m -= r1;
    const Eigen::Matrix3d curvature_per_m = at.curvature_per_m;
    // The sphere is the capsule chain's surface at the node: sliding along the tube moves the
    // contact onto the next element's side at the same distance, so the distance is taken not
    // to curve along the tube (a point rolling off an edge would see it curve there).
    const Eigen::Matrix3d across =
        Eigen::Matrix3d::Identity() - mp.tangent_W * mp.tangent_W.transpose();
    at.curvature_per_m = across * curvature_per_m * across;
    mp.offset_W = -r1 * at.normal_W;
    mp.point_W += mp.offset_W;
    Sample* smp = Record(SampleKind::kNode, p, i, 0, 0.0, weight, at, mp, Vec3::Zero());
    if (smp != nullptr && x > 0.0 && x < 1.0) {
      // d |n.t| = sign (t^T C dx_i + n^T dt), C the distance's curvature at the node.
      const double slope = -6.0 * x * (1.0 - x) / kCapFade * (along < 0.0 ? -1.0 : 1.0);
      smp->weight_gradient =
          slope * (d_.scratch.tangents.Jacobian(x_, i).transpose() * at.normal_W);
      smp->weight_gradient.segment<3>(3) += slope * (curvature_per_m * mp.tangent_W);
      smp->weight_first = i - 1;
      smp->weight_nodes = 3;
    }
  }

  // The held end's section: the sphere of radius r1 about node 0, at full share, so that the
  // coupling cannot pull the grip through a part. A point of the first element (theta 0): the
  // held end has no element before it.
  void HeldNode(int p, const PartModel& part) {
    const double r1 = m_.rod.outer_radius_m, eps = m_.contact.threshold_m;
    PartDistance at = part.geometry.Distance(x_[0], Entry(p, 0));
    Clear(0, at.distance_m);
    if (at.distance_m - r1 >= eps) return;
    MaterialPoint mp = Material(Carrier::kElement, x_, 0, 0.0, Vec3::Zero(), false);
    at.distance_m -= r1;
    mp.offset_W = -r1 * at.normal_W;
    mp.point_W += mp.offset_W;
    Record(SampleKind::kSide, p, 0, kHeldFeature, 0.0, 1.0, at, mp, Vec3::Zero());
  }

  void Rim(int p, const PartModel& part) {
    const double r1 = m_.rod.outer_radius_m, eps = m_.contact.threshold_m;
    const Vec3& c = x_[std::size_t(n_)];
    const ElementIndex entry = Entry(p, n_);
    const double centre_m = part.geometry.Distance(c, entry).distance_m;
    Clear(n_, centre_m);
    if (centre_m - r1 >= eps) return;
    const Vec3 t = CarrierTangent(Carrier::kEndNode, x_, n_);
    Vec3 rho, side;
    SectionFrame(part, p, n_, c, t, entry, rho, side);
    // The nearest point and the others equally spaced around the rim: together they press as
    // one contact (Assemble), so that a flat end bears on its whole rim.
    for (int j = 0; j < kRimSamples; ++j) {
      const double phi = 2.0 * M_PI * j / kRimSamples;
      const Vec3 offset = r1 * (std::cos(phi) * rho + std::sin(phi) * side);
      const MaterialPoint mp = Material(Carrier::kEndNode, x_, n_, 0.0, offset, false);
      const PartDistance at = part.geometry.Distance(mp.point_W, entry);
      if (at.distance_m >= eps) continue;
      Record(SampleKind::kRim, p, n_, j, 0.0, 1.0, at, mp, offset);
    }
  }

  // The band at the end face's edges over which a vertex's share of K fades: the rim's points
  // take over outside, nothing inside the bore.
  double FaceBand() const { return 0.1 * m_.rod.outer_radius_m; }

  // The length over which an edge's share fades towards the tube's ends and behind the edge's
  // face planes.
  double Ramp() const { return std::min(0.25 * m_.rod.outer_radius_m, 0.5 * m_.rod.segment_m); }

  // Records a side's contact (kSide, kCurve) with an edge (on_line) or the vertex it ends in (u 0
  // or 1), q on it: the axis point at theta is at w (length lw) from q. The distance is the
  // axis's from the edge less r1 (and less a round side's radius): it does not change as the tube
  // slides along its axis or along the edge, so it curves only across both (past a vertex, about
  // the tube's `tangent`), not as a point's distance from the edge would; its change as the tube
  // turns is left out. It moves with the axis point alone (the nearest point's own motion changes
  // it only to second order); the surface point is r1 from it.
  Sample* RecordEdge(SampleKind kind, int p, int i, int e, double theta, double weight,
                     const PartEdge& edge, bool on_line, const Vec3& q, double u, const Vec3& w,
                     double lw, const Vec3& tangent) {
    const double r1 = m_.rod.outer_radius_m;
    PartDistance at;
    at.distance_m = lw - r1 - edge.radius_m;
    at.normal_W = w / lw;
    at.point_W = q + edge.radius_m * at.normal_W;
    at.element = on_line ? edge.element : u == 0.0 ? edge.a_element : edge.b_element;
    if (on_line) {
      at.curvature_per_m.setZero();
    } else {
      const Vec3 m = tangent.normalized().cross(at.normal_W);
      at.curvature_per_m = m * m.transpose() / lw;
    }
    MaterialPoint mp = Material(CarrierOf(kind), x_, i, theta, Vec3::Zero(), false);
    mp.offset_W = -r1 * at.normal_W;
    mp.point_W += mp.offset_W;
    return Record(kind, p, i, e, theta, weight, at, mp, Vec3::Zero());
  }

  // The side surface of an end element's outer half (between the tube's end node and the middle
  // of the element, where the smooth centreline's pieces take over: Curve), a cylinder, against
  // the part's edges: where the element's axis comes nearest an edge (or a vertex it ends in)
  // there, in front of the edge's face planes. Its share of K fades out towards the end node,
  // whose sphere or rim bears there, and as the element turns parallel to the edge (the spheres
  // then are as near): the share's derivatives go into the gradient with it.
  void Side(int p, const PartModel& part, int i) {
    const double r1 = m_.rod.outer_radius_m, eps = m_.contact.threshold_m;
    const Vec3& a = x_[std::size_t(i)];
    const Vec3& b = x_[std::size_t(i + 1)];
    const Vec3 lo = a.cwiseMin(b).array() - (r1 + eps), hi = a.cwiseMax(b).array() + (r1 + eps);
    const Vec3 v = b - a;
    const double ramp_m = Ramp();
    const double lv = v.norm();
    // The half at the held end (i = 0), the free end (i = N - 1), or both for a single element.
    const double theta_lo = i == n_ - 1 && n_ > 1 ? 0.5 : 0.0;
    const double theta_hi = i == 0 && n_ > 1 ? 0.5 : 1.0;
    const auto& edges = part.geometry.edges();
    FindEdgesNear(part, lo, hi);
    FindNearestRidges(part, a + theta_lo * v, a + theta_hi * v);
    for (const int e : EdgesNear()) {
      const PartEdge& edge = edges[std::size_t(e)];
      if (!Bears(edge, e) || FacePlaneBound(edge, a, b) - r1 - edge.radius_m >= eps) continue;
      double theta = 0.0, u = 0.0;
      ClosestSegmentPoints(a, b, edge.a_W, edge.b_W, theta, u);
      if ((u == 0.0 && !edge.a_bears) || (u == 1.0 && !edge.b_bears)) continue;
      // The free end's half starts where the last curve piece ends, and bears a point there.
      if (!(theta > theta_lo || (theta == theta_lo && theta_lo > 0.0)) || !(theta < theta_hi))
        continue;
      const Vec3 c = a + theta * v;
      const Vec3 ab = edge.b_W - edge.a_W;
      const Vec3 q = edge.a_W + u * ab;
      const Vec3 w = c - q;
      const double lw = w.norm();
      if (!(lw - r1 - edge.radius_m < eps) || lw == 0.0) continue;
      // The edge bears where the axis point lies in front of both its faces' planes; its share
      // fades out over the ramp behind either plane, beside the face whose nodes' spheres bear.
      Vec3 d_above_dc;
      const double above = InFrontOfFaces(edge, c, ramp_m, d_above_dc);
      // The share: s(theta) towards the end node, times Across (1 against a vertex, a point).
      const bool on_line = u > 0.0 && u < 1.0;
      const double near_node = std::min(theta, 1.0 - theta) * lv / ramp_m;
      const double along = SmoothStep(near_node);
      Vec3 d_across_dv = Vec3::Zero();
      const double across = on_line ? Across(v, ab.normalized(), d_across_dv) : 1.0;
      const double weight = along * across * above;
      if (weight <= 0.0) continue;
      // d theta / d (a, b): theta = -(v^T P w0) / (v^T P v), w0 = a - q, P the projector across
      // the edge's line (the identity for a vertex).
      Eigen::Matrix3d P = Eigen::Matrix3d::Identity();
      if (on_line) P -= ab * ab.transpose() / ab.squaredNorm();
      const Vec3 w0 = a - q, Pv = P * v, Pw0 = P * w0;
      const double num = -v.dot(Pw0), den = v.dot(Pv);
      const Vec3 d_theta_a = ((Pw0 - Pv) * den + 2.0 * num * Pv) / (den * den);
      const Vec3 d_theta_b = (-Pw0 * den - 2.0 * num * Pv) / (den * den);
      // d near_node / d (a, b): it changes with theta and with the element's length; and
      // d along / d near_node.
      const double side_sign = theta < 0.5 ? 1.0 : -1.0;
      const double nearer = std::min(theta, 1.0 - theta);
      const Vec3 d_near_a = (side_sign * lv * d_theta_a - nearer * v / lv) / ramp_m;
      const Vec3 d_near_b = (side_sign * lv * d_theta_b + nearer * v / lv) / ramp_m;
      const double d_along = near_node < 1.0 ? 6.0 * near_node * (1.0 - near_node) : 0.0;
      Sample* smp =
          RecordEdge(SampleKind::kSide, p, i, e, theta, weight, edge, on_line, q, u, w, lw, v);
      if (smp != nullptr) {
        // d above / d (a, b) through c = a + theta (b - a).
        const double v_dot = v.dot(d_above_dc);
        const Vec3 d_above_a = (1.0 - theta) * d_above_dc + v_dot * d_theta_a;
        const Vec3 d_above_b = theta * d_above_dc + v_dot * d_theta_b;
        smp->weight_gradient.segment<3>(0) =
            above * (across * d_along * d_near_a - along * d_across_dv) +
            along * across * d_above_a;
        smp->weight_gradient.segment<3>(3) =
            above * (across * d_along * d_near_b + along * d_across_dv) +
            along * across * d_above_b;
        smp->weight_first = i;
        smp->weight_nodes = 2;
        if (near_node < 1.0) {
          smp->weight_curve = above * across * std::max(0.0, 6.0 - 12.0 * near_node);
          smp->weight_curve_gradient.segment<3>(0) = d_near_a;
          smp->weight_curve_gradient.segment<3>(3) = d_near_b;
        }
      }
    }
  }

  // The side surface about inner node i against the part's edges: the tube around its smooth
  // centreline's piece there (CurveWeights), at the piece's point nearest an edge (or a vertex it
  // ends in) where that lies inside the piece, in front of the edge's face planes. Neighbouring
  // pieces meet with the same point and tangent, so a load passing a node moves on without a
  // jump in its size or direction. Its share fades as the tube turns parallel to the edge
  // (Across), where the node spheres bear, and behind the face planes; its derivatives go into
  // the gradient with it.
  void Curve(int p, const PartModel& part, int i) {
    const double r1 = m_.rod.outer_radius_m, eps = m_.contact.threshold_m;
    const Vec3& x0 = x_[std::size_t(i - 1)];
    const Vec3& x1 = x_[std::size_t(i)];
    const Vec3& x2 = x_[std::size_t(i + 1)];
    // The piece lies within the triangle of the elements' middles and the node.
    const Vec3 m0 = 0.5 * (x0 + x1), m1 = 0.5 * (x1 + x2);
    const Vec3 lo = m0.cwiseMin(m1).cwiseMin(x1).array() - (r1 + eps);
    const Vec3 hi = m0.cwiseMax(m1).cwiseMax(x1).array() + (r1 + eps);
    const double ramp_m = Ramp();
    // How far the piece strays from the chord between the middles: at most half the node's
    // distance from it (the piece's middle).
    const double bulge = 0.5 * (x1 - 0.5 * (m0 + m1)).norm();
    const auto& edges = part.geometry.edges();
    FindEdgesNear(part, lo, hi);
    FindNearestRidges(part, m0, m1);
    for (const int e : EdgesNear()) {
      const PartEdge& edge = edges[std::size_t(e)];
      // Most edges whose boxes meet the piece's lie beyond reach: the face planes' bound leaves
      // them out before the segments' closest points are sought.
      if (!Bears(edge, e) || FacePlaneBound(edge, m0, m1) - bulge >= r1 + edge.radius_m + eps)
        continue;
      double theta = 0.0, u = 0.0;
      ClosestSegmentPoints(m0, m1, edge.a_W, edge.b_W, theta, u);
      const Vec3 ab = edge.b_W - edge.a_W;
      if ((m0 + theta * (m1 - m0) - edge.a_W - u * ab).norm() - bulge >= r1 + edge.radius_m + eps)
        continue;
      const Vec3 unit = ab.normalized();
      // The piece's point nearest the edge: nearest its line where that projects inside the
      // edge (u in [0, 1]), else nearest the vertex on the side it projects to.
      Vec3 from = edge.a_W, dir = unit;
      double curvature = 0.0;
      const double guess = theta;
      bool found = InsidePiece(x0, x1, x2, from, dir, guess, theta, curvature);
      u = (CarrierCentre(Carrier::kCurve, x_, i, theta) - edge.a_W).dot(ab) / ab.squaredNorm();
      if (!found || u < 0.0 || u > 1.0) {
        dir = Vec3::Zero();
        found = false;
        for (const double end : {0.0, 1.0}) {
          if (!(end == 0.0 ? edge.a_bears : edge.b_bears)) continue;
          from = end == 0.0 ? edge.a_W : edge.b_W;
          u = end;
          if (InsidePiece(x0, x1, x2, from, dir, guess, theta, curvature) &&
              (CarrierCentre(Carrier::kCurve, x_, i, theta) - from).dot(ab) * (end - 0.5) >= 0.0) {
            found = true;
            break;
          }
        }
      }
      if (!found) continue;
      const std::array<double, 3> w = CurveWeights(theta), dw = CurveSlopes(theta);
      const Vec3 c = w[0] * x0 + w[1] * x1 + w[2] * x2;
      const Vec3 tangent = dw[0] * x0 + dw[1] * x1 + dw[2] * x2;
      const Mat3 Q = Mat3::Identity() - dir * dir.transpose();
      const Vec3 r = Q * (c - from);
      const double lr = r.norm();
      if (!(lr - r1 - edge.radius_m < eps) || lr == 0.0) continue;
      Vec3 d_above_dc, d_across_dv = Vec3::Zero();
      const double above = InFrontOfFaces(edge, c, ramp_m, d_above_dc);
      const bool on_line = dir.squaredNorm() > 0.0;
      const double across = on_line ? Across(tangent, unit, d_across_dv) : 1.0;
      const double weight = across * above;
      if (weight <= 0.0) continue;
      Sample* smp = RecordEdge(SampleKind::kCurve, p, i, e, theta, weight, edge, on_line,
                               from + u * (on_line ? ab : Vec3::Zero()), u, r, lr, tangent);
      if (smp == nullptr) continue;
      // The share's gradient: the nearest point moves along the piece as the nodes move,
      // d theta / d x_k = -(w_k Q c' + w'_k r) / curvature (its condition r . Q c' = 0), and
      // with it the point (above) and the tangent (across).
      const Vec3 Qt = Q * tangent, second = x0 - 2.0 * x1 + x2;
      std::array<Vec3, 3> d_thetas;
      for (int k = 0; k < 3; ++k) {
        const Vec3 d_theta = -(w[std::size_t(k)] * Qt + dw[std::size_t(k)] * r) / curvature;
        d_thetas[std::size_t(k)] = d_theta;
        const Vec3 d_above = w[std::size_t(k)] * d_above_dc + tangent.dot(d_above_dc) * d_theta;
        const Vec3 d_across = dw[std::size_t(k)] * d_across_dv + second.dot(d_across_dv) * d_theta;
        smp->weight_gradient.segment<3>(3 * k) = above * d_across + across * d_above;
      }
      smp->weight_first = i - 1;
      smp->weight_nodes = 3;
      YieldNode(p, edge, i, *smp, theta, d_thetas);
    }
  }

  // Node i's sphere yields to the curve sample `curve` on its piece (at theta, d theta / d x_k
  // in d_thetas) the share that sample bears, where the node lies in the edge's region
  // (InFrontOfFaces): the edge's load is then borne at the smooth surface, not also at the node.
  // It yields y = rho w f(theta), f fading over the tenth of the piece at either end, where the
  // load passes to the next piece and the sphere is half an element from it; its share becomes
  // w_node (1 - y), with the gradient of that over nodes i - 1 .. i + 1.
  void YieldNode(int p, const PartEdge& edge, int i, const Sample& curve, double theta,
                 const std::array<Vec3, 3>& d_thetas) {
    Scratch& s = d_.scratch;
    Sample* node = nullptr;
    for (int k = s.sample_count - 1; k >= 0 && node == nullptr; --k) {
      Sample& q = s.samples[std::size_t(k)];
      if (q.kind == SampleKind::kNode && q.part == p && q.node == i) node = &q;
    }
    // A round side bears all round (no face planes to tell its region): the sphere yields only
    // when it presses on that side too, not on an end beside it.
    if (node == nullptr || (edge.radius_m > 0.0 && node->element != edge.element)) return;
    Vec3 d_rho;
    const double rho = InFrontOfFaces(edge, x_[std::size_t(i)], Ramp(), d_rho);
    const double end = std::min(theta, 1.0 - theta) / kPieceEnd;
    const double f = SmoothStep(end);
    const double y = rho * curve.weight * f;
    if (y <= 0.0) return;
    Eigen::Matrix<double, 9, 1> dy = rho * f * curve.weight_gradient;
    if (end < 1.0) {
      const double df = 6.0 * end * (1.0 - end) / kPieceEnd * (theta < 0.5 ? 1.0 : -1.0);
      for (int k = 0; k < 3; ++k)
        dy.segment<3>(3 * k) += rho * curve.weight * df * d_thetas[std::size_t(k)];
    }
    dy.segment<3>(3) += curve.weight * f * d_rho;
    if (node->weight_nodes == 0) node->weight_gradient.setZero();
    node->weight_gradient = (1.0 - y) * node->weight_gradient - node->weight * dy;
    node->weight *= 1.0 - y;
    node->weight_first = i - 1;
    node->weight_nodes = 3;
  }

  void EndFace(int p, const PartModel& part) {
    const double r1 = m_.rod.outer_radius_m, r2 = m_.rod.inner_radius_m;
    const double eps = m_.contact.threshold_m;
    const Vec3& c = x_[std::size_t(n_)];
    if (part.geometry.Distance(c).distance_m - r1 >= eps) return;
    const Vec3 t = CarrierTangent(Carrier::kEndNode, x_, n_);
    const auto& vertices = part.geometry.vertices_W();
    const double band_m = FaceBand();
    const double length_m = (c - x_[std::size_t(n_ - 1)]).norm();
    for (int v = 0; v < int(vertices.size()); ++v) {
      const Vec3 w = vertices[std::size_t(v)] - c;
      const double ahead_m = w.dot(t);
      const Vec3 radial = w - ahead_m * t;
      const double rr = radial.norm();
      if (ahead_m >= eps || ahead_m < -0.5 * r1) continue;
      const double outer = (r1 - rr) / band_m, inner = (rr - r2) / band_m;
      const double weight = SmoothStep(outer) * (r2 > 0.0 ? SmoothStep(inner) : 1.0);
      if (weight <= 0.0) continue;
      PartDistance at;
      at.distance_m = ahead_m;
      at.normal_W = -t;
      at.point_W = vertices[std::size_t(v)];
      at.element = part.geometry.vertex_elements()[std::size_t(v)];
      Sample* smp = Record(SampleKind::kEndFace, p, n_, v, 0.0, weight, at,
                           Material(Carrier::kEndNode, x_, n_, 0.0, radial, false), radial);
      if (smp != nullptr && rr > 0.0)
        FadeWithRadius(*smp, radial / rr, ahead_m / length_m, outer, inner);
    }
  }

  // An end-face sample's share w = S(outer) S(inner) fades with its vertex's distance rr from the
  // tube's axis (outer = (r1 - rr) / band, inner = (rr - r2) / band): its gradient over the end
  // element's nodes, rr changing by -(1 + a/h) rhat.dx_N + (a/h) rhat.dx_{N-1} (a the vertex's
  // distance ahead, h the element's length), and where w bends up across either band, the
  // leading part of its curvature, d2w/drr2 grad rr grad rr^T (docs/core.md, "The end face").
  void FadeWithRadius(Sample& smp, const Vec3& rhat, double ahead_per_length, double outer,
                      double inner) const {
    const double band_m = FaceBand();
    const bool bore = m_.rod.inner_radius_m > 0.0;
    const double s_outer = SmoothStep(outer), s_inner = bore ? SmoothStep(inner) : 1.0;
    const double slope_outer = SmoothStepSlope(outer),
                 slope_inner = bore ? SmoothStepSlope(inner) : 0.0;
    const double d_weight_d_rr = (s_outer * slope_inner - slope_outer * s_inner) / band_m;
    const double bend =
        std::max(0.0, s_inner * SmoothStepBend(outer) - 2.0 * slope_outer * slope_inner +
                          (bore ? s_outer * SmoothStepBend(inner) : 0.0));
    // A vertex well inside the annulus: its share is whole and does not move.
    if (d_weight_d_rr == 0.0 && bend == 0.0) return;
    Eigen::Matrix<double, 6, 1> d_rr;
    d_rr << ahead_per_length * rhat, -(1.0 + ahead_per_length) * rhat;
    smp.weight_gradient.head<6>() = d_weight_d_rr * d_rr;
    smp.weight_first = n_ - 1;
    smp.weight_nodes = 2;
    if (bend > 0.0) {
      smp.weight_curve = bend / (band_m * band_m);
      smp.weight_curve_gradient.head<6>() = d_rr;
    }
  }

  const Model& m_;
  std::span<const Vec3> x_;
  Data& d_;
  int n_;
  bool keep_;
  int edge_count_ = 0;  ///< the part's edges FindEdgesNear found, in Scratch::edges_near
  struct NearestRidge {
    ElementIndex element = kNoElement;
    int edge = 0;
    double gap_m = 0.0;
  };
  std::array<NearestRidge, 8> nearest_ridges_{};  ///< FindNearestRidges' answer, per face
  int ridge_count_ = 0;
};

}  // namespace

void FindPartsNear(const Model& model, std::span<const Vec3> x_W, double reach_m, Data& data) {
  Vec3 lo = x_W[0], hi = x_W[0];
  for (const Vec3& x : x_W) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  const double r1 = model.rod.outer_radius_m;
  const double grow = r1 + model.contact.threshold_m + reach_m;
  // The parts whose boxes come within `grow` of the nodes' box; of the others, the gap to the
  // nearest box bounds how far the tube's surface is from them.
  double far = std::numeric_limits<double>::infinity();
  for (std::size_t p = 0; p < model.parts.size(); ++p) {
    const PartGeometry& g = model.parts[p].geometry;
    const Vec3 gap = (g.min_W() - hi).cwiseMax(lo - g.max_W()).cwiseMax(0.0);
    const bool near = !(gap.array() > grow).any();
    data.scratch.parts_near[p] = near;
    if (!near) far = std::min(far, gap.maxCoeff() - r1);
  }
  data.scratch.far_clearance_m = far;
}

void FindContacts(const Model& model, std::span<const Vec3> x_W, Data& data, Choices choices) {
  data.scratch.section_pending_count = 0;
  // The parts within reach of the nodes and of the next iteration's move.
  FindPartsNear(model, x_W, model.solver.step_cap_m, data);
  Finder(model, x_W, data, choices).Run();
}

void CommitContactChoices(Data& data) {
  Scratch& s = data.scratch;
  for (int k = 0; k < s.section_pending_count; ++k) {
    const Scratch::SectionChoice& c = s.section_pending[std::size_t(k)];
    data.state.section_direction_W[c.index] = c.direction_W;
    s.section_side_W[c.index] = c.side_W;
    s.section_chosen[c.index] = 1;
  }
  s.section_pending_count = 0;
}

}  // namespace tubeplan::core
