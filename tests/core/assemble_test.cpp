// The solve's gradient against central differences of its own energy, on random bent tubes
// near an edge and a wall: every contact term (a node's sphere and its fading share, the smooth
// side about a node on the edge, the end's rim, the end face on a corner) and the rod's and the
// coupling's; and its Hessian (band and rank-one terms, the rim's and the end face's turn with
// the end) against central differences of the gradient.
#include "core/assemble.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include <catch2/catch.hpp>

#include "core/contacts.hpp"
#include "core/data.hpp"
#include "core/model.hpp"

using namespace tubeplan;

namespace {

constexpr double kPi = 3.14159265358979323846;

scene::Part Cube(const std::string& name, double size_m, const Eigen::Vector3d& centre,
                 double turn_y_rad, const Eigen::Matrix3d& then = Eigen::Matrix3d::Identity()) {
  scene::Part b;
  b.name = name;
  b.size_m = Eigen::Vector3d::Constant(size_m);
  b.X_WP.linear() =
      then * Eigen::AngleAxisd(turn_y_rad, Eigen::Vector3d::UnitY()).toRotationMatrix();
  b.X_WP.translation() = centre;
  return b;
}

// The scene's model and its data at the start pose, as a Core builds them, without a tick.
void Build(const scene::Scene& s, core::Model& model, core::Data& data) {
  std::vector<scene::PartElement> elements;
  std::vector<std::uint32_t> reachable;
  core::BuildModel(s, model, elements, reachable);
  core::InitData(model, s.X_WH_start, data);
}

// The rubber tube of scenes/groove.yaml (18 elements) on an undamped coupling, nothing else.
scene::Scene Rubber() {
  scene::Scene s;
  s.tube = {8e-3, 5e-3, 0.15, 3e6, 0.5};
  s.contact = {1e4, 1e-3, 1e-4};
  s.device.coupling_stiffness_N_per_m = 400.0;
  s.device.coupling_damping_Ns_per_m = 0.0;
  return s;
}

// The rubber tube of scenes/groove.yaml (18 elements) on an undamped coupling, over a floor: a
// box of the given size whose top is at z = 0, centred over (x, y).
scene::Scene RubberOverFloor(const Eigen::Vector3d& size_m, double x_m, double y_m) {
  scene::Scene s = Rubber();
  scene::Part floor;
  floor.name = "floor";
  floor.size_m = size_m;
  floor.X_WP.translation() = Eigen::Vector3d(x_m, y_m, -0.5 * size_m.z());
  s.parts = {floor};
  return s;
}

// The solve's gradient with the nodes x moved by `step`, the contacts found again (the sections'
// choices pending, as within a tick).
Eigen::VectorXd GradientAt(const core::Model& model, core::Data& data,
                           const std::vector<Eigen::Vector3d>& x, const Eigen::VectorXd& step) {
  std::vector<Eigen::Vector3d> y = x;
  for (std::size_t k = 0; k < y.size(); ++k) y[k] += step.segment<3>(3 * int(k));
  core::FindContacts(model, y, data, core::Choices::kPending);
  core::Assemble(model, data, y, core::Derivatives::kGradient);
  return data.scratch.gradient;
}

// The nodes on the centreline `along` (its point at arc length s), each but the held end's moved
// by up to 0.2 mm at random.
std::vector<Eigen::Vector3d> JiggledNodes(const core::Model& model,
                                          const std::function<Eigen::Vector3d(double)>& along,
                                          std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const int n = model.rod.elements;
  std::vector<Eigen::Vector3d> x(std::size_t(n) + 1);
  for (int k = 0; k <= n; ++k) {
    const Eigen::Vector3d jiggle(u01(rng) - 0.5, u01(rng) - 0.5, u01(rng) - 0.5);
    x[std::size_t(k)] = along(k * model.rod.segment_m) + (k == 0 ? 0.0 : 0.4e-3) * jiggle;
  }
  return x;
}

// Checks the gradient at x against central differences of the energy, the contact points found
// again at each point (the sections' nearest directions kept, as within a tick). Returns the
// number of unknowns checked.
int CheckGradientByDifferences(const core::Model& model, core::Data& data,
                               const std::vector<Eigen::Vector3d>& x,
                               const Eigen::VectorXd& gradient) {
  const double h = 1e-8;
  const auto energy = [&](int unknown, double by) {
    std::vector<Eigen::Vector3d> y = x;
    y[std::size_t(unknown / 3)][unknown % 3] += by;
    core::FindContacts(model, y, data, core::Choices::kPending);
    return core::Assemble(model, data, y, core::Derivatives::kNone);
  };
  const double scale = gradient.lpNorm<Eigen::Infinity>();
  for (int k = 0; k < gradient.size(); ++k) {
    const double fd = (energy(k, h) - energy(k, -h)) / (2.0 * h);
    INFO("unknown " << k << " (node " << k / 3 << ")");
    // Truncation h^2 E''' and the energy's rounding over 2h leave ~1e-7 of the largest force.
    CHECK(gradient[k] == Approx(fd).margin(1e-6 * scale + 1e-9));
  }
  return int(gradient.size());
}

}  // namespace

