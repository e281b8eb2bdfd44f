#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <functional>
#include <numbers>
#include <optional>

#include <tubeplan/core/core.hpp>
#include <tubeplan/model/elastica.hpp>
#include <tubeplan/model/tip_response.hpp>
#include <tubeplan/model/tube.hpp>
#include <tubeplan/study/accuracy.hpp>

#include "format.hpp"

namespace tubeplan::study {
namespace {

using Clock = std::chrono::steady_clock;
using Eigen::Vector2d;

double Micros(Clock::duration d) { return std::chrono::duration<double, std::micro>(d).count(); }

// ---- Tip loads ----------------------------------------------------------------------------------

// Relative error of the tip displacement (deflection, shortening) and of the tip angle.
struct TipError {
  double displacement = 0.0, deflection = 0.0, shortening = 0.0, angle = 0.0;
};

TipError Compare(double v, double h, double angle, double v_ref, double h_ref, double angle_ref) {
  TipError e;
  e.displacement = std::hypot(v - v_ref, h - h_ref) / std::hypot(v_ref, h_ref);
  e.deflection = std::abs(v - v_ref) / v_ref;
  e.shortening = std::abs(h - h_ref) / h_ref;
  e.angle = std::abs(angle - angle_ref) / angle_ref;
  return e;
}

// Time per call of f, over enough calls for the steady clock's resolution.
double TimePerCallUs(const std::function<double()>& f) {
  double sink = 0.0;
  int calls = 1;
  for (;;) {
    const Clock::time_point t0 = Clock::now();
    for (int i = 0; i < calls; ++i) sink += f();
    const double us = Micros(Clock::now() - t0);
    if (us > 2000.0 || calls >= (1 << 20)) return sink == 12345.678 ? 0.0 : us / calls;
    calls *= 4;
  }
}

void TipLoadRows(const scene::Scene& base, const AccuracyOptions& options, AccuracyReport& report) {
  const model::TubeSpec& spec = base.tube;
  const double EI = model::ComputeSection(spec).bending_stiffness_Nm2;
  const double l = spec.length_m;
  const std::vector<double> alphas =
      options.quick ? std::vector<double>{1e-3, 1.0, 100.0}
                    : std::vector<double>{1e-3, 1e-2, 0.1, 0.25, 1.0, 2.0, 5.0, 10.0, 30.0, 100.0};
  const int N = options.quick ? 64 : 256;
  for (const double alpha : alphas) {
    const model::ElasticaSolution exact = model::SolveElastica(alpha, 0.0);
    const Eigen::Vector3d F(alpha * EI / (l * l), 0.0, 0.0);
    const std::string scenario = Fmt("tip load alpha=%g", alpha);
    for (const model::BeamModel m : {model::BeamModel::kLinear, model::BeamModel::kElastica}) {
      const model::TipLoadResponse r = model::TipResponse(m, spec, F);
      const double time_us =
          TimePerCallUs([&] { return model::TipResponse(m, spec, F).tip_deflection_m; });
      AccuracyRow row;
      row.setting = std::string(model::ToString(m));
      row.scenario = scenario;
      row.time_us = time_us;
      // The rod's limit, as elements are added, is the elastica.
      row.is_default =
          (m == model::BeamModel::kLinear) == (base.model.tube == scene::TubeModel::kLinear);
      if (m == model::BeamModel::kLinear) {
        // Against the exact elastica (closed form).
        const TipError e =
            Compare(r.tip_deflection_m / l, r.tip_shortening_m / l, r.tip_angle_rad,
                    exact.tip.deflection, exact.tip.shortening, exact.tip.tip_angle_rad);
        row.metric = "tip displacement vs exact elastica";
        row.error = e.displacement;
        row.detail = Fmt("deflection %.3g, angle %.3g, shortening %.3g (relative)", e.deflection,
                         e.angle, e.shortening);
      } else {
        // The closed form against the independent reference rod (Richardson from N/2 and N).
        const reference::PlanarRod coarse{1.0, 1.0, 0.0, N / 2}, fine{1.0, 1.0, 0.0, N};
        reference::Loading load;
        load.tip_force_N = {alpha, 0.0};
        const reference::RodSolution a = reference::SolveRod(coarse, load);
        const reference::RodSolution b = reference::SolveRod(fine, load);
        const double v = reference::Richardson2(a.tip_m.x(), b.tip_m.x());
        const double h = reference::Richardson2(1.0 - a.tip_m.y(), 1.0 - b.tip_m.y());
        const double th = reference::Richardson2(a.tip_angle_rad, b.tip_angle_rad);
        const TipError e =
            Compare(r.tip_deflection_m / l, r.tip_shortening_m / l, r.tip_angle_rad, v, h, th);
        const TipError e_exact =
            Compare(r.tip_deflection_m / l, r.tip_shortening_m / l, r.tip_angle_rad,
                    exact.tip.deflection, exact.tip.shortening, exact.tip.tip_angle_rad);
        row.metric = "tip displacement vs reference rod";
        row.error = e.displacement;
        row.detail =
            Fmt("angle %.3g vs rod; reference rod N=%d extrapolated", e.angle, N) +
            Fmt(" (closed form vs itself through TipResponse: %.2g)", e_exact.displacement);
      }
      report.rows.push_back(row);
    }
  }
}

// ---- Contact scenarios --------------------------------------------------------------------------

struct Scenario {
  std::string name;
  std::vector<scene::Part> parts;
  std::vector<reference::Obstacle> obstacles;
  scene::Friction friction;     ///< for the core's scene
  std::vector<Vector2d> hands;  ///< load steps: hand (x, z) [m]
  bool sliding = false;  ///< the hand presses to press_m, then moves along +x through `hands`
  Vector2d press_m = Vector2d::Zero();
  double speed_m_per_s = 0.02;
};

scene::Part Box(const std::string& name, const Eigen::Vector3d& size,
                   const Eigen::Vector3d& centre, double turn_about_y_rad) {
  scene::Part b;
  b.name = name;
  b.size_m = size;
  b.X_WP = Eigen::Isometry3d::Identity();
  b.X_WP.linear() =
      Eigen::AngleAxisd(turn_about_y_rad, Eigen::Vector3d::UnitY()).toRotationMatrix();
  b.X_WP.translation() = centre;
  return b;
}

// A 40 mm cube turned 45 degrees about y with one edge (along y) at (x, z): the edge in the plane.
scene::Part EdgeBlock(const std::string& name, double x_m, double z_m) {
  const double half_diagonal = 0.02 * std::sqrt(2.0);
  return Box(name, {0.04, 0.04, 0.04}, {x_m + (x_m > 0 ? 1.0 : -1.0) * half_diagonal, 0.0, z_m},
             std::numbers::pi / 4);
}

// A wall whose face (the box's bottom, -z) passes through (x, z) with the outward normal
// (-sin beta, 0, -cos beta): it faces the tip, tilted by beta about y.
scene::Part Wall(const std::string& name, double x_m, double z_m, double beta_rad) {
  const double T = 0.02;
  const Eigen::Vector3d face(x_m, 0.0, z_m);
  const Eigen::Vector3d into(std::sin(beta_rad), 0.0, std::cos(beta_rad));
  return Box(name, {0.4, 0.2, T}, face + 0.5 * T * into, beta_rad);
}

std::vector<Scenario> MakeScenarios(const scene::Scene& base, bool quick) {
  const double l = base.tube.length_m, r1 = base.tube.outer_radius_m;
  const double eps = base.contact.threshold_m;
  const double EI = model::ComputeSection(base.tube).bending_stiffness_Nm2;
  const double Kc = base.device.coupling_stiffness_N_per_m.value_or(400.0);
  const double K = base.contact.stiffness_N_per_m;
  // Load steps sized by force so that both the soft and the stiff tube see 0.3 .. 2 N.
  const std::vector<double> forces =
      quick ? std::vector<double>{0.5, 1.5} : std::vector<double>{0.3, 0.7, 1.2, 2.0};
  std::vector<Scenario> out;
  scene::Friction none;

  {  // End on a wall: a frictionless wall tilted by 30 degrees facing the tip; the hand pushes.
    const double beta = std::numbers::pi / 6;
    // The nearer rim corner starts 0.5 mm beyond epsilon.
    const double g = (eps + 0.5e-3 + r1 * std::sin(beta)) / std::cos(beta);
    Scenario s;
    s.name = "end on a tilted wall";
    s.parts.push_back(Wall("wall", 0.0, l + g, beta));
    s.obstacles.push_back({reference::ObstacleKind::kPlaneEnd,
                           {0.0, l + g},
                           {-std::sin(beta), -std::cos(beta)},
                           0.0,
                           0.0});
    s.friction = none;
    for (const double F : forces) s.hands.push_back({0.0, 0.5e-3 + F * (1.0 / Kc + 1.0 / K)});
    out.push_back(s);
  }
  {  // Side on an edge at 0.6 l; the hand moves towards it.
    const double a = 0.6 * l, d0 = 0.5e-3;
    Scenario s;
    s.name = "side on an edge";
    s.parts.push_back(EdgeBlock("edge", r1 + d0, a));
    s.obstacles.push_back({reference::ObstacleKind::kEdge, {r1 + d0, a}, {}, 0.0, 0.0});
    s.friction = none;
    const double compliance = 1.0 / Kc + 1.0 / K + a * a * a / (3.0 * EI);
    // At most 1.5 N: beyond, the soft tube bends round the edge onto the block's face (45 deg
    // from it), which the reference's edge, a point, does not have.
    for (const double F : forces)
      s.hands.push_back({d0 - eps + std::min(F, 1.5) * compliance, 0.0});
    out.push_back(s);
  }
  {  // Two PCs (Fig. 6): the side on an edge at l/2 (-x), the tip swings onto one near the end.
    const double s1 = 0.5 * l, s2 = l - 1.5 * r1, d1 = 1.1 * eps, d2 = 1.3 * eps;
    Scenario s;
    s.name = "two PCs";
    s.parts.push_back(EdgeBlock("under", -(r1 + d1), s1));
    s.parts.push_back(EdgeBlock("over", r1 + d2, s2));
    s.obstacles.push_back({reference::ObstacleKind::kEdge, {-(r1 + d1), s1}, {}, 0.0, 0.0});
    s.obstacles.push_back({reference::ObstacleKind::kEdge, {r1 + d2, s2}, {}, 0.0, 0.0});
    s.friction = none;
    // The tube pivots on `under`: the tip reaches `over` after the hand moves d2 s1 / (s2 - s1).
    const double reach = (d1 + d2 - 2 * eps) * s1 / (s2 - s1) + d1 - eps;
    const double compliance = 1.0 / Kc + 1.0 / K + std::pow(s2 - s1, 3) / (3.0 * EI);
    for (const double F : forces) s.hands.push_back({-(reach + F * compliance), 0.0});
    out.push_back(s);
  }
  {  // Sliding: the end face pressed on a wall across the axis, the hand moves sideways at
     // 20 mm/s; the tip slides with mu_s = mu_k = 0.3 (beta = 1: the reference's kinetic law).
    const double g = 0.5e-3;
    Scenario s;
    s.name = "sliding on a wall";
    s.parts.push_back(Wall("floor", 0.0, l + g, 0.0));
    reference::Obstacle ob{reference::ObstacleKind::kPlaneEnd, {0.0, l + g}, {0.0, -1.0}, 0.3, 0.0};
    // The tangent of this plane is (n_z, -n_x) = (-1, 0): the tip sliding along +x is sign -1.
    ob.slide_sign = -1.0;
    s.obstacles.push_back(ob);
    s.friction = {0.3, 0.3, 1.0, 1.0};
    const double N = 1.0;
    s.press_m = {0.0, g - eps + N * (1.0 / Kc + 1.0 / K)};
    s.sliding = true;
    // Sliding starts once the lateral force reaches 0.3 N: beyond 0.3 (1/Kc + l^3/(3EI)).
    const double start = 0.3 * (1.0 / Kc + 1.0 / K + l * l * l / (3.0 * EI));
    for (const double f : quick ? std::vector<double>{2.0} : std::vector<double>{1.5, 2.5, 4.0})
      s.hands.push_back({f * start + 5e-3, s.press_m.y()});
    out.push_back(s);
  }
  return out;
}

struct CoreRun {
  std::vector<Vector2d> force_N, tip_m;
  std::vector<bool> valid;  // sliding scenarios: the core says the tip slides
  double us_per_tick = 0.0;
  int ticks = 0;
  std::uint32_t flags = 0;
  // First tick (from 1) a tube and a part overlapped, and ticks whose solve stopped short of its
  // tolerance: where a row's error may stop being the model's.
  int first_penetration_tick = -1;
  int unconverged_ticks = 0;
};

Eigen::Isometry3d HandAt(const Vector2d& xz) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = Eigen::Vector3d(xz.x(), 0.0, xz.y());
  return X;
}

CoreRun RunCore(const scene::Scene& s, const Scenario& sc) {
  core::Core c(s);
  const double dt = s.model.time_step_s;
  double t = 0.0;
  Vector2d hand = Vector2d::Zero();
  CoreRun run;
  Clock::duration spent{};
  const auto move = [&](const Vector2d& target, double duration_s) {
    const int n = std::max(1, static_cast<int>(std::ceil(duration_s / dt - 1e-9)));
    const Vector2d from = hand;
    for (int i = 1; i <= n; ++i) {
      const Vector2d h = from + (target - from) * (double(i) / n);
      const Clock::time_point t0 = Clock::now();
      const core::StepOutput& out = c.Step(t += dt, HandAt(h));
      spent += Clock::now() - t0;
      run.flags |= out.flags;
      ++run.ticks;
      if ((out.flags & core::kPenetration) && run.first_penetration_tick < 0)
        run.first_penetration_tick = run.ticks;
      if (out.flags & core::kNotConverged) ++run.unconverged_ticks;
    }
    hand = target;
  };
  const auto record = [&](bool valid) {
    const core::StepOutput& out = c.last();
    run.force_N.push_back({out.force_W_N.x(), out.force_W_N.z()});
    std::array<Eigen::Vector3d, 2> ends;
    c.Centreline(ends);
    run.tip_m.push_back({ends[1].x(), ends[1].z()});
    run.valid.push_back(valid);
  };
  if (!sc.sliding) {
    for (const Vector2d& target : sc.hands) {
      move(target, 0.2);  // a ramp: 0.2 s
      move(target, 0.2);  // then held: the state settles
      record(true);
    }
  } else {
    move(sc.press_m, 0.2);
    move(sc.press_m, 0.2);
    for (const Vector2d& target : sc.hands) {
      move(target, (target - hand).norm() / sc.speed_m_per_s);
      bool sliding = false;
      for (const core::ContactState& pc : c.last().Contacts()) sliding = sliding || pc.sliding;
      record(sliding);
    }
  }
  run.us_per_tick = Micros(spent) / std::max(1, run.ticks);
  return run;
}

// Sliding sets in at the hand's first step along the wall: friction grows from 0 to mu_k there
// while the rim's smooth minimum is widened, then the width narrows back to the law's. Under the
// law's own width a flat end tipping onto its trailing corner is too sharp a turn for Newton's
// method to follow; the widened law carries the rod across it.
reference::RodSolution SlideOnset(const reference::PlanarRod& rod, reference::Loading load,
                                  const std::vector<double>& kinetic,
                                  std::optional<reference::RodState>& warm) {
  constexpr int kFrictionSteps = 30;
  constexpr double kWideSoftness = 0.1;  // of eps: 0.1 mm on the rubber scene
  const double softness = load.law.rim_softness;
  if (load.law.rim_points > 0) load.law.rim_softness = std::max(softness, kWideSoftness);
  reference::RodSolution sol;
  for (int k = 1; k <= kFrictionSteps; ++k) {
    for (std::size_t j = 0; j < kinetic.size(); ++j)
      load.obstacles[j].kinetic_friction = kinetic[j] * k / kFrictionSteps;
    sol = reference::SolveRod(rod, load, warm);
    warm = sol.state;
  }
  while (load.law.rim_softness > softness) {
    load.law.rim_softness = std::max(softness, 0.7 * load.law.rim_softness);
    sol = reference::SolveRod(rod, load, warm);
    warm = sol.state;
  }
  return sol;
}

// The reference rod along the scenario's path: continuation in hand steps of at most min(r1 / 2,
// 0.5 mm) (a long jump could carry the rod past a thin obstacle to an equilibrium on its far
// side), each solve warm-started from the last. Returns the solutions at the scenario's load
// steps.
std::vector<reference::RodSolution> FollowPath(const reference::PlanarRod& rod, double coupling,
                                               const Scenario& sc, const reference::ContactLaw& law,
                                               double* solve_ms) {
  std::vector<Vector2d> path;
  if (sc.sliding) path.push_back(sc.press_m);
  for (const Vector2d& h : sc.hands) path.push_back(h);
  std::vector<reference::RodSolution> out;
  std::optional<reference::RodState> warm;
  Vector2d last = Vector2d::Zero();
  for (std::size_t i = 0; i < path.size(); ++i) {
    reference::Loading load;
    load.coupling_N_per_m = coupling;
    load.law = law;
    load.obstacles = sc.obstacles;
    // The press before sliding: no sliding yet. The first step along the wall: the hand moves
    // without friction, which then sets in (SlideOnset).
    const bool onset = sc.sliding && i == 1;
    std::vector<double> kinetic;
    for (reference::Obstacle& o : load.obstacles) {
      kinetic.push_back(o.kinetic_friction);
      if (sc.sliding && i == 0) o.slide_sign = 0.0;
      if (onset) o.kinetic_friction = 0.0;
    }
    const int substeps =
        std::max(1, int(std::ceil((path[i] - last).norm() / std::min(0.5 * rod.radius_m, 0.5e-3))));
    for (int k = 1; k <= substeps; ++k) {
      load.hand_m = last + (path[i] - last) * (double(k) / substeps);
      const Clock::time_point t0 = Clock::now();
      const reference::RodSolution sol = reference::SolveRod(rod, load, warm);
      if (solve_ms && k == substeps) *solve_ms += Micros(Clock::now() - t0) / 1000.0;
      warm = sol.state;
      if (k == substeps && (!sc.sliding || i > 1)) out.push_back(sol);
    }
    if (onset) out.push_back(SlideOnset(rod, load, kinetic, warm));
    last = path[i];
  }
  return out;
}

ScenarioReference SolveReference(const scene::Scene& base, double coupling_N_per_m,
                                 const Scenario& sc, const reference::ContactLaw& law, int segments,
                                 const std::string& contact_name) {
  const double EI = model::ComputeSection(base.tube).bending_stiffness_Nm2;
  ScenarioReference ref;
  ref.scenario = sc.name;
  ref.contact = contact_name;
  ref.segments = segments;
  double solve_ms = 0.0;
  const std::vector<reference::RodSolution> coarse =
      FollowPath({base.tube.length_m, EI, base.tube.outer_radius_m, segments / 2}, coupling_N_per_m,
                 sc, law, nullptr);
  const std::vector<reference::RodSolution> fine =
      FollowPath({base.tube.length_m, EI, base.tube.outer_radius_m, segments}, coupling_N_per_m, sc,
                 law, &solve_ms);
  double fmax = 0.0, diff = 0.0;
  for (std::size_t i = 0; i < fine.size(); ++i) {
    const Vector2d f(
        reference::Richardson2(coarse[i].contact_force_N.x(), fine[i].contact_force_N.x()),
        reference::Richardson2(coarse[i].contact_force_N.y(), fine[i].contact_force_N.y()));
    const Vector2d tip(reference::Richardson2(coarse[i].tip_m.x(), fine[i].tip_m.x()),
                       reference::Richardson2(coarse[i].tip_m.y(), fine[i].tip_m.y()));
    ref.step.push_back(sc.sliding ? sc.hands[i].x() : sc.hands[i].norm());
    ref.force_x_N.push_back(f.x());
    ref.force_z_N.push_back(f.y());
    ref.tip_x_m.push_back(tip.x());
    ref.tip_z_m.push_back(tip.y());
    fmax = std::max(fmax, f.norm());
    diff = std::max(diff, (f - fine[i].contact_force_N).norm());
    if (!fine[i].converged || !coarse[i].converged) ref.uncertainty = 1.0;  // flagged below
  }
  ref.uncertainty = std::max(ref.uncertainty, fmax > 0.0 ? diff / fmax : 0.0);
  ref.time_ms = solve_ms / std::max<std::size_t>(1, fine.size() + (sc.sliding ? 1 : 0));
  return ref;
}

struct Setting {
  std::string name;
  scene::TubeModel tube = scene::TubeModel::kRod;
  int elements = 0;  // 0: the scene's
  double dt_s = 1e-3;
  double K = 1e4, eps = 1e-3;
  bool vs_rigid = false;
  bool is_default = false;
};

std::string SettingName(const Setting& s, const scene::Scene& base, int elements) {
  std::string name =
      Fmt("%s N=%d", scene::ToString(s.tube), s.elements > 0 ? s.elements : elements);
  if (s.dt_s != base.model.time_step_s) name += Fmt(" dt=%gms", s.dt_s * 1e3);
  if (s.K != base.contact.stiffness_N_per_m || s.vs_rigid) name += Fmt(" K=%gN/m", s.K);
  if (s.eps != base.contact.threshold_m || s.vs_rigid) name += Fmt(" eps=%gmm", s.eps * 1e3);
  return name;
}

}  // namespace

