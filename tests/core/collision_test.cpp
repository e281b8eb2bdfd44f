// The core's closed-form distances against FCL's GJK, an independent method.
#include "core/collision.hpp"  // private to the core (src/)

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <span>
#include <vector>

#include <catch2/catch.hpp>
#include <fcl/narrowphase/detail/gjk_solver_indep.h>

#include <tubeplan/io/scene_yaml.hpp>

using namespace tubeplan;

namespace {

Eigen::Isometry3d SegmentPose(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.translation() = 0.5 * (a + b);
  X.linear() =
      Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), b - a).toRotationMatrix();
  return X;
}

// FCL's GJK as the core configures it: 1e-12 (its default 1e-6 leaves micrometres in d).
fcl::detail::GJKSolver_indep<double> TightGjk() {
  fcl::detail::GJKSolver_indep<double> gjk;
  gjk.gjk_tolerance = 1e-12;
  gjk.gjk_max_iterations = 128;
  return gjk;
}

}  // namespace

TEST_CASE("End cylinder near a box face: the closed form agrees with GJK", "[core][collision]") {
  // The groove scene's end piece (r1 = 8 mm, 12.5 mm long) around a 60 x 200 x 10 mm floor.
  const double r = 0.008, length = 0.0125;
  const Eigen::Vector3d half(0.03, 0.1, 0.005);
  fcl::detail::GJKSolver_indep<double> gjk = TightGjk();
  const fcl::Boxd box(2.0 * half);
  const fcl::Cylinderd cylinder(r, length);
  std::mt19937_64 rng(20261123);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int certified = 0, exact_ties = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    // Centres within a few radii of the box, axes in every direction; every tenth axis exactly
    // along a box axis or across it (the end face or a generator parallel to a face: the ties).
    const Eigen::Vector3d centre(unit(rng) * 0.05, unit(rng) * 0.12, unit(rng) * 0.03);
    Eigen::Vector3d u(unit(rng), unit(rng), unit(rng));
    if (trial % 10 == 0) u = Eigen::Vector3d::Unit(trial / 10 % 3) * (trial % 20 == 0 ? 1 : -1);
    if (trial % 10 == 5) u = Eigen::Vector3d(unit(rng), unit(rng), 0.0);
    if (!(u.norm() > 1e-3)) continue;
    u.normalize();
    const Eigen::Vector3d a = centre - 0.5 * length * u, b = centre + 0.5 * length * u;
    double d = 0.0;
    Eigen::Vector3d p, q;
    if (!core::CylinderBoxFaceDistance(a, b, r, half, d, p, q)) continue;
    ++certified;
    if (trial % 10 == 0 || trial % 10 == 5) ++exact_ties;
    double d_gjk = 0.0;
    Eigen::Vector3d p_gjk, q_gjk;
    const bool separated = gjk.shapeDistance(cylinder, SegmentPose(a, b), box,
                                             Eigen::Isometry3d::Identity(), &d_gjk, &p_gjk, &q_gjk);
    INFO("trial " << trial << " centre " << centre.transpose() << " axis " << u.transpose());
    REQUIRE(separated);
    // GJK at tolerance 1e-12 on a curved shape converges to ~1e-9 m here (a few iterations
    // short of the exact support point); the closed form is exact to rounding.
    CHECK(d == Approx(d_gjk).margin(1e-8));
    // The returned points are on the shapes and d apart.
    CHECK((p - q).norm() == Approx(d).margin(1e-12));
    CHECK((q.cwiseAbs() - half).maxCoeff() <= 1e-15);
    const double along = (p - a).dot(u);
    CHECK(along >= -1e-12);
    CHECK(along <= length + 1e-12);
    CHECK((p - a - along * u).norm() <= r + 1e-12);
  }
  // The certificate holds for most poses near a face (those where a face, not an edge or a
  // vertex, is nearest): the test must have compared many, ties included.
  CHECK(certified > 1000);
  CHECK(exact_ties > 50);
}

TEST_CASE("Segment to box: the closed form against dense sampling", "[core][collision]") {
  // The squared distance from a point to the box is exact (clamp); sampling the segment at 20001
  // points, both ends included, bounds the minimum from above. An interior minimum of a smooth
  // convex piece is flat, so the samples come within ~(step)^2 / length of it (< 1e-9 m here):
  // the closed form must never exceed them and must be that close.
  const Eigen::Vector3d half(0.03, 0.1, 0.005);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const auto point_sq = [&](const Eigen::Vector3d& x) {
    return (x.cwiseAbs() - half).cwiseMax(0.0).squaredNorm();
  };
  int one_face = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    Eigen::Vector3d a(unit(rng) * 0.05, unit(rng) * 0.12, unit(rng) * 0.02);
    Eigen::Vector3d b = a + 0.004 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    if (trial % 2 == 0) {  // over the top face, both ends beyond it: the fast path
      a.z() = half.z() + 1e-4 + 0.003 * std::abs(unit(rng));
      b.z() = half.z() + 1e-4 + 0.003 * std::abs(unit(rng));
      a.x() = 0.02 * unit(rng), b.x() = 0.02 * unit(rng);
      ++one_face;
    }
    double t = -1.0;
    const double f = core::SegmentBoxDistanceSquared(a, b, half, t);
    double sampled = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= 20000; ++i)
      sampled = std::min(sampled, point_sq(a + (i / 20000.0) * (b - a)));
    INFO("trial " << trial);
    CHECK(f <= sampled + 1e-18);
    CHECK(std::sqrt(f) == Approx(std::sqrt(sampled)).margin(1e-9));
    CHECK(point_sq(a + t * (b - a)) == Approx(f).margin(1e-18));
  }
  CHECK(one_face == 1000);
}

TEST_CASE("End cylinder pressed into a box: the depth through a face", "[core][collision]") {
  // The groove scene's end piece (r1 = 8 mm, 12.5 mm long) pressed into a 60 x 200 x 10 mm floor.
  const double r = 0.008, length = 0.0125;
  const Eigen::Vector3d half(0.03, 0.1, 0.005);
  double depth = 0.0;
  Eigen::Vector3d p, q, n;

  SECTION("end face flat on the top face: the depth is how far it is pressed in") {
    // Axis along -z, end face 0.3 mm below the top face: exact (the plane is the only way out).
    const Eigen::Vector3d b(0.004, -0.02, half.z() - 0.0003), a = b + Eigen::Vector3d(0, 0, length);
    REQUIRE(core::CylinderBoxPenetration(a, b, r, half, depth, p, q, n));
    CHECK(depth == Approx(0.0003).margin(1e-15));  // one subtraction of doubles
    CHECK(n == Eigen::Vector3d::UnitZ());
    CHECK(q.z() == half.z());
  }
  SECTION("tilted end: the rim point lowest along the normal sets the depth") {
    // Axis tilted 30 degrees from -z about y: the lowest rim point is r sin 30 below the end's
    // centre; centre placed so that point is 0.5 mm under the top face.
    const double tilt = std::acos(-1.0) / 6.0;
    const Eigen::Vector3d u(std::sin(tilt), 0.0, -std::cos(tilt));
    const Eigen::Vector3d b(0.0, 0.0, half.z() - 0.0005 + r * std::sin(tilt));
    REQUIRE(core::CylinderBoxPenetration(b - length * u, b, r, half, depth, p, q, n));
    CHECK(depth == Approx(0.0005).margin(1e-12));  // sin and cos to their last bits
    CHECK(n == Eigen::Vector3d::UnitZ());
  }
  SECTION("apart or deeper than r1: no depth is given") {
    const Eigen::Vector3d b(0.0, 0.0, half.z() + 0.001), a = b + Eigen::Vector3d(0, 0, length);
    CHECK_FALSE(core::CylinderBoxPenetration(a, b, r, half, depth, p, q, n));
    const Eigen::Vector3d deep(0.0, 0.0, half.z() - 1.5 * r);
    CHECK_FALSE(core::CylinderBoxPenetration(deep + Eigen::Vector3d(0, 0, length), deep, r, half,
                                             depth, p, q, n));
  }
  SECTION("random overlaps: moving out by the depth along the normal separates them (GJK)") {
    // The depth is a way out, so it bounds the true penetration from above; GJK, an independent
    // method, confirms the moved cylinder no longer overlaps the box.
    fcl::detail::GJKSolver_indep<double> gjk = TightGjk();
    const fcl::Boxd box(2.0 * half);
    const fcl::Cylinderd cylinder(r, length);
    std::mt19937_64 rng(20261123);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    int checked = 0;
    for (int trial = 0; trial < 3000; ++trial) {
      const Eigen::Vector3d centre(unit(rng) * 0.04, unit(rng) * 0.11, unit(rng) * 0.02);
      const Eigen::Vector3d u = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized();
      const Eigen::Vector3d a = centre - 0.5 * length * u, b = centre + 0.5 * length * u;
      if (!core::CylinderBoxPenetration(a, b, r, half, depth, p, q, n)) continue;
      ++checked;
      const Eigen::Vector3d out = (depth + 1e-9) * n;  // 1 nm beyond: GJK's own resolution
      double d = 0.0;
      const bool apart = gjk.shapeDistance(cylinder, SegmentPose(a + out, b + out), box,
                                           Eigen::Isometry3d::Identity(), &d, nullptr, nullptr);
      INFO("trial " << trial << " depth " << depth);
      CHECK(apart);
    }
    CHECK(checked > 300);  // the sampling overlaps the box often enough to mean something
  }
}