TEST_CASE("The solve's gradient is its energy's derivative, in contact", "[core][gradient]") {
  // The rubber tube of scenes/groove.yaml (18 elements), held at the origin along +z and bent
  // in the x-z plane; an edge along y beside it (a cube turned 45 deg), a wall across its end.
  scene::Scene s = Rubber();
  const double l = s.tube.length_m, r1 = s.tube.outer_radius_m, eps = s.contact.threshold_m;
  std::mt19937_64 rng(20261202);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  int nodes_fading = 0, sides = 0, rims = 0, checked = 0;
  for (int trial = 0; trial < 60; ++trial) {
    // The centreline: an arc of curvature kappa, each node moved up to 0.2 mm at random.
    const double kappa = 6.0 * u01(rng);
    const auto arc = [&](double s_m) {
      return kappa < 1e-9 ? Eigen::Vector3d(0.0, 0.0, s_m)
                          : Eigen::Vector3d((1.0 - std::cos(kappa * s_m)) / kappa, 0.0,
                                            std::sin(kappa * s_m) / kappa);
    };
    const auto tangent = [&](double s_m) {
      return Eigen::Vector3d(std::sin(kappa * s_m), 0.0, std::cos(kappa * s_m));
    };
    // The edge beside the arc at 0.3-0.8 l, on its convex side, from 0.5 mm inside to 1 mm
    // beyond the band; the wall facing the end, from 0.5 mm inside to 1 mm beyond.
    const double s_edge = (0.3 + 0.5 * u01(rng)) * l;
    const Eigen::Vector3d t_e = tangent(s_edge), n_e(t_e.z(), 0.0, -t_e.x());
    const Eigen::Vector3d edge_W = arc(s_edge) + (r1 + eps * (1.5 * u01(rng) - 0.5)) * n_e;
    const double half_diagonal = 0.02 * std::sqrt(2.0);
    // Every other trial turns the edge towards the tube's tangent (5-30 deg between them), where
    // the smooth side's share and the node spheres' fade with the angle.
    const double turn = trial % 2 == 0 ? 0.0 : (60.0 + 25.0 * u01(rng)) * kPi / 180.0;
    s.parts = {
        Cube("edge", 0.04, edge_W + half_diagonal * n_e, std::atan2(n_e.x(), n_e.z()) + kPi / 4.0,
             Eigen::AngleAxisd(turn, n_e).toRotationMatrix()),
        Cube("wall", 0.04, arc(l) + (eps * (1.5 * u01(rng) - 0.5) + 0.02) * tangent(l),
             std::atan2(tangent(l).x(), tangent(l).z()))};
    s.X_WH_start = Eigen::Isometry3d::Identity();
    core::Model model;
    core::Data data;
    Build(s, model, data);
    const std::vector<Eigen::Vector3d> x = JiggledNodes(model, arc, rng);
    data.input.p_hand_W = Eigen::Vector3d(0.3e-3, -0.2e-3, 0.1e-3);

    core::FindContacts(model, x, data, core::Choices::kKeep);
    core::Assemble(model, data, x, core::Derivatives::kGradient);
    const Eigen::VectorXd gradient = data.scratch.gradient;
    bool fading = false, side = false, rim = false;
    for (int k = 0; k < data.scratch.sample_count; ++k) {
      const core::Sample& smp = data.scratch.samples[std::size_t(k)];
      if (!(smp.distance_m < eps)) continue;
      fading = fading || (smp.kind == core::SampleKind::kNode && smp.weight_nodes > 0);
      side = side || smp.kind == core::SampleKind::kCurve;
      rim = rim || smp.kind == core::SampleKind::kRim;
    }
    nodes_fading += fading;
    sides += side;
    rims += rim;

    INFO("trial " << trial);
    checked += CheckGradientByDifferences(model, data, x, gradient);
  }
  // Every kind of term was in contact in some of the trials.
  CHECK(nodes_fading > 0);
  CHECK(sides > 0);
  CHECK(rims > 0);
  CHECK(checked == 60 * 3 * 19);
}

