#include "graph/explorer_motions.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <utility>

#include <tubeplan/scene/geometry.hpp>

namespace tubeplan::graph {
namespace explorer {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
// Probe moves are short and quick, as the random motions' fastest (a flick of the hand): the
// probes are most of the exploration's ticks.
constexpr double kProbeSpeed_m_per_s = 0.15;
constexpr double kProbeTurn_rad_per_s = 2.0;

bool InsideAnyPart(const scene::Scene& scene, const Eigen::Vector3d& p_W) {
  for (const scene::Part& part : scene.parts)
    if (scene::Contains(part, p_W)) return true;
  return false;
}

Eigen::Quaterniond TurnAxis(const Eigen::Quaterniond& q0, const Eigen::Vector3d& from,
                            const Eigen::Vector3d& to) {
  return (Eigen::Quaterniond::FromTwoVectors(from, to) * q0).normalized();
}

struct Frame {  // directions of the start pose
  Eigen::Vector3d p0, axis, up, lateral;
  Eigen::Vector3d tip;    // a turn about it by a positive angle tips the free end down (across,
                          // for a plumb tube)
  Eigen::Vector3d swing;  // the free end swings sideways about it
  bool plumb = false;     // the tube starts along up, or against it
  Eigen::Quaterniond q0;
};

Frame StartFrame(const scene::Scene& scene) {
  Frame f;
  const Eigen::Isometry3d X0 = MotionStart(scene);
  f.p0 = X0.translation();
  f.q0 = Eigen::Quaterniond(X0.linear());
  f.axis = X0.linear().col(2);
  // Scenes have world z up (docs/scene-format.md): "down" is where the groove's floor is.
  f.up = Eigen::Vector3d::UnitZ();
  f.lateral = f.up.cross(f.axis);
  if (f.lateral.norm() < 1e-6) f.lateral = X0.linear().col(0);
  f.lateral.normalize();
  // The tube tips down about the level direction square to it and swings about up; a plumb
  // tube, which neither turn moves, tips about its lateral direction and swings about the third.
  f.tip = f.axis.cross(-f.up);
  f.plumb = f.tip.norm() < 1e-6;
  f.tip = f.plumb ? f.lateral : f.tip.normalized();
  f.swing = f.plumb ? Eigen::Vector3d(f.axis.cross(f.tip).normalized()) : f.up;
  return f;
}

Eigen::Vector3d ClampToWorkspace(const scene::Scene& scene, const Eigen::Vector3d& p) {
  if (!scene.workspace) return p;
  return p.cwiseMax(scene.workspace->min_W_m).cwiseMin(scene.workspace->max_W_m);
}

bool InWorkspace(const scene::Scene& scene, const Eigen::Vector3d& p) {
  return !scene.workspace || ((p.array() >= scene.workspace->min_W_m.array()).all() &&
                              (p.array() <= scene.workspace->max_W_m.array()).all());
}

Move MoveTo(const Eigen::Vector3d& p, const Eigen::Quaterniond& q, double speed, double guard_N,
            const Eigen::Vector3d& from) {
  Move m;
  m.p_W_m = p;
  m.q_W = q;
  m.speed_m_per_s = speed;
  m.turn_rad_per_s = 1.0;  // about 60 deg/s, a calm wrist
  const Eigen::Vector3d d = p - from;
  if (guard_N > 0.0 && d.norm() > 1e-9) {
    m.guard_dir_W = -d.normalized();  // the force that pushes back against the move
    m.guard_N = guard_N;
  }
  return m;
}

// A move by `d` from wherever the hand is (where a guard stopped the move before), kept in the
// workspace, guarded against the force that pushes back along d.
Move MoveBy(const scene::Scene& scene, const Eigen::Vector3d& d, const Eigen::Quaterniond& q,
            double speed, double guard_N) {
  Move m = MoveTo(d, q, speed, guard_N, Eigen::Vector3d::Zero());
  m.relative = true;
  if (scene.workspace)
    m.within_W = Eigen::AlignedBox3d(scene.workspace->min_W_m, scene.workspace->max_W_m);
  return m;
}

// Whether the tube, straight and held at X, touches nothing: its axis inside no part, and a tick
// of the core with the hand there from a reset there. (Posed through a plate, a node inside it
// sees the plate's faces along the tube, which a tick leaves to the neighbouring elements: a
// tube that moved there would have met the plate first.)
bool FreePose(const scene::Scene& scene, core::Core& core, const Eigen::Isometry3d& X) {
  const double l = scene.tube.length_m, spacing_m = 0.5 * scene.tube.outer_radius_m;
  const int points = static_cast<int>(std::ceil(l / spacing_m));
  for (int k = 0; k <= points; ++k)
    if (InsideAnyPart(scene, X * Eigen::Vector3d(0.0, 0.0, l * k / points))) return false;
  core.Reset(X);
  const core::StepOutput& out = core.Step(0.0, X);
  return out.contact_count == 0 && (out.flags & core::kPenetration) == 0;
}

// A point of element e (an index into the core's elements) and its outward normal; a round
// element's where it faces the start.
scene::ElementPoint PointFacingStart(const scene::Scene& scene, const core::Core& probe, int e,
                                     const Frame& f) {
  const auto& elements = probe.elements();
  const std::size_t part_index = elements[std::size_t(e)].part_index;
  // The element's index within its part: elements come in part order.
  int first = e;
  while (first > 0 && elements[std::size_t(first - 1)].part_index == part_index) --first;
  const scene::Part& part = scene.parts[part_index];
  return scene::PointOnElement(part, e - first,
                               f.p0 - part.X_WP * scene::BoundsInPart(part).center());
}

// Whether a PC of the scene's goal is on the part element named `element` (by the tube element
// `tube`, if given).
bool InGoal(const scene::Scene& scene, const std::string& element,
            std::optional<states::TubeElement> tube = std::nullopt) {
  return std::any_of(scene.goal.contacts.begin(), scene.goal.contacts.end(),
                     [&](const states::PrincipalContact& pc) {
                       return pc.part_element == element && (!tube || pc.tube == *tube);
                     });
}

// From the start to over p at a safe height, turned to q; returns where the hand is then.
Eigen::Vector3d GoOver(const Frame& f, const Eigen::Vector3d& p, const Eigen::Quaterniond& q,
                       const ExploreOptions& o, Motion& m) {
  Eigen::Vector3d above = p;
  above.z() = std::max(f.p0.z(), p.z());
  Eigen::Vector3d lift = f.p0;
  lift.z() = above.z();
  m.moves.push_back(MoveTo(lift, f.q0, o.speed_m_per_s, 0.0, f.p0));
  m.moves.push_back(MoveTo(above, q, o.speed_m_per_s, o.push_N, lift));
  return above;
}

// The force that ends an aim's approach: a touch that bends a soft tube by less than the
// scene's bend threshold.
constexpr double kTouchGuard_N = 0.02;

// A goal's PCs as the aim at them together sees them: each element's point and outward normal,
// whether the tube's side is to lie on it (else its end is to meet it), the tube's axis and the
// hand's turn to it, and a point the tube's middle (sides only) or its end is placed nearest.
struct GoalPose {
  struct Target {
    Eigen::Vector3d c, n;
    bool side = false;
  };
  std::vector<Target> targets;
  Eigen::Vector3d axis, base;
  Eigen::MatrixXd normals;  // 3 x targets
  Eigen::Quaterniond q;