namespace {

bool SameBits(double x, double y) {
  return std::bit_cast<std::uint64_t>(x) == std::bit_cast<std::uint64_t>(y);
}
bool SameBits(const Eigen::Vector3d& x, const Eigen::Vector3d& y) {
  return SameBits(x.x(), y.x()) && SameBits(x.y(), y.y()) && SameBits(x.z(), y.z());
}
bool SameBits(const core::RawContact& x, const core::RawContact& y) {
  return x.tube == y.tube && x.part_element == y.part_element && x.face_mask == y.face_mask &&
         x.part == y.part && SameBits(x.s_m, y.s_m) && SameBits(x.distance_m, y.distance_m) &&
         x.overlap == y.overlap && x.pressure_centre == y.pressure_centre &&
         SameBits(x.normal_W, y.normal_W) && SameBits(x.q_W_m, y.q_W_m) &&
         SameBits(x.p_W_m, y.p_W_m);
}

// A tube from the held end p_W along u_W, each piece turned by `bend_rad` about `axis_W` from the
// one before: a circular arc, as the elastica draws it at small loads.
struct TubePose {
  Eigen::Vector3d p_W = Eigen::Vector3d::Zero();
  Eigen::Vector3d u_W = Eigen::Vector3d::UnitY();
  Eigen::Vector3d axis_W = Eigen::Vector3d::UnitX();
  double bend_rad = 0.0;
};

// The shipped groove scene (its tube, contact law and parts).
scene::Scene GrooveScene() {
  io::SceneLoadResult loaded =
      io::LoadSceneFile(std::string(TUBEPLAN_SOURCE_DIR) + "/scenes/groove.yaml");
  REQUIRE(loaded.scene.has_value());
  return *loaded.scene;
}

// A box part of the given size centred at p_W, aligned with the world.
scene::BoxPart Box(const char* name, const Eigen::Vector3d& size_m, const Eigen::Vector3d& p_W) {
  scene::BoxPart box;
  box.name = name;
  box.size_m = size_m;
  box.X_WP.translation() = p_W;
  return box;
}

// Each face mask its own element: the contacts carry the mask twice.
std::vector<std::array<int, 64>> MaskElements(std::size_t parts) {
  std::vector<std::array<int, 64>> element_of(parts);
  for (auto& table : element_of)
    for (int m = 0; m < 64; ++m) table[std::size_t(m)] = m;
  return element_of;
}

// Makes a query's contacts whole (Collision::Complete, as the core does for those that become
// loads). With `check`, each contact Query deferred (a capsule apart from its part) is held
// against FCL's GJK on the same capsule and box, an independent method: its distance, and its
// points on the shapes, d apart along its normal, under an arc position within its piece.
// Returns how many were checked.
int Complete(const core::Collision& collision, const scene::Scene& s, int capsules,
             std::span<core::RawContact> out, int count, std::span<const Eigen::Vector3d> nodes_W,
             bool check) {
  int checked = 0;
  const double r1 = s.tube.outer_radius_m, piece_m = s.tube.length_m / capsules;
  for (int i = 0; i < count; ++i) {
    core::RawContact& c = out[std::size_t(i)];
    const bool deferred = c.deferred;
    collision.Complete(c, nodes_W);
    CHECK_FALSE(c.deferred);
    if (!deferred || !check) continue;
    ++checked;
    const Eigen::Vector3d a = nodes_W[std::size_t(c.piece)], b = nodes_W[std::size_t(c.piece) + 1];
    const scene::BoxPart& part = s.parts[c.part];
    fcl::detail::GJKSolver_indep<double> gjk = TightGjk();
    double d_gjk = 0.0;
    Eigen::Vector3d p_gjk, q_gjk;
    const bool separated =
        gjk.shapeDistance(fcl::Capsuled(r1, (b - a).norm()), SegmentPose(a, b),
                          fcl::Boxd(part.size_m), part.X_WP, &d_gjk, &p_gjk, &q_gjk);
    INFO("contact " << i << " piece " << c.piece << " part " << c.part << " d " << c.distance_m);
    REQUIRE(separated);
    // GJK at 1e-12 on a curved shape: ~1e-9 m (as for the end cylinder above).
    CHECK(c.distance_m == Approx(d_gjk).margin(1e-8));
    // The points: rounding of coordinates of decimetres, 1e-15 m, with a margin. The normal is
    // their difference over d: its length is off by 1e-15 m / d, checked where d >= 1 nm.
    CHECK((c.p_W_m - c.q_W_m - c.distance_m * c.normal_W).norm() <= 1e-12);
    if (c.distance_m >= 1e-9) CHECK(c.normal_W.norm() == Approx(1.0).margin(1e-5));
    const Eigen::Vector3d q_P = part.X_WP.inverse() * c.q_W_m;
    CHECK((q_P.cwiseAbs() - 0.5 * part.size_m).maxCoeff() <= 1e-12);
    // p on the capsule: r1 from its axis segment.
    const Eigen::Vector3d u = (b - a).normalized();
    const double along = std::clamp((c.p_W_m - a).dot(u), 0.0, (b - a).norm());
    CHECK((c.p_W_m - a - along * u).norm() == Approx(r1).margin(1e-12));
    CHECK(c.s_m >= piece_m * c.piece - 1e-12);
    CHECK(c.s_m <= piece_m * (c.piece + 1) + 1e-12);
  }
  return checked;
}

// Query, with each strip of contacts it wrote as one entry (RawContact::strip_pieces) written out
// as its pieces' contacts (Collision::StripPiece): the contacts of a query writing each alone.
// Checks what a strip says of its pieces: one part, one face, consecutive pieces, and its least
// distance (at the first piece that has it) and greatest, against each piece's. Returns how many
// contacts; `entries`, if given, gets the query's own count.
int QueryEach(const core::Collision& collision, std::span<const Eigen::Vector3d> nodes_W,
              const Eigen::Vector3d& tip_tangent_W, double band_m, std::span<core::RawContact> out,
              core::IdleParts* idle = nullptr, int* entries = nullptr) {
  std::vector<core::RawContact> raw(out.size());
  const int n = collision.Query(nodes_W, tip_tangent_W, band_m, raw, idle);
  if (entries != nullptr) *entries = n;
  int count = 0;
  for (int i = 0; i < n; ++i) {
    const core::RawContact& e = raw[std::size_t(i)];
    REQUIRE(e.strip_pieces >= 1);
    if (e.strip_pieces == 1) {
      REQUIRE(count < static_cast<int>(out.size()));
      out[std::size_t(count++)] = e;
      continue;
    }
    INFO("strip of " << e.strip_pieces << " from piece " << e.piece);
    CHECK(e.deferred);
    CHECK(e.over_face);
    double least_m = std::numeric_limits<double>::infinity(), greatest_m = -least_m;
    int least_at = -1;
    for (int k = e.piece; k < e.piece + e.strip_pieces; ++k) {
      REQUIRE(count < static_cast<int>(out.size()));
      const core::RawContact c = collision.StripPiece(e, k);
      CHECK(c.piece == k);
      CHECK(c.strip_pieces == 1);
      CHECK((c.part == e.part && c.face_mask == e.face_mask && c.deferred));
      CHECK(c.distance_m < band_m);
      if (c.distance_m < least_m) {
        least_m = c.distance_m;
        least_at = k;
      }
      greatest_m = std::max(greatest_m, c.distance_m);
      out[std::size_t(count++)] = c;
    }
    CHECK(SameBits(e.distance_m, least_m));
    CHECK(e.strip_deepest == least_at);
    CHECK(SameBits(e.strip_farthest_m, greatest_m));
  }
  return count;
}
}  // namespace