TEST_CASE("An end face on a part's corner: its share fades with the gradient of its energy",
          "[core][gradient]") {
  // The rubber tube held along +z, its nodes moved up to 0.2 mm at random (the end turns), its
  // end face on the corner of a cube that points down the tube: the corner at a random distance
  // from the axis inside a band where the face's share fades, at the rim (7.2-8 mm) or at the
  // bore (5-5.8 mm), from 0.5 mm into the face to 0.9 mm off it. The share moves with the end
  // element as the corner's distance from the axis does: a gradient without that would hide the
  // energy's slope across the band (K eps^2 / 2 over 0.8 mm, ~6 N) from the solve.
  scene::Scene s = Rubber();
  const double l = s.tube.length_m, r1 = s.tube.outer_radius_m, r2 = s.tube.inner_radius_m;
  const double band_m = 0.1 * r1, size_m = 0.02;
  const Eigen::Matrix3d corner_down =
      Eigen::Quaterniond::FromTwoVectors(-Eigen::Vector3d::Ones().normalized(),
                                         -Eigen::Vector3d::UnitZ())
          .toRotationMatrix();
  std::mt19937_64 rng(20261206);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::array<int, 2> fading{};  // trials whose share fades in the rim's band, in the bore's
  int checked = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const double rr = (trial % 2 == 0 ? r1 - band_m : r2) + band_m * u01(rng);
    const double ahead_m = -0.5e-3 + 1.4e-3 * u01(rng);
    const Eigen::Vector3d corner_W(rr * std::cos(trial), rr * std::sin(trial), l + ahead_m);
    scene::Part cube;
    cube.name = "cube";
    cube.size_m = Eigen::Vector3d::Constant(size_m);
    // With friction, the rim's points stay where they met the part for the tick (the end face is
    // checked here, not the rim's ring placed afresh on a frictionless corner).
    cube.friction = {0.5, 0.3, 1.0, 1.0};
    cube.X_WP.linear() = corner_down;
    cube.X_WP.translation() = corner_W + 0.5 * std::sqrt(3.0) * size_m * Eigen::Vector3d::UnitZ();
    s.parts = {cube};
    s.X_WH_start = Eigen::Isometry3d::Identity();
    core::Model model;
    core::Data data;
    Build(s, model, data);
    const std::vector<Eigen::Vector3d> x = JiggledNodes(
        model, [](double s_m) { return Eigen::Vector3d(0.0, 0.0, s_m); }, rng);
    data.input.p_hand_W = Eigen::Vector3d(0.3e-3, -0.2e-3, 0.1e-3);
    core::FindContacts(model, x, data, core::Choices::kKeep);
    core::Assemble(model, data, x, core::Derivatives::kGradient);
    const Eigen::VectorXd gradient = data.scratch.gradient;
    bool fades = false;
    for (int k = 0; k < data.scratch.sample_count; ++k) {
      const core::Sample& smp = data.scratch.samples[std::size_t(k)];
      fades = fades || (smp.kind == core::SampleKind::kEndFace && smp.distance_m < 1e-3 &&
                        smp.weight > 0.0 && smp.weight < 1.0);
    }
    fading[std::size_t(trial % 2)] += fades;
    INFO("trial " << trial << ": corner " << rr * 1e3 << " mm from the axis, " << ahead_m * 1e3
                  << " mm ahead");
    checked += CheckGradientByDifferences(model, data, x, gradient);
  }
  // Most trials of each band press a fading share (the jiggle can move the corner out of it).
  CHECK(fading[0] >= 5);
  CHECK(fading[1] >= 5);
  CHECK(checked == 20 * 3 * 19);
}

