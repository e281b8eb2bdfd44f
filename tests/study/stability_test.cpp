// The stability sweep (issue 7), one test per case class at quick sizes. Each test runs the
// case through core::Core::Step twice and checks it tick by tick (study/stability.cpp). Where the
// core fails a check today, the test is tagged [!mayfail] and names the defect: the sweep reports
// it honestly and the core's engineer fixes it; the test then passes without a change here.
#include <sstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <tubeplan/cli/app.hpp>
#include <tubeplan/core/core.hpp>
#include <tubeplan/scene/scene.hpp>
#include <tubeplan/study/stability.hpp>

#include "cli/commands.hpp"
#include "quick_case.hpp"

using namespace tubeplan;

namespace {

study::StabilityResult RunNamed(const std::string& name) {
  return study::RunStabilityCase(testing::QuickCase(name));
}

}  // namespace

TEST_CASE("Stability: push into a wall, steel-stiff tube (E = 200 GPa)", "[stability]") {
  const study::StabilityResult r = RunNamed("push into a wall E=2e+11Pa");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
}

TEST_CASE("Stability: push into a wall past the buckling load, the shipped rubber tube",
          "[stability]") {
  // Pressed along its axis at the device's 8.5 N (9.5 times the cantilever's Euler load) the
  // rubber tube's tip stays on the wall: the elastica is held off past buckling and the rod
  // carries the push (docs/core.md). Before, the first-mode elastica swung the tip away, the
  // contact opened and the tube sprang back 4 mm into the wall, over and over. It holds only
  // while the push is exactly along the axis: 0.1 mm off it, the tube buckles (test below).
  const study::StabilityResult r = RunNamed("push into a wall base");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
  CHECK(r.peak_force_N <= 8.5 * (1 + 1e-9));
}

TEST_CASE("Stability: strain beyond the linear-elastic range is reported, not accepted",
          "[stability]") {
  // A tube of 0.1 MPa pressed on a wall and slid at up to the device's 8.5 N: alpha = F l^2 / (E I)
  // ~ 700, where the root's curvature (the elastica's ~ sqrt(2 alpha) / l) puts the outer fibre
  // at a strain of ~2: far beyond 50 %. (The roll over an edge used to be the case: its strain
  // came from energy made by the stuck contact and from the linear fallback's unbounded
  // deflection, both gone.)
  const study::StabilityResult r = RunNamed("slide along a wall E=100000Pa");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.warning.find("beyond the linear-elastic") != std::string::npos);
}

TEST_CASE("Stability: a stub (l/r1 = 2) is reported outside the model's validity", "[stability]") {
  const study::StabilityResult r = RunNamed("slide along a wall l/r1=2");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
  CHECK(r.warning.find("l/r1 = 2 < 10") != std::string::npos);
}

TEST_CASE("Stability: fast pass through a 1 mm wall at 2 m/s, steel-stiff tube", "[stability]") {
  const study::StabilityResult r = RunNamed("fast pass E=2e+11Pa");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
}

TEST_CASE(
    "Stability: every case gives finite outputs, the same bits twice, at most the device's force",
    "[stability]") {
  // The safety checks that hold for every case today, whatever else fails: finite, repeatable,
  // and the operator's force never above the device's maximum (1e-6 relative: the saturation's
  // and the last guard's rounding), however the tick's decisions ended.
  for (const study::StabilityCase& c : study::StabilityCases(true)) {
    const study::StabilityResult r = study::RunStabilityCase(c);
    INFO(r.name << ": " << r.detail);
    CHECK(r.detail.find("finite outputs") == std::string::npos);
    CHECK(r.detail.find("same bits") == std::string::npos);
    CHECK(r.peak_force_N <= c.scene.device.max_force_N * (1 + 1e-6));
  }
}

TEST_CASE("Stability: fast pass at 2 m/s through a 1 mm wall, rubber tube", "[stability]") {
  // The hand moves 2 mm a tick, twice the wall's thickness: the core's speculative band (the
  // contact band grown by the tick's largest rigid motion) puts the wall in the tick's system
  // before the tube reaches it. Before, the tip was beyond the wall at tick 6.
  const study::StabilityResult r = RunNamed("fast pass base");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
  CHECK(r.warning.find("tunnelling") == std::string::npos);
}