TEST_CASE("Distances kept from earlier queries change no contact, and leave out only idle parts",
          "[core][collision]") {
  // Query skips a pair that an earlier query found farther than the band by more than the piece
  // has moved since. Whatever the history (drifts of a nanometre to a tenth of a millimetre a
  // query, jumps across the scene, jumps back to an earlier pose, the band changing), its
  // contacts must be those of a Collision that has never queried, bit for bit. The groove
  // scene, plus a tilted block on the floor (rotated part, edges and vertices nearest, GJK).
  scene::Scene s = GrooveScene();
  scene::BoxPart block;
  block.name = "block";
  block.size_m = Eigen::Vector3d(0.012, 0.03, 0.012);
  block.X_WP.linear() = (Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()) *
                         Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()))
                            .toRotationMatrix();
  block.X_WP.translation() = Eigen::Vector3d(0.0, 0.02, 0.006);
  s.parts.push_back(block);
  std::vector<std::uint32_t> parts;
  for (std::uint32_t p = 0; p < s.parts.size(); ++p) parts.push_back(p);
  const std::vector<std::array<int, 64>> element_of = MaskElements(s.parts.size());
  const int capsules = 24;
  const double piece_m = s.tube.length_m / capsules;
  core::Collision kept(s, parts, capsules, element_of);
  // A third with the same history that may leave every part out (the core's IdleParts, at a
  // floor of epsilon): each contact of a part it left out must lie in one of its groups, at
  // least the group's gap away, no farther along the tube than its s_max, with a normal in its
  // span; and no end face at its dome's lowest point is left out. The dome's radius changes
  // between queries as the core sets it (the tolerance's, or a bed of springs' down to 1.25 r1):
  // a part left out while the dome's range was narrow must be looked at again once it widens.
  core::Collision idle(s, parts, capsules, element_of);
  const std::vector<std::uint8_t> may_leave_out(s.parts.size(), 1);
  std::array<core::RawContact, core::kMaxRawContacts> got_idle{};
  int left_out = 0, covered = 0;

  std::mt19937_64 rng(20261124);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const auto random_pose = [&] {
    // The held end above the groove's near half, the tube along +y tipped down by up to 40 deg
    // (its tip on the floor, in the groove, on or against the block), a little yaw and bend.
    TubePose pose;
    pose.p_W =
        Eigen::Vector3d(0.006 * unit(rng), -0.09 + 0.03 * unit(rng), 0.025 + 0.025 * unit(rng));
    pose.u_W = (Eigen::AngleAxisd(0.15 * unit(rng), Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(-0.35 + 0.35 * unit(rng), Eigen::Vector3d::UnitX()) *
                Eigen::Vector3d::UnitY())
                   .normalized();
    pose.axis_W = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized();
    pose.bend_rad = 0.01 * unit(rng);
    return pose;
  };
  std::vector<Eigen::Vector3d> nodes_W(std::size_t(capsules) + 1);
  Eigen::Vector3d tip_tangent_W;
  const auto place = [&](const TubePose& pose) {
    Eigen::Vector3d u = pose.u_W;
    nodes_W[0] = pose.p_W;
    for (int k = 0; k < capsules; ++k) {
      nodes_W[std::size_t(k) + 1] = nodes_W[std::size_t(k)] + piece_m * u;
      u = Eigen::AngleAxisd(pose.bend_rad, pose.axis_W) * u;
    }
    tip_tangent_W = u;
  };

  std::array<core::RawContact, core::kMaxRawContacts> got{}, want{};
  TubePose pose = random_pose();
  std::vector<TubePose> visited;
  int skipped = 0, at_band_edge = 0, contacts = 0, completed_checked = 0;
  double band_m = 2.0 * s.contact.threshold_m;
  for (int query = 0; query < 20000; ++query) {
    const double roll = 0.5 * (unit(rng) + 1.0);
    if (roll < 0.01) {
      pose = random_pose();  // across the scene
    } else if (roll < 0.02 && !visited.empty()) {
      pose = visited[std::size_t(query) % visited.size()];  // back where it was, exactly
    } else {
      // A drift of 1 nm to 0.1 mm, and a turn that moves the tip as far.
      const double step_m = std::pow(10.0, -9.0 + 5.0 * 0.5 * (unit(rng) + 1.0));
      pose.p_W += step_m * Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized();
      pose.u_W = (Eigen::AngleAxisd(step_m / s.tube.length_m,
                                    Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized()) *
                  pose.u_W)
                     .normalized();
    }
    if (query % 50 == 0) visited.push_back(pose);
    // The core's band: 2 epsilon and its speculative growth; now and then none or a wide one.
    const double band_roll = 0.5 * (unit(rng) + 1.0);
    if (band_roll < 0.02)
      band_m = 0.0;
    else if (band_roll < 0.04)
      band_m = 0.01;
    else if (band_roll < 0.3)
      band_m = 2.0 * s.contact.threshold_m + 1e-6 * (unit(rng) + 1.0);
    place(pose);
    // Mostly the tolerance's dome; now and then one from 1.25 r1 to it, log-uniform.
    const double dome_roll = 0.5 * (unit(rng) + 1.0);
    const double r1 = s.tube.outer_radius_m, R_tol = kept.tolerance_dome_radius_m();
    const double dome_m = dome_roll < 0.7
                              ? R_tol
                              : 1.25 * r1 * std::pow(R_tol / (1.25 * r1), 0.5 * (unit(rng) + 1.0));
    kept.set_dome_radius_m(dome_m);
    idle.set_dome_radius_m(dome_m);

    const int n = QueryEach(kept, nodes_W, tip_tangent_W, band_m, got);
    core::Collision fresh(s, parts, capsules, element_of);
    fresh.set_dome_radius_m(dome_m);
    const int m = QueryEach(fresh, nodes_W, tip_tangent_W, band_m, want);
    Complete(kept, s, capsules, got, n, nodes_W, false);
    completed_checked += Complete(fresh, s, capsules, want, m, nodes_W, query % 10 == 0);
    INFO("query " << query << " band " << band_m);
    REQUIRE(n == m);
    for (int i = 0; i < n; ++i) {
      INFO("contact " << i);
      REQUIRE(SameBits(got[std::size_t(i)], want[std::size_t(i)]));
      if (band_m - want[std::size_t(i)].distance_m < 1e-6) ++at_band_edge;
    }
    core::IdleParts groups;
    groups.may_leave_out = may_leave_out;
    groups.floor_m = s.contact.threshold_m;
    const int n_idle = QueryEach(idle, nodes_W, tip_tangent_W, band_m, got_idle, &groups);
    Complete(idle, s, capsules, got_idle, n_idle, nodes_W, false);
    left_out += groups.left_out;
    int j = 0;  // the idle query's contacts are the full one's, less whole parts
    for (int i = 0; i < m; ++i) {
      const core::RawContact& c = want[std::size_t(i)];
      if (j < n_idle && SameBits(got_idle[std::size_t(j)], c)) {
        ++j;
        continue;
      }
      INFO("left out: contact " << i << " of part " << c.part << " at s " << c.s_m << " d "
                                << c.distance_m << " n " << c.normal_W.transpose());
      CHECK_FALSE(c.pressure_centre);
      bool in_a_group = false;
      for (int g = 0; g < groups.group_count && !in_a_group; ++g) {
        const core::IdleParts::Group& group = groups.groups[std::size_t(g)];
        // Rounding: the normal's components off its span are those of a unit vector computed
        // from points a few units in the last place apart.
        const double off_span = group.dims == 1   ? c.normal_W.cross(group.axis_W).norm()
                                : group.dims == 2 ? std::abs(c.normal_W.dot(group.axis_W))
                                                  : 0.0;
        in_a_group = c.distance_m >= group.gap_m && c.s_m <= group.s_max_m && off_span < 1e-9;
      }
      CHECK(in_a_group);
      ++covered;
    }
    CHECK(j == n_idle);
    // Only the evaluations differ, never more than a fresh query's.
    CHECK(kept.last_narrow_phase_calls() <= fresh.last_narrow_phase_calls());
    CHECK(fresh.last_coherent_skips() == 0);
    skipped += kept.last_coherent_skips();
    contacts += n;
  }
  // The skipping was exercised, and so were contacts just inside the band's edge, where a
  // skip too many would show.
  INFO("skipped " << skipped << ", contacts " << contacts << ", within 1 um of the band's edge "
                  << at_band_edge);
  CHECK(skipped > 20000);
  CHECK(at_band_edge > 2000);
  // And the contacts whose points are made later (Collision::Complete) were held against GJK.
  INFO("deferred contacts checked against GJK " << completed_checked);
  CHECK(completed_checked > 1000);
  // Parts were left out, and some of them had contacts in the band, which the checks above saw.
  INFO("parts left out " << left_out << ", their contacts " << covered);
  CHECK(left_out > 1000);
  CHECK(covered > 1000);
}

