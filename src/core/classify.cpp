#include "core/classify.hpp"

#include <algorithm>
#include <cmath>

#include <tubeplan/core/friction.hpp>

#include "core/rod.hpp"
#include "core/stick_slip.hpp"

namespace tubeplan::core {
namespace {

using Vec3 = Eigen::Vector3d;
using states::Marker;
using states::TubeElement;

// A PC while it is being gathered: every contact point of one tube element on one part element.
struct Gathered {
  TubeElement tube = TubeElement::kSide;
  int part = 0;
  ElementIndex element = kNoElement;
  int merged_into = -1;
  ContactState pc;
  double s_far_m = 0.0;    ///< arc position of its point farthest from the held end
  double sliding_N = 0.0;  ///< the normal force of its points that slide
};

// The tube's element of a contact point: the rim's points are the end face when the face's
// centre is itself within epsilon of the part (the end lies flat on it, or a part's edge crosses
// the face).
TubeElement TubeElementOf(const Model& model, const Data& data, const Sample& s) {
  switch (s.kind) {
    case SampleKind::kNode:
    case SampleKind::kSide:
    case SampleKind::kCurve:
      return TubeElement::kSide;
    case SampleKind::kEndFace:
      return TubeElement::kEndFace;
    case SampleKind::kRim:
      break;
  }
  const Vec3& centre = data.state.x_W[std::size_t(model.rod.elements)];
  const double d = model.parts[std::size_t(s.part)].geometry.Distance(centre).distance_m;
  return d < model.contact.threshold_m ? TubeElement::kEndFace : TubeElement::kEndRim;
}

double ArcOf(const Model& model, const Sample& s) {
  if (s.kind == SampleKind::kSide) return (s.node + s.theta) * model.rod.segment_m;
  if (s.kind == SampleKind::kCurve) return (s.node - 0.5 + s.theta) * model.rod.segment_m;
  return s.node * model.rod.segment_m;
}

// a is a boundary element of b, or the same: the rim bounds the end face and the side; on a part,
// an edge bounds its faces and a vertex its edges and faces.
bool TubeWithin(TubeElement a, TubeElement b) {
  return a == b ||
         (a == TubeElement::kEndRim && (b == TubeElement::kEndFace || b == TubeElement::kSide));
}

// The curvature vector of the centreline at arc s [1/m], pointing to the centre of curvature:
// the turn of the tangent at each inner node over an element's length, interpolated.
Vec3 CurvatureAt(const Model& model, const Data& data, double s_m) {
  const auto& x = data.state.x_W;
  const int n = model.rod.elements;
  const double h = model.rod.segment_m;
  auto at_node = [&](int i) -> Vec3 {
    if (i >= n) return Vec3::Zero();
    const Vec3 b = (x[std::size_t(i + 1)] - x[std::size_t(i)]).normalized();
    if (i == 0) return 2.0 * (b - data.input.tangent_held_W) / h;  // over half an element
    const Vec3 a = (x[std::size_t(i)] - x[std::size_t(i - 1)]).normalized();
    return (b - a) / h;
  };
  const double u = std::clamp(s_m / h, 0.0, double(n));
  const int i = std::min(int(u), n - 1);
  const double w = u - i;
  return (1.0 - w) * at_node(i) + w * at_node(i + 1);
}

}  // namespace

double TipDeflection(const Model& model, const Data& data) {
  const auto& x = data.state.x_W;
  const Vec3 t = data.input.tangent_held_W;
  const Vec3 r = x[std::size_t(model.rod.elements)] - x[0];
  return (r - r.dot(t) * t).norm();
}

void Classify(const Model& model, Data& data) {
  const Scratch& s = data.scratch;
  StepOutput& out = data.out;
  const double eps = model.contact.threshold_m;
  const Vec3 p_H = data.state.x_W[0];

  // Gather the contact points into (tube element, part element) pairs.
  std::array<Gathered, 4 * kMaxContacts> g{};
  int count = 0;
  bool truncated = s.samples_truncated;
  for (int k = 0; k < s.sample_count; ++k) {
    const Sample& smp = s.samples[std::size_t(k)];
    if (!(smp.distance_m < eps) || !OnSurface(smp)) continue;
    const TubeElement te = TubeElementOf(model, data, smp);
    int at = -1;
    for (int i = 0; i < count && at < 0; ++i)
      if (g[std::size_t(i)].tube == te && g[std::size_t(i)].part == smp.part &&
          g[std::size_t(i)].element == smp.element)
        at = i;
    if (at < 0) {
      if (count == int(g.size())) {
        truncated = true;
        continue;
      }
      at = count++;
      Gathered& n = g[std::size_t(at)];
      n = Gathered{};
      n.tube = te;
      n.part = smp.part;
      n.element = smp.element;
      n.pc.tube = te;
      n.pc.part_element = model.parts[std::size_t(smp.part)].first_element + smp.element;
      n.pc.distance_m = smp.contact_distance_m;
      n.pc.s_m = ArcOf(model, smp);
      n.pc.normal_W = smp.normal_W;
      n.pc.p_WC_m = smp.point_W;
    }
    ContactState& pc = g[std::size_t(at)].pc;
    const Vec3 f = smp.normal_force_N * smp.normal_W + smp.friction_W_N;
    pc.points += 1;
    pc.normal_force_N += smp.normal_force_N;
    pc.friction_W_N += smp.friction_W_N;
    pc.force_W_N += f;
    pc.moment_W_Nm += ContactMoment(model, smp, p_H);
    pc.friction_ratio = std::max(pc.friction_ratio, smp.friction_ratio);
    pc.friction_work_J += smp.friction_work_J;
    if (smp.sliding) g[std::size_t(at)].sliding_N += smp.normal_force_N;
    g[std::size_t(at)].s_far_m = std::max(g[std::size_t(at)].s_far_m, ArcOf(model, smp));
    if (smp.contact_distance_m < pc.distance_m) {
      pc.distance_m = smp.contact_distance_m;
      pc.s_m = ArcOf(model, smp);
      pc.normal_W = smp.normal_W;
      pc.p_WC_m = smp.point_W;
    }
  }

  // A PC whose elements both bound (or equal) those of another PC on the same part is part of
  // that one (contact-states.md: principal contacts only).
  for (int i = 0; i < count; ++i) {
    Gathered& a = g[std::size_t(i)];
    for (int j = 0; j < count && a.merged_into < 0; ++j) {
      const Gathered& b = g[std::size_t(j)];
      if (i == j || b.merged_into >= 0 || a.part != b.part) continue;
      if (TubeWithin(a.tube, b.tube) &&
          model.parts[std::size_t(a.part)].geometry.Bounds(a.element, b.element) &&
          !(a.tube == b.tube && a.element == b.element))
        a.merged_into = j;
    }
  }
  for (int i = 0; i < count; ++i) {
    Gathered& a = g[std::size_t(i)];
    if (a.merged_into < 0) continue;
    int into = a.merged_into;
    while (g[std::size_t(into)].merged_into >= 0) into = g[std::size_t(into)].merged_into;
    ContactState& b = g[std::size_t(into)].pc;
    b.points += a.pc.points;
    b.normal_force_N += a.pc.normal_force_N;
    b.friction_W_N += a.pc.friction_W_N;
    b.force_W_N += a.pc.force_W_N;
    b.moment_W_Nm += a.pc.moment_W_Nm;
    b.friction_ratio = std::max(b.friction_ratio, a.pc.friction_ratio);
    b.friction_work_J += a.pc.friction_work_J;
    g[std::size_t(into)].sliding_N += a.sliding_N;
    g[std::size_t(into)].s_far_m = std::max(g[std::size_t(into)].s_far_m, a.s_far_m);
    if (a.pc.distance_m < b.distance_m) {
      b.distance_m = a.pc.distance_m;
      b.s_m = a.pc.s_m;
      b.normal_W = a.pc.normal_W;
      b.p_WC_m = a.pc.p_WC_m;
    }
  }

  // Markers (contact-states.md): none while the tube does not bend; the end face and rim never
  // deform; the side is concave or convex by the side of the bend that meets the part, read
  // midway along the piece of tube that leads from the previous contact (or the grip) to it.
  const double deflection = TipDeflection(model, data);
  // Bending from the threshold on, straight again below half of it: the markers do not flicker
  // while the tip hovers at the threshold.
  const double threshold = model.contact.bend_threshold_m * (data.state.bends ? 0.5 : 1.0);
  const bool bends = deflection > threshold;
  data.state.bends = bends;
  const double l = model.rod.length_m;
  const double curvature_floor = model.contact.bend_threshold_m / (l * l);
  for (int i = 0; i < count; ++i) {
    Gathered& a = g[std::size_t(i)];
    if (a.merged_into >= 0) continue;
    ContactState& pc = a.pc;
    const scene::Friction& fr = model.parts[std::size_t(a.part)].friction;
    pc.friction_limit_N = FrictionLimit(fr, fr.static_coefficient, pc.normal_force_N);
    // A PC slides when the points that bear most of its load do: a point at the band's edge,
    // bearing nothing, slides at any stretch, and does not move the contact.
    pc.sliding = a.sliding_N > 0.5 * pc.normal_force_N;
    if (!bends) {
      pc.marker = Marker::kNone;
      continue;
    }
    if (a.tube != TubeElement::kSide) {
      pc.marker = Marker::kBent;
      continue;
    }
    double before_m = 0.0;
    for (int j = 0; j < count; ++j) {
      const Gathered& b = g[std::size_t(j)];
      if (j != i && b.merged_into < 0 && b.s_far_m < a.s_far_m - model.rod.segment_m)
        before_m = std::max(before_m, b.s_far_m);
    }
    const double side = CurvatureAt(model, data, 0.5 * (before_m + a.s_far_m)).dot(pc.normal_W);
    pc.marker = side > curvature_floor    ? Marker::kConvex
                : side < -curvature_floor ? Marker::kConcave
                                          : Marker::kBent;
  }

  // The deepest kMaxContacts PCs, in the canonical order (tube element, part element).
  std::array<const ContactState*, 4 * kMaxContacts> kept{};
  int kept_count = 0;
  for (int i = 0; i < count; ++i)
    if (g[std::size_t(i)].merged_into < 0) kept[std::size_t(kept_count++)] = &g[std::size_t(i)].pc;
  std::sort(
      kept.begin(), kept.begin() + kept_count,
      [](const ContactState* a, const ContactState* b) { return a->distance_m < b->distance_m; });
  if (kept_count > kMaxContacts) {
    truncated = true;
    kept_count = kMaxContacts;
  }
  std::sort(kept.begin(), kept.begin() + kept_count,
            [](const ContactState* a, const ContactState* b) {
              if (a->tube != b->tube) return a->tube < b->tube;
              return a->part_element < b->part_element;
            });
  out.contact_count = kept_count;
  for (int i = 0; i < kept_count; ++i) out.contacts[std::size_t(i)] = *kept[std::size_t(i)];
  if (truncated) out.flags |= kContactsTruncated;
}

}  // namespace tubeplan::core