TEST_CASE(
    "Stability: pushed 0.1 mm off its axis to the device's 8.5 N, the stuck tube stays straight "
    "(the end face's tilt stiffness in the rod's tick)",
    "[stability]") {
  // The stuck tip pins the column, whose buckling load is 2.05 pi^2 EI / l^2 = 7.3 N without the
  // end face's resistance to tilting: the dome's lowest point moves against the end's tilt by
  // R = 320 mm per radian, a spring k_r = N R (2.7 N m/rad at 8.5 N) that makes the end nearly
  // clamped (4 pi^2 EI / l^2 = 14 N). Until stop 41 the rod's ticks left that spring to the next
  // tick's point: at tick 415 (7.3 N) the tube snapped and the energy held passed the hand's
  // work at tick 416. The rod's tick now carries it (its compliance's end-moment directions,
  // docs/core.md): the push reaches the device's force with no tick off its contacts (a trace:
  // 1.9e-7 J of bending, 4.7 mN sideways on the hand at the end). A snapped tube would strain past
  // the linear-elastic 0.5 and be reported outside the model's validity with the failure in its
  // warning (stop 35 saw 0.516): the warning is checked too.
  const study::StabilityResult r = RunNamed("push into a wall off-plane=0.1mm");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
  CHECK(r.warning.empty());
  CHECK(r.first_shape_off_tick < 0);
}

TEST_CASE("Stability: pushed 0.1 mm off its axis, the stuck tube stays straight past 0.90 N",
          "[stability]") {
  // Past the free end's Euler load (0.90 N, tick 82) the rod's dead-load solve lands on its
  // buckled branch, 13.9 mm off the points the contacts hold, and the Newton on the loads,
  // stepping from there, got it to 6.5 mm: refused, the tube snapped at tick 82 (stops 36-37).
  // Solved with the tip's sideways force unknown (model::Rod::SolvePinned) from last tick's
  // shape, it stays on its contacts to the held column's own buckling load, 7.3 N at tick 415.
  const study::StabilityResult r = RunNamed("push into a wall off-plane=0.1mm");
  INFO(r.detail << " | " << r.warning);
  CHECK((r.first_shape_off_tick < 0 || r.first_shape_off_tick > 400));
  CHECK((r.pass || r.first_failing_tick > 400));
}

TEST_CASE("Stability: fast pass 0.1 mm off the axis, the pushed column stays straight",
          "[stability]") {
  // The push above at 2 m/s. Pressed on the 1 mm wall, its force reaches the device's 8.5 N in
  // three ticks, through the free end's 8.1 N (kL = 3 pi / 2, where the rod's end turn per moment
  // passes infinity). It buckled at tick 19 and made energy: the tangent of 7.7 N, reused, kept
  // t_M = +40 rad/(N m) where it was -30, and at tick 19 the last capsule's cap, inside the end
  // cylinder 1.4 mm behind the face, closed under the coupling's unclamped 14 N and cut the rod
  // l / 16 from its end for the tick. The reuse now checks the straight column's t_M at the
  // end's push, and the cap inside the end cylinder is no contact (docs/accuracy.md).
  const study::StabilityResult r = RunNamed("fast pass off-plane=0.1mm");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
}

TEST_CASE("Stability: the fast pass off its axis goes neither through the 1 mm wall nor near it",
          "[stability]") {
  // The fast pass 0.1 mm off the axis buckled against the wall (until the fix above). The next
  // tick's shape, with no contact in it, sprang back straight and 11.7 mm through the wall,
  // which has no inside r1/2 deep for the core's guard to find; the sweep saw the tip beyond
  // its far face from tick 26. The guard now finds the centreline across the sheet and holds
  // the tick (docs/core.md, "Through a part"): the sweep's own check, on the centreline against
  // the wall's far face, never fired, and the case was held back. (This case no longer drives
  // the guard across the sheet: tests/core/collision_test.cpp tests AxisThrough on a sheet.)
  const study::StabilityResult r = RunNamed("fast pass off-plane=0.1mm");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.detail.find("no tunnelling") == std::string::npos);
  CHECK(r.warning.find("no tunnelling") == std::string::npos);
  // Since the fast pass no longer buckles (above), nothing is held either.
  CHECK(r.held_ticks == 0);
}