TEST_CASE("A centreline deeper than r1/2 in a part is found, by every fourth node too",
          "[core][collision]") {
  // Random curves of nodes at most h apart (a random walk of the tangent, each step h times a
  // random factor in [0.5, 1]: a shape that keeps its length), placed by random poses in and
  // around the groove's parts. The answer is judged independently, node by node against each
  // part's box, with or without the promise of the spacing (which bounds the nodes by every
  // fourth). Near misses are common: poses are drawn so that the deepest node lies within a few
  // millimetres of the threshold.
  const scene::Scene s = GrooveScene();
  std::vector<std::uint32_t> parts;
  for (std::uint32_t p = 0; p < s.parts.size(); ++p) parts.push_back(p);
  std::vector<std::array<int, 64>> element_of(s.parts.size());
  const int capsules = 48;
  const core::Collision collision(s, parts, capsules, element_of);
  const double l = s.tube.length_m, h = l / capsules, depth = 0.5 * s.tube.outer_radius_m;
  std::mt19937_64 rng(20261125);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int inside = 0, outside = 0, near = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    // Every other curve short (2 to 9 nodes) and sharply bent: there the deepest node can lie
    // between the fourth nodes with all of those outside, which only the growth of their box
    // covers.
    const int count = trial % 2 == 0 ? capsules : 1 + int(std::floor(4.5 * (1.0 + u(rng))));
    std::array<Eigen::Vector3d, core::kMaxCapsules + 1> storage;
    const std::span<Eigen::Vector3d> nodes(storage.data(), std::size_t(count) + 1);
    Eigen::Vector3d tangent = Eigen::Vector3d::UnitZ();
    nodes[0].setZero();
    const double wiggle = (count == capsules ? 0.3 : 1.0) * (1.0 + u(rng));  // radians a step
    for (int k = 1; k <= count; ++k) {
      tangent = (tangent + wiggle * Eigen::Vector3d(u(rng), u(rng), u(rng))).normalized();
      nodes[std::size_t(k)] = nodes[std::size_t(k) - 1] + h * (0.75 + 0.25 * u(rng)) * tangent;
    }
    const Eigen::Matrix3d R_WH =
        Eigen::Quaterniond(Eigen::Vector4d(u(rng), u(rng), u(rng), u(rng)).normalized())
            .toRotationMatrix();
    // The held end anywhere over the groove's 60 mm by 200 mm, from 10 mm under the floor's top
    // to 40 mm above it.
    const Eigen::Vector3d p_WH(0.04 * u(rng), 0.1 * u(rng), 0.015 + 0.025 * u(rng));
    double deepest = -1.0;
    for (const scene::BoxPart& part : s.parts) {
      const Eigen::Isometry3d X_PW = part.X_WP.inverse();
      for (const Eigen::Vector3d& x : nodes)
        deepest = std::max(deepest,
                           (0.5 * part.size_m - (X_PW * (R_WH * x + p_WH)).cwiseAbs()).minCoeff());
    }
    const bool expected = deepest > depth;
    (expected ? inside : outside) += 1;
    near += std::abs(deepest - depth) < 2e-3 ? 1 : 0;
    INFO("trial " << trial << ": deepest node " << deepest * 1e3 << " mm");
    CHECK(collision.AxisThrough(nodes, R_WH, p_WH, depth) == expected);
    CHECK(collision.AxisThrough(nodes, R_WH, p_WH, depth, h) == expected);
  }
  // Random curves seldom put their deepest node exactly where only the growth, or only the last
  // node, reaches: two made so, over the floor (its top at z = 0, deeper than r1/2 = 4 mm is
  // z < -4 mm). A fold straight down and back, nodes 0 and 4 two spacings above its tip: the box
  // of those two grown by two spacings just reaches the tip (by one, it would not). And a curve
  // of 8 nodes whose last three go down from node 4: node 7, three spacings under it, is reached
  // only because the last node is always taken.
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  std::array<Eigen::Vector3d, 5> fold = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 0, -h),
                                         Eigen::Vector3d(0, 0, -2 * h), Eigen::Vector3d(0, 0, -h),
                                         Eigen::Vector3d(0, 0, 0)};
  const Eigen::Vector3d fold_at(0.0, 0.0, -4.5e-3 + 2 * h);  // its tip 0.5 mm past r1/2
  CHECK(collision.AxisThrough(fold, I, fold_at, depth));
  CHECK(collision.AxisThrough(fold, I, fold_at, depth, h));
  CHECK_FALSE(collision.AxisThrough(fold, I, fold_at + Eigen::Vector3d(0, 0, 1e-3), depth, h));
  std::array<Eigen::Vector3d, 8> hook;
  for (int k = 0; k < 8; ++k)
    hook[std::size_t(k)] = Eigen::Vector3d(h * std::min(k, 4), 0.0, -h * std::max(0, k - 4));
  const Eigen::Vector3d hook_at(0.0, 0.0, -4.5e-3 + 3 * h);
  CHECK(collision.AxisThrough(hook, I, hook_at, depth));
  CHECK(collision.AxisThrough(hook, I, hook_at, depth, h));
  INFO(inside << " inside, " << outside << " outside, " << near << " within 2 mm of r1/2");
  CHECK(inside > 200);
  CHECK(outside > 200);
  CHECK(near > 50);
}

