// The beam chain's internals against independent evaluations.
#include "core/beam_chain.hpp"  // private to the core (src/)

#include <cmath>
#include <random>
#include <vector>

#include <catch2/catch.hpp>

using namespace tubeplan;

namespace {
scene::Scene RubberTube() {
  scene::Scene s;
  s.tube = {0.008, 0.005, 0.150, 3e6, 0.5};
  return s;
}

// The bound tests' random draws: a unit vector; the span of an idle group's normals (one axis,
// the plane across it, or every direction) and what a turn's cross product with such a normal
// keeps; and a point i where the bound must hold: at s_max with the offset r_max along the tube's
// axis (where the section's turn moves it along the bend, k = 0, 1), at s_max anywhere (k = 2) or
// anywhere before s_max.
Eigen::Vector3d RandomUnit(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Eigen::Vector3d v(unit(rng), unit(rng), unit(rng));
  return v.norm() > 1e-3 ? v.normalized() : Eigen::Vector3d::UnitX();
}
void GroupSpan(const Eigen::Vector3d& axis, int dims, Eigen::Matrix3d& P, Eigen::Matrix3d& Q) {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity(), aa = axis * axis.transpose();
  P = dims == 1 ? aa : dims == 2 ? Eigen::Matrix3d(I - aa) : I;
  Q = dims == 1 ? Eigen::Matrix3d(I - aa) : I;
}
// A load j of a trial: on the whole tube (every third trial) or on a later segment, whose clamp
// is in the tube's first half; at an arc position beyond its clamp, 8 mm off the centreline.
core::BeamLoad RandomLoad(int trial, double l, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> fraction(0.0, 1.0);
  core::BeamLoad j;
  j.clamp_m = trial % 3 == 0 ? 0.0 : 0.5 * l * fraction(rng);
  j.s_m = j.clamp_m + (l - j.clamp_m) * fraction(rng);
  j.r_H_m = 0.008 * RandomUnit(rng);
  return j;
}
core::BeamLoad BoundPoint(int k, double s_max, double r_max, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> fraction(0.0, 1.0);
  core::BeamLoad i;
  i.s_m = k < 3 ? s_max : s_max * fraction(rng);
  i.r_H_m = k == 0   ? Eigen::Vector3d(0.0, 0.0, r_max)
            : k == 1 ? Eigen::Vector3d(0.0, 0.0, -r_max)
                     : fraction(rng) * r_max * RandomUnit(rng);
  return i;
}
// Checks a displacement bound at a trial's eight points (BoundPoint): moved_at(i) <= bound, up to
// rounding (the bound is a sum of a few products of the same magnitudes). Returns the largest
// moved / bound, to show the bound is not loose.
template <class Moved>
double CheckAtBoundPoints(double bound, double s_max, double r_max, std::mt19937_64& rng,
                          const Moved& moved_at) {
  double tightest = 0.0;
  for (int k = 0; k < 8; ++k) {
    const core::BeamLoad i = BoundPoint(k, s_max, r_max, rng);
    const double moved = moved_at(i);
    INFO("point " << k);
    CHECK(moved <= bound * (1.0 + 1e-12) + 1e-18);
    if (bound > 0.0) tightest = std::max(tightest, moved / bound);
  }
  return tightest;
}
}  // namespace

TEST_CASE("Elastica nodes by Hermite interpolation stay within 2 um of the exact shape",
          "[core][beam]") {
  const scene::Scene s = RubberTube();
  const core::BeamChain beam(s);
  const double EI = beam.bending_stiffness_Nm2(), l = s.tube.length_m;
  for (const double alpha : {0.1, 1.0, 5.0, 10.0}) {
    for (const double s_load : {l, 0.6 * l}) {
      std::array<core::BeamLoad, core::kMaxLoads> loads{};
      // A tip load at 30 degrees to the lateral direction, alpha measured on the loaded length.
      const double F = alpha * EI / (s_load * s_load);
      loads[0] = {s_load,
                  F * Eigen::Vector3d(std::cos(0.5), std::sin(0.5) * 0.0, -std::sin(0.5)),
                  Eigen::Vector3d::Zero(),
                  0.0,
                  0,
                  0};
      std::array<bool, core::kMaxLoads> member{};
      member[0] = true;
      std::array<int, core::kMaxLoads> order{};
      int members = 0;
      const int groups = beam.Assign(loads, 1, member, order, members);
      REQUIRE(groups == 1);
      std::array<core::ElasticaSegment, core::kMaxLoads> segments{};
      const int count = beam.SolveElasticaChain(loads, 1, order, segments);
      std::array<Eigen::Vector3d, 49> nodes;
      beam.ElasticaNodes(segments, count, nodes);
      double worst_m = 0.0;
      for (std::size_t k = 0; k < nodes.size(); ++k) {
        const Eigen::Vector3d exact = beam.ElasticaPoint(segments, count, l * double(k) / 48.0);
        worst_m = std::max(worst_m, (nodes[k] - exact).norm());
      }
      INFO("alpha " << alpha << ", load at " << s_load);
      // 2 um: K (1e4 N/m) times it is 0.02 N of contact force, far below what a hand feels.
      CHECK(worst_m < 2e-6);
    }
  }
}