TEST_CASE("An element's side on an edge bears continuously across the edge's face planes",
          "[core]") {
  // The rubber tube straight along +z, beside a wall whose face ends in an edge (along y)
  // across the tube at 45 mm, 0.5 mm off the tube's side: the element there lies along the face
  // and meets the edge. Its axis point nearest the edge lies on the plane of the wall's end face,
  // in front of or behind it as the tube tilts by a hair; the edge's share must not switch on and
  // off there, or the solve meets a step in its energy that no Newton step can descend (a tube
  // squeezed between two such walls would stall with 3 N left over).
  scene::Scene s;
  s.tube = {8e-3, 5e-3, 0.15, 3e6, 0.5};
  s.contact = {1e4, 1e-3, 1e-4};
  const double r1 = s.tube.outer_radius_m, half = r1 + 0.5e-3, height = 0.2;
  scene::Part wall;
  wall.name = "wall";
  wall.size_m = {0.1, 0.4, height};
  wall.X_WP.translation() = Eigen::Vector3d(-half - 0.05, 0.0, 0.045 + height / 2);
  s.parts = {wall};
  core::Model model;
  core::Data data;
  Build(s, model, data);
  const int n = model.rod.elements;
  std::vector<Eigen::Vector3d> x(std::size_t(n) + 1);
  std::vector<double> energy_J;
  // Tilts of -0.05 .. 0.05 deg towards the wall (the end moves 0.13 mm): the axis point crosses
  // the end face's plane by +-7 um.
  const int steps = 1000;
  for (int k = 0; k <= steps; ++k) {
    const double tilt = (-0.05 + 0.1 * k / steps) * kPi / 180.0;
    const Eigen::Vector3d t(-std::sin(tilt), 0.0, std::cos(tilt));
    for (int j = 0; j <= n; ++j) x[std::size_t(j)] = (j * model.rod.segment_m) * t;
    core::FindContacts(model, x, data, core::Choices::kKeep);
    energy_J.push_back(core::Assemble(model, data, x, core::Derivatives::kNone));
  }
  // Smoothly, the energy (1.2e-2 J) changes by ~1e-5 J a step and that change by ~1e-9 J; the
  // edge's share switching at the plane would step by K/2 (0.5 mm)^2 = 1.25e-3 J.
  double kink_J = 0.0;
  for (int k = 1; k < steps; ++k)
    kink_J =
        std::max(kink_J, std::abs(energy_J[std::size_t(k + 1)] - 2.0 * energy_J[std::size_t(k)] +
                                  energy_J[std::size_t(k - 1)]));
  CHECK(energy_J.back() > 1e-3);
  CHECK(kink_J < 1e-6);
}