TEST_CASE("A centreline through a sheet is found: from beyond one face to beyond the other",
          "[core][collision]") {
  // A part 1 mm thick has no inside deeper than r1/2 = 4 mm (the groove's tube), so a tube whose
  // shape snapped through it (the stability sweep's fast pass through a 1 mm wall, before this)
  // was never held. Through it is: the centreline crossing its mid-plane more than r1/2 inside
  // its other faces, from a node beyond one face to a node beyond the other. The sheet is
  // 60 x 40 x 1 mm, tilted; the curves are made in its frame P (z along its normal) and placed
  // by a pose of the held end, so the answer comes through the same frames as the core's.
  scene::Scene s = GrooveScene();
  const double r1 = s.tube.outer_radius_m, depth = 0.5 * r1, spacing = 2e-3;
  s.parts.clear();
  scene::BoxPart sheet;
  sheet.name = "sheet";
  sheet.size_m = Eigen::Vector3d(0.06, 0.04, 1e-3);
  sheet.X_WP.linear() = scene::RotationFromRpy({0.3, -0.2, 0.7});
  sheet.X_WP.translation() = Eigen::Vector3d(0.01, -0.02, 0.05);
  s.parts.push_back(sheet);
  const std::vector<std::uint32_t> parts = {0};
  const core::Collision collision(s, parts, 48, MaskElements(1));
  const Eigen::Matrix3d R_WH = scene::RotationFromRpy({-0.4, 0.5, 0.1});
  const Eigen::Vector3d p_WH(0.002, 0.003, -0.001);
  // Node k of a curve given in P at points p_P(k), in frame H.
  const auto through = [&](const std::vector<Eigen::Vector3d>& points_P) {
    std::vector<Eigen::Vector3d> nodes_H;
    for (const Eigen::Vector3d& p_P : points_P)
      nodes_H.push_back(R_WH.transpose() * (sheet.X_WP * p_P - p_WH));
    const bool all = collision.AxisThrough(nodes_H, R_WH, p_WH, depth);
    // The same answer with the spacing promised (its box test over every fourth node).
    CHECK(collision.AxisThrough(nodes_H, R_WH, p_WH, depth, spacing * 1.01) == all);
    return all;
  };
  // A straight line along the normal at (x, y), nodes `spacing` apart from z0 for `count`.
  const auto line = [&](double x, double y, double z0, int count) {
    std::vector<Eigen::Vector3d> points;
    for (int k = 0; k < count; ++k) points.emplace_back(x, y, z0 + spacing * k);
    return points;
  };
  // Through the middle: with a node in the sheet (z = 0) and with none (nodes at -1 and +1 mm).
  CHECK(through(line(0.0, 0.0, -0.01, 11)));
  CHECK(through(line(0.0, 0.0, -0.009, 10)));
  // Backwards (from the far side): through as well.
  std::vector<Eigen::Vector3d> back = line(0.0, 0.0, -0.009, 10);
  std::reverse(back.begin(), back.end());
  CHECK(through(back));
  // Its end in the sheet, 0.2 mm short of the far face: pressed in, not through.
  CHECK_FALSE(through(line(0.0, 0.0, -0.0098, 6)));
  // Crossing 3 mm inside the sheet's edge (x = 27 mm of 30, y = 17 of 20): within r1/2 of it, as a
  // tube bent round the edge would; 5 mm inside it: through.
  CHECK_FALSE(through(line(0.027, 0.0, -0.009, 10)));
  CHECK(through(line(0.025, 0.0, -0.009, 10)));
  CHECK_FALSE(through(line(0.0, -0.017, -0.009, 10)));  // the same along y (20 mm)
  CHECK(through(line(0.0, -0.015, -0.009, 10)));
  // Beside the sheet altogether (x = 40 mm): never through.
  CHECK_FALSE(through(line(0.04, 0.0, -0.009, 10)));
  // A hairpin: down into the sheet to 0.2 mm short of its far face and back out the side it came
  // from; and one that goes on beyond the far face before turning back: that one went through.
  std::vector<Eigen::Vector3d> hairpin = line(0.0, 0.0, -0.0098, 6);
  for (int k = 4; k >= 0; --k)
    hairpin.push_back(hairpin[std::size_t(k)] + Eigen::Vector3d(0.001, 0, 0));
  CHECK_FALSE(through(hairpin));
  std::vector<Eigen::Vector3d> beyond = line(0.0, 0.0, -0.009, 7);  // to z = +3 mm
  for (int k = 5; k >= 0; --k)
    beyond.push_back(beyond[std::size_t(k)] + Eigen::Vector3d(0.001, 0, 0));
  CHECK(through(beyond));
  // Round the edge: from under the sheet, out past its edge at x = 30 mm, over it: not through.
  CHECK_FALSE(through({{0.02, 0.0, -0.004},
                       {0.028, 0.0, -0.004},
                       {0.034, 0.0, -0.001},
                       {0.034, 0.0, 0.001},
                       {0.028, 0.0, 0.004},
                       {0.02, 0.0, 0.004}}));
}

TEST_CASE("The end face on a wall is a dome: its lowest point, continuous into the rim's",
          "[core][collision]") {
  // The groove scene's tube (r1 = 8 mm, eps = 1 mm) straight, its end face tilted by t towards a
  // wall whose face is d_c from the face's centre F. The face is a spherical cap of height h over
  // the rim circle, the end moved back along its axis by h (its apex at F): a sphere of radius R
  // with centre C = F - R u, R^2 = (R - h)^2 + r1^2. Its lowest point towards the wall is C + R n
  // (n the wall's normal into it) while that lies in the cap, the rim's lowest point (moved back
  // by h) beyond: computed here as vectors, not by the collision's scalar formulas. Three domes:
  //  - the tolerance's, h = eps / 10, the face clear of the wall (d_c = 0.6 mm);
  //  - the bed of springs' of a face pressed 0.38 mm through the surface (R = (r1^2 + r2^2) /
  //    (4 p), 59 mm), the radius the core sets for such a face (the dome's range is then 0.14 rad);
  //  - that one with the face's centre 0.38 mm inside the wall: an overlapping end (the slide
  //    with a 10 um band) takes the same dome and the rim beyond it, not a flat face.
  scene::Scene s = GrooveScene();
  const double r1 = s.tube.outer_radius_m, r2 = s.tube.inner_radius_m, l = s.tube.length_m;
  const double wall_z = 0.5;
  s.parts = {
      Box("wall", Eigen::Vector3d(0.4, 0.4, 0.02), Eigen::Vector3d(0.0, 0.0, wall_z + 0.01))};
  const std::vector<std::uint32_t> parts{0};
  const int capsules = 24;
  core::Collision collision(s, parts, capsules, MaskElements(1));
  const double h_tol = 0.1 * s.contact.threshold_m;
  const double R_tol = (r1 * r1 + h_tol * h_tol) / (2.0 * h_tol);
  CHECK(collision.dome_radius_m() == Approx(R_tol).epsilon(1e-12));
  CHECK(collision.dome_height_m() == h_tol);
  const double R_bed = (r1 * r1 + r2 * r2) / (4.0 * 0.38e-3);
  struct Dome {
    double radius_m, d_c;
  };
  for (const Dome dome : {Dome{R_tol, 0.6e-3}, Dome{R_bed, 0.6e-3}, Dome{R_bed, -0.38e-3}}) {
    collision.set_dome_radius_m(dome.radius_m);
    const double R = dome.radius_m, d_c = dome.d_c;
    // The cap's height from R^2 = (R - h)^2 + r1^2, by the root that does not cancel; 1e-12:
    // the collision's own rounding of it (at the tolerance's radius it keeps h = eps / 10).
    const double h = r1 * r1 / (R + std::sqrt(R * R - r1 * r1));
    INFO("dome radius " << R << " m, height " << h << " m, face centre " << d_c << " m off");
    CHECK(collision.dome_radius_m() == R);
    CHECK(collision.dome_height_m() == Approx(h).epsilon(1e-12));
    const Eigen::Vector3d F(0.0, 0.0, wall_z - d_c), n = Eigen::Vector3d::UnitZ();
    struct End {
      states::TubeElement tube;
      double distance_m, offset_m;
    };
    const auto query = [&](double t) {
      const Eigen::Vector3d u(std::sin(t), 0.0, std::cos(t));
      std::vector<Eigen::Vector3d> nodes_W(std::size_t(capsules) + 1);
      for (int k = 0; k <= capsules; ++k) nodes_W[std::size_t(k)] = F - (l - l * k / capsules) * u;
      std::array<core::RawContact, core::kMaxRawContacts> out{};
      const int count = QueryEach(collision, nodes_W, u, 2.0 * s.contact.threshold_m, out);
      Complete(collision, s, capsules, out, count, nodes_W, true);
      End end{states::TubeElement::kSide, 0.0, -1.0};
      for (int i = 0; i < count; ++i) {
        const core::RawContact& c = out[std::size_t(i)];
        if (c.s_m < l) continue;
        const Eigen::Vector3d r = c.p_W_m - F;
        end = {c.tube, c.distance_m, (r - u * u.dot(r)).norm()};
      }
      return end;
    };
    const double t_switch = std::asin(r1 / R);
    for (const double t :
         {1e-4, 0.3 * t_switch, 0.9 * t_switch, 1.1 * t_switch, 2.0 * t_switch, 0.07}) {
      INFO("tilt " << t << " rad (the rim's from " << t_switch << ")");
      const Eigen::Vector3d u(std::sin(t), 0.0, std::cos(t));
      const Eigen::Vector3d C = F - R * u;
      const Eigen::Vector3d low = C + R * n;
      Eigen::Vector3d expected = low;
      if ((low - C).dot(u) < R - h) {  // beyond the cap: the rim's lowest point
        const Eigen::Vector3d radial = (n - n.dot(u) * u).normalized();
        expected = F - h * u + r1 * radial;
      }
      const End end = query(t);
      const Eigen::Vector3d rel = expected - F;
      // 1e-12 m: the closed forms' rounding at 0.5 m from the origin.
      CHECK(end.distance_m == Approx(wall_z - expected.z()).margin(1e-12));
      if (t < t_switch) {
        CHECK(end.tube == states::TubeElement::kEndFace);
        CHECK(end.offset_m == Approx((rel - u * u.dot(rel)).norm()).margin(1e-12));
      } else {
        CHECK(end.tube == states::TubeElement::kEndRim);
      }
    }
    // A potential: the penalty K (eps - d) at the load point is the gradient of K (eps - d)^2 / 2
    // when d's derivative in the tilt about F is the point's lever arm, -e (central differences,
    // dt = 1e-6 rad: an error of R sin(t) dt^2 / 6 < 1e-14 m in the slope for both radii,
    // rounding 1e-16 m / dt), and d has no jump where the rim takes over.
    for (const double t : {0.2 * t_switch, 0.5 * t_switch, 0.95 * t_switch}) {
      const double dt = 1e-6;
      const double slope = (query(t + dt).distance_m - query(t - dt).distance_m) / (2.0 * dt);
      CHECK(slope == Approx(-query(t).offset_m).margin(1e-9));
    }
    const End before = query(t_switch * (1.0 - 1e-9)), after = query(t_switch * (1.0 + 1e-9));
    CHECK(before.tube == states::TubeElement::kEndFace);
    CHECK(after.tube == states::TubeElement::kEndRim);
    // A step of 2e-9 t_switch moves the lowest point by r1 times that (4e-13 m at the
    // tolerance's R = 0.32 m, 2.2e-12 m at 59 mm), and the closed forms round at 1e-12 m.
    CHECK(std::abs(after.distance_m - before.distance_m) < r1 * 2e-9 * t_switch + 1e-12);
  }
  // Out of its range, the radius is held to [1.25 r1, the tolerance's]: a dome no higher than
  // the tolerance, and no more than a cap flatter than a hemisphere.
  collision.set_dome_radius_m(1e9);
  CHECK(collision.dome_radius_m() == R_tol);
  CHECK(collision.dome_height_m() == h_tol);
  collision.set_dome_radius_m(0.0);
  CHECK(collision.dome_radius_m() == 1.25 * r1);
  CHECK(collision.dome_height_m() == Approx(0.5 * r1).epsilon(1e-12));
}

