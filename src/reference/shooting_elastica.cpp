#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

#include <tubeplan/reference/shooting_elastica.hpp>

namespace tubeplan::reference::shooting {
namespace {

using Eigen::Vector2d;
using Y = Eigen::Matrix<double, 5, 1>;  // x, z, theta, m, bending energy so far

constexpr double kInf = std::numeric_limits<double>::infinity();

Vector2d Tangent(double theta) { return {std::sin(theta), std::cos(theta)}; }
Vector2d Section(double theta) { return {std::cos(theta), -std::sin(theta)}; }
// Moment about +y of the force f applied at the lever r.
double MomentOf(const Vector2d& r, const Vector2d& f) { return r.y() * f.x() - r.x() * f.y(); }
Vector2d PlaneTangent(const Vector2d& n) { return {n.y(), -n.x()}; }
double SideOf(double x) { return x < 0.0 ? -1.0 : 1.0; }

bool IsRim(const Obstacle& ob) { return ob.kind == ObstacleKind::kPlaneRim; }

// Everything a solve holds fixed, and where each unknown sits in the vector x: m(0); the state
// (x, z, theta, m) at the start of segments 1..J-1; per slot its force; per side slot its arc.
// Scaled: moments by EI/l, forces by EI/l^2, lengths by l.
struct Problem {
  const Rod& rod;
  const Setup& setup;
  std::vector<Slot> slots;
  std::vector<SlotFriction> friction;
  std::vector<int> arc_unknown;  // per slot: index of its arc in x, -1 for rims
  int segments = 1;
  int size = 1;
  double l = 0.0, ei = 0.0;
  double moment_scale = 0.0, force_scale = 0.0;

