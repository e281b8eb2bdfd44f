#include "core/tick.hpp"

#include <algorithm>
#include <cmath>

#include "core/assemble.hpp"
#include "core/classify.hpp"
#include "core/contacts.hpp"
#include "core/stick_slip.hpp"

namespace tubeplan::core {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

bool Finite(const Eigen::Isometry3d& X) {
  return X.translation().allFinite() && X.linear().allFinite();
}

// In contact, the solve starts where the tube would be if it went on moving as it did the tick
// before, if it moved steadily then: no node by more than a quarter of the contact threshold (a
// snap's jump, carried on, would land deep in a part).
void PredictFromLastMotion(const Model& model, CarriedState& st) {
  const double most_m = 0.25 * model.contact.threshold_m;
  for (std::size_t k = 0; k < st.x_W.size(); ++k)
    if ((st.x_W[k] - st.x_prev_W[k]).norm() > most_m) return;
  for (std::size_t k = 0; k < st.x_W.size(); ++k) st.x_W[k] += st.x_W[k] - st.x_prev_W[k];
}

}  // namespace

bool StartTick(const Model& model, double t_s, const Eigen::Isometry3d& X_W_hand, Data& data) {
  data.input.t_s = t_s;
  data.input.X_W_hand = X_W_hand;
  // A pose not finite, or farther than 1 km from the world's origin (no device's: the energies
  // would overflow), is refused.
  data.input.hand_valid =
      Finite(X_W_hand) && std::isfinite(t_s) && X_W_hand.translation().norm() <= 1e3;
  if (!data.input.hand_valid) return false;
  CarriedState& st = data.state;
  Scratch& s = data.scratch;
  std::copy(st.x_W.begin(), st.x_W.end(), s.x_start_W.begin());
  const Vec3 p_hand = X_W_hand.translation();
  // The grip is rigid: the held end turns with the hand (its rotation part, re-orthonormalised).
  const Mat3 R_new = Eigen::Quaterniond(X_W_hand.linear()).normalized().toRotationMatrix();
  const Vec3 hand_move = p_hand - data.input.p_hand_W;
  data.input.p_hand_W = p_hand;
  // A tube touching nothing moves with the hand as a rigid body, as far as one solve
  // iteration may move it: the solve then starts from where it will end.
  const bool free = data.out.contact_count == 0 && s.sample_count == 0;
  if (free && hand_move.norm() <= model.solver.step_cap_m) {
    const Vec3 p_H = st.x_W[0];
    const Mat3 turn = R_new * st.R_WH.transpose();
    for (Vec3& x : st.x_W) x = p_H + hand_move + turn * (x - p_H);
  } else if (!free) {
    PredictFromLastMotion(model, st);
  }
  st.R_WH = R_new;
  data.input.tangent_held_W = R_new.col(2);
  data.solve = SolveReport{};
  std::fill(s.section_chosen.begin(), s.section_chosen.end(), 0);
  data.out.flags = 0;
  return true;
}

void HoldStill(const Model& model, Data& data) {
  CarriedState& st = data.state;
  std::copy(data.scratch.x_start_W.begin(), data.scratch.x_start_W.end(), st.x_W.begin());
  st.friction_count = 0;
  StepOutput& out = data.out;
  out.t_s = data.input.t_s;
  if (data.input.hand_valid) out.X_W_hand = data.input.X_W_hand;
  out.force_W_N.setZero();
  out.torque_W_Nm.setZero();
  out.iterations = data.solve.iterations;
  out.residual_N = 0.0;
  out.flags = kSolverFault;
  (void)model;
}

void WriteOutput(const Model& model, Data& data) {
  const CarriedState& st = data.state;
  StepOutput& out = data.out;
  const double eps = model.contact.threshold_m;
  out.t_s = data.input.t_s;
  out.X_W_hand = data.input.X_W_hand;
  out.X_WH.linear() = st.R_WH;
  out.X_WH.translation() = st.x_W[0];

  // The operator holds the coupling: its force, and the moment of every contact force about
  // the held end, which the rigid grip passes to the hand.
  const CouplingTerm c = Coupling(model, data, st.x_W[0]);
  Vec3 force = c.force_N;
  Vec3 torque = Vec3::Zero();
  bool penetration = false;
  for (int k = 0; k < data.scratch.sample_count; ++k) {
    const Sample& smp = data.scratch.samples[std::size_t(k)];
    if (!(smp.distance_m < eps)) continue;
    torque += ContactMoment(model, smp, st.x_W[0]);
    penetration = penetration || (smp.distance_m < 0.0 && OnSurface(smp));
  }
  if (c.saturated) out.flags |= kProxySeparated;
  if (force.norm() > model.coupling.max_force_N) {
    force *= model.coupling.max_force_N / force.norm();
    out.flags |= kForceClamped;
  }
  if (torque.norm() > model.coupling.max_torque_Nm) {
    torque *= model.coupling.max_torque_Nm / torque.norm();
    out.flags |= kForceClamped;
  }
  out.force_W_N = force;
  out.torque_W_Nm = torque;
  if (penetration) out.flags |= kPenetration;

  // The tube's elastic energy, strain and tip deflection.
  out.energy_J = BendingEnergyOf(model, data, st.x_W);
  // Curvature: each node's turn over an element's length; the grip's over half of one.
  double turn = 0.0;
  for (int i = 0; i < model.rod.elements; ++i) {
    const Vec3 a = i == 0
                       ? data.input.tangent_held_W
                       : Vec3((st.x_W[std::size_t(i)] - st.x_W[std::size_t(i - 1)]).normalized());
    const Vec3 b = (st.x_W[std::size_t(i + 1)] - st.x_W[std::size_t(i)]).normalized();
    turn = std::max(turn, (i == 0 ? 2.0 : 1.0) * std::atan2(a.cross(b).norm(), a.dot(b)));
  }
  out.max_strain = model.rod.outer_radius_m * turn / model.rod.segment_m;
  out.tip_deflection_m = TipDeflection(model, data);
  if (model.rod.linear && out.tip_deflection_m > model.rod.length_m / 3.0)
    out.flags |= kBeyondLinearRange;
  out.iterations = data.solve.iterations;
  out.residual_N = data.solve.residual_N;
  if (!data.solve.converged) out.flags |= kNotConverged;
  if (data.solve.indefinite) out.flags |= kBuckled;
}

void EndTick(const Model& model, Data& data) {
  CarriedState& st = data.state;
  st.p_hand_prev_W = data.input.p_hand_W;
  st.p_held_prev_W = st.x_W[0];
  std::copy(data.scratch.x_start_W.begin(), data.scratch.x_start_W.end(), st.x_prev_W.begin());
  // Where each point pressing on a part came in: kept while it is inside, so that it is pushed
  // back out that way; forgotten once it is out of contact.
  const int stride = model.rod.elements + 1;
  std::vector<ElementIndex>& entry = st.entry_element;
  std::vector<std::uint8_t>& seen = data.scratch.entry_seen;
  std::fill(seen.begin(), seen.end(), 0);
  for (int k = 0; k < data.scratch.sample_count; ++k) {
    const Sample& smp = data.scratch.samples[std::size_t(k)];
    const std::size_t i = std::size_t(smp.part * stride + smp.node);
    seen[i] = 1;
    if (smp.distance_m >= 0.0) entry[i] = smp.element;
  }
  for (std::size_t i = 0; i < entry.size(); ++i)
    if (!seen[i]) entry[i] = kNoElement;
}

}  // namespace tubeplan::core