TEST_CASE("Stability: roll over an edge 0.1 mm off its plane", "[stability]") {
  // A motion that bends the tube anyway: 0.1 mm out of its plane changes nothing of substance,
  // and the case passes as the in-plane one does. (The off-plane variation, which the push and
  // the fast pass fail above, is not what fails them.)
  const study::StabilityResult r = RunNamed("roll over an edge off-plane=0.1mm");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
  CHECK(r.warning.empty());
}

TEST_CASE("Stability: slide along a wall: passive, and on the contact it is pushed onto",
          "[stability]") {
  // The hand pushes the tube's end face onto the wall with ~4 N along its axis and moves
  // sideways; the tip stays stuck and the leaning column tilts the face until its rim carries
  // the load. The face is a dome (collision.cpp), whose lowest point is a potential: before stop
  // 36 the face pressed at the penalty's centre of pressure, a law that is not the gradient of
  // any energy, and made 0.85 mJ over ticks 275-600 until the energy held passed the hand's
  // work (tick 604). Before stop 35 the rod's pinned shape drifted off its linearisation (tick
  // 552) and the load point jumped from the lagging centre of pressure to the rim (tick 605),
  // each time snapping the tube centimetres sideways: its shape stays on the points the tick's
  // system held (core::kShapeOffContacts never raised), and it is never held back.
  const study::StabilityResult r = RunNamed("slide along a wall base");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
  CHECK(r.warning.empty());
  CHECK(r.first_shape_off_tick == -1);
  CHECK(r.held_ticks == 0);
}

TEST_CASE("Stability: slide along a wall with a stiff penalty (K = 1e7 N/m): the rim stays on",
          "[stability]") {
  // The slide above with a penalty a thousand times stiffer: the rim's 3.1 N presses it only
  // 0.3 um in, less than the drawn shape's own error, so each tick found the rim 2.3 um beyond
  // eps and it began open. The tick's prediction closed it again while the rod's tangent was the
  // one computed 50 ticks before. At tick 974 the renewed tangent's prediction of the unloaded
  // tube moved away from the wall: the load stayed open, the tube sprang straight 3.5 mm into
  // the wall, and the energy held passed the hand's work at tick 975. A load that pressed last
  // tick now starts in the system within eps / 10 of the band, and only the system lets it go.
  // (Before stop 36's dome it failed at tick 270.)
  const study::StabilityResult r = RunNamed("slide along a wall K=1e+07N/m");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
  CHECK(r.first_shape_off_tick == -1);
  CHECK(r.held_ticks == 0);
}

TEST_CASE("Stability: slide along a wall with a 10 um band: the pressed face is a bed of springs",
          "[stability]") {
  // The base slide with eps = 1e-5 m: ~3.9 N presses the end face 0.38 mm (38 eps) into the
  // wall. Until stop 43 such an overlapping face took no dome and its flat law's range was
  // 2 r1 sin(tilt) < eps / 10 (6e-5 rad): at tick 223, 0.1 mm into the slide, the stuck tip's
  // tilt passed it, the load point jumped 8 mm from the face's centre to the rim, the tube took
  // 4.6 mJ of bending in that tick and the energy held passed the hand's work. The dome now
  // serves a face pressed in too, and its radius is the bed of springs' (r1^2 + r2^2) / (4 p) at
  // the depth p = N / K - eps that last tick's force pressed it through the wall's surface (59 mm
  // here, against the tolerance's 32 m), so its point moves from the centre by 59 mm per radian
  // of tilt: the case passes, on its contacts.
  const study::StabilityResult r = RunNamed("slide along a wall eps=1e-05m");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
  CHECK(r.first_shape_off_tick == -1);
  CHECK(r.held_ticks == 0);
}

