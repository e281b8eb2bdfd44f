#include "core/assemble.hpp"

#include <algorithm>
#include <cmath>

namespace tubeplan::core {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

// The block of unknowns node k moves with: nodes 0 and 1 with the held end, node k >= 2 its own.
int BlockOf(int node) { return node <= 1 ? 0 : node - 1; }

class Assembler {
 public:
  Assembler(const Model& model, Data& data, bool derivatives)
      : m_(model), s_(data.scratch), derivatives_(derivatives) {
    if (derivatives_) {
      s_.gradient.setZero();
      s_.hessian.SetZero();
    }
  }

  void AddStencil(const StencilTerm& t) {
    if (!derivatives_) return;
    for (int a = 0; a < t.nodes; ++a) {
      const int ba = BlockOf(t.first + a);
      s_.gradient.segment<3>(3 * ba) += t.gradient.segment<3>(3 * a);
      for (int b = 0; b < t.nodes; ++b) {
        const int bb = BlockOf(t.first + b);
        if (ba >= bb) s_.hessian.AddBlock(ba, bb, t.hessian.block<3, 3>(3 * a, 3 * b));
      }
    }
  }

  // A force-like term at a material point: energy's gradient g_p (3) and Hessian H_p (3 x 3)
  // with respect to the point, mapped through the point's Jacobian.
  void AddAtPoint(const Eigen::Matrix<double, 3, 9>& J, int first, int nodes, const Vec3& g_p,
                  const Mat3& H_p) {
    if (!derivatives_) return;
    StencilTerm t;
    t.first = first;
    t.nodes = nodes;
    const int n = 3 * nodes;
    t.gradient.head(n) = J.leftCols(n).transpose() * g_p;
    t.hessian.topLeftCorner(n, n) = J.leftCols(n).transpose() * H_p * J.leftCols(n);
    AddStencil(t);
  }

  void AddHeldEnd(const Vec3& g, const Mat3& H) {
    if (!derivatives_) return;
    s_.gradient.segment<3>(0) += g;
    s_.hessian.AddBlock(0, 0, H);
  }

 private:
  const Model& m_;
  Scratch& s_;
  bool derivatives_;
};

}  // namespace

int UnknownCount(const Model& model) { return 3 * model.rod.elements; }

void NodesOf(const Model& model, const Data& data, const Eigen::VectorXd& q,
             std::span<Vec3> x_W) {
  const Vec3 p = q.segment<3>(0);
  x_W[0] = p;
  x_W[1] = p + model.rod.segment_m * data.input.tangent_held_W;
  for (int k = 2; k <= model.rod.elements; ++k) x_W[std::size_t(k)] = q.segment<3>(3 * (k - 1));
}

void UnknownsOf(const Model& model, std::span<const Vec3> x_W, Eigen::VectorXd& q) {
  q.segment<3>(0) = x_W[0];
  for (int k = 2; k <= model.rod.elements; ++k) q.segment<3>(3 * (k - 1)) = x_W[std::size_t(k)];
}

MaterialPoint FrictionMaterial(const Model& model, const FrictionPoint& f,
                               std::span<const Vec3> x_W, bool jacobian) {
  (void)model;
  return Material(CarrierOf(f.kind), x_W, f.node, f.theta, f.offset_W, jacobian);
}

CouplingTerm Coupling(const Model& model, const Data& data, const Vec3& p_held_W) {
  // A spring that saturates at the device's force, and a damper, from the held end to the hand.
  const CouplingModel& c = model.coupling;
  CouplingTerm t;
  const Vec3 r = p_held_W - data.input.p_hand_W;
  const double lr = r.norm();
  const double r_sat = c.max_force_N / c.stiffness_N_per_m;
  if (lr <= r_sat) {
    t.energy_J = 0.5 * c.stiffness_N_per_m * lr * lr;
    t.force_N = c.stiffness_N_per_m * r;
    t.stiffness_N_per_m = c.stiffness_N_per_m * Mat3::Identity();
  } else {
    const Vec3 u = r / lr;
    t.energy_J = c.max_force_N * (lr - 0.5 * r_sat);
    t.force_N = c.max_force_N * u;
    t.stiffness_N_per_m = (c.max_force_N / lr) * (Mat3::Identity() - u * u.transpose());
    t.saturated = true;
  }
  const double b = c.damping_Ns_per_m / c.time_step_s;
  const Vec3 slip =
      (p_held_W - data.state.p_held_prev_W) - (data.input.p_hand_W - data.state.p_hand_prev_W);
  t.energy_J += 0.5 * b * slip.squaredNorm();
  t.force_N += b * slip;
  t.stiffness_N_per_m += b * Mat3::Identity();
  return t;
}