TEST_CASE("Elastica points walked a segment at a time are the points one by one", "[core][beam]") {
  // ElasticaEvenPoints walks each segment's points by the addition theorems (ElasticaSamples over
  // the points' range); ElasticaPoint evaluates every point on its own by Landen
  // transformations. The walk's own error is below 1e-12 of the segment's length
  // (elastica_test.cpp), so 1e-12 l: two segments (the segmented rule cuts at the first load),
  // 150 points (more than one chunk of 64: a chunk's range starts past the root and ends short
  // of the tip), some beyond the last load where the tube runs straight.
  const scene::Scene s = RubberTube();
  const core::BeamChain beam(s);
  const double EI = beam.bending_stiffness_Nm2(), l = s.tube.length_m;
  std::array<core::BeamLoad, core::kMaxLoads> loads{};
  const double F = 3.0 * EI / (l * l);
  loads[0] = {0.4 * l, F * Eigen::Vector3d(0.8, 0.3, -0.5), Eigen::Vector3d::Zero(), 0.0, 0, 0};
  loads[1] = {0.9 * l, F * Eigen::Vector3d(-0.4, 0.9, -0.2), Eigen::Vector3d::Zero(), 0.0, 0, 1};
  std::array<bool, core::kMaxLoads> member{};
  member[0] = member[1] = true;
  std::array<int, core::kMaxLoads> order{};
  int members = 0;
  REQUIRE(beam.Assign(loads, 2, member, order, members) == 2);
  std::array<core::ElasticaSegment, core::kMaxLoads> segments{};
  const int count = beam.SolveElasticaChain(loads, 2, order, segments);
  REQUIRE(count == 2);
  for (const std::size_t n : {std::size_t{2}, std::size_t{21}, std::size_t{150}}) {
    std::vector<Eigen::Vector3d> points(n);
    beam.ElasticaEvenPoints(segments, count, points);
    double worst_m = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      const double s_m = l * double(k) / double(n - 1);
      worst_m = std::max(worst_m, (points[k] - beam.ElasticaPoint(segments, count, s_m)).norm());
    }
    INFO(n << " points");
    CHECK(worst_m <= 1e-12 * l);
    // And they are the shape: the tip where the second segment's elastica puts it, not straight.
    CHECK((points.back() - Eigen::Vector3d(0.0, 0.0, l)).norm() > 1e-3);
  }
}

TEST_CASE("A rod chain solved with its nodes draws what RodNodes draws of it, bit for bit",
          "[core][beam]") {
  // SolveRodChain given the nodes has each segment's solve draw its share of them on its way
  // (model::Rod::Solve with samples); RodNodes integrates each solved segment once more through
  // the same arc positions. The same discrete rods, so the same bits: under the segmented rule
  // (two segments, the second clamped where the first ends, nodes shared out between them and
  // the straight run beyond the last load) and under the coupled rule (one rod, two loads).
  for (const scene::MultiContactRule rule :
       {scene::MultiContactRule::kSegmented, scene::MultiContactRule::kCoupled}) {
    scene::Scene s = RubberTube();
    s.model.multi_contact = rule;
    const core::BeamChain beam(s);
    const double EI = beam.bending_stiffness_Nm2(), l = s.tube.length_m;
    const double F = 6.0 * EI / (l * l);  // past the elastica's linear range: alpha 6
    std::array<core::BeamLoad, core::kMaxLoads> loads{};
    const Eigen::Vector3d r_H(0.0, s.tube.outer_radius_m, 0.0);
    loads[0] = {0.45 * l, F * Eigen::Vector3d(0.7, -0.4, -0.2), r_H, 0.0, 0, 0};
    loads[1] = {0.8 * l, F * Eigen::Vector3d(-0.3, -0.6, -0.4), r_H, 0.0, 0, 1};
    std::array<bool, core::kMaxLoads> member{};
    member[0] = member[1] = true;
    std::array<int, core::kMaxLoads> order{};
    int members = 0;
    beam.Assign(loads, 2, member, order, members);
    REQUIRE(members == 2);
    std::array<core::RodSegment, core::kMaxLoads> segments{};
    std::array<Eigen::Vector3d, 49> drawn;
    const int count = beam.SolveRodChain(loads, 2, order, segments, drawn);
    INFO((rule == scene::MultiContactRule::kCoupled ? "coupled" : "segmented"));
    REQUIRE(count == (rule == scene::MultiContactRule::kCoupled ? 1 : 2));
    std::array<Eigen::Vector3d, 49> nodes;
    beam.RodNodes(segments, count, nodes);
    int differing = 0;
    for (std::size_t k = 0; k < nodes.size(); ++k)
      if (drawn[k] != nodes[k]) ++differing;
    CHECK(differing == 0);
    CHECK((drawn.back() - Eigen::Vector3d(0.0, 0.0, l)).norm() > 1e-3);  // bent, not straight
  }
}