  // The free end's centre where the side's axis is r + gap off its faces and the end face gap off
  // its own, nearest `base` (least squares where they cannot all hold: between facing faces).
  Eigen::Vector3d Tip(double r, double gap) const {
    Eigen::VectorXd rhs(Eigen::Index(targets.size()));
    for (std::size_t i = 0; i < targets.size(); ++i)
      rhs[Eigen::Index(i)] =
          targets[i].n.dot(targets[i].c - base) + (targets[i].side ? r : 0.0) + gap;
    return base +
           normals * (normals.transpose() * normals).completeOrthogonalDecomposition().solve(rhs);
  }
};

// The goal's targets and the pose's axis: into the first end contact's element, else along the
// first two sides' faces (the start's axis between facing faces), turned into every side's
// face; the base point is the targets' mean. False where there is no such axis.
bool MakeGoalPose(const scene::Scene& scene, const core::Core& probe, const Frame& f, GoalPose& g) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const states::PrincipalContact& pc : scene.goal.contacts) {
    const auto& elements = probe.elements();
    const auto it = std::find_if(elements.begin(), elements.end(),
                                 [&](const auto& e) { return e.name == pc.part_element; });
    if (it == elements.end()) return false;
    const scene::ElementPoint at =
        PointFacingStart(scene, probe, static_cast<int>(it - elements.begin()), f);
    g.targets.push_back({at.p_W, at.n_W, pc.tube == states::TubeElement::kSide});
    mean += at.p_W / double(scene.goal.contacts.size());
  }
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  for (const GoalPose::Target& t : g.targets)
    if (!t.side && a.isZero()) a = -t.n;
  if (a.isZero()) {
    for (std::size_t j = 1; j < g.targets.size() && a.norm() < 1e-3; ++j)
      a = g.targets[0].n.cross(g.targets[j].n);
    if (a.norm() < 1e-3) a = f.axis;
    if (a.dot(f.axis) < 0.0) a = -a;
  }
  for (const GoalPose::Target& t : g.targets)
    if (t.side) a -= a.dot(t.n) * t.n;
  if (a.norm() < 1e-3) return false;
  g.axis = a.normalized();
  const bool sides_only =
      std::all_of(g.targets.begin(), g.targets.end(), [](const auto& t) { return t.side; });
  g.base = mean + (sides_only ? 0.5 * scene.tube.length_m : 0.0) * g.axis;
  g.normals.resize(3, Eigen::Index(g.targets.size()));
  for (std::size_t i = 0; i < g.targets.size(); ++i)
    g.normals.col(Eigen::Index(i)) = g.targets[i].n;
  g.q = TurnAxis(f.q0, f.axis, g.axis);
  return true;
}

