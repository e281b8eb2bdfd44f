#include "core/solve.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/assemble.hpp"
#include "core/contacts.hpp"

namespace tubeplan::core {
namespace {

using Vec3 = Eigen::Vector3d;

// Below this Newton decrement (the energy a full step would release) a tick has converged.
constexpr double kDecrementFloor_J = 1e-14;

// Solves that step with one set of kept factors at most before the Hessian is factored again
// (StepWithKeptFactors).
constexpr int kKeptSolves = 16;

// Largest displacement of a node (or of the held end) in a step of the unknowns.
double LargestMove(const Eigen::VectorXd& step) {
  double m = 0.0;
  for (int b = 0; b < step.size() / 3; ++b) m = std::max(m, step.segment<3>(3 * b).norm());
  return m;
}

// The largest fraction of a step that moves no node farther than it may go: half its clearance
// from the parts, and at least the step cap (within which a point meets a part's penalty before
// it could pass its middle).
double StepFraction(const Model& model, const Scratch& s, const Eigen::VectorXd& step) {
  double fraction = 1.0;
  for (int k = 0; k < step.size() / 3; ++k) {
    const double move = step.segment<3>(3 * k).norm();
    const double may = std::max(model.solver.step_cap_m, 0.5 * s.clearance_m[std::size_t(k)]);
    if (move > may) fraction = std::min(fraction, may / move);
  }
  return fraction;
}

// Factors the Hessian: its band B, then the capacitance S = C^-1 + U^T B^-1 U of its rank-one
// terms U C U^T (Woodbury). False where B + U C U^T is not positive definite: B is not, or S has
// not as many negative eigenvalues as C (Haynsworth's inertia additivity).
bool FactorHessian(const BandMatrix& hessian, HessianFactors& f, double min_pivot) {
  if (!f.band.Factor(hessian, min_pivot)) return false;
  const int k = f.low_rank_count;
  if (k == 0) return true;
  HessianFactors::Capacitance S(k, k);
  int negative = 0;
  for (int i = 0; i < k; ++i) {
    f.low_rank_z[std::size_t(i)] = f.low_rank_u[std::size_t(i)];
    f.band.Solve(f.low_rank_z[std::size_t(i)]);
    negative += f.low_rank_c[std::size_t(i)] < 0.0;
  }
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j)
      S(i, j) = f.low_rank_u[std::size_t(i)].dot(f.low_rank_z[std::size_t(j)]) +
                (i == j ? 1.0 / f.low_rank_c[std::size_t(i)] : 0.0);
  f.capacitance.compute(S);
  int found = 0;
  for (int i = 0; i < k; ++i) {
    const double d = f.capacitance.vectorD()[i];
    if (!(std::abs(d) > 1e-13 * std::abs(S(i, i)))) return false;
    found += d < 0.0;
  }
  return found == negative;
}

// x = H^-1 x, in place, with the factors of FactorHessian.
void SolveHessian(const HessianFactors& f, Eigen::VectorXd& x) {
  f.band.Solve(x);
  const int k = f.low_rank_count;
  if (k == 0) return;
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxSideGroups, 1> b(k), w(k);
  for (int i = 0; i < k; ++i) b[i] = f.low_rank_u[std::size_t(i)].dot(x);
  w = f.capacitance.solve(b);
  for (int i = 0; i < k; ++i) x -= w[i] * f.low_rank_z[std::size_t(i)];
}

// y = H x: the band and the rank-one terms.
void MultiplyHessian(const Scratch& s, const Eigen::VectorXd& x, Eigen::VectorXd& y) {
  const HessianFactors& f = s.factors;
  s.hessian.Multiply(x, y);
  for (int i = 0; i < f.low_rank_count; ++i)
    y += (f.low_rank_c[std::size_t(i)] * f.low_rank_u[std::size_t(i)].dot(x)) *
         f.low_rank_u[std::size_t(i)];
}

// Factors H + (shift + lambda) I with the smallest lambda >= 0 (0, then growing from a small
// fraction of the diagonal) that is positive definite. Returns lambda, or -1 if none was found.
double FactorShifted(Scratch& s, double shift) {
  double diag = 0.0;
  for (int i = 0; i < s.hessian.size(); ++i) diag = std::max(diag, std::abs(s.hessian(i, i)));
  const double min_pivot = 1e-13 * diag;
  s.hessian.AddDiagonal(shift);
  double lambda = 0.0;
  bool ok = FactorHessian(s.hessian, s.factors, min_pivot);
  for (double add = 1e-7 * diag; !ok && add < 1e3 * diag; add *= 4.0) {
    s.hessian.AddDiagonal(add - lambda);
    lambda = add;
    ok = FactorHessian(s.hessian, s.factors, min_pivot);
  }
  s.hessian.AddDiagonal(-shift - lambda);
  s.factors_current = ok && shift == 0.0 && lambda == 0.0;
  return ok ? lambda : -1.0;
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
    SolveHessian(s.factors, v);
    v.normalize();
  }
  MultiplyHessian(s, v, s.work);
  return v.dot(s.work);
}