TEST_CASE("Stability: slide along a wall and back: the face takes the load over from the rim",
          "[stability]") {
  // The base slide's motion driven back to where it started (the sweep slides one way only): the
  // end face tilts back under its dome's range while the rim carries the load. Before stop 36's
  // review the face's point started from nothing, at its target, and the tube snapped at tick
  // 1494 (tilt 1.7 -> 5.9 degrees in two ticks, N 3.7 -> 4.5 -> 3.5 N, 2.3 mJ over the sweep's
  // slack). Now the face continues the rim's load from the rim's point: the shape stays on its
  // contacts, the tube is never held back, and the normal force changes by less than 0.25 N a
  // tick (0.1 N at most, measured; the snap's was 0.93 N).
  // The same with a 10 um band: the face pressed 0.38 mm through the wall has the bed of
  // springs' dome (stop 43), and its rim, reached on the way back, overlaps the wall in most
  // ticks. Before stop 43 its load jumped 3.5 N in a tick and its shape left its contacts (tick
  // 223); now 0.08 N at most, measured.
  for (const char* name : {"slide along a wall base", "slide along a wall eps=1e-05m"}) {
    INFO(name);
    const study::StabilityCase base = testing::QuickCase(name);
    const scene::Scene& s = base.scene;
    core::Core core(s);
    const double gap = 2.0 * s.contact.threshold_m + 1e-3, dt = s.model.time_step_s;
    const std::vector<Eigen::Vector3d> waypoints{
        {0, 0, gap + 0.01}, {0.04, 0, gap + 0.01}, {0, 0, gap + 0.01}};
    Eigen::Vector3d hand = Eigen::Vector3d::Zero();
    double t = 0.0, last_N = 0.0, worst_jump_N = 0.0;
    int tick = 0, off = 0, held = 0, worst_at = 0;
    const auto step = [&](const Eigen::Vector3d& h) {
      Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
      X.translation() = h;
      const core::StepOutput& o = core.Step(t += dt, X);
      ++tick;
      if (o.flags & core::kShapeOffContacts) ++off;
      if (o.flags & core::kHeldBack) ++held;
      double N = 0.0;
      for (const core::ContactState& pc : o.Contacts()) N += pc.normal_force_N;
      if (tick > 1 && std::abs(N - last_N) > worst_jump_N) {
        worst_jump_N = std::abs(N - last_N);
        worst_at = tick;
      }
      last_N = N;
    };
    for (const Eigen::Vector3d& target : waypoints) {
      const int n = std::max(1, int(std::ceil((target - hand).norm() / (base.speed_m_per_s * dt))));
      const Eigen::Vector3d from = hand;
      for (int i = 1; i <= n; ++i) step(from + (target - from) * (double(i) / n));
      hand = target;
    }
    for (int i = 0; i < 100; ++i) step(hand);
    INFO("largest change of N " << worst_jump_N << " N at tick " << worst_at);
    CHECK(off == 0);
    CHECK(held == 0);
    CHECK(worst_jump_N < 0.25);
  }
}

TEST_CASE("Stability: roll over an edge, the side pressed on it with stuck friction, then drawn",
          "[stability]") {
  // The stuck contact's stretch is carried with the contact, not held in the world against a
  // point found again each tick, and under the elastica it does not see the one-way turn of the
  // surface point's offset (docs/core.md, "Stuck contacts"). Before, the energy held exceeded the
  // hand's work by 7 % at tick 63.
  const study::StabilityResult r = RunNamed("roll over an edge base");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
}

TEST_CASE("Stability: roll over an edge with mu = 2: the rim slides off the corner, not through",
          "[stability]") {
  // Drawn back along its axis, the tube's rim leaves the edge it is bent 4 mm onto. A tick
  // starts with its contacts stuck; the stuck spring's trial force (far beyond the limit, which
  // is zero at N <= 0) dragged the rim off the edge, the load was released for the tick, and the
  // tube sprang straight 2.4 mm into the part's far face: 7.5 mJ held, more than twice the hand's
  // work, from tick 1662. A stuck load that pulls now slides before it is released (docs/core.md).
  const study::StabilityResult r = RunNamed("roll over an edge mu=2");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
  CHECK(r.held_ticks == 0);
}