// The hand's pose that puts the straight tube's free end at `tip` along the goal's axis.
Eigen::Isometry3d HandFor(const scene::Scene& scene, const GoalPose& g,
                          const Eigen::Vector3d& tip) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = g.q.toRotationMatrix();
  X.translation() = tip - scene.tube.length_m * g.axis;
  return X;
}

// A move by d that stops where the force against it passes guard_N, then a hold of 100 ms (so
// the state there counts).
void GuardedMoveAndHold(const scene::Scene& scene, const Eigen::Vector3d& d,
                        const Eigen::Quaterniond& q, double speed, double guard_N, Motion& m) {
  m.moves.push_back(MoveBy(scene, d, q, speed, guard_N));
  m.moves.push_back(MoveBy(scene, Eigen::Vector3d::Zero(), q, speed, 0.0));
  m.moves.back().min_ticks = 100;
}

// The straight tube clear of every goal element by the same gap, brought in along the sum of
// their inward normals so that it meets them together (a tube lying in a corner, or on a floor
// with its end against a wall), held at the first light touch, pressed and backed off. None
// where that sum does not close on every element (facing faces) or no pose is clear.
std::optional<Motion> ApproachTogether(const scene::Scene& scene, core::Core& probe, const Frame& f,
                                       const GoalPose& g, const ExploreOptions& o) {
  Eigen::Vector3d push = -g.normals.rowwise().sum();
  if (push.norm() < 1e-6) return std::nullopt;
  push.normalize();
  // Each element's distance falls at this rate along push, or the approach cannot meet it.
  double slowest = 1.0;
  for (const GoalPose::Target& t : g.targets) slowest = std::min(slowest, -push.dot(t.n));
  if (slowest < 0.1) return std::nullopt;
  // A narrower gap where the wider does not fit (a tube seated in a groove's corner has 2 mm to
  // spare on the other side).
  for (const double gap : {scene.contact.threshold_m + 3e-3, scene.contact.threshold_m + 1e-3}) {
    const double travel = gap / slowest;  // until the last element is within reach
    const Eigen::Isometry3d X = HandFor(scene, g, g.Tip(scene.tube.outer_radius_m, gap));
    if (!InWorkspace(scene, X.translation()) || !FreePose(scene, probe, X)) continue;
    Motion m;
    m.kind = "aim goal";
    // Straight down onto the clear pose (the way in to a hole), then in along push.
    const Eigen::Vector3d above = GoOver(f, X.translation(), g.q, o, m);
    m.moves.push_back(MoveTo(X.translation(), g.q, 0.5 * o.speed_m_per_s, o.push_N, above));
    GuardedMoveAndHold(scene, travel * push, g.q, 0.1 * o.speed_m_per_s, kTouchGuard_N, m);
    m.moves.push_back(MoveBy(scene, 3e-3 * push, g.q, 0.5 * o.speed_m_per_s, o.push_N));
    m.moves.push_back(
        MoveBy(scene, -2.5 * scene.tube.outer_radius_m * push, g.q, o.speed_m_per_s, 0.0));
    return m;
  }
  return std::nullopt;
}

