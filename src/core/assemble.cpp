#include "core/assemble.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace tubeplan::core {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

// The block of unknowns of node k: node 0 is the held end.
int BlockOf(int node) { return node; }

class Assembler {
 public:
  Assembler(Data& data, Derivatives need)
      : s_(data.scratch),
        gradient_(need != Derivatives::kNone),
        hessian_(need == Derivatives::kHessian) {
    if (gradient_) s_.gradient.setZero();
    if (hessian_) s_.hessian.SetZero();
  }
  bool gradient() const { return gradient_; }
  bool hessian() const { return hessian_; }

  void AddStencil(const StencilTerm& t) {
    if (!gradient_) return;
    for (int a = 0; a < t.nodes; ++a) {
      const int ba = BlockOf(t.first + a);
      s_.gradient.segment<3>(3 * ba) += t.gradient.segment<3>(3 * a);
      if (!hessian_) continue;
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
    if (!gradient_) return;
    // Fixed-size products: the columns of a two-node stencil's third node are zero.
    StencilTerm t;
    t.first = first;
    t.nodes = nodes;
    t.gradient.noalias() = J.transpose() * g_p;
    if (hessian_) {
      const Eigen::Matrix<double, 3, 9> HJ = H_p * J;
      t.hessian.noalias() = J.transpose().lazyProduct(HJ);
    }
    AddStencil(t);
  }

  void AddHeldEnd(const Vec3& g, const Mat3& H) {
    if (!gradient_) return;
    s_.gradient.segment<3>(0) += g;
    if (hessian_) s_.hessian.AddBlock(0, 0, H);
  }

 private:
  Scratch& s_;
  bool gradient_, hessian_;
};

}  // namespace

int UnknownCount(const Model& model) { return 3 * (model.rod.elements + 1); }

void NodesOf(const Model& model, const Eigen::VectorXd& q, std::span<Vec3> x_W) {
  for (int k = 0; k <= model.rod.elements; ++k) x_W[std::size_t(k)] = q.segment<3>(3 * k);
}

void UnknownsOf(const Model& model, std::span<const Vec3> x_W, Eigen::VectorXd& q) {
  for (int k = 0; k <= model.rod.elements; ++k) q.segment<3>(3 * k) = x_W[std::size_t(k)];
}

MaterialPoint FrictionMaterial(const Model& model, const FrictionPoint& f,
                               std::span<const Vec3> x_W, NodeTangents& tangents, bool jacobian) {
  (void)model;
  return Material(CarrierOf(f.kind), x_W, f.node, f.theta, f.offset_W, jacobian, &tangents);
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
  // The damper on the held end's motion relative to the hand's this tick, saturating at the
  // device's force as the spring does: a hand that jumps cannot drag the tube harder than that.
  const double b = c.damping_Ns_per_m / c.time_step_s;
  const Vec3 slip =
      (p_held_W - data.state.p_held_prev_W) - (data.input.p_hand_W - data.state.p_hand_prev_W);
  const double ls = slip.norm();
  const double s_sat = c.max_force_N / b;
  if (ls <= s_sat) {
    t.energy_J += 0.5 * b * ls * ls;
    t.force_N += b * slip;
    t.stiffness_N_per_m += b * Mat3::Identity();
  } else {
    const Vec3 u = slip / ls;
    t.energy_J += c.max_force_N * (ls - 0.5 * s_sat);
    t.force_N += c.max_force_N * u;
    t.stiffness_N_per_m += (c.max_force_N / ls) * (Mat3::Identity() - u * u.transpose());
    t.saturated = true;
  }
  return t;
}

double BendingEnergyOf(const Model& model, const Data& data, std::span<const Vec3> x_W) {
  double energy = 0.0;
  for (int i = 0; i < model.rod.elements; ++i)
    energy += model.rod.linear
                  ? LinearBendingEnergy(model.rod, data.state.R_WH, x_W, i, nullptr)
                  : BendingEnergy(model.rod, data.input.tangent_held_W, x_W, i, nullptr);
  return energy;
}