TEST_CASE("Stability: squeeze between walls: the segmented rule out of range, judged coupled",
          "[stability]") {
  // Pinched between both walls (0.5 mm clearance, 5 N of penalty a side from the first tick) and
  // swung, the frictionless tube carries loads on both walls, on different segments. The paper's
  // segmented rule leaves out what the far loads move the near contact by (core::kSegmentationOff,
  // past eps / 10 from tick 35, millimetres soon after), and its one-way compliance makes energy:
  // the energy held exceeds the hand's work from tick 95. That is reported, and the case is judged
  // with the coupled rule, which must pass every check on the same motion.
  const study::StabilityResult r = RunNamed("squeeze between walls mu=0");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.judged_coupled);
  CHECK(r.first_segmentation_off_tick > 0);
  CHECK(r.warning.find("the segmented rule outside its range") != std::string::npos);
  CHECK(r.warning.find("under the segmented rule: passivity") != std::string::npos);
  CHECK(r.peak_force_N <= 8.5 * (1 + 1e-6));
  CHECK(r.pass);
  CHECK(!r.outside);
}

TEST_CASE("Stability: squeeze between walls with friction: the segmented rule stays in range",
          "[stability]") {
  // The same squeeze with the scene's friction. Until stop 42 the segmented rule left its range
  // here at tick 46 too: a load that closed in a pass of the tick and was released in a later one
  // kept cutting the elastica's and the rod's chain for the rest of the tick (the linear model
  // rebuilt its cuts; the nonlinear models kept every load that had been in contact), so the far
  // segment's loads moved the near one by millimetres the rule did not see. Released, such a load
  // now leaves the chain: the rule stays within eps / 10 and the case passes as given.
  const study::StabilityResult r = RunNamed("squeeze between walls base");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
  CHECK(!r.judged_coupled);
  CHECK(r.first_segmentation_off_tick == -1);
  CHECK(!r.outside);
}

TEST_CASE("Stability: squeeze with a 10 um band: a released load leaves the chain", "[stability]") {
  // Pinched with 0.5 mm to spare each side and a band of 10 um, the tube's contacts open and
  // close from tick to tick (the tip swings 0.1 mm a tick across a band of 10 um). At tick 75 the
  // tip's line contact on the left wall closed in a pass of the tick, pulled and was released,
  // but its cut stayed in the elastica's and the rod's chain for the rest of the tick: the drawn
  // shape put the tip's surface 4.6 mm into the left wall with no contact, and from tick 108
  // (stops 38 to 41) the energy held exceeded the hand's work. A released load that joined in the
  // tick now leaves the chain (stop 42). The segmented rule still leaves its range (tick 29):
  // the case is judged with the coupled rule, which must pass.
  const study::StabilityResult r = RunNamed("squeeze between walls eps=1e-05m");
  INFO(r.detail << " | " << r.warning);
  CHECK(r.judged_coupled);
  CHECK(r.pass);
}

TEST_CASE("Stability: a stiff plastic tube (E = 2e8 Pa) squeezed between walls does not rock",
          "[stability]") {
  // The full sweep's case: pinched with 5 N a side along both walls and swung. The region of each
  // wall's line contact ran from its first piece's nearest point, which is one end or the other of
  // the stretch over the face by the sign of the piece's tilt: the region's end jumped 6.5 mm
  // from tick to tick, the held end rocked 50 um back and forth, the operator felt 0.5 N at
  // 500 Hz, and the energy held passed the hand's work at tick 35 (under both rules). The region
  // now runs over its pieces' stretches whatever their tilt.
  const study::StabilityResult r =
      study::RunStabilityCase(testing::SweepCase("squeeze between walls E=2e+08Pa", false));
  INFO(r.detail << " | " << r.warning);
  CHECK(r.pass);
  CHECK(r.held_ticks == 0);
  CHECK(r.first_shape_off_tick == -1);
}

