#include "core/stick_slip.hpp"

#include <algorithm>
#include <cmath>

#include <tubeplan/core/friction.hpp>

#include "core/assemble.hpp"

namespace tubeplan::core {

Eigen::Vector3d FrictionOffset(const Model& model, const Sample& smp) {
  if (smp.kind == SampleKind::kRim || smp.kind == SampleKind::kEndFace) return smp.offset_W;
  // Past half the radius inside a part, no farther in.
  const double gap_m = std::max(smp.distance_m, -0.5 * model.rod.outer_radius_m);
  return smp.offset_W - gap_m * smp.normal_W;
}

namespace {

// Where a contact point's friction holds the tube (FrictionOffset), in the world.
Eigen::Vector3d HeldPoint(const Model& model, const Sample& smp) {
  return smp.point_W - smp.offset_W + FrictionOffset(model, smp);
}

}  // namespace

Eigen::Vector3d ContactMoment(const Model& model, const Sample& smp, const Eigen::Vector3d& p_W) {
  return (smp.point_W - p_W).cross(smp.normal_force_N * smp.normal_W) +
         (HeldPoint(model, smp) - p_W).cross(smp.friction_W_N);
}

namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

bool Active(const Model& model, const Sample& s) {
  return s.distance_m < model.contact.threshold_m &&
         !model.parts[std::size_t(s.part)].friction.IsFrictionless();
}

bool SameKey(const FrictionPoint& f, const Sample& s) {
  return f.part == s.part && f.kind == s.kind && f.node == s.node && f.feature == s.feature;
}

// Pairs contact points with friction points: the same point first, then, for a contact point
// that moved along the tube (a section to the next, the rim's points around), the nearest
// unpaired friction point of the same part within half an element.
void Match(const Model& model, Data& data) {
  Scratch& s = data.scratch;
  CarriedState& st = data.state;
  for (int k = 0; k < s.sample_count; ++k) s.samples[std::size_t(k)].friction_point = -1;
  for (int f = 0; f < st.friction_count; ++f) st.friction[std::size_t(f)].sample = -1;
  for (int k = 0; k < s.sample_count; ++k) {
    Sample& smp = s.samples[std::size_t(k)];
    if (!Active(model, smp)) continue;
    for (int f = 0; f < st.friction_count; ++f) {
      FrictionPoint& fp = st.friction[std::size_t(f)];
      if (fp.sample < 0 && SameKey(fp, smp)) {
        fp.sample = k;
        smp.friction_point = f;
        break;
      }
    }
  }
  const double reach_m = 0.5 * model.rod.segment_m;
  for (int k = 0; k < s.sample_count; ++k) {
    Sample& smp = s.samples[std::size_t(k)];
    if (!Active(model, smp) || smp.friction_point >= 0) continue;
    int best = -1;
    double best_m = reach_m;
    const Vec3 held_W = HeldPoint(model, smp);
    for (int f = 0; f < st.friction_count; ++f) {
      const FrictionPoint& fp = st.friction[std::size_t(f)];
      if (fp.sample >= 0 || fp.part != smp.part) continue;
      const double d_m = (FrictionMaterial(model, fp, st.x_W, s.tangents).point_W - held_W).norm();
      if (d_m < best_m) {
        best_m = d_m;
        best = f;
      }
    }
    if (best >= 0) {
      st.friction[std::size_t(best)].sample = k;
      smp.friction_point = best;
    }
  }
}

struct Limits {
  double static_N = 0.0, kinetic_N = 0.0;
};

// Sums the loads of the part elements the contact points press on (Scratch::ElementLoad), each
// in the contact points' order, and the friction limits of their totals.
void SumElementLoads(const Model& model, Data& data) {
  Scratch& s = data.scratch;
  const double eps = model.contact.threshold_m;
  int count = 0;
  for (int k = 0; k < s.sample_count; ++k) {
    const Sample& smp = s.samples[std::size_t(k)];
    int e = 0;
    while (e < count && (s.element_loads[std::size_t(e)].part != smp.part ||
                         s.element_loads[std::size_t(e)].element != smp.element))
      ++e;
    Scratch::ElementLoad& load = s.element_loads[std::size_t(e)];
    if (e == count) {
      load = {smp.part, smp.element};
      ++count;
    }
    s.element_of[std::size_t(k)] = e;
    if (smp.distance_m < eps) load.group_N += smp.normal_force_N;
  }
  // The side's sections on one part press as one contact (Assemble): their loads are summed
  // over the part, whichever of its elements each lies on.
  for (int k = 0; k < s.sample_count; ++k) {
    const Sample& smp = s.samples[std::size_t(k)];
    if (!IsSideSection(smp)) continue;
    for (int e = 0; e < count; ++e) {
      Scratch::ElementLoad& load = s.element_loads[std::size_t(e)];
      if (load.part != smp.part) continue;
      load.side_N += smp.normal_force_N;
      load.side_depth_m += std::max(0.0, eps - smp.distance_m);
    }
  }
  for (int e = 0; e < count; ++e) {
    Scratch::ElementLoad& load = s.element_loads[std::size_t(e)];
    const scene::Friction& fr = model.parts[std::size_t(load.part)].friction;
    if (fr.IsFrictionless()) continue;
    load.static_N = FrictionLimit(fr, fr.static_coefficient, load.group_N);
    load.kinetic_N = FrictionLimit(fr, fr.kinetic_coefficient, load.group_N);
  }
}

// Contact point k's friction limits: its share of its part element's limit (its PC's share rule,
// friction.hpp) in proportion to its load, with the element's loads of SumElementLoads. Its load
// is its own normal force, or for one of the side's sections, which press on a part as one
// contact (Assemble), the contact's force shared by their depths eps - d: the smooth minimum puts
// the force on the deepest section, which changes with every small tilt of a side lying flat;
// shared by depth, the friction limits do not jump.
Limits LimitsOf(const Model& model, const Data& data, int k) {
  const Sample& of = data.scratch.samples[std::size_t(k)];
  const Scratch::ElementLoad& load =
      data.scratch.element_loads[std::size_t(data.scratch.element_of[std::size_t(k)])];
  const double eps = model.contact.threshold_m;
  double own_N = of.normal_force_N;
  if (IsSideSection(of))
    own_N = load.side_depth_m > 0.0
                ? load.side_N * std::max(0.0, eps - of.distance_m) / load.side_depth_m
                : 0.0;
  const scene::Friction& fr = model.parts[std::size_t(of.part)].friction;
  return {FrictionShare(fr, fr.static_coefficient, own_N, load.group_N, load.static_N),
          FrictionShare(fr, fr.kinetic_coefficient, own_N, load.group_N, load.kinetic_N)};
}

// The spring's stretch of a friction point at the solved nodes, in its tangent plane.
Vec3 Stretch(const Model& model, Data& data, const FrictionPoint& f) {
  const Vec3 p = FrictionMaterial(model, f, data.state.x_W, data.scratch.tangents).point_W;
  const Vec3 u = p - f.anchor_W;
  return u - u.dot(f.normal_W) * f.normal_W;
}

}  // namespace

