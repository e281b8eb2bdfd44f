#include <array>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <numbers>

#include <tubeplan/core/core.hpp>
#include <tubeplan/model/tube.hpp>
#include <tubeplan/plan/judge.hpp>
#include <tubeplan/study/stability.hpp>

#include "format.hpp"

namespace tubeplan::study {
namespace {

using Eigen::Vector3d;

scene::Part Box(const std::string& name, const Vector3d& size, const Vector3d& centre) {
  scene::Part b;
  b.name = name;
  b.size_m = size;
  b.X_WP = Eigen::Isometry3d::Identity();
  b.X_WP.translation() = centre;
  return b;
}

// The rubber tube of scenes/groove.yaml (Table I material, the paper's K, eps and friction) with
// the PHANToM Premium and the rod: the shipped default.
scene::Scene BaseScene() {
  scene::Scene s;
  s.name = "stability";
  s.tube = {8e-3, 5e-3, 0.15, 3e6, 0.5};
  s.contact = {1e4, 1e-3, 1e-4};
  s.friction = {0.7, 0.08, 2.0 / 3.0, 1.0};
  s.device.coupling_stiffness_N_per_m = 400.0;
  s.device.coupling_damping_Ns_per_m = 2.0;
  return s;
}

// The parts of a motion, placed around a tube held at the origin along +z.
void AddParts(Motion motion, scene::Scene& s) {
  const double l = s.tube.length_m, r1 = s.tube.outer_radius_m, eps = s.contact.threshold_m;
  const double gap = 2.0 * eps + 1e-3;  // clear of the band at the start
  switch (motion) {
    case Motion::kPushIntoWall:
    case Motion::kSlideAlongWall:
      s.parts.push_back(Box("wall", {0.6, 0.4, 0.02}, {0.0, 0.0, l + gap + 0.01}));
      break;
    case Motion::kRollOverEdge: {
      // A 40 mm cube turned 45 degrees about y: its edge along y at half the tube's length.
      scene::Part b =
          Box("edge", {0.04, 0.04, 0.04}, {r1 + gap + 0.02 * std::sqrt(2.0), 0.0, 0.5 * l});
      b.X_WP.linear() =
          Eigen::AngleAxisd(std::numbers::pi / 4, Vector3d::UnitY()).toRotationMatrix();
      s.parts.push_back(b);
      break;
    }
    case Motion::kSqueeze: {
      // A groove 1 mm wider than the tube from 0.3 l to beyond the tip, and its floor.
      const double half = r1 + 0.5e-3, depth = 0.7 * l + 0.05;
      s.parts.push_back(Box("left", {0.1, 0.4, depth}, {-half - 0.05, 0.0, 0.3 * l + depth / 2}));
      s.parts.push_back(Box("right", {0.1, 0.4, depth}, {half + 0.05, 0.0, 0.3 * l + depth / 2}));
      s.parts.push_back(Box("floor", {0.4, 0.4, 0.02}, {0.0, 0.0, l + gap + 0.01}));
      break;
    }
    case Motion::kFastPass:
      // 1 mm thick, 5 mm beyond the tip plus the band.
      s.parts.push_back(Box("thin", {0.6, 0.4, 1e-3}, {0.0, 0.0, l + gap + 5e-3 + 0.5e-3}));
      break;
  }
}

// Waypoints of the hand (positions; the orientation is held, so the torque does no work).
std::vector<Vector3d> Waypoints(Motion motion, const scene::Scene& s) {
  const double l = s.tube.length_m, r1 = s.tube.outer_radius_m, eps = s.contact.threshold_m;
  const double gap = 2.0 * eps + 1e-3;
  switch (motion) {
    case Motion::kPushIntoWall:
      // Far enough that the coupling saturates at the device's force (8.5 N at 400 N/m: 21 mm).
      return {{0, 0, gap + 0.03}};
    case Motion::kSlideAlongWall:
      return {{0, 0, gap + 0.01}, {0.04, 0, gap + 0.01}};
    case Motion::kRollOverEdge:
      return {{gap + 4e-3, 0, 0}, {gap + 4e-3, 0, -0.7 * l}, {0, 0, -0.7 * l}};
    case Motion::kSqueeze:
      return {{0, 0, 0.5 * gap},
              {6e-3 + r1 * 0, 0, 0.5 * gap},
              {-6e-3, 0, 0.5 * gap},
              {0, 0, 0.5 * gap}};
    case Motion::kFastPass:
      return {{0, 0, gap + 0.05}};
  }
  return {};
}

std::uint64_t Mix(std::uint64_t h, double v) {
  std::uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  for (int i = 0; i < 8; ++i) {
    h ^= (bits >> (8 * i)) & 0xffu;
    h *= 1099511628211ull;
  }
  return h;
}

std::uint64_t HashOf(const core::StepOutput& o) {
  std::uint64_t h = 1469598103934665603ull;
  for (int i = 0; i < 3; ++i) h = Mix(h, o.force_W_N(i)), h = Mix(h, o.torque_W_Nm(i));
  for (int i = 0; i < 16; ++i) h = Mix(h, o.X_WH.matrix()(i));
  h = Mix(h, o.energy_J);
  h = Mix(h, o.max_strain);
  h = Mix(h, double(o.flags));
  h = Mix(h, double(o.contact_count));
  for (const core::ContactState& c : o.Contacts()) {
    h = Mix(h, c.normal_force_N);
    for (int i = 0; i < 3; ++i) h = Mix(h, c.friction_W_N(i));
  }
  return h;
}

bool Finite(const core::StepOutput& o) {
  bool ok = o.force_W_N.allFinite() && o.torque_W_Nm.allFinite() && o.X_WH.matrix().allFinite() &&
            std::isfinite(o.energy_J) && std::isfinite(o.max_strain) &&
            std::isfinite(o.tip_deflection_m);
  for (const core::ContactState& c : o.Contacts())
    ok = ok && std::isfinite(c.normal_force_N) && c.friction_W_N.allFinite() &&
         c.force_W_N.allFinite() && std::isfinite(c.distance_m) && c.normal_W.allFinite();
  return ok;
}

// Everything one run saw, checked tick by tick.
struct Run {
  std::vector<std::uint64_t> hashes;
  int ticks = 0;
  double peak_force_N = 0.0;
  double max_strain = 0.0;
  // First failing tick of each check (-1: never) and what it saw there.
  int fail_finite = -1, fail_force = -1, fail_law = -1, fail_friction = -1, fail_passive = -1,
      fail_tunnel = -1, fail_fault = -1;
  int beyond_linear = -1;  // first tick the linear shape was beyond its range (not a check)
  int unconverged = 0, first_unconverged = -1;  // ticks the solve stopped short (not a check)
  std::string why_force, why_law, why_friction, why_passive, why_tunnel;
  double work_J = 0.0, stored_J = 0.0, initial_J = 0.0;
};

void Note(int& first, std::string& why, int tick, const std::string& what) {
  if (first < 0) {
    first = tick;
    why = what;
  }
}

Run Drive(const StabilityCase& c, bool check) {
  const scene::Scene& s = c.scene;
  auto core = std::make_unique<core::Core>(s);
  const double dt = s.model.time_step_s;
  const double Kc = core->coupling_stiffness_N_per_m(), B = core->coupling_damping_Ns_per_m();
  const double K = s.contact.stiffness_N_per_m, eps = s.contact.threshold_m;
  const double r1 = s.tube.outer_radius_m;
  Run run;
  Vector3d hand = Vector3d::Zero(), prev_hand = hand, prev_p = hand;
  Vector3d prev_F = Vector3d::Zero();
  double slack_J = 0.0;
  std::array<Vector3d, 17> centre;
  double t = 0.0;
  int tick = 0;
  const auto step = [&](const Vector3d& h) {
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    X.translation() = h;
    const core::StepOutput& o = core->Step(t += dt, X);
    ++tick;
    run.hashes.push_back(HashOf(o));
    if (!check) return;
    if (!Finite(o)) {
      Note(run.fail_finite, run.why_force, tick, "");
      return;
    }
    if (o.flags & core::kSolverFault) Note(run.fail_fault, run.why_force, tick, run.why_force);
    if ((o.flags & core::kBeyondLinearRange) && run.beyond_linear < 0) run.beyond_linear = tick;
    if (o.flags & core::kNotConverged) {
      ++run.unconverged;
      if (run.first_unconverged < 0) run.first_unconverged = tick;
    }
    const Vector3d F = o.force_W_N, p = o.X_WH.translation();
    run.peak_force_N = std::max(run.peak_force_N, F.norm());
    run.max_strain = std::max(run.max_strain, o.max_strain);
    // Force bounds: the operator's force is the coupling's, capped at the device's maximum; the
    // coupling cannot carry more than its spring and damper at this stretch and rate (1e-6
    // relative: the saturation's own rounding).
    const double coupling_bound =
        Kc * (h - p).norm() + std::abs(B) * ((h - prev_hand) - (p - prev_p)).norm() / dt;
    if (F.norm() > s.device.max_force_N * (1 + 1e-6) + 1e-9 ||
        F.norm() > coupling_bound * (1 + 1e-6) + 1e-9)
      Note(run.fail_force, run.why_force, tick,
           Fmt("|F| %.4g N against the device's %.4g N and the coupling's %.4g N", F.norm(),
               s.device.max_force_N, coupling_bound));
    // The contact law: a PC of n contact points carries at most n K (eps - d), d its smallest
    // distance.
    double contact_energy_J = 0.0;
    for (const core::ContactState& pc : o.Contacts()) {
      const double bound = std::max(0.0, pc.points * K * (eps - pc.distance_m));
      if (pc.normal_force_N > bound * (1 + 1e-6) + 1e-9)
        Note(run.fail_law, run.why_law, tick,
             Fmt("a contact carries %.4g N, its law allows %.4g N at d = %.4g m", pc.normal_force_N,
                 bound, pc.distance_m));
      // 1e-6 relative and 1e-9 N: the return mapping's Newton stops at that precision.
      if (pc.friction_W_N.norm() > pc.friction_limit_N * (1 + 1e-6) + 1e-9)
        Note(run.fail_friction, run.why_friction, tick,
             Fmt("friction %.4g N beyond its limit %.4g N", pc.friction_W_N.norm(),
                 pc.friction_limit_N));
      // Lower bound of the penalty energy: n springs sharing N hold at least N^2 / (2 n K).
      contact_energy_J +=
          pc.normal_force_N * pc.normal_force_N / (2.0 * std::max(1, pc.points) * K);
    }
    // Passivity: what tube, proxy, contacts and coupling hold (a lower bound) never exceeds the
    // work the hand did on them. The hand pushes with -F; the work over the tick is integrated by
    // the trapezoid, whose error is at most |dF| |dh| / 2 (added to the slack).
    const Vector3d dh = h - prev_hand;
    run.work_J += -0.5 * (F + prev_F).dot(dh);
    slack_J += 0.5 * (F - prev_F).norm() * dh.norm();
    // The coupling's spring holds 1/2 K_c |h - p|^2 up to its cap at the device's force (the
    // stretch beyond the cap stores nothing; the damper stores nothing). Energy held at the first
    // tick (a part already within the band) was not put in by the hand: it is the zero.
    const double spring_N = std::min(Kc * (h - p).norm(), s.device.max_force_N);
    run.stored_J = o.energy_J + 0.5 * spring_N * spring_N / Kc + contact_energy_J;
    if (tick == 1) run.initial_J = run.stored_J;
    if (run.stored_J - run.initial_J > run.work_J + slack_J + 1e-6 * run.stored_J + 1e-9)
      Note(run.fail_passive, run.why_passive, tick,
           Fmt("the system holds %.4g J, the hand put in %.4g J (slack %.2g J)", run.stored_J,
               run.work_J, slack_J));
    // Tunnelling: the tube's axis never inside a part (its surface may press in, its centre
    // line may not: that is going through), and never beyond the thin wall's far face.
    core->Centreline(centre);
    for (const scene::Part& part : s.parts) {
      const Eigen::Isometry3d X_PW = part.X_WP.inverse();
      for (const Vector3d& x : centre) {
        const Vector3d q = X_PW * x;
        const Vector3d depth = 0.5 * part.size_m - q.cwiseAbs();
        // The axis may sit inside by less than r1 / 2 (the surface pressed in, the centreline
        // drawn between exact points); deeper, the tube is going through.
        if (depth.minCoeff() > 0.5 * r1)
          Note(run.fail_tunnel, run.why_tunnel, tick,
               "the tube's axis is inside " + part.name +
                   Fmt(" by %.3g mm", depth.minCoeff() * 1e3));
      }
      if (c.motion == Motion::kFastPass) {
        const double far_z = part.X_WP.translation().z() + 0.5 * part.size_m.z();
        if (centre.back().z() > far_z)
          Note(
              run.fail_tunnel, run.why_tunnel, tick,
              Fmt("the tip is beyond the 1 mm wall (z %.4g m > %.4g m)", centre.back().z(), far_z));
      }
    }
    prev_F = F;
    prev_hand = h;
    prev_p = p;
  };
  for (Vector3d target : Waypoints(c.motion, s)) {
    target.y() += c.off_plane_m;
    const int n = std::max(1, int(std::ceil((target - hand).norm() / (c.speed_m_per_s * dt))));
    const Vector3d from = hand;
    for (int i = 1; i <= n; ++i) step(from + (target - from) * (double(i) / n));
    hand = target;
  }
  for (int i = 0; i < 100; ++i) step(hand);  // held: the state must settle, not wander
  run.ticks = tick;
  return run;
}

}  // namespace

const char* ToString(Motion motion) {
  switch (motion) {
    case Motion::kPushIntoWall:
      return "push into a wall";
    case Motion::kSlideAlongWall:
      return "slide along a wall";
    case Motion::kRollOverEdge:
      return "roll over an edge";
    case Motion::kSqueeze:
      return "squeeze between walls";
    case Motion::kFastPass:
      return "fast pass";
  }
  return "?";
}

std::vector<StabilityCase> StabilityCases(bool quick) {
  struct Variation {
    std::string parameter;
    std::function<void(scene::Scene&, double&, double&)> apply;  // scene, speed, off-plane
  };
  std::vector<Variation> variations;
  variations.push_back({"base", [](scene::Scene&, double&, double&) {}});
  const auto values = [quick](std::vector<double> full, std::vector<double> extremes) {
    return quick ? extremes : full;
  };
  for (const double E : values({1e5, 2e8, 2e11}, {1e5, 2e11}))
    variations.push_back({Fmt("E=%gPa", E), [E](scene::Scene& s, double&, double&) {
                            s.tube.youngs_modulus_Pa = E;
                          }});
  for (const double K : values({1e2, 1e7}, {1e2, 1e7}))
    variations.push_back({Fmt("K=%gN/m", K), [K](scene::Scene& s, double&, double&) {
                            s.contact.stiffness_N_per_m = K;
                          }});
  for (const double e : values({1e-5, 1e-2}, {1e-5, 1e-2}))
    variations.push_back({Fmt("eps=%gm", e), [e](scene::Scene& s, double&, double&) {
                            s.contact.threshold_m = e;
                            s.contact.bend_threshold_m = std::min(1e-4, e / 10);
                          }});
  for (const double ratio : values({0.0, 0.99}, {0.0, 0.99}))
    variations.push_back({Fmt("r2/r1=%g", ratio), [ratio](scene::Scene& s, double&, double&) {
                            s.tube.inner_radius_m = ratio * s.tube.outer_radius_m;
                          }});
  for (const double slender : values({2.0, 1000.0}, {2.0, 1000.0}))
    variations.push_back({Fmt("l/r1=%g", slender), [slender](scene::Scene& s, double&, double&) {
                            const double ratio = s.tube.inner_radius_m / s.tube.outer_radius_m;
                            s.tube.outer_radius_m = s.tube.length_m / slender;
                            s.tube.inner_radius_m = ratio * s.tube.outer_radius_m;
                          }});
  for (const double v : values({0.5, 2.0}, {2.0}))
    variations.push_back(
        {Fmt("speed=%gm/s", v), [v](scene::Scene&, double& speed, double&) { speed = v; }});
  for (const double mu : values({0.0, 2.0}, {0.0, 2.0}))
    variations.push_back({Fmt("mu=%g", mu), [mu](scene::Scene& s, double&, double&) {
                            s.friction.static_coefficient = mu;
                            s.friction.kinetic_coefficient = mu;
                          }});
  // The hand 0.1 mm out of the motion's plane (y) at every waypoint: no operator pushes exactly
  // along the tube's axis, and a case symmetric about it hides what an instability needs to grow
  // from (the push and the fast pass hold the rubber tube straight past its buckling loads only
  // while nothing breaks the symmetry; docs/accuracy.md).
  variations.push_back(
      {"off-plane=0.1mm", [](scene::Scene&, double&, double& off_plane_m) { off_plane_m = 1e-4; }});
  variations.push_back(
      {"beta=1", [](scene::Scene& s, double&, double&) { s.friction.exponent = 1.0; }});
  variations.push_back({"alpha=1000", [](scene::Scene& s, double&, double&) {
                          // E such that the device's largest force bends the tube at alpha 1000.
                          const double I = model::ComputeSection(s.tube).second_moment_m4;
                          s.tube.youngs_modulus_Pa = s.device.max_force_N * s.tube.length_m *
                                                     s.tube.length_m / (1000.0 * I);
                        }});

  std::vector<StabilityCase> cases;
  for (const Motion motion : {Motion::kPushIntoWall, Motion::kSlideAlongWall, Motion::kRollOverEdge,
                              Motion::kSqueeze, Motion::kFastPass}) {
    for (const Variation& v : variations) {
      StabilityCase c;
      c.motion = motion;
      c.parameter = v.parameter;
      c.scene = BaseScene();
      c.speed_m_per_s = motion == Motion::kFastPass ? 2.0 : 0.05;
      v.apply(c.scene, c.speed_m_per_s, c.off_plane_m);
      AddParts(motion, c.scene);
      c.name = std::string(ToString(motion)) + " " + v.parameter;
      // Validity of the model (docs/accuracy.md, "tubeplan stability"): slender beam, the penalty
      // stiff enough that the device cannot push the tube through more than a radius, epsilon
      // below the radius, a wall not so thin that the section would ovalise.
      const model::TubeSpec& t = c.scene.tube;
      std::string why;
      if (t.length_m / t.outer_radius_m < 10.0)
        why += Fmt("l/r1 = %.3g < 10: not a slender beam; ", t.length_m / t.outer_radius_m);
      if (c.scene.device.max_force_N / c.scene.contact.stiffness_N_per_m > t.outer_radius_m)
        why += Fmt("penalty too soft: the device's %.3g N presses %.3g m in, more than r1; ",
                   c.scene.device.max_force_N,
                   c.scene.device.max_force_N / c.scene.contact.stiffness_N_per_m);
      // The contact's force at the thinnest part's middle: below the device's force, a full
      // push carries the tube out the far side (scene::ContactHoldAtMiddle_N).
      const scene::Part* thinnest = nullptr;
      for (const scene::Part& part : c.scene.parts)
        if (!thinnest || part.size_m.minCoeff() < thinnest->size_m.minCoeff()) thinnest = &part;
      if (thinnest && scene::ContactHoldAtMiddle_N(c.scene, *thinnest) < c.scene.device.max_force_N)
        why +=
            Fmt("penalty too soft for a %.3g m part: K (eps + half its thickness) = %.3g N, "
                "below the device's %.3g N; ",
                thinnest->size_m.minCoeff(), scene::ContactHoldAtMiddle_N(c.scene, *thinnest),
                c.scene.device.max_force_N);
      if (c.scene.contact.threshold_m >= t.outer_radius_m)
        why += "eps >= r1: the contact band is wider than the tube; ";
      if (t.inner_radius_m > 0.95 * t.outer_radius_m)
        why += "wall thinner than r1/20: the section would ovalise (not modelled); ";
      if (!why.empty()) why.resize(why.size() - 2);
      c.outside_validity = why;
      cases.push_back(std::move(c));
    }
  }
  return cases;
}

namespace {

// The first tick at which two runs' hashes differ (1-based), -1 if none.
int FirstDifferentTick(const Run& first, const Run& second) {
  for (std::size_t i = 0; i < first.hashes.size(); ++i)
    if (i >= second.hashes.size() || first.hashes[i] != second.hashes[i]) return int(i) + 1;
  return -1;
}

// Why a run is outside the model's validity ("" if it is not): the case's own reasons, and the
// strain beyond the material's elastic range (plan::ElasticStrainLimit, the limit `simulate` and
// `evaluate` warn at; judged on what the run reached).
std::string Validity(const StabilityCase& c, const Run& run) {
  std::string validity = c.outside_validity;
  const double strain_limit = plan::ElasticStrainLimit(c.scene.tube);
  if (run.max_strain > strain_limit)
    validity += std::string(validity.empty() ? "" : "; ") +
                Fmt("strain %.3g beyond the linear-elastic %.3g", run.max_strain, strain_limit);
  return validity;
}

// A run's checks: `failed` gets those that count (the safety checks always, the physical ones
// where the run is within the model's validity, before tick `outside_from`), `warned` the others.
struct Verdict {
  bool pass = true;
  int first_failing_tick = -1;
  std::string failed, warned;
};
Verdict Judge(const StabilityCase& c, const Run& first, int bits, int outside_from) {
  struct Check {
    const char* name;
    int tick;
    std::string why;
    bool safety;  // checked even outside the model's validity
  };
  const std::vector<Check> checks = {
      {"finite outputs", first.fail_finite, "a NaN or Inf left the core", true},
      {"same bits", bits, "the second run differs", true},
      {"force bounds", first.fail_force, first.why_force, true},
      {"solver", first.fail_fault, "the tick's system was singular (kSolverFault)", true},
      {"contact law", first.fail_law, first.why_law, false},
      {"friction bound", first.fail_friction, first.why_friction, false},
      {"passivity", first.fail_passive, first.why_passive, false},
      // Going through a wall is never acceptable, unless the penalty is too soft to stop the
      // device's force within the tube's radius or the part's middle (then it is the scene's
      // choice, warned about).
      {"no tunnelling", first.fail_tunnel, first.why_tunnel,
       c.outside_validity.find("penalty too soft") == std::string::npos},
  };
  Verdict v;
  for (const Check& k : checks) {
    if (k.tick < 0) continue;
    const std::string text =
        std::string(k.name) + " at tick " + std::to_string(k.tick) + ": " + k.why;
    if (k.safety || k.tick < outside_from) {
      v.pass = false;
      if (v.first_failing_tick < 0 || k.tick < v.first_failing_tick) v.first_failing_tick = k.tick;
      v.failed += (v.failed.empty() ? "" : "; ") + text;
    } else {
      v.warned += (v.warned.empty() ? "" : "; ") + text;
    }
  }
  return v;
}

}  // namespace

StabilityResult RunStabilityCase(const StabilityCase& c) {
  StabilityResult r;
  r.name = c.name;
  r.motion = ToString(c.motion);
  r.parameter = c.parameter;
  const Run first = Drive(c, true);
  const int bits = FirstDifferentTick(first, Drive(c, false));
  r.ticks = first.ticks;
  r.peak_force_N = first.peak_force_N;
  constexpr int kNever = std::numeric_limits<int>::max();
  const std::string validity = Validity(c, first);
  r.outside = !validity.empty();
  const Verdict v = Judge(c, first, bits, r.outside ? 0 : kNever);
  r.pass = v.pass;
  r.first_failing_tick = v.first_failing_tick;
  if (r.outside)
    r.warning = "outside the model's validity (" + validity + ")" +
                (v.warned.empty() ? "" : "; there: " + v.warned);
  r.detail = r.pass ? Fmt("%d ticks, peak force %.3g N, largest strain %.3g", r.ticks,
                          r.peak_force_N, first.max_strain)
                    : v.failed;
  // Where the linear beam was drawn beyond its range, and where the solve stopped short of its
  // tolerance (a snap through, or a jump of the hand): shown, not judged.
  if (first.beyond_linear >= 0)
    r.detail += Fmt("; the linear shape beyond l/3 from tick %d", first.beyond_linear);
  r.unconverged_ticks = first.unconverged;
  r.first_unconverged_tick = first.first_unconverged;
  if (first.unconverged > 0)
    r.detail += Fmt("; the solve stopped short of its tolerance in %d of %d ticks, from tick %d",
                    first.unconverged, first.ticks, first.first_unconverged);
  return r;
}

}  // namespace tubeplan::study