enum class Outcome { kStep, kDefiniteStep, kConverged, kFailed };

// The Newton step of the assembled system, damped by `damping` [N/m] on every unknown; at a
// saddle (a straight column past its buckling load, where the gradient vanishes) it also leaves
// along the direction in which the energy falls, as far as one iteration may move.
Outcome NewtonStep(const Model& model, Data& data, double damping) {
  Scratch& s = data.scratch;
  const double lambda = FactorShifted(s, damping);
  if (lambda < 0.0) return Outcome::kFailed;
  const bool balanced = data.solve.residual_N <= model.solver.tolerance_N;
  if (balanced && lambda == 0.0) return Outcome::kConverged;
  s.step = -s.gradient;
  SolveHessian(s.factors, s.step);
  if (lambda > 0.0) {
    const double curvature = NegativeCurvature(s, s.direction);
    if (curvature < 0.0) {
      // Balanced where the energy falls away: a saddle, the straight column past its load.
      if (balanced) data.solve.indefinite = true;
      const double sign = s.direction.dot(s.gradient) > 0.0 ? -1.0 : 1.0;
      s.step += sign * (model.solver.step_cap_m / std::max(LargestMove(s.direction), 1e-300)) *
                s.direction;
    } else if (balanced) {
      return Outcome::kConverged;
    }
    return Outcome::kStep;
  }
  return damping == 0.0 ? Outcome::kDefiniteStep : Outcome::kStep;
}

// The energy, gradient and Hessian at x_W: the factors are then no longer the Hessian's.
double AssembleHessian(const Model& model, Data& data, std::span<const Vec3> x_W) {
  data.scratch.factors_current = false;
  return Assemble(model, data, x_W, Derivatives::kHessian);
}

// The energy at alpha along the step (its gradient too where asked), with the contacts there;
// their choices are pending until TakeTrial.
double TrialEnergy(const Model& model, Data& data, double alpha, Derivatives derivatives) {
  Scratch& s = data.scratch;
  s.unknowns_trial = s.unknowns + alpha * s.step;
  NodesOf(model, s.unknowns_trial, s.x_trial_W);
  FindContacts(model, s.x_trial_W, data, Choices::kPending);
  return Assemble(model, data, s.x_trial_W, derivatives);
}

// Moves the unknowns to the trial point.
void TakeTrial(Data& data) {
  Scratch& s = data.scratch;
  CommitContactChoices(data);
  s.unknowns = s.unknowns_trial;
  std::copy(s.x_trial_W.begin(), s.x_trial_W.end(), data.state.x_W.begin());
}

// Whether energy e at alpha along a step of the given slope falls enough from `energy` (Armijo),
// with room for the rounding of a sum of terms near equilibrium.
bool FallsEnough(double e, double energy, double alpha, double slope) {
  return e <= energy + 1e-4 * alpha * std::min(slope, 0.0) + 1e-13 * std::abs(energy);
}