TEST_CASE("The solve's Hessian, band and rank-one terms, is its gradient's derivative",
          "[core][gradient]") {
  // The rubber tube lying level along a floor, every section within epsilon: its sections press
  // as one contact whose smooth minimum spreads over all of them, so its Hessian has a term
  // coupling every node (the rank-one term the solve adds to the band). Tipped up by 0.5 mm
  // over its length, its held end bears alone and the term fits in the band. Either way, H v
  // must be the central difference of the gradient along v.
  scene::Scene s = RubberOverFloor({0.4, 0.2, 0.02}, 0.1, 0.0);
  const double l = s.tube.length_m, r1 = s.tube.outer_radius_m;
  s.X_WH_start.linear() =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX())
          .toRotationMatrix();
  std::mt19937_64 rng(20261203);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (const double rise_m : {0.0, 0.5e-3}) {
    core::Model model;
    core::Data data;
    Build(s, model, data);
    const int n = model.rod.elements;
    std::vector<Eigen::Vector3d> x(std::size_t(n) + 1);
    for (int k = 0; k <= n; ++k) {
      const double along = k * model.rod.segment_m;
      x[std::size_t(k)] = Eigen::Vector3d(along, 0.0, r1 + 0.4e-3 + rise_m * along / l);
    }
    data.input.p_hand_W = x[0] + Eigen::Vector3d(0.0, 0.0, -0.2e-3);
    core::FindContacts(model, x, data, core::Choices::kKeep);
    core::Assemble(model, data, x, core::Derivatives::kHessian);
    const core::Scratch& sc = data.scratch;
    INFO("rise " << rise_m << " m: " << sc.factors.low_rank_count << " rank-one terms");
    CHECK(sc.factors.low_rank_count == (rise_m == 0.0 ? 1 : 0));
    const core::BandMatrix band = sc.hessian;
    std::vector<Eigen::VectorXd> u;
    std::vector<double> c;
    for (int i = 0; i < sc.factors.low_rank_count; ++i) {
      u.push_back(sc.factors.low_rank_u[std::size_t(i)]);
      c.push_back(sc.factors.low_rank_c[std::size_t(i)]);
    }
    for (int trial = 0; trial < 6; ++trial) {
      Eigen::VectorXd v(3 * (n + 1));
      for (int i = 0; i < v.size(); ++i) v[i] = u01(rng) - 0.5;
      Eigen::VectorXd Hv(v.size());
      band.Multiply(v, Hv);
      for (std::size_t i = 0; i < u.size(); ++i) Hv += c[i] * u[i].dot(v) * u[i];
      // A step far inside the smooth minimum's width (kRimSoftness eps = 0.2 um), where its
      // weights change smoothly; the gradient's rounding (1e-16 of ~1 N over 2e-11 m) is ~1e-5
      // of H v's ~F / tau.
      const double h = 1e-11;
      const Eigen::VectorXd fd =
          (GradientAt(model, data, x, h * v) - GradientAt(model, data, x, -h * v)) / (2.0 * h);
      const double scale = Hv.lpNorm<Eigen::Infinity>();
      INFO("trial " << trial);
      CHECK((Hv - fd).lpNorm<Eigen::Infinity>() < 1e-4 * scale);
    }
  }
}