  const Obstacle& ObstacleOf(std::size_t i) const {
    return setup.obstacles[std::size_t(slots[i].obstacle)];
  }
  int StartIndex(int j) const { return 1 + 4 * (j - 1); }  // j >= 1
  int ForceIndex(std::size_t i) const { return 1 + 4 * (segments - 1) + 2 * int(i); }
  double Boundary(int j) const { return j == segments ? l : l * j / segments; }
  // The segment holding arc s: segment j is [b_j, b_j+1), the last one closed.
  int SegmentOf(double s) const {
    int j = std::clamp(int(s / l * segments), 0, segments - 1);
    while (j > 0 && Boundary(j) > s) --j;
    while (j + 1 < segments && Boundary(j + 1) <= s) ++j;
    return j;
  }
};

// Where a contact acts and how far its obstacle is, at the centreline's state (p, theta) there.
struct ContactGeometry {
  double distance_m = kInf;
  Vector2d normal = Vector2d::Zero();
  Vector2d tangent = Vector2d::Zero();
  Vector2d point_m = Vector2d::Zero();
  double side = 1.0;   // the loaded surface point is p + side r1 g
  double slope = 0.0;  // side contacts: d(distance)/ds
};

ContactGeometry Geometry(const Problem& P, std::size_t i, const Vector2d& p, double theta) {
  const Obstacle& ob = P.ObstacleOf(i);
  const double r1 = P.rod.radius_m;
  const Vector2d t = Tangent(theta), g = Section(theta);
  ContactGeometry c;
  switch (ob.kind) {
    case ObstacleKind::kPlaneRim: {
      const double d_minus = ob.normal.dot(p - r1 * g - ob.point_m);
      const double d_plus = ob.normal.dot(p + r1 * g - ob.point_m);
      c.side =
          P.slots[i].corner != 0 ? double(P.slots[i].corner) : (d_minus <= d_plus ? -1.0 : 1.0);
      c.distance_m = c.side < 0.0 ? d_minus : d_plus;
      c.point_m = p + c.side * r1 * g;
      c.normal = ob.normal;
      c.tangent = PlaneTangent(ob.normal);
      break;
    }
    case ObstacleKind::kPlaneSide:
      c.distance_m = ob.normal.dot(p - ob.point_m) - r1;
      c.normal = ob.normal;
      c.tangent = PlaneTangent(ob.normal);
      c.point_m = p - r1 * ob.normal;
      c.side = SideOf(-ob.normal.dot(g));
      c.slope = ob.normal.dot(t);
      break;
    case ObstacleKind::kEdge: {
      const Vector2d v = p - ob.point_m;
      const double length = v.norm();
      c.normal = length > 0.0 ? Vector2d(v / length) : g;
      c.distance_m = length - r1;
      c.point_m = p - r1 * c.normal;
      const Vector2d along = t - t.dot(c.normal) * c.normal;
      c.tangent = along.norm() > 1e-12 ? Vector2d(along.normalized()) : PlaneTangent(c.normal);
      c.side = SideOf(-c.normal.dot(g));
      c.slope = c.normal.dot(t);
      break;
    }
  }
  return c;
}

// A point of the tube's surface: the centreline at arc s offset by side r1 g.
Vector2d SurfacePoint(const Problem& P, const Vector2d& p, double theta, double side) {
  return p + side * P.rod.radius_m * Section(theta);
}

double ArcOf(const Problem& P, const Eigen::VectorXd& x, std::size_t i) {
  if (P.arc_unknown[i] < 0) return P.l;
  return std::clamp(x(P.arc_unknown[i]) * P.l, 0.0, P.l);
}

Vector2d ForceOf(const Problem& P, const Eigen::VectorXd& x, std::size_t i) {
  return x.segment<2>(P.ForceIndex(i)) * P.force_scale;
}

Y Derivative(const Y& y, const Vector2d& n, double ei) {
  const double st = std::sin(y(2)), ct = std::cos(y(2));
  Y d;
  d << st, ct, y(3) / ei, -(n.x() * ct - n.y() * st), 0.5 * y(3) * y(3) / ei;
  return d;
}

void PushNode(std::vector<CentrelinePoint>& nodes, double s, const Y& y, double ei) {
  nodes.push_back({s, Vector2d(y(0), y(1)), y(2), y(3) / ei, y(3)});
}

// Classical Runge-Kutta from s0 to s1 in `steps` equal steps, n constant in between.
void Integrate(Y& y, const Vector2d& n, double s0, double s1, int steps, double ei,
               std::vector<CentrelinePoint>& nodes) {
  const double h = (s1 - s0) / steps;
  for (int k = 0; k < steps; ++k) {
    const Y k1 = Derivative(y, n, ei);
    const Y k2 = Derivative(y + 0.5 * h * k1, n, ei);
    const Y k3 = Derivative(y + 0.5 * h * k2, n, ei);
    const Y k4 = Derivative(y + h * k3, n, ei);
    y += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    PushNode(nodes, k + 1 == steps ? s1 : s0 + (k + 1) * h, y, ei);
  }
}

// Something that happens at an arc: a contact's load, the point a stuck contact holds (an
// observation only), or the dead loads at the free end (slot -1).
struct Event {
  double arc_m = 0.0;
  int slot = -1;
  bool anchor = false;
};

// What the forces and arcs decide before any integration.
struct Layout {
  std::vector<Event> events;        // by arc
  std::vector<int> first_event;     // per segment, and one past the last
  std::vector<Vector2d> n_start_N;  // n at each segment's start
  Vector2d held_m = Vector2d::Zero();
};

// The centreline's state where an event happens.
struct Station {
  Vector2d p = Vector2d::Zero();
  double theta = 0.0;
};

struct SegmentResult {
  Y end = Y::Zero();  // at the segment's end (the last: past the loads at the free end)
  std::vector<CentrelinePoint> nodes;
  std::vector<std::pair<int, Station>> stations;  // event index, state there
};

struct Evaluation {
  Layout layout;
  std::vector<SegmentResult> segments;
  Eigen::VectorXd residual;
  std::vector<Station> at_contact, at_anchor;  // per slot
  std::vector<ContactGeometry> geometry;       // per slot
  std::vector<double> normal_N, tangential_N, stretch_m;
  double bending_energy_J = 0.0;
};

Layout MakeLayout(const Problem& P, const Eigen::VectorXd& x) {
  Layout L;
  for (std::size_t i = 0; i < P.slots.size(); ++i) {
    L.events.push_back({ArcOf(P, x, i), int(i), false});
    if (P.friction[i].mode != FrictionMode::kNone && P.arc_unknown[i] >= 0)
      L.events.push_back({std::clamp(P.friction[i].anchor_arc_m, 0.0, P.l), int(i), true});
  }
  L.events.push_back({P.l, -1, false});
  std::stable_sort(L.events.begin(), L.events.end(),
                   [](const Event& a, const Event& b) { return a.arc_m < b.arc_m; });
  // n at a segment's start is the sum of the loads from there on.
  L.first_event.assign(std::size_t(P.segments + 1), int(L.events.size()));
  L.n_start_N.assign(std::size_t(P.segments), Vector2d::Zero());
  for (int e = int(L.events.size()) - 1; e >= 0; --e) {
    const int j = P.SegmentOf(L.events[std::size_t(e)].arc_m);
    for (int k = 0; k <= j; ++k)
      L.first_event[std::size_t(k)] = std::min(L.first_event[std::size_t(k)], e);
    const Event& ev = L.events[std::size_t(e)];
    if (ev.anchor) continue;
    const Vector2d f = ev.slot < 0 ? P.setup.tip_force_N : ForceOf(P, x, std::size_t(ev.slot));
    for (int k = 0; k <= j; ++k) L.n_start_N[std::size_t(k)] += f;
  }
  // The held end follows from n(0) through the coupling.
  L.held_m = P.setup.hand_m;
  if (P.setup.coupling_N_per_m > 0.0) L.held_m += L.n_start_N[0] / P.setup.coupling_N_per_m;
  return L;
}

Y SegmentStart(const Problem& P, const Eigen::VectorXd& x, const Layout& L, int j) {
  Y y;
  if (j == 0) {
    y << L.held_m.x(), L.held_m.y(), P.setup.root_angle_rad, x(0) * P.moment_scale, 0.0;
  } else {
    const int k = P.StartIndex(j);
    y << x(k) * P.l, x(k + 1) * P.l, x(k + 2), x(k + 3) * P.moment_scale, 0.0;
  }
  return y;
}

// Integrates segment j from its start, applying the loads in it: each drops n by its force and m
// by its moment about the centreline there.
SegmentResult IntegrateSegment(const Problem& P, const Eigen::VectorXd& x, const Layout& L, int j) {
  SegmentResult r;
  const int steps = P.rod.steps_per_piece;
  Y y = SegmentStart(P, x, L, j);
  Vector2d n = L.n_start_N[std::size_t(j)];
  double s = P.Boundary(j);
  const int first = L.first_event[std::size_t(j)], last = L.first_event[std::size_t(j + 1)];
  r.nodes.reserve(std::size_t(steps * (last - first + 1) + (last - first) + 1));
  PushNode(r.nodes, s, y, P.ei);
  for (int e = first; e < last; ++e) {
    const Event& ev = L.events[std::size_t(e)];
    if (ev.arc_m > s) {
      Integrate(y, n, s, ev.arc_m, steps, P.ei, r.nodes);
      s = ev.arc_m;
    }
    const Station here{Vector2d(y(0), y(1)), y(2)};
    r.stations.emplace_back(e, here);
    if (ev.anchor) continue;
    if (ev.slot < 0) {
      n -= P.setup.tip_force_N;
      y(3) -= P.setup.tip_moment_Nm;
    } else {
      const std::size_t i = std::size_t(ev.slot);
      const Vector2d f = ForceOf(P, x, i);
      n -= f;
      y(3) -= MomentOf(Geometry(P, i, here.p, here.theta).point_m - here.p, f);
    }
    PushNode(r.nodes, s, y, P.ei);
  }
  const double s_end = P.Boundary(j + 1);
  if (s_end > s) Integrate(y, n, s, s_end, steps, P.ei, r.nodes);
  r.end = y;
  return r;
}

// The equations: continuity between segments, no moment beyond the free end, each force its
// law, each side contact at the nearest point (projected gradient: interior minimum or an end).
void Assemble(const Problem& P, const Eigen::VectorXd& x, Evaluation& ev) {
  const std::size_t S = P.slots.size();
  ev.at_contact.assign(S, Station{});
  ev.at_anchor.assign(S, Station{});
  ev.bending_energy_J = 0.0;
  for (const SegmentResult& seg : ev.segments) {
    ev.bending_energy_J += seg.end(4);
    for (const auto& [e, station] : seg.stations) {
      const Event& event = ev.layout.events[std::size_t(e)];
      if (event.slot < 0) continue;
      (event.anchor ? ev.at_anchor : ev.at_contact)[std::size_t(event.slot)] = station;
    }
  }
  ev.residual.setZero(P.size);
  ev.residual(0) = ev.segments.back().end(3) / P.moment_scale;
  for (int j = 1; j < P.segments; ++j) {
    const Y& end = ev.segments[std::size_t(j - 1)].end;
    const Y start = SegmentStart(P, x, ev.layout, j);
    const int k = P.StartIndex(j);
    ev.residual(k) = (end(0) - start(0)) / P.l;
    ev.residual(k + 1) = (end(1) - start(1)) / P.l;
    ev.residual(k + 2) = end(2) - start(2);
    ev.residual(k + 3) = (end(3) - start(3)) / P.moment_scale;
  }
  const ContactLaw& law = P.setup.law;
  ev.geometry.resize(S);
  ev.normal_N.assign(S, 0.0);
  ev.tangential_N.assign(S, 0.0);
  ev.stretch_m.assign(S, 0.0);
  for (std::size_t i = 0; i < S; ++i) {
    const Obstacle& ob = P.ObstacleOf(i);
    const SlotFriction& fr = P.friction[i];
    const ContactGeometry c = Geometry(P, i, ev.at_contact[i].p, ev.at_contact[i].theta);
    ev.geometry[i] = c;
    const double N = law.stiffness_N_per_m * std::max(0.0, law.threshold_m - c.distance_m);
    if (fr.mode != FrictionMode::kNone) {
      const Station& a = P.arc_unknown[i] >= 0 ? ev.at_anchor[i] : ev.at_contact[i];
      const Vector2d held_point = SurfacePoint(P, a.p, a.theta, double(fr.anchor_side));
      const Vector2d anchor = ob.kind == ObstacleKind::kEdge ? ob.point_m : fr.anchor_m;
      ev.stretch_m[i] = c.tangent.dot(held_point - anchor);
    }
    double T = 0.0;
    if (N > 0.0 && fr.mode == FrictionMode::kSliding)
      T = -fr.slide_sign * KineticForce(ob.friction, N);
    if (N > 0.0 && fr.mode == FrictionMode::kStuck) T = -law.stiffness_N_per_m * ev.stretch_m[i];
    ev.normal_N[i] = N;
    ev.tangential_N[i] = T;
    const Vector2d f_law = N * c.normal + T * c.tangent;
    ev.residual.segment<2>(P.ForceIndex(i)) = (ForceOf(P, x, i) - f_law) / P.force_scale;
    if (P.arc_unknown[i] >= 0) {
      const double arc = x(P.arc_unknown[i]) * P.l;
      ev.residual(P.arc_unknown[i]) = (arc - std::clamp(arc - P.l * c.slope, 0.0, P.l)) / P.l;
    }
  }
}

Evaluation Evaluate(const Problem& P, const Eigen::VectorXd& x) {
  Evaluation ev;
  ev.layout = MakeLayout(P, x);
  for (int j = 0; j < P.segments; ++j) ev.segments.push_back(IntegrateSegment(P, x, ev.layout, j));
  Assemble(P, x, ev);
  return ev;
}

std::vector<CentrelinePoint> Nodes(const Evaluation& ev) {
  std::vector<CentrelinePoint> nodes;
  for (const SegmentResult& seg : ev.segments)
    nodes.insert(nodes.end(), seg.nodes.begin(), seg.nodes.end());
  return nodes;
}

Vector2d PositionAt(const Problem& P, const Evaluation& ev, double s) {
  return At(ev.segments[std::size_t(P.SegmentOf(s))].nodes, s).position_m;
}

// The largest distance between two centrelines at a few arcs, held ends included.
double Move(const Problem& P, const Evaluation& a, const Evaluation& b) {
  double largest = 0.0;
  constexpr int kSamples = 16;
  for (int k = 0; k <= kSamples; ++k) {
    const double s = P.l * k / kSamples;
    largest = std::max(largest, (PositionAt(P, a, s) - PositionAt(P, b, s)).norm());
  }
  return largest;
}

// Central differences (O(delta^2)) in the scaled unknowns. The clamp moment and a segment's
// start move that segment alone: only it is integrated again.
Eigen::MatrixXd Jacobian(const Problem& P, const Eigen::VectorXd& x, const Evaluation& base) {
  Eigen::MatrixXd J(P.size, P.size);
  constexpr double kDelta = 1e-7;
  const int shape_end = P.StartIndex(P.segments);
  Evaluation work = base;
  for (int k = 0; k < P.size; ++k) {
    Eigen::VectorXd column = Eigen::VectorXd::Zero(P.size);
    for (const double sign : {1.0, -1.0}) {
      Eigen::VectorXd xk = x;
      xk(k) += sign * kDelta;
      if (k < shape_end) {
        const int j = k == 0 ? 0 : 1 + (k - 1) / 4;
        work.segments[std::size_t(j)] = IntegrateSegment(P, xk, work.layout, j);
        Assemble(P, xk, work);
        column += sign * work.residual;
        work.segments[std::size_t(j)] = base.segments[std::size_t(j)];
      } else {
        column += sign * Evaluate(P, xk).residual;
      }
    }
    J.col(k) = column / (2.0 * kDelta);
  }
  return J;
}

struct NewtonResult {
  Eigen::VectorXd x;
  Evaluation ev;
  bool converged = false;
  int iterations = 0;
  double residual = kInf;
};

double Merit(const Evaluation& ev) { return 0.5 * ev.residual.squaredNorm(); }

// Damped Newton: a step is halved until the centreline moves at most max_move and the squared
// residual falls (Armijo). A contact's kink can end a valley of that merit short of the answer
// (a step that closes a gap between segments presses the tube into a part while its force is
// still that of no contact): then the longest step within max_move is taken anyway, and the
// best point is kept, up to 8 steps without a new best. A stall within 1000 tolerances of
// converged is rounding.
NewtonResult Newton(const Problem& P, Eigen::VectorXd x, const SolveOptions& options,
                    double max_move) {
  NewtonResult r;
  Evaluation ev = Evaluate(P, x);
  Eigen::VectorXd best_x = x;
  Evaluation best_ev = ev;
  int since_best = 0;
  for (int it = 0;; ++it) {
    r.iterations = it;
    r.residual = ev.residual.lpNorm<Eigen::Infinity>();
    if (Merit(ev) < Merit(best_ev)) {
      best_x = x;
      best_ev = ev;
      since_best = 0;
    }
    if (r.residual <= options.tolerance) {
      r.converged = true;
      break;
    }
    if (it >= options.max_iterations || !ev.residual.allFinite() || since_best >= 8) break;
    ++since_best;
    const Eigen::VectorXd step =
        -Jacobian(P, x, ev).completeOrthogonalDecomposition().solve(ev.residual);
    if (!step.allFinite()) break;
    double lambda = 1.0, longest = 0.0;
    bool accepted = false;
    for (int b = 0; b < 50 && !accepted; ++b, lambda *= 0.5) {
      const Eigen::VectorXd xt = x + lambda * step;
      Evaluation et = Evaluate(P, xt);
      if (!et.residual.allFinite() || Move(P, ev, et) > max_move) continue;
      if (longest == 0.0) longest = lambda;
      if (Merit(et) <= (1.0 - 2e-4 * lambda) * Merit(ev)) {
        x = xt;
        ev = std::move(et);
        accepted = true;
      }
    }
    if (!accepted && r.residual <= 1e3 * options.tolerance) {
      r.converged = true;
      break;
    }
    if (!accepted) {
      if (longest == 0.0) break;
      x += longest * step;
      ev = Evaluate(P, x);
    }
  }
  if (!r.converged && Merit(best_ev) < Merit(ev)) {
    x = best_x;
    ev = std::move(best_ev);
    r.residual = ev.residual.lpNorm<Eigen::Infinity>();
  }
  r.x = std::move(x);
  r.ev = std::move(ev);
  return r;
}

// Side contacts: the arc of the centreline's nearest sample to the obstacle, and its distance.
std::pair<double, double> NearestSample(const Problem& P, std::size_t i, const Evaluation& ev) {
  double best_arc = 0.0, best_d = kInf;
  for (const SegmentResult& seg : ev.segments)
    for (const CentrelinePoint& q : seg.nodes) {
      const double d = Geometry(P, i, q.position_m, q.angle_rad).distance_m;
      if (d < best_d) {
        best_d = d;
        best_arc = q.arc_m;
      }
    }
  return {best_arc, best_d};
}

void CheckInputs(const Rod& rod, const Setup& setup, const SolveOptions& options) {
  std::ostringstream bad;
  if (!(rod.length_m > 0.0)) bad << " length_m " << rod.length_m << " must be > 0;";
  if (!(rod.bending_stiffness_Nm2 > 0.0))
    bad << " bending_stiffness_Nm2 " << rod.bending_stiffness_Nm2 << " must be > 0;";
  if (!(rod.radius_m >= 0.0)) bad << " radius_m " << rod.radius_m << " must be >= 0;";
  if (rod.segments < 1) bad << " segments " << rod.segments << " < 1;";
  if (rod.steps_per_piece < 2) bad << " steps_per_piece " << rod.steps_per_piece << " < 2;";
  if (!(setup.coupling_N_per_m >= 0.0)) bad << " coupling " << setup.coupling_N_per_m << " < 0;";
  if (!(setup.law.stiffness_N_per_m > 0.0) || !(setup.law.threshold_m >= 0.0))
    bad << " contact law needs K > 0 and eps >= 0;";
  for (std::size_t j = 0; j < setup.obstacles.size(); ++j) {
    const Obstacle& ob = setup.obstacles[j];
    if (ob.kind != ObstacleKind::kEdge && std::abs(ob.normal.norm() - 1.0) > 1e-9)
      bad << " obstacle " << j << ": normal (" << ob.normal.transpose() << ") is not unit;";
  }
  const std::size_t S = Slots(setup).size();
  if (!options.friction.empty() && options.friction.size() != S)
    bad << " friction has " << options.friction.size() << " entries for " << S << " contacts;";
  if (options.start && (options.start->force_N.size() != S || options.start->arc_m.size() != S))
    bad << " start has " << options.start->force_N.size() << " forces for " << S << " contacts;";
  if (!bad.str().empty()) throw std::invalid_argument("shooting::Solve:" + bad.str());
}

Problem MakeProblem(const Rod& rod, const Setup& setup, const SolveOptions& options) {
  Problem P{rod, setup, Slots(setup), options.friction, {}, rod.segments, 1, 0.0, 0.0, 0.0, 0.0};
  const std::size_t S = P.slots.size();
  if (P.friction.empty()) P.friction.assign(S, SlotFriction{});
  P.l = rod.length_m;
  P.ei = rod.bending_stiffness_Nm2;
  P.moment_scale = P.ei / P.l;
  P.force_scale = P.ei / (P.l * P.l);
  P.size = P.ForceIndex(S);
  for (std::size_t i = 0; i < S; ++i)
    P.arc_unknown.push_back(IsRim(P.ObstacleOf(i)) ? -1 : P.size++);
  return P;
}

// The segments' starts integrated from the clamp, one after the other (an initial-value
// solution for the clamp moment and forces in x).
void FillShape(const Problem& P, Eigen::VectorXd& x) {
  const Layout L = MakeLayout(P, x);
  for (int j = 0; j + 1 < P.segments; ++j) {
    const Y end = IntegrateSegment(P, x, L, j).end;
    const int k = P.StartIndex(j + 1);
    x(k) = end(0) / P.l;
    x(k + 1) = end(1) / P.l;
    x(k + 2) = end(2);
    x(k + 3) = end(3) / P.moment_scale;
  }
}

Eigen::VectorXd Pack(const Problem& P, const Unknowns& u) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(P.size);
  x(0) = u.clamp_moment_Nm / P.moment_scale;
  for (std::size_t i = 0; i < P.slots.size(); ++i) {
    x.segment<2>(P.ForceIndex(i)) = u.force_N[i] / P.force_scale;
    if (P.arc_unknown[i] >= 0) x(P.arc_unknown[i]) = u.arc_m[i] / P.l;
  }
  if (u.shape.size() + 1 != std::size_t(P.segments)) {
    FillShape(P, x);
    return x;
  }
  // The shape moves rigidly with the held end and the grip's angle (a predictor for the next
  // hold of a path: no gap between segments to close against a contact's kink).
  const Vector2d held = MakeLayout(P, x).held_m;
  const double turn = P.setup.root_angle_rad - u.root_angle_rad;
  Eigen::Matrix2d R;  // turns theta by `turn`: t(theta) -> t(theta + turn)
  R << std::cos(turn), std::sin(turn), -std::sin(turn), std::cos(turn);
  for (int j = 1; j < P.segments; ++j) {
    const Eigen::Vector4d& q = u.shape[std::size_t(j - 1)];
    const Vector2d p = held + R * (Vector2d(q(0), q(1)) - u.held_m);
    const int k = P.StartIndex(j);
    x(k) = p.x() / P.l;
    x(k + 1) = p.y() / P.l;
    x(k + 2) = q(2) + turn;
    x(k + 3) = q(3) / P.moment_scale;
  }
  return x;
}

// The unknowns of x in units, their shape belonging to the held end it gives.
Unknowns ToUnknowns(const Problem& P, const Eigen::VectorXd& x) {
  Unknowns u;
  u.clamp_moment_Nm = x(0) * P.moment_scale;
  u.held_m = MakeLayout(P, x).held_m;
  u.root_angle_rad = P.setup.root_angle_rad;
  for (int j = 1; j < P.segments; ++j) {
    const int k = P.StartIndex(j);
    u.shape.emplace_back(x(k) * P.l, x(k + 1) * P.l, x(k + 2), x(k + 3) * P.moment_scale);
  }
  for (std::size_t i = 0; i < P.slots.size(); ++i) {
    u.force_N.push_back(ForceOf(P, x, i));
    u.arc_m.push_back(P.arc_unknown[i] >= 0 ? x(P.arc_unknown[i]) * P.l : P.l);
  }
  return u;
}

Solution Unpack(const Problem& P, const NewtonResult& r) {
  const Evaluation& ev = r.ev;
  const ContactLaw& law = P.setup.law;
  Solution sol;
  sol.converged = r.converged;
  sol.iterations = r.iterations;
  sol.residual = r.residual;
  sol.unknowns = ToUnknowns(P, r.x);
  const Vector2d n0 = ev.layout.n_start_N[0];
  sol.held_m = ev.layout.held_m;
  sol.operator_force_N = -n0;
  sol.operator_moment_Nm = -sol.unknowns.clamp_moment_Nm;
  sol.centreline = Nodes(ev);
  sol.tip_m = sol.centreline.back().position_m;
  sol.tip_angle_rad = sol.centreline.back().angle_rad;
  sol.bending_energy_J = ev.bending_energy_J;
  for (const CentrelinePoint& q : sol.centreline)
    sol.max_turn_rad = std::max(sol.max_turn_rad, std::abs(q.angle_rad - P.setup.root_angle_rad));
  double potential = ev.bending_energy_J - P.setup.tip_force_N.dot(sol.tip_m) -
                     P.setup.tip_moment_Nm * sol.tip_angle_rad;
  if (P.setup.coupling_N_per_m > 0.0)
    potential += 0.5 * n0.squaredNorm() / P.setup.coupling_N_per_m;
  for (std::size_t i = 0; i < P.slots.size(); ++i) {
    const ContactGeometry& c = ev.geometry[i];
    const Friction& friction = P.ObstacleOf(i).friction;
    ContactResult cr;
    cr.slot = P.slots[i];
    cr.arc_m = ArcOf(P, r.x, i);
    cr.distance_m = c.distance_m;
    cr.active = ev.normal_N[i] > 0.0;
    cr.point_m = c.point_m;
    cr.normal = c.normal;
    cr.tangent = c.tangent;
    cr.normal_N = ev.normal_N[i];
    cr.tangential_N = ev.tangential_N[i];
    cr.force_N = ForceOf(P, r.x, i);
    cr.stretch_m = ev.stretch_m[i];
    cr.static_limit_N = StaticLimit(friction, cr.normal_N);
    cr.kinetic_force_N = KineticForce(friction, cr.normal_N);
    const double T = std::abs(cr.tangential_N);
    cr.friction_ratio = T == 0.0 ? 0.0 : (cr.static_limit_N > 0.0 ? T / cr.static_limit_N : kInf);
    sol.contacts.push_back(cr);
    potential += 0.5 * cr.normal_N * cr.normal_N / law.stiffness_N_per_m;
    if (cr.active && P.friction[i].mode == FrictionMode::kStuck)
      potential += 0.5 * law.stiffness_N_per_m * cr.stretch_m * cr.stretch_m;
  }
  sol.potential_energy_J = potential;
  return sol;
}

// Newton finds a stationary point of each side contact's distance; if a sample of the solved
// centreline lies nearer its obstacle (and within the band), it starts again from there.
NewtonResult SolveFrom(const Problem& P, Eigen::VectorXd x, const SolveOptions& options,
                       double max_move) {
  NewtonResult r;
  int iterations = 0;
  for (int restart = 0; restart < 4; ++restart) {
    r = Newton(P, x, options, max_move);
    iterations += r.iterations;
    if (!r.converged) break;
    bool moved = false;
    for (std::size_t i = 0; i < P.slots.size(); ++i) {
      if (P.arc_unknown[i] < 0) continue;
      const auto [arc, d] = NearestSample(P, i, r.ev);
      if (d < P.setup.law.threshold_m && d < r.ev.geometry[i].distance_m - 1e-9 * P.l) {
        r.x(P.arc_unknown[i]) = arc / P.l;
        moved = true;
      }
    }
    if (!moved) break;
    x = r.x;
  }
  r.iterations = iterations;
  return r;
}

// --- path ------------------------------------------------------------------------------------

// What the path carries from one hold to the next.
struct PathState {
  std::vector<SlotFriction> friction;
  std::optional<Unknowns> unknowns;
  std::optional<Solution> last;
  // Buckling: the sign of det(Jacobian) on the straight, pressed branch (0: not on it), and
  // whether a sign change is still waiting for a bent equilibrium.
  int straight_sign = 0;
  bool seeds_pending = false;
};

Setup AtHold(const Setup& base, const Hold& hold) {
  Setup setup = base;
  setup.hand_m = hold.hand_m;
  setup.root_angle_rad = hold.root_angle_rad;
  return setup;
}

// The side of the tube (+-1: p +- r1 g) that carries a contact.
double ContactSide(const ContactResult& c, const CentrelinePoint& q) {
  const Vector2d g = Section(q.angle_rad);
  const Vector2d lever = c.point_m - q.position_m;
  if (lever.norm() > 0.0) return SideOf(lever.dot(g));
  return SideOf(-c.normal.dot(g));
}

// A stuck contact holding the tube's point now at the contact, its anchor placed so that the
// spring is stretched by target_m along the contact's tangent. On a plane the anchor moves; an
// edge is its own anchor, so the held point moves along the tube instead.
SlotFriction PlaceAnchor(const Rod& rod, const Obstacle& ob, const ContactResult& c,
                         const Solution& sol, double target_m) {
  SlotFriction f;
  f.mode = FrictionMode::kStuck;
  const CentrelinePoint q = At(sol.centreline, c.arc_m);
  const double side = ContactSide(c, q);
  f.anchor_side = int(side);
  f.anchor_arc_m = c.arc_m;
  if (ob.kind != ObstacleKind::kEdge) {
    const Vector2d held = q.position_m + side * rod.radius_m * Section(q.angle_rad);
    f.anchor_m = held - ob.normal.dot(held - ob.point_m) * ob.normal - target_m * c.tangent;
    return f;
  }
  f.anchor_m = ob.point_m;
  double s = c.arc_m;
  for (int k = 0; k < 30; ++k) {
    const CentrelinePoint a = At(sol.centreline, s);
    const Vector2d held = a.position_m + side * rod.radius_m * Section(a.angle_rad);
    const double error = c.tangent.dot(held - ob.point_m) - target_m;
    const double slope =
        c.tangent.dot(Tangent(a.angle_rad)) * (1.0 - side * rod.radius_m * a.curvature_per_m);
    if (std::abs(error) <= 1e-15 * rod.length_m || slope == 0.0) break;
    s = std::clamp(s - error / slope, 0.0, rod.length_m);
  }
  f.anchor_arc_m = s;
  return f;
}

// First touch: the anchor is where the surface crossed d = eps, interpolated between the last
// hold (open) and this one; the spring is stretched by the tangential travel since then.
SlotFriction FirstTouch(const Rod& rod, const Setup& setup, std::size_t i, const Solution& sol,
                        const std::optional<Solution>& last) {
  const ContactResult& c = sol.contacts[i];
  const Obstacle& ob = setup.obstacles[std::size_t(c.slot.obstacle)];
  double target_m = 0.0;
  if (last) {
    const double d_last = last->contacts[i].distance_m;
    const double eps = setup.law.threshold_m;
    const double f = d_last > c.distance_m
                         ? std::clamp((d_last - eps) / (d_last - c.distance_m), 0.0, 1.0)
                         : 1.0;
    const CentrelinePoint now = At(sol.centreline, c.arc_m);
    const CentrelinePoint then = At(last->centreline, c.arc_m);
    const double side = ContactSide(c, now);
    const Vector2d x_now = now.position_m + side * rod.radius_m * Section(now.angle_rad);
    const Vector2d x_then = then.position_m + side * rod.radius_m * Section(then.angle_rad);
    target_m = (1.0 - f) * c.tangent.dot(x_now - x_then);
  }
  return PlaceAnchor(rod, ob, c, sol, target_m);
}

bool Frictional(const Obstacle& ob) {
  return ob.friction.static_coefficient > 0.0 || ob.friction.kinetic_coefficient > 0.0;
}

// The Jacobian at a solution: the sign of its determinant, which changes where the straight
// branch of a pressed column crosses a bifurcation (a real eigenvalue of J passes zero there:
// the test function of path following), and that eigenvalue's eigenvector, the buckling mode.
// (Not the smallest singular vector: a stiff contact, K l against EI / l^2, makes J badly scaled,
// and its smallest singular value belongs to that scaling, not to the rod.)
struct Criticality {
  int sign = 0;
  Eigen::VectorXd mode;
};

Criticality Critical(const Rod& rod, const Setup& setup, const SolveOptions& so,
                     const Unknowns& u) {
  const Problem P = MakeProblem(rod, setup, so);
  const Eigen::VectorXd x = Pack(P, u);
  const Eigen::MatrixXd J = Jacobian(P, x, Evaluate(P, x));
  Criticality c;
  const double det = J.partialPivLu().determinant();
  c.sign = det > 0.0 ? 1 : (det < 0.0 ? -1 : 0);
  const Eigen::EigenSolver<Eigen::MatrixXd> eigen(J);
  Eigen::Index nearest = -1;
  for (Eigen::Index k = 0; k < eigen.eigenvalues().size(); ++k) {
    const std::complex<double> lambda = eigen.eigenvalues()(k);
    if (std::abs(lambda.imag()) > 1e-9 * std::abs(lambda)) continue;  // real ones only
    if (nearest < 0 || std::abs(lambda) < std::abs(eigen.eigenvalues()(nearest))) nearest = k;
  }
  if (nearest >= 0) c.mode = eigen.eigenvectors().col(nearest).real();
  return c;
}

bool StraightAndPressed(const Solution& sol) {
  bool pressed = false;
  for (const ContactResult& c : sol.contacts) pressed = pressed || c.active;
  return pressed && sol.max_turn_rad <= 1e-7;
}

// Branch switching: Newton from the straight solution moved along the buckling mode, either way,
// turning a section by seed_rad and then by factors of 4 less down to 1/256 of it (just past
// the bifurcation the bent equilibrium is barely bent, and Newton from too small a move falls
// back to the straight one). A bent equilibrium of lower potential energy replaces the straight.
bool TryBucklingSeeds(const Rod& rod, const Setup& setup, const SolveOptions& so, double seed_rad,
                      const Eigen::VectorXd& mode, Solution& sol) {
  if (mode.size() == 0) return false;
  const Problem P = MakeProblem(rod, setup, so);
  const Solution straight = sol;
  const Eigen::VectorXd x = Pack(P, straight.unknowns);
  double turn = std::abs(mode(0));  // a unit of m(0) turns the rod by about 1 rad
  for (int j = 1; j < P.segments; ++j) turn = std::max(turn, std::abs(mode(P.StartIndex(j) + 2)));
  if (!(turn > 0.0)) return false;
  const double energy_scale = rod.bending_stiffness_Nm2 / rod.length_m;
  bool seeded = false;
  for (double amplitude = std::abs(seed_rad); amplitude >= std::abs(seed_rad) / 256.0 && !seeded;
       amplitude /= 4.0) {
    for (const double sign : {1.0, -1.0}) {
      SolveOptions bent = so;
      bent.start = ToUnknowns(P, x + (sign * amplitude / turn) * mode);
      bent.max_iterations = std::min(bent.max_iterations, 30);
      Solution b = Solve(rod, setup, bent);
      if (b.converged && b.max_turn_rad > 1e-5 &&
          b.potential_energy_J < sol.potential_energy_J - 1e-12 * energy_scale) {
        sol = std::move(b);
        seeded = true;
      }
    }
  }
  return seeded;
}

// One stick-slip decision per contact on the last solution; true when any changed what the
// solve sees.
bool Decide(const Rod& rod, const Setup& setup, const Solution& sol,
            const std::optional<Solution>& last, std::vector<SlotFriction>& fr,
            std::vector<bool>& reverted) {
  bool changed = false;
  const double K = setup.law.stiffness_N_per_m;
  for (std::size_t i = 0; i < fr.size(); ++i) {
    const ContactResult& c = sol.contacts[i];
    const Obstacle& ob = setup.obstacles[std::size_t(c.slot.obstacle)];
    if (!c.active) {
      fr[i] = SlotFriction{};  // an open contact carries no force in any mode
      continue;
    }
    if (!Frictional(ob)) continue;
    switch (fr[i].mode) {
      case FrictionMode::kNone:
        fr[i] = FirstTouch(rod, setup, i, sol, last);
        changed = true;
        break;
      case FrictionMode::kStuck:
        if (c.friction_ratio > 1.0 + 1e-9) {
          fr[i].mode = FrictionMode::kSliding;
          fr[i].slide_sign = c.tangential_N > 0.0 ? -1.0 : 1.0;
          changed = true;
        }
        break;
      case FrictionMode::kSliding:
        // It slides only if the spring from the hold's anchor would carry f_k the slide's way.
        if (!reverted[i] && fr[i].slide_sign * K * c.stretch_m < c.kinetic_force_N) {
          fr[i].mode = FrictionMode::kStuck;
          reverted[i] = true;
          changed = true;
        }
        break;
    }
  }
  return changed;
}

// Solves the stick-slip decisions of one hold from `sol` to a fixed point (at most 16 solves).
bool Settle(const Rod& rod, const Setup& setup, const std::optional<Solution>& last,
            SolveOptions& so, std::vector<SlotFriction>& fr, Solution& sol, int& passes) {
  std::vector<bool> reverted(fr.size(), false);
  while (passes < 16) {
    if (!Decide(rod, setup, sol, last, fr, reverted)) return true;
    so.friction = fr;
    so.start = sol.unknowns;
    sol = Solve(rod, setup, so);
    ++passes;
    if (!sol.converged) return false;
  }
  return false;
}

// What a hold hands on besides its result.
struct AttemptState {
  int straight_sign = 0;
  bool seeds_pending = false;
};

// Solves one hold from the carried state; `ok` false when a solve did not converge.
HoldResult Attempt(const Rod& rod, const Setup& base, const Hold& hold, const PathState& state,
                   const PathOptions& options, bool& ok, AttemptState& next) {
  const Setup setup = AtHold(base, hold);
  HoldResult h;
  h.hold = hold;
  std::vector<SlotFriction> fr = state.friction;
  SolveOptions so = options.solve;
  so.friction = fr;
  so.start = state.unknowns;
  Solution sol = Solve(rod, setup, so);
  h.passes = 1;
  ok = sol.converged;
  h.settled = ok && Settle(rod, setup, state.last, so, fr, sol, h.passes);
  // A pressed straight column past a bifurcation (det J changed sign since the last straight
  // hold) is also started bent, until a bent equilibrium is found.
  next = AttemptState{};
  if (h.settled && options.buckling_seed_rad != 0.0 && StraightAndPressed(sol)) {
    so.friction = fr;
    const Criticality critical = Critical(rod, setup, so, sol.unknowns);
    next.straight_sign = critical.sign;
    next.seeds_pending = state.seeds_pending || (state.straight_sign != 0 && critical.sign != 0 &&
                                                 critical.sign != state.straight_sign);
    if (next.seeds_pending &&
        TryBucklingSeeds(rod, setup, so, options.buckling_seed_rad, critical.mode, sol)) {
      h.seeded = true;
      next = AttemptState{};
      h.settled = Settle(rod, setup, state.last, so, fr, sol, h.passes);
    }
  }
  ok = ok && sol.converged;
  // The state carried on: a stuck contact keeps its stretch at the new contact point; a sliding
  // one is returned so that its spring carries exactly the kinetic force, and sticks first next.
  const double K = setup.law.stiffness_N_per_m;
  for (std::size_t i = 0; i < fr.size(); ++i) {
    const ContactResult& c = sol.contacts[i];
    const Obstacle& ob = setup.obstacles[std::size_t(c.slot.obstacle)];
    ContactPhase phase = ContactPhase::kSliding;
    if (!c.active) {
      phase = ContactPhase::kOpen;
      fr[i] = SlotFriction{};
    } else if (fr[i].mode == FrictionMode::kStuck) {
      phase = ContactPhase::kStuck;
      fr[i] = PlaceAnchor(rod, ob, c, sol, c.stretch_m);
    } else if (fr[i].mode == FrictionMode::kSliding) {
      fr[i] = PlaceAnchor(rod, ob, c, sol, -c.tangential_N / K);
    }
    h.phase.push_back(phase);
  }
  h.friction = fr;
  h.solution = std::move(sol);
  return h;
}

// A hold, split in halves while it does not converge from the last one.
HoldResult Advance(const Rod& rod, const Setup& base, const std::optional<Hold>& from,
                   const Hold& to, int depth, PathState& state, const PathOptions& options,
                   bool& ok) {
  bool good = false;
  AttemptState next;
  HoldResult h = Attempt(rod, base, to, state, options, good, next);
  if ((good && h.settled) || !from || depth >= options.max_bisections) {
    ok = ok && good && h.settled;
    if (good) {
      state.friction = h.friction;
      state.unknowns = h.solution.unknowns;
      state.last = h.solution;
      state.straight_sign = next.straight_sign;
      state.seeds_pending = next.seeds_pending;
    }
    return h;
  }
  const Hold mid{0.5 * (from->hand_m + to.hand_m),
                 0.5 * (from->root_angle_rad + to.root_angle_rad)};
  const HoldResult first = Advance(rod, base, from, mid, depth + 1, state, options, ok);
  HoldResult second = Advance(rod, base, mid, to, depth + 1, state, options, ok);
  second.substeps += first.substeps;
  return second;
}

}  // namespace