double BendingEnergyOf(const Model& model, const Data& data, std::span<const Vec3> x_W) {
  double energy = 0.0;
  for (int i = 1; i < model.rod.elements; ++i)
    energy += model.rod.linear
                  ? LinearBendingEnergy(model.rod, data.state.R_WH, x_W, i, nullptr)
                  : BendingEnergy(model.rod, x_W, i, nullptr);
  return energy;
}

double Assemble(const Model& model, Data& data, std::span<const Vec3> x_W, bool derivatives) {
  Assembler a(model, data, derivatives);
  const RodModel& rod = model.rod;
  double energy = 0.0;
  StencilTerm term;
  StencilTerm* want = derivatives ? &term : nullptr;

  // The rod: bending at the inner nodes, the stiff axial spring of every free element.
  for (int i = 1; i < rod.elements; ++i) {
    energy += rod.linear ? LinearBendingEnergy(rod, data.state.R_WH, x_W, i, want)
                         : BendingEnergy(rod, x_W, i, want);
    a.AddStencil(term);
    energy += rod.linear ? AxialHoldEnergy(rod, data.state.R_WH, x_W, i, want)
                         : StretchEnergy(rod, x_W, i, want);
    a.AddStencil(term);
  }

  // The coupling to the hand.
  const CouplingTerm c = Coupling(model, data, x_W[0]);
  energy += c.energy_J;
  a.AddHeldEnd(c.force_N, c.stiffness_N_per_m);

  // The penalty K (eps - d)+ of every contact point, along its normal (Gauss-Newton: the
  // curvature of the distance is left out of the Hessian).
  const double K = model.contact.stiffness_N_per_m, eps = model.contact.threshold_m;
  for (int k = 0; k < data.scratch.sample_count; ++k) {
    Sample& smp = data.scratch.samples[std::size_t(k)];
    const double depth = eps - smp.distance_m;
    if (!(depth > 0.0)) continue;
    const double kw = K * smp.weight;
    energy += 0.5 * kw * depth * depth;
    smp.normal_force_N = kw * depth;
    if (!derivatives) continue;
    const MaterialPoint mp =
        Material(CarrierOf(smp.kind), x_W, smp.node, smp.theta, smp.moving_offset_W);
    a.AddAtPoint(mp.jacobian, mp.first, mp.nodes, -kw * depth * smp.normal_W,
                 kw * smp.normal_W * smp.normal_W.transpose());
  }

  // Friction: a spring from each friction point to its anchor in the tangent plane, stiffness
  // K, that gives way at the point's limit (a Huber potential): the static limit while it
  // sticks, the kinetic one once it slides, at the normal force its limit was last set for.
  for (int k = 0; k < data.state.friction_count; ++k) {
    const FrictionPoint& f = data.state.friction[std::size_t(k)];
    const MaterialPoint mp = FrictionMaterial(model, f, x_W, derivatives);
    const Mat3 P = Mat3::Identity() - f.normal_W * f.normal_W.transpose();
    const Vec3 u = P * (mp.point_W - f.anchor_W);
    const double lu = u.norm();
    const double u_limit = f.limit_N / K;
    Vec3 g;
    Mat3 H;
    if (lu <= u_limit) {
      energy += 0.5 * K * lu * lu;
      g = K * u;
      H = K * P;
    } else {
      const Vec3 w = u / lu;
      energy += f.limit_N * (lu - 0.5 * u_limit);
      g = f.limit_N * w;
      H = (f.limit_N / lu) * P * (Mat3::Identity() - w * w.transpose()) * P;
    }
    a.AddAtPoint(mp.jacobian, mp.first, mp.nodes, P * g, H);
  }
  return energy;
}

}  // namespace tubeplan::core