TEST_CASE("On a frictionless part the rim's Hessian is its gradient's derivative",
          "[core][gradient]") {
  // The rubber tube straight, 30 deg from plumb, its end's rim pressed 0.1 mm into a frictionless
  // floor: one rim point bears about 1 N. The ring is placed afresh at the nearest point at every
  // iterate, so turning the end moves the bearing point on the rim to second order, by about
  // F r1 / h^2 (~100 N/m against the contact's K = 1e4 and bending's EI / h^3 ~ 1e4 N/m), both as
  // a material point turning with the end and as the ring turning to the nearest point. Steps
  // across the tube at every node (the stiff axial springs of the straight tube do not resist
  // them to first order) must see both in H v as in the central difference of the gradient.
  scene::Scene s = RubberOverFloor({0.4, 0.4, 0.02}, 0.0, 0.0);
  const double r1 = s.tube.outer_radius_m, eps = s.contact.threshold_m;
  const double tilt = 30.0 * kPi / 180.0;
  const Eigen::Vector3d d(std::sin(tilt), 0.0, -std::cos(tilt));
  s.X_WH_start.linear() =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), d).toRotationMatrix();
  core::Model model;
  core::Data data;
  Build(s, model, data);
  const int n = model.rod.elements;
  // The rim's lowest point is r1 sin(tilt) below the end's centre; it is put eps - 0.1 mm above
  // the floor's top.
  const double end_z = eps - 1e-4 + r1 * std::sin(tilt);
  std::vector<Eigen::Vector3d> x(std::size_t(n) + 1);
  for (int k = 0; k <= n; ++k)
    x[std::size_t(k)] = Eigen::Vector3d(0.0, 0.0, end_z) - (n - k) * model.rod.segment_m * d;
  data.input.p_hand_W = x[0];
  data.input.tangent_held_W = d;
  core::FindContacts(model, x, data, core::Choices::kKeep);
  core::Assemble(model, data, x, core::Derivatives::kHessian);
  const core::Scratch& sc = data.scratch;
  double rim_force_N = 0.0;
  for (int k = 0; k < sc.sample_count; ++k)
    if (sc.samples[std::size_t(k)].kind == core::SampleKind::kRim)
      rim_force_N += sc.samples[std::size_t(k)].normal_force_N;
  CHECK(rim_force_N == Approx(1.0).epsilon(0.01));
  REQUIRE(sc.factors.low_rank_count == 0);
  const core::BandMatrix band = sc.hessian;
  std::mt19937_64 rng(20261205);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const Eigen::Vector3d across_1 = d.unitOrthogonal(), across_2 = d.cross(across_1);
  for (int trial = 0; trial < 6; ++trial) {
    Eigen::VectorXd v(3 * (n + 1));
    for (int k = 0; k <= n; ++k)
      v.segment<3>(3 * k) = (u01(rng) - 0.5) * across_1 + (u01(rng) - 0.5) * across_2;
    Eigen::VectorXd Hv(v.size());
    band.Multiply(v, Hv);
    // A step far inside the rim's smooth minimum's width (0.2 um): the rounding of the stiff
    // axial springs' forces (1.8e7 N/m times ~1e-17 m over 2e-9 m) leaves 0.2-0.5 N/m, 1e-5 of
    // H v's ~6e4 N/m; the turn's terms are ~100 N/m.
    const double h = 1e-9;
    const Eigen::VectorXd fd =
        (GradientAt(model, data, x, h * v) - GradientAt(model, data, x, -h * v)) / (2.0 * h);
    const double scale = Hv.lpNorm<Eigen::Infinity>();
    INFO("trial " << trial << ": |H v| " << scale << " N/m, |H v - fd| "
                  << (Hv - fd).lpNorm<Eigen::Infinity>() << " N/m");
    // 1e-4 of H v: a hundredth of the turn's term.
    CHECK((Hv - fd).lpNorm<Eigen::Infinity>() < 1e-4 * scale);
  }
}