TEST_CASE("A part left out under a narrow dome is looked at again when the dome widens",
          "[core][collision]") {
  // A thin tube (r1 = 1.5 mm, eps = 1 mm: a tube thinner than 2 eps, where a dome's point can
  // lie in the band while the capsule round the end piece, the distance kept for it, is beyond
  // the idle floor eps) pointing down at a floor, its end face tilted by sin(t) = 0.78 to it,
  // the face's centre 2.55 mm above it. Under the tolerance's dome (R = 11.3 mm, range
  // sin(t) < 0.13) the rim is the contact (1.38 mm off), the end does not face the floor, and the
  // floor, idle, is left out and its evaluation kept. The core then sets a bed of springs' dome
  // at its floor, R = 1.25 r1 (range sin(t) < 0.8): the end faces the floor within it, and a
  // fresh query finds the dome's lowest point, 1.85 mm off, in the band. The kept evaluation,
  // made for the narrow range, must not leave it out (collision.cpp, StillLeftOut).
  scene::Scene s = GrooveScene();
  s.tube.outer_radius_m = 1.5e-3;
  s.tube.inner_radius_m = 1.0e-3;
  const double r1 = s.tube.outer_radius_m, l = s.tube.length_m, eps = s.contact.threshold_m;
  // Its top at z = 0.
  s.parts = {Box("floor", Eigen::Vector3d(0.4, 0.4, 0.02), Eigen::Vector3d(0.0, 0.0, -0.01))};
  const std::vector<std::uint32_t> parts{0};
  const int capsules = 24;
  core::Collision idle(s, parts, capsules, MaskElements(1));
  core::Collision fresh(s, parts, capsules, MaskElements(1));
  const double sin_t = 0.78, cos_t = std::sqrt(1.0 - sin_t * sin_t);
  const Eigen::Vector3d u(0.0, sin_t, -cos_t);  // towards the floor
  const Eigen::Vector3d tip(0.0, 0.0, 2.55e-3);
  std::vector<Eigen::Vector3d> nodes_W(std::size_t(capsules) + 1);
  for (int k = 0; k <= capsules; ++k) nodes_W[std::size_t(k)] = tip - (l - l * k / capsules) * u;
  const double band_m = 2.0 * eps;
  const std::vector<std::uint8_t> may_leave_out{1};
  std::array<core::RawContact, core::kMaxRawContacts> out{};
  const auto pressure_centres = [&](int count) {
    int found = 0;
    for (int i = 0; i < count; ++i) found += out[std::size_t(i)].pressure_centre ? 1 : 0;
    return found;
  };
  // The tolerance's dome: once a query has kept the pieces' distances, the floor is left out.
  const int rim_only = QueryEach(idle, nodes_W, u, band_m, out);
  REQUIRE(rim_only > 0);
  REQUIRE(pressure_centres(rim_only) == 0);
  core::IdleParts first;
  first.may_leave_out = may_leave_out;
  first.floor_m = eps;
  CHECK(QueryEach(idle, nodes_W, u, band_m, out, &first) == 0);
  CHECK(first.left_out == 1);
  // The bed of springs' dome, the tube where it was.
  idle.set_dome_radius_m(0.0);
  fresh.set_dome_radius_m(0.0);
  REQUIRE(fresh.dome_radius_m() == 1.25 * r1);
  const int want = QueryEach(fresh, nodes_W, u, band_m, out);
  REQUIRE(pressure_centres(want) == 1);
  core::IdleParts second;
  second.may_leave_out = may_leave_out;
  second.floor_m = eps;
  const int got = QueryEach(idle, nodes_W, u, band_m, out, &second);
  CHECK(second.left_out == 0);
  CHECK(got == want);
  CHECK(pressure_centres(got) == 1);
}