bool ReturnFrictionToLimits(const Model& model, Data& data) {
  if (model.frictionless) return false;
  Match(model, data);
  SumElementLoads(model, data);
  const double K = model.contact.stiffness_N_per_m;
  bool changed = false;
  for (int f = 0; f < data.state.friction_count; ++f) {
    FrictionPoint& fp = data.state.friction[std::size_t(f)];
    if (fp.sample < 0) {
      // Its contact opened: the spring lets go.
      if (!(fp.sliding && fp.limit_N == 0.0)) {
        fp.sliding = true;
        fp.limit_N = 0.0;
        changed = true;
      }
      continue;
    }
    const Limits lim = LimitsOf(model, data, fp.sample);
    const double trial_N = K * Stretch(model, data, fp).norm();
    // A point's limit follows its load with a tick's lag unless the load moved it by more than
    // a tenth (a contact closing or opening): then the tick is solved again.
    const auto follow = [&](double limit_N) {
      if (std::abs(fp.limit_N - limit_N) > 0.1 * limit_N + 1e-4) {
        fp.limit_N = limit_N;
        changed = true;
      }
    };
    if (!fp.sliding && trial_N > lim.static_N * (1.0 + 1e-9) + 1e-12) {
      fp.sliding = true;
      fp.limit_N = lim.kinetic_N;
      changed = true;
    } else {
      follow(fp.sliding ? lim.kinetic_N : lim.static_N);
    }
  }
  return changed;
}