// For facing faces (a slot under a bar): the tube set down on the goal face that faces up most,
// drawn back along its axis by the fewest whole radii (up to its length) that take it clear,
// slid in (guarded at the probing force), held and drawn back. None where no such pose is
// clear, or no goal face takes the tube's side.
std::optional<Motion> SlideIn(const scene::Scene& scene, core::Core& probe, const Frame& f,
                              const GoalPose& g, const ExploreOptions& o) {
  const auto set_down_on =
      std::max_element(g.targets.begin(), g.targets.end(), [&](const auto& x, const auto& y) {
        return x.side < y.side || (x.side == y.side && x.n.dot(f.up) < y.n.dot(f.up));
      });
  if (!set_down_on->side) return std::nullopt;
  const Eigen::Vector3d& n_up = set_down_on->n;
  const double l = scene.tube.length_m, r = scene.tube.outer_radius_m;
  const double eps = scene.contact.threshold_m, gap = eps + 3e-3;
  const Eigen::Vector3d tip = g.Tip(r, 0.5 * eps);
  for (double back = r; back <= l; back += r) {
    const Eigen::Isometry3d X = HandFor(scene, g, tip - back * g.axis + gap * n_up);
    if (!InWorkspace(scene, X.translation()) || !FreePose(scene, probe, X)) continue;
    Motion m;
    m.kind = "aim goal";
    const Eigen::Vector3d above = GoOver(f, X.translation(), g.q, o, m);
    m.moves.push_back(MoveTo(X.translation(), g.q, 0.5 * o.speed_m_per_s, o.push_N, above));
    GuardedMoveAndHold(scene, -gap * n_up, g.q, 0.1 * o.speed_m_per_s, kTouchGuard_N, m);
    GuardedMoveAndHold(scene, back * g.axis, g.q, 0.25 * o.speed_m_per_s, o.push_N, m);
    m.moves.push_back(MoveBy(scene, -back * g.axis, g.q, 0.5 * o.speed_m_per_s, 0.0));
    m.moves.push_back(MoveBy(scene, 2.5 * r * n_up, g.q, o.speed_m_per_s, 0.0));
    return m;
  }
  return std::nullopt;
}

}  // namespace

bool Covered(const scene::Scene& scene, const core::Core& probe, int e) {
  const scene::ElementPoint at = PointFacingStart(scene, probe, e, StartFrame(scene));
  return InsideAnyPart(scene, at.p_W + 0.5 * scene.contact.threshold_m * at.n_W);
}

Box PartsBox(const scene::Scene& scene, const std::vector<std::uint32_t>& parts) {
  Box box;
  for (std::uint32_t p : parts) {
    const scene::Part& part = scene.parts[p];
    const Eigen::AlignedBox3d bounds_P = scene::BoundsInPart(part);
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d c_P = bounds_P.corner(Eigen::AlignedBox3d::CornerType(corner));
      box.lo = box.lo.cwiseMin(part.X_WP * c_P);
      box.hi = box.hi.cwiseMax(part.X_WP * c_P);
    }
  }
  return box;
}

