#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <Eigen/LU>

#include <tubeplan/reference/planar_rod.hpp>

namespace tubeplan::reference {
namespace {

using Eigen::Vector2d;

// A force applied at a material point: on segment k (1..N) at the fraction t of its length from
// node k-1, offset by o along the segment's normal g_k = (cos theta_k, -sin theta_k); k = 0 is
// the held end.
struct PointForce {
  int segment = 0;
  double t = 1.0;
  double offset_m = 0.0;
  Vector2d force_N = Vector2d::Zero();
};

Vector2d Tangent(double theta) { return {std::sin(theta), std::cos(theta)}; }
Vector2d Normal(double theta) { return {std::cos(theta), -std::sin(theta)}; }

struct Evaluation {
  Eigen::VectorXd residual;
  std::vector<Vector2d> nodes;
  std::vector<PointForce> forces;
  std::vector<Vector2d> obstacle_force_N;
  std::vector<double> obstacle_distance_m;
  double bending_energy_J = 0.0;
};

// The end face on a plane under the rim law: the rim's points share K (eps - d)+, d the smooth
// minimum of their distances, by the softmin's weights; each point's share acts at its offset.
void RimForces(const PlanarRod& rod, const Loading& loading, const Obstacle& ob,
               const Vector2d& tip, const Vector2d& g, Evaluation& ev) {
  const int n = loading.law.rim_points;
  const double tau = loading.law.rim_softness * loading.law.threshold_m;
  const Vector2d tangent(ob.normal.y(), -ob.normal.x());
  std::vector<double> offset(static_cast<std::size_t>(n)), dist(offset), w(offset);
  double d_min = std::numeric_limits<double>::infinity();
  for (int j = 0; j < n; ++j) {
    offset[std::size_t(j)] = rod.radius_m * std::cos(2.0 * std::numbers::pi * j / n);
    dist[std::size_t(j)] = ob.normal.dot(tip + offset[std::size_t(j)] * g - ob.point_m);
    d_min = std::min(d_min, dist[std::size_t(j)]);
  }
  double sum = 0.0;
  for (int j = 0; j < n; ++j)
    sum += (w[std::size_t(j)] = tau > 0.0 ? std::exp(-(dist[std::size_t(j)] - d_min) / tau)
                                          : double(dist[std::size_t(j)] == d_min));
  const double d = d_min - tau * std::log(sum);
  const double lambda = loading.law.stiffness_N_per_m * std::max(0.0, loading.law.threshold_m - d);
  Vector2d total = Vector2d::Zero();
  for (int j = 0; j < n && lambda > 0.0; ++j) {
    const double share = lambda * w[std::size_t(j)] / sum;
    if (share <= 0.0) continue;
    const Vector2d f = share * ob.normal - ob.slide_sign * ob.kinetic_friction * share * tangent;
    ev.forces.push_back({rod.segments, 1.0, offset[std::size_t(j)], f});
    total += f;
  }
  ev.obstacle_distance_m.push_back(d);
  ev.obstacle_force_N.push_back(total);
}

// The penalty force of one obstacle at the current configuration, and where it acts.
void ContactForce(const PlanarRod& rod, const Loading& loading, const Obstacle& ob,
                  const std::vector<Vector2d>& nodes, const Eigen::VectorXd& theta,
                  Evaluation& ev) {
  const int N = rod.segments;
  const double h = rod.length_m / N;
  PointForce pf;
  double d = std::numeric_limits<double>::infinity();
  Vector2d normal = ob.normal;
  Vector2d tangent = Vector2d(ob.normal.y(), -ob.normal.x());
  switch (ob.kind) {
    case ObstacleKind::kPlaneEnd: {
      const Vector2d g = Normal(theta(N - 1));
      if (loading.law.threshold_m == 0.0) {
        // A hard contact (no band) is not the core's one-PC law: each corner of the end face
        // that presses in carries its own force, as on a real wall. Without this the force
        // would jump between the corners as they pass each other and Newton could not settle.
        Vector2d total = Vector2d::Zero();
        for (const double side : {-1.0, 1.0}) {
          const Vector2d corner = nodes[std::size_t(N)] + side * rod.radius_m * g;
          const double dc = ob.normal.dot(corner - ob.point_m);
          d = std::min(d, dc);
          const double lam = loading.law.stiffness_N_per_m * std::max(0.0, -dc);
          if (lam <= 0.0) continue;
          const Vector2d f = lam * ob.normal - ob.slide_sign * ob.kinetic_friction * lam * tangent;
          ev.forces.push_back({N, 1.0, side * rod.radius_m, f});
          total += f;
        }
        ev.obstacle_distance_m.push_back(d);
        ev.obstacle_force_N.push_back(total);
        return;
      }
      if (loading.law.rim_points > 0) {
        RimForces(rod, loading, ob, nodes[std::size_t(N)], g, ev);
        return;
      }
      for (const double side : {-1.0, 1.0}) {
        const Vector2d corner = nodes[std::size_t(N)] + side * rod.radius_m * g;
        const double dc = ob.normal.dot(corner - ob.point_m);
        if (dc < d) {
          d = dc;
          pf.segment = N;
          pf.t = 1.0;
          pf.offset_m = side * rod.radius_m;
        }
      }
      break;
    }
    case ObstacleKind::kPlaneSide: {
      for (int k = 0; k <= N; ++k) {
        const double dk = ob.normal.dot(nodes[std::size_t(k)] - ob.point_m) - rod.radius_m;
        if (dk < d) {
          d = dk;
          pf.segment = k;
          pf.t = 1.0;
          pf.offset_m = 0.0;
        }
      }
      break;
    }
    case ObstacleKind::kEdge: {
      for (int k = 1; k <= N; ++k) {
        const Vector2d a = nodes[std::size_t(k - 1)];
        const Vector2d e = Tangent(theta(k - 1));
        const double t = std::clamp((ob.point_m - a).dot(e) / h, 0.0, 1.0);
        const Vector2d x = a + t * h * e;
        const double dk = (x - ob.point_m).norm() - rod.radius_m;
        if (dk < d) {
          d = dk;
          pf.segment = k;
          pf.t = t;
          pf.offset_m = 0.0;
          const Vector2d away = x - ob.point_m;
          normal =
              away.norm() > 0.0 ? Vector2d(away / away.norm()) : Vector2d(Normal(theta(k - 1)));
          tangent = e;
        }
      }
      break;
    }
  }
  const double lambda = loading.law.stiffness_N_per_m * std::max(0.0, loading.law.threshold_m - d);
  pf.force_N = lambda * normal - ob.slide_sign * ob.kinetic_friction * lambda * tangent;
  ev.obstacle_distance_m.push_back(d);
  ev.obstacle_force_N.push_back(pf.force_N);
  if (lambda > 0.0) ev.forces.push_back(pf);
}

// Residual of the equilibrium at q = (p_x, p_z, theta_1..theta_N).
void Evaluate(const PlanarRod& rod, const Loading& loading, const Eigen::VectorXd& q,
              Evaluation& ev) {
  const int N = rod.segments;
  const double h = rod.length_m / N;
  const double EI = rod.bending_stiffness_Nm2;
  const Vector2d p = q.head<2>();
  const Eigen::VectorXd theta = q.tail(N);
  ev.nodes.assign(std::size_t(N + 1), p);
  for (int k = 1; k <= N; ++k)
    ev.nodes[std::size_t(k)] = ev.nodes[std::size_t(k - 1)] + h * Tangent(theta(k - 1));
  ev.forces.clear();
  ev.obstacle_force_N.clear();
  ev.obstacle_distance_m.clear();
  for (const Obstacle& ob : loading.obstacles) ContactForce(rod, loading, ob, ev.nodes, theta, ev);
  if (loading.tip_force_N.squaredNorm() > 0.0)
    ev.forces.push_back({N, 1.0, 0.0, loading.tip_force_N});

  ev.residual.setZero(N + 2);
  // Bending: gradient of U.
  ev.bending_energy_J = EI / h * std::pow(theta(0) - loading.root_angle_rad, 2);
  ev.residual(2) += 2.0 * EI / h * (theta(0) - loading.root_angle_rad);
  for (int k = 1; k < N; ++k) {
    const double dth = theta(k) - theta(k - 1);
    ev.bending_energy_J += 0.5 * EI / h * dth * dth;
    ev.residual(2 + k) += EI / h * dth;
    ev.residual(2 + k - 1) -= EI / h * dth;
  }
  // Generalised forces: a force on segment k acts on p, on every theta_j (j < k) through the lever
  // h g_j, and on theta_k through t h g_k - o e_k.
  std::vector<Vector2d> beyond(std::size_t(N + 2), Vector2d::Zero());  // forces on segments > j
  Vector2d total = Vector2d::Zero();
  for (const PointForce& f : ev.forces) {
    total += f.force_N;
    if (f.segment == 0) continue;
    const double th = theta(f.segment - 1);
    ev.residual(2 + f.segment - 1) -=
        f.force_N.dot(f.t * h * Normal(th) - f.offset_m * Tangent(th));
    beyond[std::size_t(f.segment - 1)] += f.force_N;
  }
  Vector2d running = Vector2d::Zero();
  for (int j = N; j >= 1; --j) {
    // running = sum of forces attached to segments > j
    ev.residual(2 + j - 1) -= running.dot(h * Normal(theta(j - 1)));
    running += beyond[std::size_t(j - 1)];
  }
  if (loading.coupling_N_per_m > 0.0) {
    ev.residual.head<2>() = -loading.coupling_N_per_m * (loading.hand_m - p) - total;
  } else {
    // Held end fixed: its equation only pins p (scaled like a stiff spring for the conditioning).
    ev.residual.head<2>() = (p - loading.hand_m) * (EI / (h * rod.length_m * rod.length_m));
  }
}

}  // namespace

RodState StraightState(const PlanarRod& rod, const Loading& loading) {
  RodState s;
  s.held_m = loading.hand_m;
  s.theta_rad = Eigen::VectorXd::Constant(rod.segments, loading.root_angle_rad);
  return s;
}

std::vector<Vector2d> RodNodes(const PlanarRod& rod, const RodState& state) {
  const int N = rod.segments;
  const double h = rod.length_m / N;
  std::vector<Vector2d> nodes(std::size_t(N + 1), state.held_m);
  for (int k = 1; k <= N; ++k)
    nodes[std::size_t(k)] = nodes[std::size_t(k - 1)] + h * Tangent(state.theta_rad(k - 1));
  return nodes;
}

RodSolution SolveRod(const PlanarRod& rod, const Loading& loading,
                     const std::optional<RodState>& start) {
  if (rod.segments < 2 || !(rod.length_m > 0.0) || !(rod.bending_stiffness_Nm2 > 0.0))
    throw std::invalid_argument("SolveRod: a rod needs >= 2 segments, l > 0 and EI > 0");
  const int N = rod.segments;
  const int n = N + 2;
  const double l = rod.length_m;
  RodState s0 = start && start->theta_rad.size() == N ? *start : StraightState(rod, loading);
  Eigen::VectorXd q(n);
  q.head<2>() = s0.held_m;
  q.tail(N) = s0.theta_rad;

  // Scales: a moment EI/l, a force EI/l^2 (both make the residual's size independent of units).
  const double moment_scale = rod.bending_stiffness_Nm2 / l;
  Eigen::VectorXd scale(n);
  scale.head<2>().setConstant(1.0 / l);
  scale.tail(N).setConstant(1.0);
  const auto merit = [&](const Evaluation& e) {
    Eigen::VectorXd r = e.residual;
    r.head<2>() *= l;  // forces times l: moments
    return r.lpNorm<Eigen::Infinity>() / moment_scale;
  };

  // A quarter of the tube's radius (or of its length for a line without a radius).
  const double max_node_step_m = rod.radius_m > 0.0 ? 0.25 * rod.radius_m : 0.05 * l;
  Evaluation ev, trial;
  Evaluate(rod, loading, q, ev);
  double m = merit(ev);
  Eigen::MatrixXd J(n, n);
  RodSolution sol;
  for (int it = 1; it <= 400; ++it) {
    sol.iterations = it;
    // Central differences: the residual is smooth except where a contact opens or the nearest
    // pair switches; there Newton's step is still a descent direction for the merit.
    for (int j = 0; j < n; ++j) {
      const double delta = 1e-7 / scale(j);
      Eigen::VectorXd qp = q, qm = q;
      qp(j) += delta;
      qm(j) -= delta;
      Evaluate(rod, loading, qp, trial);
      const Eigen::VectorXd rp = trial.residual;
      Evaluate(rod, loading, qm, trial);
      J.col(j) = (rp - trial.residual) / (2.0 * delta);
    }
    Eigen::VectorXd step = -J.partialPivLu().solve(ev.residual);
    if (!step.allFinite()) break;
    // Contacts are one-sided penalties on thin obstacles: a long Newton step could carry the rod
    // through an edge or a wall to an equilibrium on the far side. The step is shortened so that
    // no node moves (to first order) more than max_node_step_m.
    {
      Vector2d moved = step.head<2>();
      double largest = moved.norm();
      const double h = l / N;
      for (int k = 0; k < N; ++k) {
        moved += h * Normal(q(2 + k)) * step(2 + k);
        largest = std::max(largest, moved.norm());
      }
      if (largest > max_node_step_m) step *= max_node_step_m / largest;
    }
    // Backtracking on the merit (the residual's scaled norm).
    double lambda = 1.0;
    bool accepted = false;
    for (int b = 0; b < 30; ++b) {
      const Eigen::VectorXd qt = q + lambda * step;
      Evaluate(rod, loading, qt, trial);
      const double mt = merit(trial);
      if (mt < (1.0 - 1e-4 * lambda) * m ||
          (step.cwiseProduct(scale)).lpNorm<Eigen::Infinity>() * lambda < 1e-13) {
        q = qt;
        std::swap(ev, trial);
        m = mt;
        accepted = true;
        break;
      }
      lambda *= 0.5;
    }
    const double step_size = (lambda * step.cwiseProduct(scale)).lpNorm<Eigen::Infinity>();
    if (!accepted) {
      // No decrease: rounding (or a kink of the penalty law) stops the merit falling; accept a
      // residual within 10x of the converged test's.
      sol.converged = m < 1e-8;
      break;
    }
    if (step_size < 1e-12 && m < 1e-9) {
      sol.converged = true;
      break;
    }
  }
  sol.residual = m;
  sol.state.held_m = q.head<2>();
  sol.state.theta_rad = q.tail(N);
  sol.tip_m = ev.nodes.back();
  const Eigen::VectorXd& th = sol.state.theta_rad;
  sol.tip_angle_rad = th(N - 1) + 0.5 * (th(N - 1) - th(N - 2));
  sol.energy_J = ev.bending_energy_J;
  sol.obstacle_force_N = ev.obstacle_force_N;
  sol.obstacle_distance_m = ev.obstacle_distance_m;
  sol.contact_force_N.setZero();
  for (const Vector2d& f : ev.obstacle_force_N) sol.contact_force_N += f;
  return sol;
}

}  // namespace tubeplan::reference