std::vector<Slot> Slots(const Setup& setup) {
  std::vector<Slot> slots;
  for (std::size_t j = 0; j < setup.obstacles.size(); ++j) {
    const Obstacle& ob = setup.obstacles[j];
    if (IsRim(ob) && ob.corners == RimCorners::kEach) {
      slots.push_back({int(j), -1});
      slots.push_back({int(j), 1});
    } else {
      slots.push_back({int(j), 0});
    }
  }
  return slots;
}

double StaticLimit(const Friction& friction, double normal_N) {
  if (!(normal_N > 0.0)) return 0.0;
  if (friction.exponent == 1.0) return friction.static_coefficient * normal_N;
  const double n0 = friction.reference_load_N;
  return friction.static_coefficient * n0 * std::pow(normal_N / n0, friction.exponent);
}

double KineticForce(const Friction& friction, double normal_N) {
  if (!(normal_N > 0.0)) return 0.0;
  if (!friction.kinetic_uses_exponent || friction.exponent == 1.0)
    return friction.kinetic_coefficient * normal_N;
  const double n0 = friction.reference_load_N;
  return friction.kinetic_coefficient * n0 * std::pow(normal_N / n0, friction.exponent);
}

CentrelinePoint At(const std::vector<CentrelinePoint>& centreline, double arc_m) {
  if (centreline.empty()) throw std::invalid_argument("shooting::At: empty centreline");
  if (arc_m <= centreline.front().arc_m) return centreline.front();
  if (arc_m >= centreline.back().arc_m) return centreline.back();
  // The interval [a, b] of positive length holding arc_m (nodes repeat where loads act).
  const auto it = std::upper_bound(centreline.begin(), centreline.end(), arc_m,
                                   [](double s, const CentrelinePoint& q) { return s < q.arc_m; });
  const CentrelinePoint& b = *it;
  const CentrelinePoint& a = *(it - 1);
  const double h = b.arc_m - a.arc_m;
  const double u = (arc_m - a.arc_m) / h;
  // Cubic Hermite basis on [0, 1].
  const double h00 = (1 + 2 * u) * (1 - u) * (1 - u), h10 = u * (1 - u) * (1 - u);
  const double h01 = u * u * (3 - 2 * u), h11 = u * u * (u - 1);
  CentrelinePoint q;
  q.arc_m = arc_m;
  q.position_m = h00 * a.position_m + h10 * h * Tangent(a.angle_rad) + h01 * b.position_m +
                 h11 * h * Tangent(b.angle_rad);
  q.angle_rad = h00 * a.angle_rad + h10 * h * a.curvature_per_m + h01 * b.angle_rad +
                h11 * h * b.curvature_per_m;
  q.curvature_per_m = (1 - u) * a.curvature_per_m + u * b.curvature_per_m;
  q.moment_Nm = (1 - u) * a.moment_Nm + u * b.moment_Nm;
  return q;
}