std::vector<Motion> Sweeps(const scene::Scene& scene, const Box& box, const ExploreOptions& o) {
  const Frame f = StartFrame(scene);
  const double r = scene.tube.outer_radius_m;
  // Lateral offsets across the parts, a tube radius apart; the tube level and tipped down.
  const double half = 0.5 * std::abs((box.hi - box.lo).dot(f.lateral.cwiseAbs()));
  const Eigen::Vector3d centre = 0.5 * (box.lo + box.hi);
  const double centre_lateral = (centre - f.p0).dot(f.lateral);
  const int n = std::max(1, static_cast<int>(std::floor(half / r)));
  std::vector<Motion> motions;
  for (double tilt_deg : {0.0, 12.0}) {
    const Eigen::Vector3d tipped = Eigen::AngleAxisd(tilt_deg * kDeg, f.tip) * f.axis;
    const Eigen::Quaterniond q = TurnAxis(f.q0, f.axis, tipped);
    for (int i = -n; i <= n; ++i) {
      Motion m;
      m.kind = "sweep";
      Eigen::Vector3d p = ClampToWorkspace(scene, f.p0 + (centre_lateral + i * r) * f.lateral);
      m.moves.push_back(MoveTo(p, q, o.speed_m_per_s, o.push_N, f.p0));
      // Down until it pushes back (or to the bottom of the parts).
      Eigen::Vector3d down = p;
      down.z() = std::min(p.z(), box.lo.z());
      down = ClampToWorkspace(scene, down);
      m.moves.push_back(MoveTo(down, q, 0.5 * o.speed_m_per_s, o.push_N, p));
      // Sideways both ways, then along the tube's axis: contact moves, at half speed, each from
      // where the last one stopped (the friction of the pressed tube stays below its guard).
      const double slide = 2.0 * r;
      for (const Eigen::Vector3d& d :
           {Eigen::Vector3d(slide * f.lateral), Eigen::Vector3d(-2.0 * slide * f.lateral),
            Eigen::Vector3d(2.5 * r * f.axis)})
        m.moves.push_back(MoveBy(scene, d, q, 0.5 * o.speed_m_per_s, 1.5 * o.push_N));
      m.moves.push_back(MoveBy(scene, 5.0 * r * f.up, f.q0, o.speed_m_per_s, 0.0));
      motions.push_back(std::move(m));
    }
  }
  return motions;
}

std::vector<Motion> Aims(const scene::Scene& scene, core::Core& probe,
                         const std::vector<int>& elements, const ExploreOptions& o) {
  const Frame f = StartFrame(scene);
  const double l = scene.tube.length_m, r = scene.tube.outer_radius_m;
  const double gap = scene.contact.threshold_m + 3e-3;  // start clear of epsilon
  std::vector<Motion> motions;
  for (int e : elements) {
    if (Covered(scene, probe, e)) continue;
    const scene::PartElement& element = probe.elements()[std::size_t(e)];
    const scene::ElementPoint at = PointFacingStart(scene, probe, e, f);
    const Eigen::Vector3d& c_W = at.p_W;
    const Eigen::Vector3d& n_W = at.n_W;
    // A direction along the element, leaning down and along the start axis where it can.
    Eigen::Vector3d t = f.axis - f.up;
    t -= t.dot(n_W) * n_W;
    if (t.norm() < 1e-6) t = n_W.cross(f.lateral);
    t.normalize();
    struct Approach {
      Eigen::Vector3d axis, hand, push, slide;
      bool along_axis = false;  // the last stretch of the approach along the tube's axis
    };
    std::vector<Approach> tip_aims, side_aims;
    // The tip, its axis leaning off the normal; where no leaning pose is free on an element of
    // the goal (the floor of a hole to insert into), straight along the normal, end first,
    // coming in along its axis.
    const bool in_goal = InGoal(scene, element.name);
    // The goal's end face flat on the element: the axis along its normal first.
    const bool flat_in_goal = InGoal(scene, element.name, states::TubeElement::kEndFace);
    const std::array<double, 4> leaning_deg = {30.0, 60.0, 80.0, 0.0},
                                flat_deg = {0.0, 30.0, 60.0, 80.0};
    // The goal's rim caught on an edge or a vertex: first the end along the normal, moved back
    // along t by its radius so that one point of its rim comes down onto the element (leaning,
    // the rim's lowest point meets it from beside).
    const bool rim_on_point = element.kind != scene::ElementKind::kFace &&
                              InGoal(scene, element.name, states::TubeElement::kEndRim);
    if (rim_on_point) {
      const Eigen::Vector3d p_W_end = c_W + gap * n_W - r * t;
      tip_aims.push_back({-n_W, p_W_end + l * n_W, -n_W, t, true});
    }
    for (double phi_deg : flat_in_goal ? flat_deg : leaning_deg) {
      if (phi_deg == 0.0 && !in_goal) continue;
      const Eigen::Vector3d a = -n_W * std::cos(phi_deg * kDeg) + t * std::sin(phi_deg * kDeg);
      const Eigen::Vector3d tip = c_W + gap * n_W + r * std::sin(phi_deg * kDeg) * n_W;
      tip_aims.push_back({a, tip - l * a, a, t, phi_deg == 0.0});
    }
    // The side along the element: along t, across it, and on an element of the goal where
    // neither pose is clear, turned from t about the normal by 10 deg steps either way (along
    // a trough that t crosses).
    std::vector<Eigen::Vector3d> along = {t, n_W.cross(t).normalized()};
    for (int k = 1; k < 9 && in_goal; ++k)
      for (const double sign : {-1.0, 1.0})
        along.push_back(Eigen::AngleAxisd(sign * k * 10.0 * kDeg, n_W) * t);
    for (const Eigen::Vector3d& a : along) {
      const Eigen::Vector3d mid = c_W + (gap + r) * n_W;
      side_aims.push_back({a, mid - 0.5 * l * a, -n_W, a});
    }
    for (const std::vector<Approach>* aims : {&tip_aims, &side_aims}) {
      for (const Approach& aim : *aims) {
        const Eigen::Quaterniond q = TurnAxis(f.q0, f.axis, aim.axis);
        Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
        X.linear() = q.toRotationMatrix();
        X.translation() = aim.hand;
        if (!InWorkspace(scene, aim.hand) || !FreePose(scene, probe, X)) continue;
        Motion m;
        m.kind = "aim " + element.name;
        // Over the target at a safe height, down onto it (straight in: down to an entry back
        // along the axis, as far as fits the workspace and is clear, then along it), press,
        // slide, back off.
        Eigen::Vector3d entry = aim.hand;
        for (const double back_of_length : {0.5, 0.25, 0.125}) {
          if (!aim.along_axis) break;
          Eigen::Isometry3d X_entry = X;
          X_entry.translation() = aim.hand - back_of_length * l * aim.axis;
          if (InWorkspace(scene, X_entry.translation()) && FreePose(scene, probe, X_entry)) {
            entry = X_entry.translation();
            break;
          }
        }
        const Eigen::Vector3d above = GoOver(f, entry, q, o, m);
        if (entry != aim.hand)
          m.moves.push_back(MoveTo(entry, q, 0.5 * o.speed_m_per_s, o.push_N, above));
        // The descent guarded against what pushes back along it, from the entry or from above.
        m.moves.push_back(MoveTo(aim.hand, q, 0.5 * o.speed_m_per_s, o.push_N,
                                 entry != aim.hand ? entry : above));
        // Onto the surface, stopped by the first light push (the element touched, the tube not
        // yet bent by it) and held where it stopped, then pressed, slid and backed off, each
        // from where the last move stopped.
        m.moves.push_back(MoveBy(scene, gap * aim.push, q, 0.1 * o.speed_m_per_s, kTouchGuard_N));
        m.moves.push_back(MoveBy(scene, Eigen::Vector3d::Zero(), q, o.speed_m_per_s, 0.0));
        m.moves.back().min_ticks = 100;
        m.moves.push_back(MoveBy(scene, 3e-3 * aim.push, q, 0.5 * o.speed_m_per_s, o.push_N));
        m.moves.push_back(
            MoveBy(scene, 1.5 * r * aim.slide, q, 0.5 * o.speed_m_per_s, 1.5 * o.push_N));
        m.moves.push_back(MoveBy(scene, 2.5 * r * n_W, q, o.speed_m_per_s, 0.0));
        motions.push_back(std::move(m));
        break;  // one tip motion and one side motion per element
      }
    }
  }
  return motions;
}