void CarryFriction(const Model& model, Data& data) {
  Scratch& s = data.scratch;
  for (int k = 0; k < s.sample_count; ++k) {
    Sample& smp = s.samples[std::size_t(k)];
    smp.friction_W_N.setZero();
    smp.friction_ratio = smp.static_limit_N = smp.friction_work_J = 0.0;
    smp.sliding = false;
  }
  if (model.frictionless) {
    data.state.friction_count = 0;
    return;
  }
  Match(model, data);
  SumElementLoads(model, data);
  const double K = model.contact.stiffness_N_per_m;
  int next = 0;
  for (int k = 0; k < s.sample_count && next < kMaxFrictionPoints; ++k) {
    Sample& smp = s.samples[std::size_t(k)];
    if (!Active(model, smp)) continue;
    const Limits lim = LimitsOf(model, data, k);
    Vec3 stretch = Vec3::Zero();
    bool sliding = false;
    if (smp.friction_point >= 0) {
      const FrictionPoint& fp = data.state.friction[std::size_t(smp.friction_point)];
      const Vec3 u = Stretch(model, data, fp);
      const double trial_N = K * u.norm();
      // A sliding point slides on while its spring is at the kinetic limit; a stuck one once it
      // passes the static limit. Sliding, the anchor is dragged to where the spring carries the
      // kinetic force, and the slip dissipates that force times its length.
      sliding = fp.sliding ? trial_N > lim.kinetic_N : trial_N > lim.static_N;
      stretch = u;
      if (sliding && trial_N > 0.0) {
        stretch = u * (lim.kinetic_N / trial_N);
        smp.friction_work_J = lim.kinetic_N * (u.norm() - stretch.norm());
      }
    }
    // Re-anchored at the friction point's material point as it is now (where the next tick's
    // spring will measure it from: a node's sphere's point turned square to the tube), in its
    // tangent plane, with the same stretch.
    stretch -= stretch.dot(smp.normal_W) * smp.normal_W;
    smp.friction_W_N = -K * stretch;
    smp.sliding = sliding;
    smp.static_limit_N = lim.static_N;
    smp.friction_ratio =
        lim.static_N > 0.0 ? std::min(1.0, smp.friction_W_N.norm() / lim.static_N) : 0.0;
    FrictionPoint& nf = s.friction_next[std::size_t(next++)];
    nf.kind = smp.kind;
    nf.part = smp.part;
    nf.node = smp.node;
    nf.feature = smp.feature;
    nf.theta = smp.theta;
    nf.offset_W = FrictionOffset(model, smp);
    nf.anchor_W = FrictionMaterial(model, nf, data.state.x_W, s.tangents).point_W - stretch;
    nf.normal_W = smp.normal_W;
    nf.sliding = sliding;
    nf.limit_N = sliding ? lim.kinetic_N : lim.static_N;
    nf.normal_N = smp.normal_force_N;
    nf.sample = -1;
  }
  std::copy_n(s.friction_next.begin(), next, data.state.friction.begin());
  data.state.friction_count = next;
}

}  // namespace tubeplan::core