TEST_CASE("An end face on a part's corner: its Hessian is its gradient's derivative",
          "[core][gradient]") {
  // The rubber tube held along +z, its nodes moved up to 0.2 mm at random (the end turns), its
  // end face pressed by the corner of a cube that points down the end's axis, placed in the end's
  // own frame: 5.9-6.6 mm from the axis (the share whole) and 0.4-0.9 mm ahead of the face (the
  // rim, at least 1.4 mm across the cube's rising faces from the corner, stays beyond eps). The
  // face turns with the end element, so its distance to the corner curves with the end's two
  // nodes: K (eps - d) d'' is of order F / h here (F 1-6 N, h 8.3 mm: 100-700 N/m). Steps across
  // the tube at every node, and along it at the end's two nodes, must see it in H v as in the
  // central difference of the gradient.
  scene::Scene s = Rubber();
  const double size_m = 0.02;
  std::mt19937_64 rng(20261207);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (int trial = 0; trial < 10; ++trial) {
    s.X_WH_start = Eigen::Isometry3d::Identity();
    s.parts.clear();
    core::Model model;
    core::Data data;
    Build(s, model, data);
    const int n = model.rod.elements;
    const std::vector<Eigen::Vector3d> x = JiggledNodes(
        model, [](double s_m) { return Eigen::Vector3d(0.0, 0.0, s_m); }, rng);
    const Eigen::Vector3d t = (x[std::size_t(n)] - x[std::size_t(n - 1)]).normalized();
    const Eigen::Vector3d across = t.unitOrthogonal();
    const double rr = 5.9e-3 + 0.7e-3 * u01(rng);
    const double ahead_m = 0.4e-3 + 0.5e-3 * u01(rng);
    const Eigen::Vector3d corner_W = x[std::size_t(n)] +
                                     rr * Eigen::AngleAxisd(trial, t).toRotationMatrix() * across +
                                     ahead_m * t;
    scene::Part cube;
    cube.name = "cube";
    cube.size_m = Eigen::Vector3d::Constant(size_m);
    cube.friction = {0.5, 0.3, 1.0, 1.0};
    cube.X_WP.linear() =
        Eigen::Quaterniond::FromTwoVectors(-Eigen::Vector3d::Ones().normalized(), -t)
            .toRotationMatrix();
    cube.X_WP.translation() = corner_W + 0.5 * std::sqrt(3.0) * size_m * t;
    s.parts = {cube};
    Build(s, model, data);
    data.input.p_hand_W = Eigen::Vector3d(0.3e-3, -0.2e-3, 0.1e-3);
    core::FindContacts(model, x, data, core::Choices::kKeep);
    core::Assemble(model, data, x, core::Derivatives::kHessian);
    const core::Scratch& sc = data.scratch;
    // One contact point within eps: the corner on the face, its share whole.
    int faces = 0, others = 0;
    for (int k = 0; k < sc.sample_count; ++k) {
      const core::Sample& smp = sc.samples[std::size_t(k)];
      if (!(smp.distance_m < s.contact.threshold_m)) continue;
      const bool whole_face = smp.kind == core::SampleKind::kEndFace && smp.weight == 1.0;
      faces += whole_face;
      others += !whole_face;
    }
    INFO("trial " << trial << ": corner " << rr * 1e3 << " mm from the axis, " << ahead_m * 1e3
                  << " mm ahead");
    CHECK(faces == 1);
    CHECK(others == 0);
    REQUIRE(sc.factors.low_rank_count == 0);
    Eigen::VectorXd v(3 * (n + 1));
    for (int k = 0; k <= n; ++k) {
      const Eigen::Vector3d jiggle(u01(rng) - 0.5, u01(rng) - 0.5, u01(rng) - 0.5);
      v.segment<3>(3 * k) = k >= n - 1 ? jiggle : Eigen::Vector3d(jiggle - jiggle.dot(t) * t);
    }
    Eigen::VectorXd Hv(v.size());
    sc.hessian.Multiply(v, Hv);
    const double h = 1e-7;
    const Eigen::VectorXd fd =
        (GradientAt(model, data, x, h * v) - GradientAt(model, data, x, -h * v)) / (2.0 * h);
    const double off_N_per_m = (Hv - fd).lpNorm<Eigen::Infinity>();
    INFO("|H v| " << Hv.lpNorm<Eigen::Infinity>() << " N/m, |H v - fd| " << off_N_per_m << " N/m");
    // A step of 0.1 um keeps the rounding of the stiff axial springs' forces (1.8e7 N/m times
    // ~1e-17 m over 2e-7 m) and the truncation below 0.01 N/m (measured 0.002-0.006): 0.1 N/m
    // is a fiftieth of the least part of the face's turn these steps reach (K (eps - d) a / h^2
    // over a de ~0.5 mm: 5-25 N/m).
    CHECK(off_N_per_m < 0.1);
  }
}