namespace {

// How many softness widths a point takes to join a smooth minimum (AddRim, AddSideGroup).
constexpr double kEaseInWidths = 10.0;

// A point joins its contact's smooth minimum gradually: its weight there is eased in from 0 where
// it is first recorded (distance epsilon) to 1 at kEaseInWidths softness widths inside, so that
// the contact's distance does not jump when a point joins it. The factor s, and the slope of the
// distance it adds, -tau log s, per metre of the point's distance.
struct EaseIn {
  double factor = 1.0;
  double slope = 0.0;
};

EaseIn EaseInOf(double distance_m, double eps, double tau) {
  const double band = kEaseInWidths * tau;
  const double x = (eps - distance_m) / band;
  if (x >= 1.0) return {};
  if (!(x > 0.0)) return {0.0, 0.0};
  const double factor = x * x * (3.0 - 2.0 * x);
  return {factor, tau * 6.0 * x * (1.0 - x) / (factor * band)};
}

// The second derivative over the end's element vector e of c . o, o the offset o0 of a rim point
// turned with the end's tangent t = e / |e| as Material turns it (o = |o0| v / |v|, v = (I - t t^T)
// o0), c fixed: the turn's share of the rim's Hessian, about F r1 / h^2 (docs/core.md, "The end
// rim").
Mat3 OffsetTurnHessian(const Vec3& o0, const Vec3& e, const Vec3& c) {
  const Mat3 I = Mat3::Identity();
  const double le = e.norm(), l0 = o0.norm();
  if (!(le > 0.0)) return Mat3::Zero();
  const Vec3 t = e / le;
  const double a = o0.dot(t);
  const Vec3 v = o0 - a * t;
  const double lv = v.norm();
  if (!(lv > 0.0)) return Mat3::Zero();
  const Vec3 vh = v / lv;
  const Vec3 c_across = c - c.dot(vh) * vh;
  // Over t: the gradient g and its derivative M, through v / |v| and |v|^2 = |o0|^2 - a^2.
  const Vec3 w = c.dot(t) * o0 + a * c_across;
  const Vec3 g = -(l0 / lv) * w;
  const Mat3 dvh_dt = -((I - vh * vh.transpose()) / lv) * (t * o0.transpose() + a * I);
  const Mat3 dc_across_dt = -(vh * c.transpose() + c.dot(vh) * I) * dvh_dt;
  const Mat3 M = -l0 * ((a / (lv * lv * lv)) * w * o0.transpose() +
                        (o0 * c.transpose() + c_across * o0.transpose() + a * dc_across_dt) / lv);
  // Over e, through t = e / |e|: T^T M T and g's share of the unit vector's curvature.
  const Mat3 T = (I - t * t.transpose()) / le;
  return T * (0.5 * (M + M.transpose())) * T -
         (g * t.transpose() + t * g.transpose() + g.dot(t) * (I - 3.0 * t * t.transpose())) /
             (le * le);
}

// The second derivative over (x_{N-1}, x_N) of the end face's distance a = (v - x_N) . t to a
// vertex v, t = e / |e| the end's tangent, e = x_N - x_{N-1}, r = (I - t t^T)(v - x_N) the
// vertex's offset from the axis: the face turns with the end (docs/core.md, "The end face").
Eigen::Matrix<double, 6, 6> FaceTurnHessian(const Vec3& r_W, double a_m, const Vec3& e_W) {
  const double le = e_W.norm();
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  if (!(le > 0.0)) return H;
  const Vec3 t = e_W / le;
  const Mat3 P = Mat3::Identity() - t * t.transpose();
  // d2a = -(2 / |e|) dx_N^T P de - (2 (t.de)(r.de) + a de^T P de) / |e|^2, de = dx_N - dx_{N-1}.
  const Mat3 ee = -(t * r_W.transpose() + r_W * t.transpose() + a_m * P) / (le * le);
  const Mat3 ne = -P / le;
  H.block<3, 3>(0, 0) = ee;
  H.block<3, 3>(0, 3) = -ee - ne;
  H.block<3, 3>(3, 0) = -ee - ne;
  H.block<3, 3>(3, 3) = ee + 2.0 * ne;
  return H;
}

// The rim's points on one part, samples [first, end): one contact whose distance is the smooth
// minimum d = -tau log sum exp(-d_j / tau) of theirs (each eased in as it joins: EaseInOf), with
// the paper's K (eps - d)+ shared by the softmin's weights. Tilted, the nearest point takes it all
// (a point contact, K); flat, the points share it evenly (the whole end face, K), and the end
// resists tilting as a rigid flat end does, up to the moment that puts the whole force on its rim
// (docs/core.md).
double AddRim(const Model& model, Data& data, std::span<const Vec3> x_W, int first, int end,
              Assembler& a) {
  const double K = model.contact.stiffness_N_per_m, eps = model.contact.threshold_m;
  const double tau = kRimSoftness * eps;
  Sample* s = &data.scratch.samples[std::size_t(first)];
  const int count = end - first;
  double d_min = s[0].distance_m;
  for (int j = 1; j < count; ++j) d_min = std::min(d_min, s[j].distance_m);
  double sum = 0.0;
  std::array<double, kRimSamples> w{};
  std::array<EaseIn, kRimSamples> ease{};
  for (int j = 0; j < count; ++j) {
    ease[std::size_t(j)] = EaseInOf(s[j].distance_m, eps, tau);
    sum += (w[std::size_t(j)] =
                ease[std::size_t(j)].factor * std::exp(-(s[j].distance_m - d_min) / tau));
  }
  // Every point just joining: no contact yet.
  const double d = sum > 0.0 ? d_min - tau * std::log(sum) : eps;
  for (int j = 0; j < count; ++j) s[j].contact_distance_m = d;
  const double depth = eps - d;
  if (!(depth > 0.0)) {
    for (int j = 0; j < count; ++j) s[j].normal_force_N = 0.0;
    return 0.0;
  }
  for (int j = 0; j < count; ++j) w[std::size_t(j)] /= sum;
  const double force = K * depth;
  for (int j = 0; j < count; ++j) s[j].normal_force_N = force * w[std::size_t(j)];
  if (!a.gradient()) return 0.5 * K * depth * depth;
  // d distance / d (x_{N-1}, x_N) of each point g_j, their weighted mean m, and the softmin's
  // curvature: H = K m m^T + (F / tau) (sum w g g^T - m m^T). On a frictionless part, where the
  // ring is placed afresh at every iterate with its first point the nearest, also each point's own
  // - F sum mu_j d2 d_j, mu_j = w_j (1 + ease slope), of the part's distance about it and of its
  // turn with the end, and the ring's turn theta with the nodes where the nearest point bears
  // (docs/core.md, "The end rim").
  const int n = model.rod.elements;
  const Vec3 e = x_W[std::size_t(n)] - x_W[std::size_t(n - 1)];
  const Vec3 t_end = e.normalized();
  const bool placed = model.parts[std::size_t(s[0].part)].friction.IsFrictionless();
  using Vec6 = Eigen::Matrix<double, 6, 1>;
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  Vec6 mean = Vec6::Zero(), mean_x_theta = Vec6::Zero(), own_x_theta = Vec6::Zero();
  Mat6 spread = Mat6::Zero(), own = Mat6::Zero();
  Mat3 turn = Mat3::Zero();
  double mean_theta = 0.0, spread_theta = 0.0, own_theta = 0.0;
  Vec6 nearest_x_theta = Vec6::Zero();
  double nearest_theta_theta = 0.0, nearest_share = 0.0;
  for (int j = 0; j < count; ++j) {
    if (!(w[std::size_t(j)] > 0.0)) continue;
    const double slope = 1.0 + ease[std::size_t(j)].slope;
    const double mu = w[std::size_t(j)] * slope;
    const Vec3& n_j = s[j].normal_W;
    const Mat3& C = s[j].curvature_per_m;
    const MaterialPoint mp = Material(Carrier::kEndNode, x_W, s[j].node, 0.0, s[j].moving_offset_W);
    const Eigen::Matrix<double, 3, 6> J = mp.jacobian.leftCols<6>();
    const Vec6 g = slope * (J.transpose() * n_j);
    mean += w[std::size_t(j)] * g;
    spread += w[std::size_t(j)] * g * g.transpose();
    if (!a.hessian() || !placed) continue;
    own += mu * (J.transpose() * C * J);
    turn += OffsetTurnHessian(s[j].moving_offset_W, e, -force * mu * n_j);
    // The point's distance over the ring's turn theta (its offset o turning to t x o).
    const Vec3 o = mp.offset_W, q = t_end.cross(o);
    Eigen::Matrix<double, 3, 6> Jq =
        Material(Carrier::kEndNode, x_W, s[j].node, 0.0, t_end.cross(s[j].moving_offset_W))
            .jacobian.leftCols<6>();
    Jq.rightCols<3>() -= Mat3::Identity();
    const double d_theta = n_j.dot(q);
    const Vec6 d_x_theta = J.transpose() * (C * q) + Jq.transpose() * n_j;
    const double d_theta_theta = q.dot(C * q) - n_j.dot(o);
    mean_theta += w[std::size_t(j)] * slope * d_theta;
    spread_theta += w[std::size_t(j)] * slope * slope * d_theta * d_theta;
    mean_x_theta += w[std::size_t(j)] * slope * d_theta * g;
    own_x_theta += mu * d_x_theta;
    own_theta += mu * d_theta_theta;
    if (s[j].feature == 0) {
      nearest_x_theta = d_x_theta;
      nearest_theta_theta = d_theta_theta;
      nearest_share = w[std::size_t(j)];
    }
  }
  StencilTerm t;
  t.first = n - 1;
  t.nodes = 2;
  t.gradient.head<6>() = -force * mean;
  if (a.hessian()) {
    Mat6 H = K * mean * mean.transpose() + (force / tau) * (spread - mean * mean.transpose()) -
             force * own;
    H.block<3, 3>(0, 0) += turn;
    H.block<3, 3>(3, 3) += turn;
    H.block<3, 3>(0, 3) -= turn;
    H.block<3, 3>(3, 0) -= turn;
    // The ring's turn fades in as the nearest point takes over, from half the load to 90 %.
    const double x = std::clamp((nearest_share - 0.5) / 0.4, 0.0, 1.0);
    const double fade = x * x * (3.0 - 2.0 * x);
    if (placed && nearest_theta_theta > tau && fade > 0.0) {
      // theta*(x), the nearest point's turn: d theta* / dx = -d_x_theta / d_theta_theta.
      const Vec6 e_x_theta = K * mean * mean_theta +
                             (force / tau) * (mean_x_theta - mean * mean_theta) -
                             force * own_x_theta;
      const double e_theta_theta = K * mean_theta * mean_theta +
                                   (force / tau) * (spread_theta - mean_theta * mean_theta) -
                                   force * own_theta;
      const Vec6 theta_x = -nearest_x_theta / nearest_theta_theta;
      H += fade * (e_x_theta * theta_x.transpose() + theta_x * e_x_theta.transpose() +
                   e_theta_theta * theta_x * theta_x.transpose());
    }
    t.hessian.topLeftCorner<6, 6>() = H;
  }
  a.AddStencil(t);
  return 0.5 * K * depth * depth;
}

// A side section's distance on its stencil (the nodes its point and its share move with): the
// gradient of its distance, less epsilon times its share's (a fading section is taken farther
// off), and the distance's curvature J^T C J (the share's own is left out).
struct SectionStencil {
  int first = 0, nodes = 0;
  Eigen::Matrix<double, 9, 1> gradient = Eigen::Matrix<double, 9, 1>::Zero();
  Eigen::Matrix<double, 9, 9> curvature = Eigen::Matrix<double, 9, 9>::Zero();
};

SectionStencil StencilOf(const Sample& smp, std::span<const Vec3> x_W, double eps, bool curvature,
                         double ease_slope) {
  const MaterialPoint mp =
      Material(CarrierOf(smp.kind), x_W, smp.node, smp.theta, smp.moving_offset_W);
  SectionStencil st;
  const bool fades = smp.weight_nodes > 0;
  st.first = fades ? std::min(mp.first, smp.weight_first) : mp.first;
  st.nodes = (fades ? std::max(mp.first + mp.nodes, smp.weight_first + smp.weight_nodes)
                    : mp.first + mp.nodes) -
             st.first;
  const int d0 = 3 * (mp.first - st.first);
  st.gradient.segment(d0, 9 - d0) =
      (1.0 + ease_slope) * (mp.jacobian.transpose() * smp.normal_W).head(9 - d0);
  if (fades) {
    const int w0 = 3 * (smp.weight_first - st.first);
    st.gradient.segment(w0, 9 - w0) -= eps * smp.weight_gradient.head(9 - w0);
  }
  // A face's distance does not curve: only an edge's or a vertex's has a curvature to add.
  if (!curvature || smp.curvature_per_m.isZero(0.0)) return st;
  const Eigen::Matrix<double, 3, 9> CJ = smp.curvature_per_m * mp.jacobian;
  const Eigen::Matrix<double, 9, 9> JCJ = mp.jacobian.transpose().lazyProduct(CJ);
  st.curvature.block(d0, d0, 9 - d0, 9 - d0) =
      (1.0 + ease_slope) * JCJ.topLeftCorner(9 - d0, 9 - d0);
  return st;
}

// The first and last node of a side section's stencil (StencilOf's, without its derivatives).
std::pair<int, int> SectionNodes(const Sample& smp) {
  const int first = smp.kind == SampleKind::kNode ? smp.node - 1 : smp.node;
  const int last = smp.node + 1;
  return {smp.weight_nodes > 0 ? std::min(first, smp.weight_first) : first,
          smp.weight_nodes > 0 ? std::max(last, smp.weight_first + smp.weight_nodes - 1) : last};
}

// A side section's softmin weight below which it is left out of the mean gradient m's span (its
// part of m is below the rounding of the rest).
constexpr double kNegligibleWeight = 1e-14;

// Groups the side's sections (IsSideSection) by the part element they press on, in the order
// their first section was found; sections beyond kMaxSideGroups elements stay on their own.
void GroupSideSections(Scratch& s) {
  s.side_group_count = 0;
  int members = 0;
  std::array<bool, kMaxSamples> grouped{};
  for (int k = 0; k < s.sample_count; ++k) {
    const Sample& first = s.samples[std::size_t(k)];
    if (grouped[std::size_t(k)] || !IsSideSection(first)) continue;
    if (s.side_group_count == kMaxSideGroups) break;
    SideGroup& g = s.side_groups[std::size_t(s.side_group_count++)];
    g.first = members;
    for (int j = k; j < s.sample_count; ++j) {
      const Sample& smp = s.samples[std::size_t(j)];
      if (grouped[std::size_t(j)] || !IsSideSection(smp) || smp.part != first.part) continue;
      grouped[std::size_t(j)] = true;
      s.side_members[std::size_t(members++)] = j;
    }
    g.count = members - g.first;
  }
}

// The side's sections on one part press as one contact, as the rim's points do: its
// distance is the smooth minimum d = -tau log sum exp(-d_j / tau) of theirs, where a section
// whose share w_j fades is taken (1 - w_j) epsilon farther off and one joining is eased in
// (EaseInOf), and the paper's K (eps - d)+ is shared by the softmin's weights. A side lying along
// a face is then one contact of stiffness K however many sections bear on it, and a curved side
// presses with its nearest section. The part, not its element: a section that moves from a face
// onto its edge stays in the contact (its distance to the part is continuous there).
// Its Hessian K m m^T + (F / tau) (sum s_j g_j g_j^T - m m^T) - F sum s_j C_j (m the weighted
// mean of the distances' gradients g_j, C_j their curvatures) goes into the band where m fits
// in it, and as a band part and a rank-one term c m m^T otherwise (SolveEquilibrium).
double AddSideGroup(const Model& model, Data& data, std::span<const Vec3> x_W, const SideGroup& g,
                    Assembler& a) {
  Scratch& sc = data.scratch;
  const double K = model.contact.stiffness_N_per_m, eps = model.contact.threshold_m;
  const double tau = kRimSoftness * eps;
  const auto member = [&](int j) -> Sample& {
    return sc.samples[std::size_t(sc.side_members[std::size_t(g.first + j)])];
  };
  const auto distance = [&](const Sample& smp) {
    return smp.distance_m + (1.0 - smp.weight) * eps;
  };
  double d_min = distance(member(0));
  for (int j = 1; j < g.count; ++j) d_min = std::min(d_min, distance(member(j)));
  const auto share = [&](const Sample& smp) {
    return EaseInOf(smp.distance_m, eps, tau).factor * std::exp(-(distance(smp) - d_min) / tau);
  };
  double sum = 0.0;
  for (int j = 0; j < g.count; ++j) sum += share(member(j));
  // Every section just joining: no contact yet.
  const double d = sum > 0.0 ? d_min - tau * std::log(sum) : eps;
  const double depth = eps - d;
  const double force = depth > 0.0 ? K * depth : 0.0;
  for (int j = 0; j < g.count; ++j) {
    Sample& smp = member(j);
    smp.contact_distance_m = d;
    smp.normal_force_N = force > 0.0 ? force * share(smp) / sum : 0.0;
  }
  if (!(depth > 0.0)) return 0.0;
  if (!a.gradient()) return 0.5 * K * depth * depth;
  // The nodes the sections of any weight span: the mean gradient m lies on them.
  int lo = std::numeric_limits<int>::max(), hi = -1;
  for (int j = 0; j < g.count; ++j) {
    const Sample& smp = member(j);
    if (!(smp.normal_force_N > kNegligibleWeight * force)) continue;
    const auto [first, last] = SectionNodes(smp);
    lo = std::min(lo, first);
    hi = std::max(hi, last);
  }
  // m in the band (three nodes at most), else as a rank-one term of its own while there is room
  // for one (beyond, its term is left out of the Hessian: the gradient stays exact).
  const bool banded = hi - lo <= 2;
  const bool low_rank = a.hessian() && !banded && sc.factors.low_rank_count < kMaxSideGroups;
  Eigen::Matrix<double, 9, 1> band_mean = Eigen::Matrix<double, 9, 1>::Zero();
  Eigen::VectorXd* mean =
      low_rank ? &sc.factors.low_rank_u[std::size_t(sc.factors.low_rank_count)] : nullptr;
  if (mean != nullptr) mean->setZero();
  for (int j = 0; j < g.count; ++j) {
    const Sample& smp = member(j);
    const double weight = smp.normal_force_N / force;
    if (!(weight > 0.0)) continue;
    const SectionStencil st =
        StencilOf(smp, x_W, eps, a.hessian(), EaseInOf(smp.distance_m, eps, tau).slope);
    StencilTerm t;
    t.first = st.first;
    t.nodes = st.nodes;
    t.gradient = -force * weight * st.gradient;
    if (a.hessian()) {
      t.hessian = (force / tau) * weight * st.gradient * st.gradient.transpose() -
                  force * weight * st.curvature;
      if (banded && weight > kNegligibleWeight)
        band_mean.segment(3 * (t.first - lo), 3 * t.nodes) +=
            weight * st.gradient.head(3 * t.nodes);
      if (mean != nullptr)
        mean->segment(3 * t.first, 3 * t.nodes) += weight * st.gradient.head(3 * t.nodes);
    }
    a.AddStencil(t);
  }
  if (!a.hessian()) return 0.5 * K * depth * depth;
  const double c = K - force / tau;
  if (banded) {
    StencilTerm t;
    t.first = lo;
    t.nodes = hi - lo + 1;
    t.hessian = c * band_mean * band_mean.transpose();
    a.AddStencil(t);
  } else if (low_rank && std::abs(c) > 1e-12 * K) {
    sc.factors.low_rank_c[std::size_t(sc.factors.low_rank_count++)] = c;
  }
  return 0.5 * K * depth * depth;
}

// The terms of a contact point's share w that fades with the nodes: E = (K/2) w depth^2 gives
// (K/2) depth^2 grad w, and -K depth (grad w grad d^T + grad d grad w^T) in the Hessian, both on
// the three-node window that holds the share's nodes and the point's.
void AddFadingShare(const MaterialPoint& mp, const Sample& smp, double K, double depth,
                    Assembler& a) {
  StencilTerm t;
  t.first = std::min(mp.first, smp.weight_first);
  t.nodes = std::max(mp.first + mp.nodes, smp.weight_first + smp.weight_nodes) - t.first;
  Eigen::Matrix<double, 9, 1> grad_w = Eigen::Matrix<double, 9, 1>::Zero();
  const int w0 = 3 * (smp.weight_first - t.first);
  grad_w.segment(w0, 9 - w0) = smp.weight_gradient.head(9 - w0);
  t.gradient = 0.5 * K * depth * depth * grad_w;
  if (a.hessian()) {
    Eigen::Matrix<double, 9, 1> grad_d = Eigen::Matrix<double, 9, 1>::Zero();
    const int d0 = 3 * (mp.first - t.first);
    grad_d.segment(d0, 9 - d0) = (mp.jacobian.transpose() * smp.normal_W).head(9 - d0);
    t.hessian = -K * depth * (grad_w * grad_d.transpose() + grad_d * grad_w.transpose());
    if (smp.weight_curve > 0.0) {
      Eigen::Matrix<double, 9, 1> g = Eigen::Matrix<double, 9, 1>::Zero();
      g.segment(w0, 9 - w0) = smp.weight_curve_gradient.head(9 - w0);
      t.hessian += 0.5 * K * depth * depth * smp.weight_curve * g * g.transpose();
    }
  }
  a.AddStencil(t);
}

}  // namespace