TEST_CASE("A frictionless tube pinched in a groove follows the hand without stepping back",
          "[stability][core]") {
  // The squeeze's scene and its first swing, frictionless, with the linear beam and the coupled
  // rule: then each tick's state minimises a convex energy (the coupling's spring and damper, the
  // beam's symmetric compliance, the penalty's max(0, eps - d)^2), in which the hand's position
  // enters linearly, so the held end's position is monotone in the hand's: as the hand moves
  // along +x, the held end never moves back. It stepped back by 51 um (E = 2e8 Pa) and 0.27 um
  // (steel) while the line contacts' region ends rocked with the sign of the pieces' tilt.
  for (const char* name : {"squeeze between walls E=100000Pa", "squeeze between walls base",
                           "squeeze between walls E=2e+08Pa", "squeeze between walls E=2e+11Pa"}) {
    study::StabilityCase c = testing::SweepCase(name, false);
    c.scene.friction = scene::Friction{};
    c.scene.model.beam = model::BeamModel::kLinear;
    c.scene.model.multi_contact = scene::MultiContactRule::kCoupled;
    core::Core core(c.scene);
    const double dt = c.scene.model.time_step_s;
    const double z_m = 0.5 * (2.0 * c.scene.contact.threshold_m + 1e-3);  // the sweep's waypoint
    double t = 0.0;
    const auto step = [&](const Eigen::Vector3d& hand) -> const core::StepOutput& {
      Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
      X.translation() = hand;
      return core.Step(t += dt, X);
    };
    for (int i = 1; i <= 20; ++i) step(Eigen::Vector3d(0.0, 0.0, z_m * i / 20));
    double x_m = core.last().X_WH.translation().x(), worst_m = 0.0;
    int pinched = 0;
    for (int i = 1; i <= 120; ++i) {  // 6 mm at 50 um a tick, as the sweep swings it
      const core::StepOutput& out = step(Eigen::Vector3d(6e-3 * i / 120, 0.0, z_m));
      worst_m = std::min(worst_m, out.X_WH.translation().x() - x_m);
      x_m = out.X_WH.translation().x();
      if (out.contact_count >= 2) ++pinched;
    }
    INFO(name);
    CHECK(pinched > 0);  // both walls hold it
    // 1e-12 m: rounding of a position of millimetres.
    CHECK(worst_m >= -1e-12);
  }
}

TEST_CASE("Stability: the segmented rule is judged in range where it is", "[stability]") {
  // One PC, or loads on one segment: nothing is left out, and the case is judged as given.
  for (const char* name : {"push into a wall base", "roll over an edge base", "fast pass base",
                           "squeeze between walls E=2e+11Pa"}) {
    const study::StabilityResult r = RunNamed(name);
    INFO(name << ": " << r.detail << " | " << r.warning);
    CHECK(!r.judged_coupled);
    CHECK(r.first_segmentation_off_tick == -1);
  }
}

TEST_CASE("Stability: the core holds the tube back where it went through a wall", "[stability]") {
  // core::kHeldBack (docs/core.md, "Through a part"): a tick whose solution would put a point of
  // the centreline more than r1/2 inside a part is not taken. Before it, these three drove the
  // tube's axis 4-6 mm into a wall (the sweep's tunnelling check, which is independent of the
  // core's: the centreline against the parts' boxes); now none does, and each was held back.
  for (const char* name : {"squeeze between walls r2/r1=0", "squeeze between walls speed=2m/s",
                           "squeeze between walls alpha=1000"}) {
    const study::StabilityResult r = RunNamed(name);
    INFO(name << ": " << r.detail << " | " << r.warning);
    CHECK(r.detail.find("no tunnelling") == std::string::npos);
    CHECK(r.warning.find("no tunnelling") == std::string::npos);
    CHECK(r.held_ticks > 0);
    CHECK(r.first_held_tick >= 1);
    CHECK(r.detail.find("held back from going through a part") != std::string::npos);
  }
  // A case the core resolves is never held back, nor flagged: the rod shapes the rubber tube
  // pushed past buckling here within the tolerance every tick.
  for (const char* name : {"push into a wall base", "roll over an edge base"}) {
    const study::StabilityResult r = RunNamed(name);
    INFO(name << ": " << r.detail);
    CHECK(r.pass);
    CHECK(r.first_shape_off_tick == -1);
    CHECK(r.held_ticks == 0);
  }
}