// Moves the unknowns along the step, capped so that no point moves farther than the step cap
// (contacts are found again before a part could be crossed), halving it while the energy does
// not fall enough (Armijo). Returns the fraction of the step taken (0 for none), with the nodes,
// contacts, energy and derivatives of the new point.
double LineSearch(const Model& model, Data& data, double& energy) {
  Scratch& s = data.scratch;
  double alpha = StepFraction(model, s, s.step);
  const double slope = s.gradient.dot(s.step);
  for (int halving = 0; halving < 8; ++halving, alpha *= 0.5) {
    // The first trial is taken most often: its gradient is assembled with its energy.
    const double e =
        TrialEnergy(model, data, alpha, halving == 0 ? Derivatives::kGradient : Derivatives::kNone);
    if (FallsEnough(e, energy, alpha, slope)) {
      TakeTrial(data);
      if (halving > 0) Assemble(model, data, data.state.x_W, Derivatives::kGradient);
      energy = e;
      return alpha;
    }
  }
  // None taken: the contacts and derivatives of where the search started.
  FindContacts(model, data.state.x_W, data);
  energy = AssembleHessian(model, data, data.state.x_W);
  return 0.0;
}

// Which points of the tube press on which part elements, and which friction points slide: a
// solve whose key is the kept one's starts where those factors still fit, most likely (a change
// the key misses costs the checked step, not accuracy).
std::uint64_t ContactSetKey(const Data& data) {
  std::uint64_t key = 14695981039346656037ull;  // FNV-1a
  const auto mix = [&key](std::int64_t v) { key = (key ^ std::uint64_t(v)) * 1099511628211ull; };
  const Scratch& s = data.scratch;
  for (int k = 0; k < s.sample_count; ++k) {
    const Sample& smp = s.samples[std::size_t(k)];
    for (const std::int64_t v :
         {std::int64_t(smp.kind), std::int64_t(smp.part), std::int64_t(smp.node),
          std::int64_t(smp.feature), std::int64_t(smp.element)})
      mix(v);
  }
  mix(data.state.friction_count);
  for (int k = 0; k < data.state.friction_count; ++k)
    mix(data.state.friction[std::size_t(k)].sliding);
  return key;
}

// The factors' own data, and only the rank-one terms in use.
void CopyFactors(const HessianFactors& from, HessianFactors& to) {
  to.band = from.band;
  for (std::size_t i = 0; i < std::size_t(from.low_rank_count); ++i) {
    to.low_rank_u[i] = from.low_rank_u[i];
    to.low_rank_z[i] = from.low_rank_z[i];
  }
  to.low_rank_c = from.low_rank_c;
  to.low_rank_count = from.low_rank_count;
  to.capacitance = from.capacitance;
}

// A solve that starts with the contacts of the last factored Hessian first tries its factors (a
// chord step): where the hand moved little since, it is balanced there, or one full step with
// them (where no point moves beyond the step cap) lowers the energy and lands within the
// tolerance, and no Hessian is assembled or factored. A step that lowers the energy but lands
// short of the tolerance is kept, as an iteration, and Newton's method goes on from there; one
// that does not is dropped. The factors were positive definite; a straight column past its
// buckling load (a saddle whose gradient stays zero) is found by the factorisation after
// kKeptSolves solves. True when converged.
bool StepWithKeptFactors(const Model& model, Data& data) {
  KeptFactors& kept = data.state.kept;
  Scratch& s = data.scratch;
  SolveReport& report = data.solve;
  if (!kept.valid || kept.solves >= kKeptSolves || kept.contacts != ContactSetKey(data))
    return false;
  ++kept.solves;
  const double energy = Assemble(model, data, data.state.x_W, Derivatives::kGradient);
  report.residual_N = s.gradient.lpNorm<Eigen::Infinity>();
  if (report.residual_N <= model.solver.tolerance_N) return true;
  if (report.iterations >= model.solver.max_iterations) return false;
  s.step = -s.gradient;
  SolveHessian(kept.factors, s.step);
  const double slope = s.gradient.dot(s.step);
  if (StepFraction(model, s, s.step) == 1.0) {
    const double e = TrialEnergy(model, data, 1.0, Derivatives::kGradient);
    const double residual_N = s.gradient.lpNorm<Eigen::Infinity>();
    if (FallsEnough(e, energy, 1.0, slope)) {
      TakeTrial(data);
      ++report.iterations;
      report.residual_N = residual_N;
      return residual_N <= model.solver.tolerance_N;
    }
    FindContacts(model, data.state.x_W, data);
  }
  return false;
}