double Assemble(const Model& model, Data& data, std::span<const Vec3> x_W,
                Derivatives derivatives) {
  Assembler a(data, derivatives);
  const RodModel& rod = model.rod;
  double energy = 0.0;
  StencilTerm term;
  term.with_hessian = a.hessian();
  StencilTerm* want = a.gradient() ? &term : nullptr;

  // The rod: bending at the grip (against the held end's axis) and at the inner nodes, the
  // stiff axial spring of every element.
  for (int i = 0; i < rod.elements; ++i) {
    energy += rod.linear ? LinearBendingEnergy(rod, data.state.R_WH, x_W, i, want)
                         : BendingEnergy(rod, data.input.tangent_held_W, x_W, i, want);
    a.AddStencil(term);
    energy += rod.linear ? AxialHoldEnergy(rod, data.state.R_WH, x_W, i, want)
                         : StretchEnergy(rod, x_W, i, want);
    a.AddStencil(term);
  }

  // The coupling to the hand.
  const CouplingTerm c = Coupling(model, data, x_W[0]);
  energy += c.energy_J;
  a.AddHeldEnd(c.force_N, c.stiffness_N_per_m);

  // The penalty K (eps - d)+ of every contact point, along its normal, with the curvature of
  // the distance near an edge or vertex (a point rolling round it); the rim's points on one
  // part press as one contact.
  const double K = model.contact.stiffness_N_per_m, eps = model.contact.threshold_m;
  Scratch& sc = data.scratch;
  if (a.hessian()) sc.factors.low_rank_count = 0;
  GroupSideSections(sc);
  std::array<bool, kMaxSamples> in_group{};
  for (int g = 0; g < sc.side_group_count; ++g) {
    const SideGroup& group = sc.side_groups[std::size_t(g)];
    for (int j = 0; j < group.count; ++j)
      in_group[std::size_t(sc.side_members[std::size_t(group.first + j)])] = true;
    energy += AddSideGroup(model, data, x_W, group, a);
  }
  for (int k = 0; k < data.scratch.sample_count; ++k) {
    Sample& smp = data.scratch.samples[std::size_t(k)];
    if (in_group[std::size_t(k)]) continue;
    if (smp.kind == SampleKind::kRim) {
      int end = k + 1;
      while (end < data.scratch.sample_count &&
             data.scratch.samples[std::size_t(end)].kind == SampleKind::kRim &&
             data.scratch.samples[std::size_t(end)].part == smp.part)
        ++end;
      energy += AddRim(model, data, x_W, k, end, a);
      k = end - 1;
      continue;
    }
    smp.contact_distance_m = smp.distance_m;
    const double depth = eps - smp.distance_m;
    if (!(depth > 0.0)) continue;
    const double kw = K * smp.weight;
    energy += 0.5 * kw * depth * depth;
    smp.normal_force_N = kw * depth;
    if (!a.gradient()) continue;
    const MaterialPoint mp =
        Material(CarrierOf(smp.kind), x_W, smp.node, smp.theta, smp.moving_offset_W);
    a.AddAtPoint(mp.jacobian, mp.first, mp.nodes, -kw * depth * smp.normal_W,
                 kw * (smp.normal_W * smp.normal_W.transpose() - depth * smp.curvature_per_m));
    // The end face turns with the end element: its distance's own curvature.
    if (smp.kind == SampleKind::kEndFace && a.hessian()) {
      StencilTerm t;
      t.first = smp.node - 1;
      t.nodes = 2;
      t.hessian.topLeftCorner<6, 6>() =
          -kw * depth *
          FaceTurnHessian(smp.moving_offset_W, smp.distance_m,
                          x_W[std::size_t(smp.node)] - x_W[std::size_t(smp.node - 1)]);
      a.AddStencil(t);
    }
    // A share that fades: its change moves the energy too, with the cross terms of its change
    // and the distance's in the Hessian (the share's own curvature is left out).
    if (smp.weight_nodes > 0) AddFadingShare(mp, smp, K, depth, a);
  }

  // Friction: a spring from each friction point to its anchor in the tangent plane, stiffness
  // K, that gives way at the point's limit (a Huber potential): the static limit while it
  // sticks, the kinetic one once it slides, at the normal force its limit was last set for.
  for (int k = 0; k < data.state.friction_count; ++k) {
    const FrictionPoint& f = data.state.friction[std::size_t(k)];
    // A spring that let go (its contact opened) holds nothing.
    if (!(f.limit_N > 0.0)) continue;
    const MaterialPoint mp = FrictionMaterial(model, f, x_W, sc.tangents, a.gradient());
    const Mat3 P = Mat3::Identity() - f.normal_W * f.normal_W.transpose();
    const Vec3 u = P * (mp.point_W - f.anchor_W);
    const double lu = u.norm();
    const double u_limit = f.limit_N / K;
    Vec3 g;
    Mat3 H;
    // A sliding point starts its tick at its limit (its anchor was dragged there): it is taken
    // as sliding there, so that Newton's first step lets it slide on rather than holding it
    // with K (which costs two or three more iterations a tick).
    const bool stuck = f.sliding ? lu < (1.0 - 1e-9) * u_limit : lu <= u_limit;
    if (stuck) {
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