TEST_CASE("tubeplan stability --json: one document, passing cases exit 0", "[stability][cli]") {
  const auto run = [](std::vector<std::string> args, std::string& out_text) {
    std::ostringstream out, err;
    const int code = cli::Run(args, out, err);
    out_text = out.str();
    return code;
  };
  std::string text;
  CHECK(run({"stability", "--quick", "--json", "--only", "push into a wall E=2e+11Pa"}, text) == 0);
  const nlohmann::json j = nlohmann::json::parse(text);
  REQUIRE(j["cases"].size() == 1);
  CHECK(j["cases"][0]["name"] == "push into a wall E=2e+11Pa");
  CHECK(j["cases"][0]["pass"] == true);
  // A case judged with the coupled rule says so, in the matrix and in the document.
  CHECK(run({"stability", "--quick", "--only", "squeeze between walls mu=0"}, text) == 0);
  CHECK(text.find("pass (coupled") != std::string::npos);
  CHECK(run({"stability", "--quick", "--json", "--only", "squeeze between walls mu=0"}, text) == 0);
  const nlohmann::json squeeze = nlohmann::json::parse(text);
  CHECK(squeeze["cases"][0]["judged_with"] == "coupled");
  CHECK(squeeze["cases"][0]["first_segmentation_off_tick"].get<int>() > 0);
}

TEST_CASE("tubeplan stability's report: a failing case is named with its tick, and exits 1",
          "[stability][cli]") {
  // The failure path driven with results made here, independent of which cases the core fails:
  // one pass, one failure at tick 223, one pass outside the model's validity.
  std::vector<study::StabilityResult> results(3);
  results[0].name = "slide along a wall base";
  results[0].motion = "slide along a wall";
  results[0].parameter = "base";
  results[1].name = "slide along a wall eps=1e-05m";
  results[1].motion = "slide along a wall";
  results[1].parameter = "eps=1e-05m";
  results[1].pass = false;
  results[1].first_failing_tick = 223;
  results[1].detail = "passivity at tick 223";
  results[2].name = "push into a wall l/r1=2";
  results[2].motion = "push into a wall";
  results[2].parameter = "l/r1=2";
  results[2].outside = true;
  results[2].warning = "outside the model's validity (l/r1 = 2 < 10: not a slender beam)";
  std::ostringstream out, err;
  CHECK(cli::ReportStability(results, false, {out, err}) == 1);
  CHECK(out.str().find("FAIL @223") != std::string::npos);
  CHECK(out.str().find("FAIL slide along a wall eps=1e-05m: passivity at tick 223") !=
        std::string::npos);
  CHECK(out.str().find("pass (outside)") != std::string::npos);
  CHECK(out.str().find("2 of 3 cases pass") != std::string::npos);
  CHECK(err.str().find("warning: push into a wall l/r1=2: outside") != std::string::npos);
  std::ostringstream json_out, json_err;
  CHECK(cli::ReportStability(results, true, {json_out, json_err}) == 1);
  const nlohmann::json j = nlohmann::json::parse(json_out.str());
  CHECK(j["pass"] == false);
  REQUIRE(j["cases"].size() == 3);
  CHECK(j["cases"][1]["pass"] == false);
  CHECK(j["cases"][1]["first_failing_tick"] == 223);
  CHECK(j["cases"][0]["first_failing_tick"].is_null());
  // And all passing: 0.
  results[1].pass = true;
  results[1].first_failing_tick = -1;
  std::ostringstream ok_out, ok_err;
  CHECK(cli::ReportStability(results, false, {ok_out, ok_err}) == 0);
  CHECK(ok_out.str().find("3 of 3 cases pass") != std::string::npos);
}