std::vector<Motion> GoalAims(const scene::Scene& scene, core::Core& probe,
                             const ExploreOptions& o) {
  if (scene.goal.contacts.size() < 2) return {};
  const Frame f = StartFrame(scene);
  GoalPose g;
  if (!MakeGoalPose(scene, probe, f, g)) return {};
  std::optional<Motion> m = ApproachTogether(scene, probe, f, g, o);
  if (!m) m = SlideIn(scene, probe, f, g, o);
  if (!m) return {};
  return {std::move(*m)};
}

std::vector<Move> Probes(const scene::Scene& scene, const Eigen::Isometry3d& X_W_hand,
                         const ExploreOptions& o) {
  const Frame f = StartFrame(scene);
  const int hold = 5 + static_cast<int>(std::lround(o.dwell_s / scene.model.time_step_s));
  const Eigen::Vector3d p = X_W_hand.translation();
  const Eigen::Quaterniond q(X_W_hand.linear());
  std::vector<std::pair<Eigen::Vector3d, Eigen::Quaterniond>> targets;
  // Along the tube's axis, or for a plumb tube (whose axis is up) along the third direction.
  for (const Eigen::Vector3d& d : {f.lateral, f.plumb ? f.swing : f.axis, f.up})
    for (double sign : {1.0, -1.0})
      targets.push_back({ClampToWorkspace(scene, p + sign * o.probe_step_m * d), q});
  for (const Eigen::Vector3d& axis : {f.tip, f.swing})
    for (double sign : {1.0, -1.0})
      targets.push_back(
          {p, (Eigen::Quaterniond(Eigen::AngleAxisd(sign * o.probe_turn_rad, axis)) * q)
                  .normalized()});
  std::vector<Move> moves;
  auto go = [&](const Eigen::Vector3d& to_p, const Eigen::Quaterniond& to_q, double limit_N) {
    Move move = MoveTo(to_p, to_q, kProbeSpeed_m_per_s, 0.0, to_p);
    move.turn_rad_per_s = kProbeTurn_rad_per_s;
    move.force_limit_N = limit_N;
    moves.push_back(move);
    move.min_ticks = hold;  // the same pose again: held still
    moves.push_back(move);
  };
  // Out, stopped where the operator force passes the explorer's limit, and back.
  const double limit_N = ExploreForceLimit(scene, o);
  for (const auto& [to_p, to_q] : targets) {
    go(to_p, to_q, limit_N);
    go(p, q, 0.0);
  }
  return moves;
}