// A converged, stable solve whose factors are of its last Hessian keeps them for the solves after
// it; any other solve that did not converge with the kept ones drops them.
void KeepFactors(Data& data) {
  KeptFactors& kept = data.state.kept;
  const Scratch& s = data.scratch;
  kept.valid = data.solve.converged && !data.solve.indefinite && s.factors_current;
  if (!kept.valid) return;
  CopyFactors(s.factors, kept.factors);
  kept.contacts = ContactSetKey(data);
  kept.solves = 0;
}

}  // namespace

void SolveEquilibrium(const Model& model, Data& data) {
  Scratch& s = data.scratch;
  SolveReport& report = data.solve;
  std::span<Vec3> x(data.state.x_W);
  UnknownsOf(model, x, s.unknowns);
  FindContacts(model, x, data);
  report.converged = false;
  if (StepWithKeptFactors(model, data)) {
    report.converged = true;
    return;
  }
  // The contact forces and derivatives where the solve stands (the friction stage reads the
  // forces even when the iterations are spent).
  double energy = AssembleHessian(model, data, x);
  // The iterations left of the tick's budget, which its friction passes share.
  while (report.iterations < model.solver.max_iterations) {
    report.residual_N = s.gradient.lpNorm<Eigen::Infinity>();
    const Outcome o = NewtonStep(model, data, 0.0);
    if (o == Outcome::kConverged) report.converged = true;
    if (o != Outcome::kStep && o != Outcome::kDefiniteStep) break;
    ++report.iterations;
    // Converged when the Newton step would change the energy by less than the rounding of its
    // stiff axial terms (their lengths cancel to ~1e-18 m): what is left is below any figure.
    if (!report.indefinite && -s.gradient.dot(s.step) < kDecrementFloor_J) {
      s.unknowns += s.step;
      NodesOf(model, s.unknowns, x);
      FindContacts(model, x, data);
      energy = Assemble(model, data, x, Derivatives::kGradient);
      report.converged = true;
      break;
    }
    // Where the full step does not lower the energy (a contact it did not foresee), damped
    // steps, shorter and nearer the gradient (Levenberg-Marquardt), from the contact stiffness
    // up.
    const double taken = LineSearch(model, data, energy);
    // A full Newton step from a stable point that lands within the tolerance has converged (the
    // Hessian barely changed: it is not factored again to be sure).
    if (o == Outcome::kDefiniteStep && taken == 1.0 &&
        s.gradient.lpNorm<Eigen::Infinity>() <= model.solver.tolerance_N) {
      report.converged = true;
      break;
    }
    // The next iteration needs the Hessian where the search ended.
    if (taken > 0.0) AssembleHessian(model, data, x);
    bool moved = taken > 0.0;
    for (double damping = model.contact.stiffness_N_per_m;
         !moved && damping < 1e5 * model.contact.stiffness_N_per_m; damping *= 10.0) {
      if (NewtonStep(model, data, damping) != Outcome::kStep) break;
      moved = LineSearch(model, data, energy) > 0.0;
    }
    // Nothing lowers the energy: the last state stands.
    if (!moved) break;
  }
  report.residual_N = s.gradient.lpNorm<Eigen::Infinity>();
  KeepFactors(data);
}

}  // namespace tubeplan::core