ConvergenceStudy TipLoadConvergence(double alpha, int max_segments) {
  ConvergenceStudy c;
  c.problem = Fmt("tip load alpha=%g (l = 1, EI = 1)", alpha);
  c.quantity = "tip deflection v/l";
  c.against = "closed-form elastica";
  const double exact = model::SolveElastica(alpha, 0.0).tip.deflection;
  for (int N = 16; N <= max_segments; N *= 2) {
    reference::Loading load;
    load.tip_force_N = {alpha, 0.0};
    const Clock::time_point t0 = Clock::now();
    const reference::RodSolution s = reference::SolveRod({1.0, 1.0, 0.0, N}, load);
    c.time_ms.push_back(Micros(Clock::now() - t0) / 1000.0);
    c.segments.push_back(N);
    c.value.push_back(s.tip_m.x());
    c.error.push_back(std::abs(s.tip_m.x() - exact));
  }
  for (std::size_t i = 1; i < c.error.size(); ++i)
    c.order.push_back(std::log2(c.error[i - 1] / c.error[i]));
  return c;
}

AccuracyReport RunAccuracy(const scene::Scene& base_in, const AccuracyOptions& options) {
  AccuracyReport report;
  report.scene = base_in.name;
  scene::Scene base = base_in;
  // The accuracy scenes keep the tube, contact law and device, with a rigid grip (the reference
  // rod's clamp), no coupling damping (quasi-static: the answer does not depend on the hand's
  // speed) and no workspace limit.
  base.parts.clear();
  base.X_WH_start = Eigen::Isometry3d::Identity();
  base.device.max_torque_Nm = 100.0;
  base.device.coupling_damping_Ns_per_m = 0.0;
  base.workspace.reset();
  {
    core::Core probe(base);
    report.elements = probe.element_count();
    base.device.coupling_stiffness_N_per_m = probe.coupling_stiffness_N_per_m();
  }
  const double Kc = *base.device.coupling_stiffness_N_per_m;

  TipLoadRows(base, options, report);
  report.convergence.push_back(TipLoadConvergence(5.0, options.quick ? 128 : 512));

  const int N = options.quick ? 64 : 128;
  const std::vector<Scenario> scenarios = MakeScenarios(base, options.quick);

  // The settings: the scene's model at its element count, and the rod at other counts (its
  // convergence); the other model; a finer time step; contact stiffness and threshold (these
  // against the rigid contact: how far the penalty law itself is from a hard wall).
  std::vector<Setting> settings;
  const double K0 = base.contact.stiffness_N_per_m, eps0 = base.contact.threshold_m;
  const double dt0 = base.model.time_step_s;
  const scene::TubeModel own = base.model.tube;
  settings.push_back({"", own, 0, dt0, K0, eps0, false, true});
  // The counts the core takes as asked (it keeps elements at least r1 long).
  for (const int n : {8, 12, 16, 32, 48}) {
    scene::Scene asked = base;
    asked.model.elements = n;
    if (n != report.elements && core::ElementCount(asked) == n)
      settings.push_back({"", scene::TubeModel::kRod, n, dt0, K0, eps0});
  }
  settings.push_back(
      {"", own == scene::TubeModel::kRod ? scene::TubeModel::kLinear : scene::TubeModel::kRod, 0,
       dt0, K0, eps0});
  settings.push_back({"", own, 0, dt0 / 4, K0, eps0});
  for (const double k : {0.1, 1.0, 10.0})
    for (const double e : {0.1, 1.0}) settings.push_back({"", own, 0, dt0, k * K0, e * eps0, true});
  for (Setting& s : settings) s.name = SettingName(s, base, report.elements);

  for (const Scenario& sc : scenarios) {
    const ScenarioReference same = SolveReference(
        base, Kc, sc, {K0, eps0, core::kRimSamples, core::kRimSoftness}, N, "same law");
    const ScenarioReference rigid = SolveReference(base, Kc, sc, {10.0 * K0, 0.0}, N, "hard");
    report.references.push_back(same);
    report.references.push_back(rigid);
    for (const Setting& st : settings) {
      scene::Scene s = base;
      s.parts = sc.parts;
      s.friction = sc.friction;
      s.model.tube = st.tube;
      if (st.elements > 0) s.model.elements = st.elements;
      s.model.time_step_s = st.dt_s;
      s.contact.stiffness_N_per_m = st.K;
      s.contact.threshold_m = st.eps;
      const CoreRun run = RunCore(s, sc);
      const ScenarioReference& ref = st.vs_rigid ? rigid : same;
      double fmax = 0.0;
      for (std::size_t i = 0; i < ref.step.size(); ++i)
        fmax = std::max(fmax, std::hypot(ref.force_x_N[i], ref.force_z_N[i]));
      double ferr = 0.0, tiperr = 0.0;
      int compared = 0;
      for (std::size_t i = 0; i < ref.step.size(); ++i) {
        // Sliding scenarios count the steps where the core itself reports sliding; every step
        // is compared (beyond the start of sliding by construction, so the tip should slide).
        if (run.valid[i]) ++compared;
        ferr =
            std::max(ferr, (run.force_N[i] - Vector2d(ref.force_x_N[i], ref.force_z_N[i])).norm());
        tiperr = std::max(tiperr, (run.tip_m[i] - Vector2d(ref.tip_x_m[i], ref.tip_z_m[i])).norm());
      }
      AccuracyRow row;
      row.setting = st.name;
      row.scenario = sc.name + (st.vs_rigid ? " (vs hard contact)" : "");
      row.metric = "operator force, max |dF| / max |F| over the load steps";
      row.error = fmax > 0.0 ? ferr / fmax : std::nan("");
      row.time_us = run.us_per_tick;
      row.is_default = st.is_default;
      row.detail = Fmt("tip position %.3g l; largest reference force %.3g N",
                       tiperr / base.tube.length_m, fmax) +
                   (sc.sliding ? Fmt("; the core reports sliding at %d of %zu steps", compared,
                                     ref.step.size())
                               : std::string());
      if (ref.uncertainty >= 1.0) row.detail += "; REFERENCE NOT CONVERGED at some step";
      if (run.flags & core::kSolverFault) row.detail += "; SOLVER FAULT seen";
      if (run.flags & core::kForceClamped) row.detail += "; force clamped";
      if (run.first_penetration_tick >= 0)
        row.detail += Fmt("; tube and part overlap from tick %d", run.first_penetration_tick);
      if (run.unconverged_ticks > 0)
        row.detail += Fmt("; the solve stopped short of its tolerance in %d of %d ticks",
                          run.unconverged_ticks, run.ticks);
      report.rows.push_back(row);
    }
  }

  // The reference's self-convergence on a contact scenario (side on an edge, last load step).
  {
    const Scenario& sc = scenarios[1];
    ConvergenceStudy c;
    c.problem = sc.name + " (" + base.name + ", last load step)";
    c.quantity = "operator force |F| [N]";
    c.against = "Richardson extrapolation of the two finest";
    const double EI = model::ComputeSection(base.tube).bending_stiffness_Nm2;
    for (int n = 16; n <= (options.quick ? 128 : 256); n *= 2) {
      const reference::PlanarRod rod{base.tube.length_m, EI, base.tube.outer_radius_m, n};
      double ms = 0.0;
      const std::vector<reference::RodSolution> sols = FollowPath(rod, Kc, sc, {K0, eps0}, &ms);
      c.segments.push_back(n);
      c.value.push_back(sols.back().contact_force_N.norm());
      c.time_ms.push_back(ms / double(sols.size()));
    }
    const double best = reference::Richardson2(c.value[c.value.size() - 2], c.value.back());
    for (const double v : c.value) c.error.push_back(std::abs(v - best));
    // The last error is measured against an extrapolation from itself: its order is not shown.
    for (std::size_t i = 1; i + 1 < c.error.size(); ++i)
      c.order.push_back(std::log2(c.error[i - 1] / c.error[i]));
    report.convergence.push_back(c);
  }
  report.notes.push_back("rod elements: " + std::to_string(report.elements) +
                         " here (the scene's model.elements, or the core's default); the 'N=' "
                         "rows show the rod's convergence in its element count");
  report.notes.push_back(
      "contact rows 'vs hard contact' compare with a contact at the geometric surface "
      "(reference K = 10 x the scene's, eps = 0: 0.1 mm in at 1 N on the rubber scene's K): "
      "the penalty law's own error");
  return report;
}

}  // namespace tubeplan::study
