#include "core/solve.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "core/assemble.hpp"
#include "core/contacts.hpp"

namespace tubeplan::core {
namespace {

using Vec3 = Eigen::Vector3d;

// Below this Newton decrement (the energy a full step would release) a tick has converged.
constexpr double kDecrementFloor_J = 1e-14;

// Largest displacement of a node (or of the held end) in a step of the unknowns.
double LargestMove(const Eigen::VectorXd& step) {
  double m = 0.0;
  for (int b = 0; b < step.size() / 3; ++b) m = std::max(m, step.segment<3>(3 * b).norm());
  return m;
}

// Factors H + lambda I with the smallest lambda >= 0 (0, then growing from a small fraction of
// the diagonal) that is positive definite. Returns lambda, or -1 if none was found.
double FactorShifted(Scratch& s) {
  double diag = 0.0;
  for (int i = 0; i < s.hessian.size(); ++i) diag = std::max(diag, std::abs(s.hessian(i, i)));
  const double min_pivot = 1e-13 * diag;
  if (s.factor.Factor(s.hessian, min_pivot)) return 0.0;
  double lambda = 1e-7 * diag;
  for (int attempt = 0; attempt < 40; ++attempt) {
    s.hessian.AddDiagonal(lambda);
    const bool ok = s.factor.Factor(s.hessian, min_pivot);
    s.hessian.AddDiagonal(-lambda);
    if (ok) return lambda;
    lambda *= 4.0;
  }
  return -1.0;
}

// A direction of negative curvature of H, given the factors of H + lambda I: inverse iteration
// converges on the eigenvector of H's lowest eigenvalue. Returns its curvature v^T H v (< 0 when
// H is indefinite along it); v is unit.
double NegativeCurvature(Scratch& s, Eigen::VectorXd& v) {
  // A fixed start that is not orthogonal to any mode of a chain: deterministic, so the same
  // inputs buckle the same way.
  for (int i = 0; i < v.size(); ++i) v[i] = 1.0 + 0.5 * std::sin(1.7 * i + 0.3);
  v.normalize();
  for (int k = 0; k < 8; ++k) {
    s.factor.Solve(v);
    v.normalize();
  }
  s.hessian.Multiply(v, s.work);
  return v.dot(s.work);
}

}  // namespace

void SolveEquilibrium(const Model& model, Data& data) {
  Scratch& s = data.scratch;
  SolveReport& report = data.solve;
  std::span<Vec3> x(data.state.x_W);
  std::span<Vec3> trial(s.x_trial_W);
  Eigen::VectorXd& q = s.unknowns;
  Eigen::VectorXd& q_trial = s.unknowns_trial;
  UnknownsOf(model, x, q);

  FindContacts(model, x, data);
  double energy = Assemble(model, data, x, true);
  const int max_iterations = model.solver.max_iterations;
  report.converged = false;
  for (int it = 0; it < max_iterations; ++it) {
    report.residual_N = s.gradient.lpNorm<Eigen::Infinity>();
    const double lambda = FactorShifted(s);
    if (lambda < 0.0) break;
    const bool small = report.residual_N <= model.solver.tolerance_N;
    // Converged at a minimum: balanced and stable.
    if (small && lambda == 0.0) {
      report.converged = true;
      break;
    }
    s.step = -s.gradient;
    s.factor.Solve(s.step);
    // Converged when the Newton step would change the energy by less than the rounding of its
    // stiff axial terms (their lengths cancel to ~1e-18 m): what is left is below any figure.
    if (lambda == 0.0 && -s.gradient.dot(s.step) < kDecrementFloor_J) {
      q += s.step;
      NodesOf(model, data, q, x);
      FindContacts(model, x, data);
      energy = Assemble(model, data, x, true);
      ++report.iterations;
      report.converged = true;
      break;
    }
    // At a saddle (a straight column past its buckling load) the gradient vanishes: leave along
    // the direction in which the energy falls, as far as one step may go.
    if (lambda > 0.0) {
      const double curvature = NegativeCurvature(s, s.direction);
      if (curvature < 0.0) {
        report.indefinite = true;
        double sign = s.direction.dot(s.gradient) > 0.0 ? -1.0 : 1.0;
        s.step += sign * (model.solver.step_cap_m / std::max(LargestMove(s.direction), 1e-300)) *
                  s.direction;
      } else if (small) {
        report.converged = true;
        break;
      }
    }
    // No point moves farther than the cap: contacts are found again before a part is crossed.
    const double move = LargestMove(s.step);
    double alpha = move > model.solver.step_cap_m ? model.solver.step_cap_m / move : 1.0;
    const double slope = s.gradient.dot(s.step);
    bool accepted = false;
    for (int ls = 0; ls < 12; ++ls) {
      q_trial = q + alpha * s.step;
      NodesOf(model, data, q_trial, trial);
      FindContacts(model, trial, data);
      const double e = Assemble(model, data, trial, false);
      // Armijo's condition, with room for rounding in a sum of terms near equilibrium.
      if (e <= energy + 1e-4 * alpha * std::min(slope, 0.0) + 1e-13 * std::abs(energy)) {
        accepted = true;
        break;
      }
      alpha *= 0.5;
    }
    ++report.iterations;
    if (std::getenv("TP_DEBUG")) std::fprintf(stderr, "  it %d E=%.17g res=%.3e lambda=%.3e slope=%.3e alpha=%.3e acc=%d samples=%d\n", it, energy, report.residual_N, lambda, slope, alpha, accepted, s.sample_count);
    if (!accepted) {
      // Nothing lowers the energy along this direction: the last state stands.
      FindContacts(model, x, data);
      energy = Assemble(model, data, x, true);
      break;
    }
    q = q_trial;
    std::copy(trial.begin(), trial.end(), x.begin());
    energy = Assemble(model, data, x, true);
  }
  report.residual_N = s.gradient.lpNorm<Eigen::Infinity>();
}

}  // namespace tubeplan::core
