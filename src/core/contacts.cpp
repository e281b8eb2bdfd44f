#include "core/contacts.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

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
      // How far each node's surface is from the part, for the solve's step.
      for (int i = 0; i <= n_; ++i)
        s.clearance_m[std::size_t(i)] =
            std::min(s.clearance_m[std::size_t(i)],
                     part.geometry.Distance(x_[std::size_t(i)], Entry(p, i)).distance_m -
                         m_.rod.outer_radius_m);
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
              const PartDistance& dist, const MaterialPoint& mp, const Vec3& moving_offset_W) {
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
    smp->curvature_per_m = dist.curvature_per_m;
    smp->face_mask = dist.face_mask;
    smp->point_W = mp.point_W;
    smp->offset_W = mp.offset_W;
    smp->moving_offset_W = moving_offset_W;
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
    for (int k = 0; k < 8; ++k) {
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

  // The direction of a section's point nearest the part, and the direction a quarter turn on
  // (tangent x direction): found when the section first meets the part in a tick and fixed on
  // the section for the rest of the tick (Material turns them with it).
  void SectionFrame(const PartModel& part, int p, int node, const Vec3& c, const Vec3& t,
                    std::uint8_t entry, Vec3& rho, Vec3& side) {
    Scratch& s = d_.scratch;
    const double r1 = m_.rod.outer_radius_m;
    const std::size_t k = std::size_t(p * (n_ + 1) + node);
    Vec3& kept = d_.state.section_direction_W[k];
    if (s.section_chosen[k]) {
      rho = kept;
      side = s.section_side_W[k];
      return;
    }
    rho = NearestOnCircle(part, c, t, r1, kept, entry);
    side = t.cross(rho);
    if (keep_) {
      kept = rho;
      s.section_side_W[k] = side;
      s.section_chosen[k] = 1;
    } else if (s.section_pending_count < int(s.section_pending.size())) {
      s.section_pending[std::size_t(s.section_pending_count++)] = {k, rho, side};
    }
  }

  void Section(int p, const PartModel& part, int i) {
    const double r1 = m_.rod.outer_radius_m, eps = m_.contact.threshold_m;
    const Vec3& c = x_[std::size_t(i)];
    const std::uint8_t entry = Entry(p, i);
    if (part.geometry.Distance(c, entry).distance_m - r1 >= eps) return;
    const Vec3 t = CarrierTangent(Carrier::kInnerNode, x_, i);
    Vec3 rho, side;
    SectionFrame(part, p, i, c, t, entry, rho, side);
    const MaterialPoint mp = Material(Carrier::kInnerNode, x_, i, 0.0, r1 * rho, false);
    const PartDistance at = part.geometry.Distance(mp.point_W, entry);
    if (at.distance_m >= eps) return;
    Record(SampleKind::kSection, p, i, 0, 0.0, 1.0, at, mp, r1 * rho);
  }

  void Rim(int p, const PartModel& part) {
    const double r1 = m_.rod.outer_radius_m, eps = m_.contact.threshold_m;
    const Vec3& c = x_[std::size_t(n_)];
    const std::uint8_t entry = Entry(p, n_);
    if (part.geometry.Distance(c, entry).distance_m - r1 >= eps) return;
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

  // Where along element i its point nearest edge e lies: found when first met in the tick, then
  // kept for the tick. False when the element does not pass the edge (or there is no room).
  bool SidePosition(int p, int i, int e, const Vec3& a, const Vec3& b, const PartEdge& edge,
                    double& theta) {
    Scratch& s = d_.scratch;
    for (int k = 0; k < s.side_chosen_count; ++k) {
      const Scratch::SideChoice& c = s.side_chosen[std::size_t(k)];
      if (c.part == p && c.element == i && c.edge == e) {
        theta = c.theta;
        return true;
      }
    }
    double u = 0.0;
    ClosestSegmentPoints(a, b, edge.a_W, edge.b_W, theta, u);
    if (!(theta > 0.0 && theta < 1.0)) return false;
    auto& list = keep_ ? s.side_chosen : s.side_pending;
    int& count = keep_ ? s.side_chosen_count : s.side_pending_count;
    if (count == int(list.size())) {
      s.samples_truncated = true;
      return false;
    }
    list[std::size_t(count++)] = {p, i, e, theta};
    return true;
  }

  void Side(int p, const PartModel& part, int i) {
    const double r1 = m_.rod.outer_radius_m, eps = m_.contact.threshold_m;
    const double h = m_.rod.segment_m;
    const Vec3& a = x_[std::size_t(i)];
    const Vec3& b = x_[std::size_t(i + 1)];
    const Vec3 mid = 0.5 * (a + b);
    const std::uint8_t entry = Entry(p, i);
    if (part.geometry.Distance(mid, entry).distance_m - 0.5 * (b - a).norm() - r1 >= eps) return;
    // Between nodes an edge of the part can come nearer than both sections. The point's share of
    // K fades out towards the nodes, whose sections carry it there.
    const double ramp_m = std::min(0.25 * r1, 0.5 * h);
    const auto& edges = part.geometry.edges();
    const Vec3 lo = a.cwiseMin(b).array() - (r1 + eps), hi = a.cwiseMax(b).array() + (r1 + eps);
    for (int e = 0; e < int(edges.size()); ++e) {
      const PartEdge& edge = edges[std::size_t(e)];
      if ((edge.min_W.array() > hi.array()).any() || (edge.max_W.array() < lo.array()).any())
        continue;
      double theta = 0.0;
      if (!SidePosition(p, i, e, a, b, edge, theta)) continue;
      const Vec3 c = a + theta * (b - a);
      const Vec3 ab = edge.b_W - edge.a_W;
      const double u = std::clamp((c - edge.a_W).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
      const Vec3 q = edge.a_W + u * ab;
      const Vec3 w = c - q;
      const double lw = w.norm();
      if (!(lw - r1 < eps) || lw == 0.0) continue;
      const double weight = SmoothStep(std::min(theta, 1.0 - theta) * (b - a).norm() / ramp_m);
      if (weight <= 0.0) continue;
      // The edge, or the vertex it ends in.
      const std::uint8_t mask = u == 0.0 ? edge.a_mask : u == 1.0 ? edge.b_mask : edge.face_mask;
      PartDistance at;
      at.distance_m = lw - r1;
      at.normal_W = w / lw;
      at.point_W = q;
      at.face_mask = mask;
      at.curvature_per_m = Eigen::Matrix3d::Identity() - at.normal_W * at.normal_W.transpose();
      if (u > 0.0 && u < 1.0) at.curvature_per_m -= ab * ab.transpose() / ab.squaredNorm();
      at.curvature_per_m /= lw;
      // The distance moves with the axis point alone; the surface point is r1 from it towards
      // the edge.
      MaterialPoint mp = Material(Carrier::kElement, x_, i, theta, Vec3::Zero(), false);
      mp.offset_W = -r1 * at.normal_W;
      mp.point_W += mp.offset_W;
      Record(SampleKind::kSide, p, i, e, theta, weight, at, mp, Vec3::Zero());
    }
  }

  void EndFace(int p, const PartModel& part) {
    const double r1 = m_.rod.outer_radius_m, r2 = m_.rod.inner_radius_m;
    const double eps = m_.contact.threshold_m;
    const Vec3& c = x_[std::size_t(n_)];
    if (part.geometry.Distance(c).distance_m - r1 >= eps) return;
    const Vec3 t = CarrierTangent(Carrier::kEndNode, x_, n_);
    const auto& vertices = part.geometry.vertices_W();
    // A band at the annulus' edges over which a vertex's share of K fades: the rim's points take
    // over outside, nothing inside the bore.
    const double band_m = 0.1 * r1;
    for (int v = 0; v < int(vertices.size()); ++v) {
      const Vec3 w = vertices[std::size_t(v)] - c;
      const double ahead_m = w.dot(t);
      const Vec3 radial = w - ahead_m * t;
      const double rr = radial.norm();
      if (ahead_m >= eps || ahead_m < -0.5 * r1) continue;
      const double weight =
          SmoothStep((r1 - rr) / band_m) * (r2 > 0.0 ? SmoothStep((rr - r2) / band_m) : 1.0);
      if (weight <= 0.0) continue;
      PartDistance at;
      at.distance_m = ahead_m;
      at.normal_W = -t;
      at.point_W = vertices[std::size_t(v)];
      at.face_mask = part.geometry.vertex_masks()[std::size_t(v)];
      Record(SampleKind::kEndFace, p, n_, v, 0.0, weight, at,
             Material(Carrier::kEndNode, x_, n_, 0.0, radial, false), radial);
    }
  }

  const Model& m_;
  std::span<const Vec3> x_;
  Data& d_;
  int n_;
  bool keep_;
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
    const BoxGeometry& g = model.parts[p].geometry;
    const Vec3 gap = (g.min_W() - hi).cwiseMax(lo - g.max_W()).cwiseMax(0.0);
    const bool near = !(gap.array() > grow).any();
    data.scratch.parts_near[p] = near;
    if (!near) far = std::min(far, gap.maxCoeff() - r1);
  }
  data.scratch.far_clearance_m = far;
}

void FindContacts(const Model& model, std::span<const Vec3> x_W, Data& data, Choices choices) {
  data.scratch.section_pending_count = 0;
  data.scratch.side_pending_count = 0;
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
  for (int k = 0; k < s.side_pending_count && s.side_chosen_count < int(s.side_chosen.size()); ++k)
    s.side_chosen[std::size_t(s.side_chosen_count++)] = s.side_pending[std::size_t(k)];
  s.section_pending_count = s.side_pending_count = 0;
}

}  // namespace tubeplan::core