TEST_CASE("A capsule over a face spans the stretch of its axis over it, whatever its tilt",
          "[core][collision]") {
  // The groove scene's tube lying along +y over a floor whose near edge is at y = 0, its axis
  // 0.5 mm above the floor's plane plus r1, tilted about x; the first pieces begin before the
  // edge. Each capsule over the floor's top face reports the stretch of its axis over the face,
  // its ends moved towards its nearest point by 1 - w, w = 1 - |d_hi - d_lo| / (eps / 10) (the
  // ends' distances; at least 0), and the distance there: computed here from the geometry as
  // vectors. Its nearest point is one end of the stretch or the other, which one by the tilt's
  // sign; the PC's region (the lo end of its first piece to the hi end of its last, the pieces on
  // the face's edges joining it at their nearest points, as the core joins them) is not.
  scene::Scene s = GrooveScene();
  const double r1 = s.tube.outer_radius_m, l = s.tube.length_m, eps = s.contact.threshold_m;
  // Its top at z = 0, its near edge at y = 0.
  s.parts = {Box("floor", Eigen::Vector3d(0.2, 0.4, 0.02), Eigen::Vector3d(0.0, 0.2, -0.01))};
  const std::vector<std::uint32_t> parts{0};
  const int capsules = 24;
  const double piece_m = l / capsules;
  const core::Collision collision(s, parts, capsules, MaskElements(1));
  const Eigen::Vector3d start(0.0, -1.1 * piece_m, r1 + 0.5e-3);
  const std::uint8_t top = 1u << 0;  // FaceMask's bit of the +z face (kPositiveFace[2])
  struct Region {
    double lo_m = 1e9, hi_m = -1e9;
    int nearest_at_lo = 0, nearest_at_hi = 0, lines = 0, collapsed = 0;
  };
  const auto query = [&](double tilt) {
    const Eigen::Vector3d u(0.0, std::cos(tilt), std::sin(tilt));
    std::vector<Eigen::Vector3d> nodes_W(std::size_t(capsules) + 1);
    for (int k = 0; k <= capsules; ++k) nodes_W[std::size_t(k)] = start + (l * k / capsules) * u;
    std::array<core::RawContact, core::kMaxRawContacts> out{};
    const int count = QueryEach(collision, nodes_W, u, 2.0 * eps, out);
    Complete(collision, s, capsules, out, count, nodes_W, true);
    Region region;
    for (int i = 0; i < count; ++i) {
      core::RawContact& c = out[std::size_t(i)];
      if ((c.face_mask & top) == 0) continue;
      collision.LineEnds(c, nodes_W);
      CHECK((!c.over_face || c.face_mask == top));  // a capsule over the face, no other
      region.lo_m = std::min(region.lo_m, c.line ? c.s_lo_m : c.s_m);
      region.hi_m = std::max(region.hi_m, c.line ? c.s_hi_m : c.s_m);
      if (!c.line) continue;
      INFO("tilt " << tilt << " s " << c.s_m);
      CHECK(c.face_mask == top);
      ++region.lines;
      // Which piece: the one (of those beside the nearest point's arc position) whose geometry
      // gives what the contact says. Its axis from a to b, where it crosses the edge's plane
      // y = 0, its ends' distances to the floor's plane z = 0, and the ends moved towards the
      // nearer; 1e-15 m: rounding of coordinates of centimetres (1e-12 in t: a division by the
      // piece's extent across the edge's plane).
      bool matched = false;
      const int k0 = int(c.s_m / piece_m);
      for (int k = std::max(0, k0 - 1); k <= std::min(capsules - 1, k0 + 1) && !matched; ++k) {
        const Eigen::Vector3d a = nodes_W[std::size_t(k)], b = nodes_W[std::size_t(k) + 1];
        const double t_lo = std::clamp(-a.y() / (b.y() - a.y()), 0.0, 1.0);
        const auto surface = [&](double t) {
          return Eigen::Vector3d(a + t * (b - a) - r1 * Eigen::Vector3d::UnitZ());
        };
        const double d_lo = surface(t_lo).z(), d_hi = surface(1.0).z();
        const double t_near = d_lo <= d_hi ? t_lo : 1.0;
        const double w = std::max(0.0, 1.0 - std::abs(d_hi - d_lo) / (0.1 * eps));
        matched = std::abs(c.distance_m - std::min(d_lo, d_hi)) <= 1e-15;
        for (const bool lo : {true, false}) {
          const double t = t_near + w * ((lo ? t_lo : 1.0) - t_near);
          const Eigen::Vector3d p = surface(t);
          // The arc position of the surface point's foot on the chord, within the piece.
          const double along =
              std::clamp((p - 0.5 * (a + b)).dot(u), -0.5 * piece_m, 0.5 * piece_m);
          matched =
              matched && c.piece == k && std::abs((lo ? c.t_lo : c.t_hi) - t) <= 1e-12 &&
              std::abs((lo ? c.d_lo_m : c.d_hi_m) - p.z()) <= 1e-15 &&
              std::abs((lo ? c.s_lo_m : c.s_hi_m) - (piece_m * (k + 0.5) + along)) <= 1e-15 &&
              (core::LineSurfacePoint(c, lo ? c.t_lo : c.t_hi, nodes_W, r1) - p).norm() <= 1e-15;
        }
        if (!matched) continue;
        // The nearest point is the nearer end of the stretch.
        if ((c.p_W_m - surface(t_lo)).norm() <= 1e-15) ++region.nearest_at_lo;
        if ((c.p_W_m - surface(1.0)).norm() <= 1e-15) ++region.nearest_at_hi;
        if (w == 0.0) ++region.collapsed;
      }
      CHECK(matched);
    }
    return region;
  };
  // Nearly parallel (the far end 0.15 um higher, or lower): every piece spans its whole stretch,
  // within (1 - w) of it, 6e-5 of a piece's 6.25 mm.
  const double tilt = 1e-6;
  const Region up = query(tilt), down = query(-tilt);
  CHECK(up.lines > 10);
  CHECK(down.lines > 10);
  // Its nearest point is its lo end when the tube rises towards its tip, its hi end when it
  // falls...
  CHECK(up.nearest_at_lo == up.lines);
  CHECK(down.nearest_at_hi == down.lines);
  // ...and the region's ends move by at most 1e-6 m (tilt r1 = 8e-9 m, and twice the ends' pull
  // towards the nearest point, 3.9e-7 m).
  CHECK(std::abs(up.lo_m - down.lo_m) <= 1e-6);
  CHECK(std::abs(up.hi_m - down.hi_m) <= 1e-6);
  // Tilted by 0.02 rad, the stretch's ends are 0.125 mm apart in distance, beyond eps / 10: both
  // ends are the nearest point, and a PC of such pieces is carried where it presses.
  const Region steep = query(0.02);
  CHECK(steep.lines > 10);
  CHECK(steep.collapsed == steep.lines);
  CHECK(up.collapsed == 0);
}

TEST_CASE("The last capsule's cap inside the end cylinder is no contact", "[core][collision]") {
  // The last capsule ends where the end cylinder starts, and its round cap reaches r1 into the
  // cylinder: not the tube's surface. The groove scene's tube straight along +z, its end pressed
  // 3 mm into a wall (past the 2 mm the cap's pole keeps from the face less the band: the pole
  // lies end - r1 behind the tip). The end face is the wall's contact; no side contact lies inside
  // the end cylinder near its axis (within r1 / 2 of it: the part of the cap that faces where the
  // end face does). A cap that bulges outside the cylinder (a bend) is another matter, kept.
  scene::Scene s = GrooveScene();
  const double r1 = s.tube.outer_radius_m, l = s.tube.length_m, eps = s.contact.threshold_m;
  // Its face at z = l.
  s.parts = {Box("wall", Eigen::Vector3d(0.4, 0.4, 0.02), Eigen::Vector3d(0.0, 0.0, l + 0.01))};
  const int capsules = 24;
  const std::vector<std::uint32_t> parts{0};
  const core::Collision collision(s, parts, capsules, MaskElements(1));
  const double end_m = collision.end_length_m(), press_m = 3e-3;
  // The cap's pole is within the band of the wall: the case the filter is for.
  REQUIRE(end_m - r1 - press_m < 2.0 * eps);
  const Eigen::Vector3d u = Eigen::Vector3d::UnitZ();
  std::vector<Eigen::Vector3d> nodes_W(std::size_t(capsules) + 1);
  for (int k = 0; k <= capsules; ++k)
    nodes_W[std::size_t(k)] = (press_m + l * double(k) / capsules) * u;
  std::array<core::RawContact, core::kMaxRawContacts> out{};
  const int count = QueryEach(collision, nodes_W, u, 2.0 * eps, out);
  Complete(collision, s, capsules, out, count, nodes_W, false);
  const Eigen::Vector3d end_start_W = nodes_W.back() - end_m * u;
  int end_face = 0;
  for (int i = 0; i < count; ++i) {
    const core::RawContact& c = out[std::size_t(i)];
    INFO("contact " << i << " tube " << int(c.tube) << " s " << c.s_m << " d " << c.distance_m);
    if (c.tube == states::TubeElement::kEndFace) ++end_face;
    if (c.tube != states::TubeElement::kSide) continue;
    const Eigen::Vector3d from_end = c.p_W_m - end_start_W;
    const double along = from_end.dot(u);
    const bool inside = along > 0.0 && along < end_m && (from_end - along * u).norm() < 0.5 * r1;
    CHECK_FALSE(inside);
  }
  CHECK(end_face == 1);
}