Solution Solve(const Rod& rod, const Setup& setup, const SolveOptions& options) {
  CheckInputs(rod, setup, options);
  const Problem P = MakeProblem(rod, setup, options);
  const std::size_t S = P.slots.size();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(P.size);
  if (options.start) {
    x = Pack(P, *options.start);
  } else {
    // The unloaded rod, each side contact started at its nearest sample.
    for (std::size_t i = 0; i < S; ++i)
      if (P.arc_unknown[i] >= 0) x(P.arc_unknown[i]) = 0.5;
    FillShape(P, x);
    const Evaluation ev = Evaluate(P, x);
    for (std::size_t i = 0; i < S; ++i)
      if (P.arc_unknown[i] >= 0) x(P.arc_unknown[i]) = NearestSample(P, i, ev).first / P.l;
  }
  const double max_move =
      options.max_move_m > 0.0
          ? options.max_move_m
          : (setup.obstacles.empty() ? 0.1 * rod.length_m
                                     : std::max(0.5 * std::max(rod.radius_m, setup.law.threshold_m),
                                                0.02 * rod.length_m));
  // Dead loads from the unloaded rod, or where Newton from the start does not converge, are
  // reached by continuation in their size (steps of at most 1/8, halved where a step fails):
  // Newton from far away may find no descent, or an equilibrium of another branch (a loop).
  const bool dead_loads = setup.tip_force_N.squaredNorm() > 0.0 || setup.tip_moment_Nm != 0.0;
  NewtonResult r;
  if (options.start || !dead_loads) r = SolveFrom(P, x, options, max_move);
  int total_iterations = r.iterations;
  if (!r.converged && dead_loads) {
    double done = 0.0, step = 0.125;
    Eigen::VectorXd y = x;
    while (done < 1.0 && step >= 1.0 / 4096.0) {
      const double next = std::min(1.0, done + step);
      Setup scaled = setup;
      scaled.tip_force_N *= next;
      scaled.tip_moment_Nm *= next;
      const Problem Q = MakeProblem(rod, scaled, options);
      NewtonResult q = SolveFrom(Q, y, options, max_move);
      total_iterations += q.iterations;
      if (q.converged) {
        y = q.x;
        done = next;
        step = std::min(0.125, 2.0 * step);
        if (done == 1.0) {
          r = SolveFrom(P, y, options, max_move);
          total_iterations += r.iterations;
        }
      } else {
        step *= 0.5;
      }
    }
    if (done < 1.0) {
      r = SolveFrom(P, y, options, max_move);  // reported as not converged, from the furthest
      total_iterations += r.iterations;
    }
  }
  r.iterations = total_iterations;
  return Unpack(P, r);
}

PathResult FollowPath(const Rod& rod, const Setup& setup, const std::vector<Hold>& holds,
                      const PathOptions& options) {
  const std::size_t S = Slots(setup).size();
  if (!options.start_friction.empty() && options.start_friction.size() != S)
    throw std::invalid_argument("shooting::FollowPath: start_friction has " +
                                std::to_string(options.start_friction.size()) + " entries for " +
                                std::to_string(S) + " contacts");
  PathState state;
  state.friction =
      options.start_friction.empty() ? std::vector<SlotFriction>(S) : options.start_friction;
  state.unknowns = options.start;
  PathResult result;
  std::optional<Hold> from;
  for (const Hold& hold : holds) {
    result.holds.push_back(Advance(rod, setup, from, hold, 0, state, options, result.ok));
    from = hold;
  }
  return result;
}

}  // namespace tubeplan::reference::shooting