TEST_CASE("DisplacementBound bounds the compliance of every point up to s_max, along any normal",
          "[core][beam]") {
  // The core leaves an idle part out while this bound of how far a load point could move stays
  // below the part's gap (core.cpp); an open load's row is Compliance(i, j), so the bound must
  // hold for every point i it could be: any arc position up to s_max, any offset up to r_max,
  // and every unit normal n in the span it is given (one axis, the plane across one, or all).
  const scene::Scene s = RubberTube();
  const core::BeamChain chain(s);
  const double l = s.tube.length_m, r_max = 0.03;
  std::mt19937_64 rng(20261125);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), fraction(0.0, 1.0);
  double tightest = 0.0;  // the largest |n . W df| / bound seen
  for (int trial = 0; trial < 20000; ++trial) {
    const core::BeamLoad j = RandomLoad(trial, l, rng);
    const Eigen::Vector3d df_H = 0.1 * unit(rng) * RandomUnit(rng);
    const bool moments = trial % 2 == 0;
    const double s_max = l * fraction(rng);
    const int dims = 1 + trial % 3;
    Eigen::Matrix3d P, Q;
    GroupSpan(RandomUnit(rng), dims, P, Q);
    const double bound = chain.DisplacementBound(j, df_H, moments, r_max, s_max, P, Q);
    INFO("trial " << trial << " dims " << dims);
    // The largest |n . v| over unit n in P's range is |P v|.
    tightest = std::max(tightest, CheckAtBoundPoints(bound, s_max, r_max, rng, [&](const auto& i) {
                          return (P * (chain.Compliance(i, j, moments) * df_H)).norm();
                        }));
  }
  // And it is not loose: some points reach it to within 2 % (a lateral force's bend and turn
  // at s_max, with the offset along the axis, add up along the force).
  CHECK(tightest > 0.98);
}

TEST_CASE("DisplacementChangeBound bounds a force's moved compliance at every point up to s_max",
          "[core][beam]") {
  // The linear model takes last tick's force out where its load was and puts it in where the
  // load that continues it is (core.cpp); an idle part stays out while this bound of the change
  // (Compliance(i, now) - Compliance(i, then)) f stays below its gap. Moves of a few
  // millimetres, the offset turned a little, the clamp the same or not (a cut that moved).
  const scene::Scene s = RubberTube();
  const core::BeamChain chain(s);
  const double l = s.tube.length_m, r_max = 0.03;
  std::mt19937_64 rng(20261126);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), fraction(0.0, 1.0);
  double tightest = 0.0;
  int same_clamp = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const core::BeamLoad then = RandomLoad(trial, l, rng);
    core::BeamLoad now = then;
    if (trial % 5 == 0) now.clamp_m = 0.5 * l * fraction(rng);
    now.s_m = std::clamp(then.s_m + 0.01 * unit(rng), now.clamp_m + 1e-6, l);
    now.r_H_m = (then.r_H_m + 0.002 * RandomUnit(rng)).normalized() * 0.008;
    same_clamp += now.clamp_m == then.clamp_m;
    const Eigen::Vector3d f_H = 5.0 * unit(rng) * RandomUnit(rng);
    const bool moments = trial % 2 == 0;
    const double s_max = l * fraction(rng);
    const int dims = 1 + trial % 3;
    Eigen::Matrix3d P, Q;
    GroupSpan(RandomUnit(rng), dims, P, Q);
    const double bound = chain.DisplacementChangeBound(now, then, f_H, moments, r_max, s_max, P, Q);
    for (int k = 0; k < 8; ++k) {
      const core::BeamLoad i = BoundPoint(k, s_max, r_max, rng);
      const double moved =
          (P * ((chain.Compliance(i, now, moments) - chain.Compliance(i, then, moments)) * f_H))
              .norm();
      INFO("trial " << trial << " dims " << dims << " k " << k);
      // Rounding: the bound is a sum of a few products of the same magnitudes, the change a
      // difference of two compliances of the size of the bound's terms (1e-12 of them).
      const double scale = chain.DisplacementBound(now, f_H, moments, r_max, s_max, P, Q) +
                           chain.DisplacementBound(then, f_H, moments, r_max, s_max, P, Q);
      CHECK(moved <= bound * (1.0 + 1e-12) + 1e-12 * scale + 1e-18);
      if (bound > 0.0 && now.clamp_m == then.clamp_m) tightest = std::max(tightest, moved / bound);
    }
  }
  CHECK(same_clamp > 10000);
  // Not loose where the clamp stays: some points reach it to within 5 %.
  CHECK(tightest > 0.95);
}