TEST_CASE(
    "A tube lying on a face: strips of its pieces' contacts, each piece's distance exact, "
    "cut where a full out cuts single contacts",
    "[core][collision]") {
  // The groove scene's tube lying along y over a floor whose top is z = 0, its nodes at heights
  // rising slowly from r1 + eps / 5, and a hump of 3 eps over nodes 15 .. 24: the capsules
  // between (15 .. 23) are beyond the band 2 eps, the others within it. A capsule over the face
  // with both nodes above it is min(z_a, z_b) - r1 from it (its nearest point is over its
  // nearer end): each piece's contact from a strip must carry exactly that, and the pieces with
  // contacts must be exactly those within the band. The hump cuts the strip in two.
  scene::Scene s = GrooveScene();
  const double r1 = s.tube.outer_radius_m, l = s.tube.length_m, eps = s.contact.threshold_m;
  s.parts = {Box("floor", Eigen::Vector3d(0.12, 0.4, 0.02), Eigen::Vector3d(0.0, 0.0, -0.01))};
  const int capsules = 48;
  const core::Collision collision(s, std::vector<std::uint32_t>{0}, capsules, MaskElements(1));
  const Eigen::Vector3d u = Eigen::Vector3d::UnitY();
  std::vector<Eigen::Vector3d> nodes_W(std::size_t(capsules) + 1);
  for (int k = 0; k <= capsules; ++k) {
    const double hump_m = k >= 15 && k <= 24 ? 3.0 * eps : 0.0;
    nodes_W[std::size_t(k)] = Eigen::Vector3d(0.0, -0.08 + l * double(k) / capsules,
                                              r1 + eps * (0.2 + 0.5 * k / capsules) + hump_m);
  }
  const double band_m = 2.0 * eps;
  std::array<core::RawContact, core::kMaxRawContacts> out{};
  int entries = 0;
  const int count = QueryEach(collision, nodes_W, u, band_m, out, nullptr, &entries);
  std::vector<int> strip_pieces;
  for (int i = 0; i < count; ++i) {
    const core::RawContact& c = out[std::size_t(i)];
    if (!c.deferred) continue;  // the last capsule and the end cylinder's: made whole by Query
    const int k = c.piece;
    INFO("piece " << k);
    // Within the rounding of the shift into the floor's frame (coordinates of centimetres,
    // ~1e-18 m), with a margin.
    CHECK(c.distance_m ==
          Approx(std::min(nodes_W[std::size_t(k)].z(), nodes_W[std::size_t(k) + 1].z()) - r1)
              .margin(1e-15));
    strip_pieces.push_back(k);
  }
  // Every capsule but the last within the band, and no other: the end cylinder covers the last
  // node intervals (at least r1 of tube), and the capsule before it is made whole by Query (its
  // cap is looked at against the cylinder).
  const double piece_m = l / capsules;
  const int end_pieces = static_cast<int>(std::lround(collision.end_length_m() / piece_m));
  std::vector<int> expected;
  for (int k = 0; k < capsules - end_pieces - 1; ++k)
    if (k < 15 || k > 23) expected.push_back(k);
  CHECK(strip_pieces == expected);
  // Two strips, and the few contacts near the end (the last capsule, the end cylinder's side as
  // its generator's two ends), not a contact a piece.
  CHECK(entries <= 5);
  CHECK(count == static_cast<int>(expected.size()) + entries - 2);

  // Out full: Query stops where it would stop writing each contact alone, in the middle of a
  // strip too.
  for (const int room : {1, 7, 15, 16, 30, count - 1}) {
    INFO("room for " << room);
    std::vector<core::RawContact> small(static_cast<std::size_t>(room));
    REQUIRE(QueryEach(collision, nodes_W, u, band_m, small) == room);
    for (int i = 0; i < room; ++i) {
      CHECK(small[std::size_t(i)].piece == out[std::size_t(i)].piece);
      CHECK(SameBits(small[std::size_t(i)].distance_m, out[std::size_t(i)].distance_m));
    }
  }
}

// The world directions of a face mask's faces, summed (at most one face an axis here: the sum
// names the set). FaceMask's bits: +x 2, -x 3, +y 4, -y 5, +z 0, -z 1.
Eigen::Vector3d MaskNormals_W(std::uint8_t mask, const Eigen::Matrix3d& R_WP) {
  constexpr std::array<int, 3> kPositive = {2, 4, 0}, kNegative = {3, 5, 1};
  Eigen::Vector3d sum_W = Eigen::Vector3d::Zero();
  for (int a = 0; a < 3; ++a) {
    if (mask & (1u << kPositive[std::size_t(a)])) sum_W += R_WP.col(a);
    if (mask & (1u << kNegative[std::size_t(a)])) sum_W -= R_WP.col(a);
  }
  return sum_W;
}

TEST_CASE("A run of capsules beyond one face of an aligned part: the same contacts as a turned one",
          "[core][collision]") {
  // Query settles a run of capsules beyond one face of a part aligned with the world by a path of
  // its own (and its face mask once, when the run is clear of the face's edges). The same floor
  // turned a quarter about z, its x and y sizes swapped, is the same box, but not aligned: each
  // of its capsules takes the general steps. The rotation's entries are 0 and +-1, so the part
  // frame's coordinates are the aligned ones permuted, exactly, and every contact must match bit
  // for bit: its piece, distance, points, normal and arc position (after Complete), and its faces'
  // directions. Tubes of the groove scene lying over the floor at random: along either axis or
  // askew, bent, tilted, across its edges and corners, from dipping into it to beyond the band.
  scene::Scene s = GrooveScene();
  const double r1 = s.tube.outer_radius_m, l = s.tube.length_m, eps = s.contact.threshold_m;
  // Its top at z = 0.
  const scene::BoxPart aligned =
      Box("aligned", Eigen::Vector3d(0.12, 0.2, 0.02), Eigen::Vector3d(0.013, 0.07, -0.01));
  scene::BoxPart turned =
      Box("turned", Eigen::Vector3d(0.2, 0.12, 0.02), aligned.X_WP.translation());
  turned.X_WP.linear() << 0.0, -1.0, 0.0,  //
      1.0, 0.0, 0.0,                       //
      0.0, 0.0, 1.0;
  s.parts = {aligned, turned};
  const int capsules = 48;
  const core::Collision on_aligned(s, std::vector<std::uint32_t>{0}, capsules, MaskElements(2));
  const core::Collision on_turned(s, std::vector<std::uint32_t>{1}, capsules, MaskElements(2));
  std::mt19937 rng(20261129);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int deferred = 0, compared = 0;
  // FaceMask's edges lie 1 % of epsilon inside the faces' borders: the askew tubes of the last
  // kind run along y within a few of that of the floor's x borders, so that its edges' bits
  // change within a run of capsules.
  const double edge_m = 0.01 * eps, x_border = aligned.X_WP.translation().x() + 0.06;
  for (int trial = 0; trial < 600; ++trial) {
    // Along x, along y or askew; from the floor's middle or from beyond its edges.
    const int kind = trial < 400 ? trial % 3 : 3;
    const double side = trial % 2 == 0 ? 1.0 : -1.0;  // which x border, for the last kind
    double yaw = kind == 0 ? 0.0 : kind == 1 ? 0.5 * std::numbers::pi : 2.0 * unit(rng);
    if (kind == 3) yaw = 0.5 * std::numbers::pi + side * (unit(rng) - 0.5) * 12.0 * edge_m / l;
    const double tilt = (unit(rng) - 0.5) * 4.0 * eps / l, bend = (unit(rng) - 0.5) * 1e-3;
    Eigen::Vector3d start(-0.08 + 0.2 * unit(rng), -0.06 + 0.2 * unit(rng),
                          r1 - 0.3e-3 + 3.0 * eps * unit(rng));
    if (kind == 3)
      start.x() = aligned.X_WP.translation().x() +
                  side * (x_border - aligned.X_WP.translation().x() - 4.0 * edge_m * unit(rng));
    Eigen::Vector3d u(std::cos(yaw) * std::cos(tilt), std::sin(yaw) * std::cos(tilt),
                      std::sin(tilt));
    std::vector<Eigen::Vector3d> nodes_W(std::size_t(capsules) + 1);
    nodes_W[0] = start;
    const Eigen::AngleAxisd turn(kind == 3 ? 0.0 : bend,
                                 Eigen::Vector3d::UnitZ().cross(u).normalized());
    for (int k = 1; k <= capsules; ++k) {
      nodes_W[std::size_t(k)] = nodes_W[std::size_t(k) - 1] + (l / capsules) * u;
      u = turn * u;
    }
    std::array<core::RawContact, core::kMaxRawContacts> out_a{}, out_t{};
    const int count_a = QueryEach(on_aligned, nodes_W, u, 2.0 * eps, out_a);
    const int count_t = QueryEach(on_turned, nodes_W, u, 2.0 * eps, out_t);
    INFO("trial " << trial);
    REQUIRE(count_a == count_t);
    for (int i = 0; i < count_a; ++i) deferred += out_a[std::size_t(i)].deferred ? 1 : 0;
    Complete(on_aligned, s, capsules, out_a, count_a, nodes_W, false);
    Complete(on_turned, s, capsules, out_t, count_t, nodes_W, false);
    for (int i = 0; i < count_a; ++i) {
      const core::RawContact& a = out_a[std::size_t(i)];
      const core::RawContact& t = out_t[std::size_t(i)];
      INFO("contact " << i << " piece " << a.piece << " d " << a.distance_m);
      CHECK(a.piece == t.piece);
      CHECK(a.tube == t.tube);
      CHECK(SameBits(a.distance_m, t.distance_m));
      CHECK(SameBits(a.s_m, t.s_m));
      CHECK(SameBits(a.p_W_m, t.p_W_m));
      CHECK(SameBits(a.q_W_m, t.q_W_m));
      CHECK(SameBits(a.normal_W, t.normal_W));
      CHECK(a.over_face == t.over_face);
      CHECK(MaskNormals_W(a.face_mask, aligned.X_WP.linear()) ==
            MaskNormals_W(t.face_mask, turned.X_WP.linear()));
      ++compared;
    }
  }
  // Most contacts are of capsules apart from the floor within the band: the runs' own path.
  CHECK(deferred > compared / 2);
  CHECK(compared > 4000);
}
