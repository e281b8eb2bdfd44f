#include "core/contacts.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

#include "core/rod.hpp"

namespace tubeplan::core {
namespace {

using Vec3 = Eigen::Vector3d;

// Closest points of segments [p0, p1] and [q0, q1]: parameters (s, u) in [0, 1] (Ericson,
// Real-Time Collision Detection, 5.1.9).
void ClosestSegmentPoints(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1,
                          double& s, double& u) {
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

// Smooth step from 0 at a = 0 to 1 at a = 1.
double SmoothStep(double a) {
  a = std::clamp(a, 0.0, 1.0);
  return a * a * (3.0 - 2.0 * a);
}

class Finder {
 public:
  Finder(const Model& model, std::span<const Vec3> x_W, Data& data)
      : m_(model), x_(x_W), d_(data), n_(model.rod.elements) {}

  void Run() {
    Scratch& s = d_.scratch;
    s.sample_count = 0;
    s.samples_truncated = false;
    for (int p = 0; p < int(m_.parts.size()); ++p) {
      if (!s.parts_near[std::size_t(p)]) continue;
      const PartModel& part = m_.parts[std::size_t(p)];
      // The side's sections at the inner nodes, the free end's rim, the side between nodes
      // against the part's edges, the end face against its vertices.
      for (int i = 1; i < n_; ++i) Section(p, part, i);
      Rim(p, part);
      for (int i = 0; i < n_; ++i) Side(p, part, i);
      EndFace(p, part);
    }
  }

 private:
  std::uint8_t Entry(int part, int node) const {
    return d_.state.entry_mask[std::size_t(part * (n_ + 1) + node)];
  }

  Sample* Add() {
    Scratch& s = d_.scratch;
    if (s.sample_count == kMaxSamples) {
      s.samples_truncated = true;
      return nullptr;
    }
    return &s.samples[std::size_t(s.sample_count++)];
  }

  void Record(SampleKind kind, int part, int node, int feature, double theta, double weight,
              const PartDistance& dist, const MaterialPoint& mp) {
    Sample* smp = Add();
    if (smp == nullptr) return;
    smp->kind = kind;
    smp->part = part;
    smp->node = node;
    smp->feature = feature;
    smp->theta = theta;
    smp->weight = weight;
    smp->distance_m = dist.distance_m;
    smp->normal_W = dist.normal_W;
    smp->face_mask = dist.face_mask;
    smp->point_W = mp.point_W;
    smp->offset_W = mp.offset_W;
    smp->jacobian = mp.jacobian;
    smp->first = mp.first;
    smp->normal_force_N = 0.0;
  }

  // The point of a section circle (centre c, unit axis t, radius r) nearest the part: where the
  // part's distance gradient, seen in the section's plane, points back at the centre. Starts
  // from `guess` (any direction in the plane); a section parallel to a face keeps the guess.
  Vec3 NearestOnCircle(const PartModel& part, const Vec3& c, const Vec3& t, double r,
                       const Vec3& guess, std::uint8_t entry) const {
    Vec3 rho = guess - guess.dot(t) * t;
    if (rho.norm() < 1e-12) rho = t.unitOrthogonal();
    rho.normalize();
    PartDistance at = part.geometry.Distance(c, entry);
    for (int k = 0; k < 4; ++k) {
      Vec3 g = -(at.normal_W - at.normal_W.dot(t) * t);
      const double lg = g.norm();
      if (lg < 1e-9) break;  // the section faces the part squarely: every point is as near
      g /= lg;
      const bool settled = (g - rho).norm() < 1e-10;
      rho = g;
      if (settled) break;
      at = part.geometry.Distance(c + r * rho, entry);
    }
    return rho;
  }

  void Section(int p, const PartModel& part, int i) {
    const double r1 = m_.rod.outer_radius_m, eps = m_.contact.threshold_m;
    const Vec3& c = x_[std::size_t(i)];
    const std::uint8_t entry = Entry(p, i);
    if (part.geometry.Distance(c, entry).distance_m - r1 >= eps) return;
    const Vec3 t = CarrierTangent(Carrier::kInnerNode, x_, i);
    const Vec3 rho = NearestOnCircle(part, c, t, r1, -t.unitOrthogonal(), entry);
    const PartDistance at = part.geometry.Distance(c + r1 * rho, entry);
    if (at.distance_m >= eps) return;
    Record(SampleKind::kSection, p, i, 0, 0.0, 1.0, at,
           Material(Carrier::kInnerNode, x_, i, 0.0, r1 * rho));
  }

  void Rim(int p, const PartModel& part) {
    const double r1 = m_.rod.outer_radius_m, eps = m_.contact.threshold_m;
    const Vec3& c = x_[std::size_t(n_)];
    const std::uint8_t entry = Entry(p, n_);
    if (part.geometry.Distance(c, entry).distance_m - r1 >= eps) return;
    const Vec3 t = CarrierTangent(Carrier::kEndNode, x_, n_);
    Vec3& kept = d_.state.rim_direction_W[std::size_t(p)];
    const Vec3 rho = NearestOnCircle(part, c, t, r1, kept, entry);
    kept = rho;
    const Vec3 side = t.cross(rho);
    // The nearest point and the others equally spaced around the rim.
    for (int j = 0; j < kRimSamples; ++j) {
      const double phi = 2.0 * M_PI * j / kRimSamples;
      const Vec3 dir = std::cos(phi) * rho + std::sin(phi) * side;
      const PartDistance at = part.geometry.Distance(c + r1 * dir, entry);
      if (at.distance_m >= eps) continue;
      Record(SampleKind::kRim, p, n_, j, 0.0, 1.0, at,
             Material(Carrier::kEndNode, x_, n_, 0.0, r1 * dir));
    }
  }

  void Side(int p, const PartModel& part, int i) {
    const double r1 = m_.rod.outer_radius_m, eps = m_.contact.threshold_m;
    const double h = m_.rod.segment_m;
    const Vec3& a = x_[std::size_t(i)];
    const Vec3& b = x_[std::size_t(i + 1)];
    const Vec3 mid = 0.5 * (a + b);
    const std::uint8_t entry = Entry(p, i);
    if (part.geometry.Distance(mid, entry).distance_m - 0.5 * (b - a).norm() - r1 >= eps) return;
    // Between nodes, only an edge or a vertex of the part can come nearer than both sections.
    const double ramp_m = std::min(0.25 * r1, 0.5 * h);
    const auto& edges = part.geometry.edges();
    for (int e = 0; e < int(edges.size()); ++e) {
      const PartEdge& edge = edges[std::size_t(e)];
      double theta = 0.0, u = 0.0;
      ClosestSegmentPoints(a, b, edge.a_W, edge.b_W, theta, u);
      if (!(theta > 0.0 && theta < 1.0)) continue;
      const Vec3 c = a + theta * (b - a);
      const Vec3 q = edge.a_W + u * (edge.b_W - edge.a_W);
      if ((c - q).norm() - r1 >= eps) continue;
      // Only where this edge (or its end vertex) is the part's nearest feature to the axis.
      const PartDistance at_axis = part.geometry.Distance(c, entry);
      if ((at_axis.face_mask & edge.face_mask) != edge.face_mask ||
          std::popcount(unsigned(at_axis.face_mask)) < 2)
        continue;
      PartDistance at = at_axis;
      at.distance_m = at_axis.distance_m - r1;
      const double weight = SmoothStep(std::min(theta, 1.0 - theta) * (b - a).norm() / ramp_m);
      if (weight <= 0.0) continue;
      Record(SampleKind::kSide, p, i, e, theta, weight, at,
             Material(Carrier::kElement, x_, i, theta, -r1 * at_axis.normal_W));
    }
  }

  void EndFace(int p, const PartModel& part) {
    const double r1 = m_.rod.outer_radius_m, r2 = m_.rod.inner_radius_m;
    const double eps = m_.contact.threshold_m;
    const Vec3& c = x_[std::size_t(n_)];
    if (part.geometry.Distance(c).distance_m - r1 >= eps) return;
    const Vec3 t = CarrierTangent(Carrier::kEndNode, x_, n_);
    const auto& vertices = part.geometry.vertices_W();
    for (int v = 0; v < int(vertices.size()); ++v) {
      const Vec3 w = vertices[std::size_t(v)] - c;
      const double ahead_m = w.dot(t);
      const Vec3 radial = w - ahead_m * t;
      const double rr = radial.norm();
      // In front of the annulus (not the bore, not the rim, which the rim's points carry), and
      // not far behind it.
      if (ahead_m >= eps || ahead_m < -0.5 * r1 || rr < r2 || rr > 0.95 * r1) continue;
      PartDistance at;
      at.distance_m = ahead_m;
      at.normal_W = -t;
      at.point_W = vertices[std::size_t(v)];
      at.face_mask = part.geometry.vertex_masks()[std::size_t(v)];
      // The vertex must be the part's nearest feature to that point of the face.
      if (ahead_m > 0.0 &&
          part.geometry.Distance(c + radial).face_mask != at.face_mask)
        continue;
      Record(SampleKind::kEndFace, p, n_, v, 0.0, 1.0, at,
             Material(Carrier::kEndNode, x_, n_, 0.0, radial));
    }
  }

  const Model& m_;
  std::span<const Vec3> x_;
  Data& d_;
  int n_;
};

}  // namespace

void FindPartsNear(const Model& model, std::span<const Vec3> x_W, double reach_m, Data& data) {
  Vec3 lo = x_W[0], hi = x_W[0];
  for (const Vec3& x : x_W) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  const double grow = model.rod.outer_radius_m + model.contact.threshold_m + reach_m;
  lo.array() -= grow;
  hi.array() += grow;
  for (std::size_t p = 0; p < model.parts.size(); ++p) {
    const BoxGeometry& g = model.parts[p].geometry;
    data.scratch.parts_near[p] =
        !((g.min_W().array() > hi.array()).any() || (g.max_W().array() < lo.array()).any());
  }
}

void FindContacts(const Model& model, std::span<const Vec3> x_W, Data& data) {
  Finder(model, x_W, data).Run();
}

}  // namespace tubeplan::core