TEST_CASE("The moment's compliances are Compliance's moment terms, transposed by Maxwell-Betti",
          "[core][beam]") {
  // The dome's spring (core.cpp) needs the linear beam's response to a moment on the end
  // section: MomentCompliance, TurnCompliance and TurnPerMoment. Each is checked against what
  // Compliance and SectionRotation already give for a load's offset moment (an independent
  // assembly of the same coefficients): a force F at offset r is the force at the centre plus
  // the moment r x F, so Compliance(i, j) - Compliance(i, j at the centre) is
  // MomentCompliance(i, j) [r_j]x; TurnCompliance(s, j) F is SectionRotation(s, j); and the turn
  // per moment is the section's turn under the moment r x F of a force along the axis.
  const scene::Scene s = RubberTube();
  const core::BeamChain chain(s);
  const double l = s.tube.length_m;
  std::mt19937_64 rng(20261128);
  std::uniform_real_distribution<double> fraction(0.0, 1.0);
  const auto skew = [](const Eigen::Vector3d& v) {
    Eigen::Matrix3d m;
    m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
    return m;
  };
  for (int trial = 0; trial < 2000; ++trial) {
    const core::BeamLoad j = RandomLoad(trial, l, rng);
    core::BeamLoad i = RandomLoad(trial, l, rng);
    i.clamp_m = j.clamp_m;
    core::BeamLoad j_centre = j;
    j_centre.r_H_m.setZero();
    const Eigen::Matrix3d scale = chain.Compliance(i, j).cwiseAbs();
    const double tol = 1e-12 * scale.maxCoeff() + 1e-18;
    INFO("trial " << trial);
    CHECK((chain.Compliance(i, j) - chain.Compliance(i, j_centre) -
           chain.MomentCompliance(i, j) * skew(j.r_H_m))
              .cwiseAbs()
              .maxCoeff() <= tol);
    const Eigen::Vector3d F(fraction(rng) - 0.5, fraction(rng) - 0.5, fraction(rng) - 0.5);
    core::BeamLoad j_loaded = j;
    j_loaded.f_H_N = F;
    const Eigen::Vector3d turn = chain.SectionRotation(i.s_m, j_loaded);
    CHECK((chain.TurnCompliance(i.s_m, j) * F - turn).norm() <= 1e-12 * turn.norm() + 1e-18);
    // Maxwell-Betti: i's displacement per moment at j's section is the transpose of j's
    // section's turn per force at i (one clamp), in the lateral directions the model bends in.
    const Eigen::Matrix3d lateral = Eigen::Vector3d(1.0, 1.0, 0.0).asDiagonal();
    CHECK((chain.MomentCompliance(i, j) * lateral -
           chain.TurnCompliance(j.s_m, i).transpose() * lateral)
              .cwiseAbs()
              .maxCoeff() <= tol);
    // The turn per moment: a unit axial force at offset x gives the moment y (x cross z = -y).
    core::BeamLoad axial = j;
    axial.r_H_m = Eigen::Vector3d::UnitX();
    axial.f_H_N = Eigen::Vector3d::UnitZ();
    CHECK(chain.TurnPerMoment(j) ==
          Approx(-chain.SectionRotation(j.s_m, axial).y()).epsilon(1e-12));
  }
}

TEST_CASE("MomentDisplacementBound bounds a moment's displacement of every point up to s_max",
          "[core][beam]") {
  const scene::Scene s = RubberTube();
  const core::BeamChain chain(s);
  const double l = s.tube.length_m, r_max = 0.03;
  std::mt19937_64 rng(20261129);
  std::uniform_real_distribution<double> fraction(0.0, 1.0);
  double tightest = 0.0;
  for (int trial = 0; trial < 5000; ++trial) {
    const core::BeamLoad at = RandomLoad(trial, l, rng);
    const Eigen::Vector3d M = 0.05 * fraction(rng) * RandomUnit(rng);
    const double s_max = l * fraction(rng);
    const double bound = chain.MomentDisplacementBound(at, M.norm(), r_max, s_max);
    INFO("trial " << trial);
    tightest = std::max(tightest, CheckAtBoundPoints(bound, s_max, r_max, rng, [&](const auto& i) {
                          return (chain.MomentCompliance(i, at) * M).norm();
                        }));
  }
  // Not loose: a moment's bend and turn at s_max add up for an offset along the axis (2 %).
  CHECK(tightest > 0.98);
}