std::vector<Motion> RandomMotionsIn(const scene::Scene& scene, const Box& box, std::uint64_t seed,
                                    int first, int count, const ExploreOptions& o) {
  const Frame f = StartFrame(scene);
  const double l = scene.tube.length_m;
  // The hand roams across the parts (sideways), from their bottom to a quarter tube length above
  // their top, and along the tube's start axis from the start to a fifth of a tube length
  // further in: the region of the insertion task. Further along, the tube only meets the far
  // ends of the parts, which are another task's states.
  const auto range = [&](const Eigen::Vector3d& d) {
    double a = std::numeric_limits<double>::infinity(), b = -a;
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d c(corner & 1 ? box.hi.x() : box.lo.x(),
                              corner & 2 ? box.hi.y() : box.lo.y(),
                              corner & 4 ? box.hi.z() : box.lo.z());
      a = std::min(a, (c - f.p0).dot(d)), b = std::max(b, (c - f.p0).dot(d));
    }
    return std::pair{a, b};
  };
  const auto [lateral_lo, lateral_hi] = range(f.lateral);
  const auto [up_lo, up_hi] = range(f.up);
  const double along_lo = 0.0, along_hi = 0.2 * l;
  const double up_top = up_hi + 0.25 * l;
  std::vector<Motion> motions;
  for (int i = first; i < first + count; ++i) {
    // One generator per motion, seeded by (seed, index): motion i is the same whichever
    // motions were made before it.
    std::seed_seq sequence{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                           static_cast<std::uint32_t>(i)};
    std::mt19937_64 rng(sequence);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    auto uniform = [&](double a, double b) { return a + (b - a) * unit(rng); };
    Motion m;
    m.kind = "random";
    Eigen::Vector3d from = f.p0;
    Eigen::Quaterniond q = f.q0;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d p = ClampToWorkspace(
          scene, f.p0 + uniform(lateral_lo, lateral_hi) * f.lateral +
                     uniform(along_lo, along_hi) * f.axis + uniform(up_lo, up_top) * f.up);
      if (unit(rng) < 0.7) {
        const Eigen::Vector3d tipped =
            Eigen::AngleAxisd(uniform(-8.0, 8.0) * kDeg, f.swing) *
            (Eigen::AngleAxisd(uniform(-5.0, 30.0) * kDeg, f.tip) * f.axis);
        q = TurnAxis(f.q0, f.axis, tipped);
      }
      const double guard = unit(rng) < 0.6 ? uniform(1.0, 4.0) : 0.0;
      m.moves.push_back(MoveTo(p, q, uniform(0.05, 0.15), guard, from));
      from = p;
    }
    m.moves.push_back(MoveTo(from + 0.05 * f.up, q, o.speed_m_per_s, 0.0, from));
    motions.push_back(std::move(m));
  }
  return motions;
}

}  // namespace explorer

std::vector<Motion> RandomMotions(const scene::Scene& scene, std::uint64_t seed, int first,
                                  int count, const ExploreOptions& options) {
  const core::Core probe(scene);
  return explorer::RandomMotionsIn(scene, explorer::PartsBox(scene, probe.reachable_parts()), seed,
                                   first, count, options);
}

}  // namespace tubeplan::graph
