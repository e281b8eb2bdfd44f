#include <tubeplan/core/core.hpp>

#include <algorithm>
#include <cmath>

#include <Eigen/LU>

#include <tubeplan/core/coupling.hpp>
#include <tubeplan/core/friction.hpp>
#include <tubeplan/model/tube.hpp>

#include "beam_chain.hpp"
#include "collision.hpp"

namespace tubeplan::core {

namespace {

constexpr int kMaxUnknowns = 3 * kMaxContacts + 3;
using SystemMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxUnknowns,
                                   kMaxUnknowns>;
using SystemVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxUnknowns, 1>;
// Friction, release and saturation decisions re-solve the tick's system; each pass settles at
// least one contact, so kMaxContacts + 2 passes always suffice (the rest is a safety bound).
constexpr int kMaxPasses = 2 * kMaxContacts + 4;

bool IsBoundaryOf(states::TubeElement a, states::TubeElement b) {
  // The rim bounds both the end face and the side surface.
  return a == states::TubeElement::kEndRim &&
         (b == states::TubeElement::kEndFace || b == states::TubeElement::kSide);
}

bool AllFinite(const Eigen::Vector3d& v) { return v.allFinite(); }

}  // namespace

int ChainCapsuleCount(const scene::Scene& scene) {
  const model::TubeSection section = model::ComputeSection(scene.tube);
  const double l = scene.tube.length_m;
  const double kappa = scene.device.max_force_N * l / section.bending_stiffness_Nm2;
  const double tolerance_m = 0.1 * scene.contact.threshold_m;
  // kappa (l/N)^2 / 8 <= tolerance  <=>  N >= l sqrt(kappa / (8 tolerance)).
  const double n = std::ceil(l * std::sqrt(kappa / (8.0 * tolerance_m)));
  return static_cast<int>(std::clamp(n, 8.0, static_cast<double>(kMaxCapsules)));
}

struct Core::Impl {
  Impl(const scene::Scene& scene, std::span<const std::uint32_t> parts, int capsules,
       std::vector<std::array<int, 64>> element_of)
      : collision(scene, parts, capsules, std::move(element_of)), beam(scene) {}

  Collision collision;
  BeamChain beam;

  // State carried between ticks.
  std::array<Eigen::Vector3d, kMaxCapsules + 1> nodes_H{};  // centreline at s_k = k l / N
  Eigen::Vector3d tip_tangent_H = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d p_hand_prev_W = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_held_prev_W = Eigen::Vector3d::Zero();
  std::array<ContactState, kMaxContacts> prev{};
  int prev_count = 0;
  // The loads of the last tick as the beam saw them (for Centreline on request).
  std::array<BeamLoad, kMaxContacts> loads{};
  std::array<int, kMaxContacts> order{};
  std::array<ElasticaSegment, kMaxContacts> segments{};
  int load_count = 0, group_count = 0, segment_count = 0;
  bool elastica_shape = false;

  // Per-tick scratch (kept here so that Step allocates nothing).
  std::array<RawContact, kMaxRawContacts> raw{};
  std::array<Eigen::Vector3d, kMaxCapsules + 1> nodes_W{};
  SystemMatrix M;
  SystemVector rhs, z;
  Eigen::PartialPivLU<SystemMatrix> lu;

  // Per contact, for the solve.
  struct Solve {
    Eigen::Vector3d x0_W = Eigen::Vector3d::Zero();       // load point where d was measured
    Eigen::Vector3d base_H = Eigen::Vector3d::Zero();     // x_i = p + R (base_H + J F^H)
    Eigen::Vector3d f_slide_W = Eigen::Vector3d::Zero();  // imposed friction when sliding
    Eigen::Vector3d f_lin_H = Eigen::Vector3d::Zero();    // linearisation force (elastica)
    bool active = true, sliding = false, shifted = false;
  };
  std::array<Solve, kMaxContacts> solve{};
  std::array<std::array<Eigen::Matrix3d, kMaxContacts>, kMaxContacts> J{};  // H frame
};

Core::Core(const scene::Scene& scene) : scene_(scene) {
  const model::TubeSpec& tube = scene_.tube;
  capsule_count_ = ChainCapsuleCount(scene_);
  const Coupling coupling = ResolveCoupling(scene_.device, scene_.model.time_step_s);
  coupling_stiffness_ = coupling.stiffness_N_per_m;
  coupling_damping_ = coupling.damping_Ns_per_m;

  // Reachable parts: those whose box meets the hand's workspace grown by everything the tube can
  // reach from it (its length, its radius and epsilon). Others are left out of the core entirely.
  Eigen::Vector3d lo, hi;
  const double reach = tube.length_m + tube.outer_radius_m + scene_.contact.threshold_m;
  if (scene_.workspace) {
    lo = scene_.workspace->min_W_m.array() - reach;
    hi = scene_.workspace->max_W_m.array() + reach;
  } else {
    lo.setConstant(-std::numeric_limits<double>::infinity());
    hi.setConstant(std::numeric_limits<double>::infinity());
  }
  const std::vector<scene::PartElement> all = scene::EnumerateElements(scene_);
  std::vector<std::array<int, 64>> element_of(scene_.parts.size());
  for (auto& table : element_of) table.fill(-1);
  for (std::uint32_t p = 0; p < scene_.parts.size(); ++p) {
    const scene::BoxPart& part = scene_.parts[p];
    Eigen::Vector3d box_lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d box_hi = -box_lo;
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d c_P((corner & 1 ? 0.5 : -0.5) * part.size_m.x(),
                                (corner & 2 ? 0.5 : -0.5) * part.size_m.y(),
                                (corner & 4 ? 0.5 : -0.5) * part.size_m.z());
      const Eigen::Vector3d c_W = part.X_WP * c_P;
      box_lo = box_lo.cwiseMin(c_W);
      box_hi = box_hi.cwiseMax(c_W);
    }
    if ((box_lo.array() > hi.array()).any() || (box_hi.array() < lo.array()).any()) continue;
    reachable_parts_.push_back(p);
    for (const scene::PartElement& e : all) {
      if (e.part_index != p) continue;
      element_of[p][e.face_mask] = static_cast<int>(elements_.size());
      elements_.push_back(e);
    }
  }
  impl_ = std::make_unique<Impl>(scene_, reachable_parts_, capsule_count_, std::move(element_of));
  Reset(scene_.X_WH_start);
}

Core::~Core() = default;

void Core::Reset(const Eigen::Isometry3d& X_WH) {
  Impl& m = *impl_;
  const double l = scene_.tube.length_m;
  for (int k = 0; k <= capsule_count_; ++k)
    m.nodes_H[std::size_t(k)] = Eigen::Vector3d(0.0, 0.0, l * k / capsule_count_);
  m.tip_tangent_H = Eigen::Vector3d::UnitZ();
  m.p_hand_prev_W = X_WH.translation();
  m.p_held_prev_W = X_WH.translation();
  m.prev_count = 0;
  m.load_count = m.group_count = m.segment_count = 0;
  m.elastica_shape = false;
  out_ = StepOutput{};
  out_.X_W_hand = X_WH;
  out_.X_WH = X_WH;
}

const StepOutput& Core::Step(double t_s, const Eigen::Isometry3d& X_W_hand) {
  Impl& m = *impl_;
  const double T = scene_.model.time_step_s;
  const double K = scene_.contact.stiffness_N_per_m;
  const double eps = scene_.contact.threshold_m;
  const double Kt = K;  // tangential stiffness of a stuck contact: as stiff as the normal one
  const double l = scene_.tube.length_m;
  const int N = capsule_count_;
  const bool frictionless_scene = [&] {
    if (!scene_.friction.IsFrictionless()) return false;
    for (const scene::BoxPart& part : scene_.parts)
      if (part.friction && !part.friction->IsFrictionless()) return false;
    return true;
  }();

  StepOutput& out = out_;
  out.t_s = t_s;
  out.X_W_hand = X_W_hand;
  out.flags = 0;
  const Eigen::Matrix3d R_WH = X_W_hand.linear();
  Eigen::Vector3d p_hand_W = X_W_hand.translation();
  if (!p_hand_W.allFinite() || !R_WH.allFinite()) {
    // A non-finite hand pose: hold everything where it was and send nothing.
    out.flags |= kSolverFault;
    out.force_W_N.setZero();
    out.torque_W_Nm.setZero();
    return out;
  }

  // 1. The tube where it is: last tick's held position, this tick's orientation, last shape.
  const Eigen::Vector3d p_start_W = m.p_held_prev_W;
  for (int k = 0; k <= N; ++k)
    m.nodes_W[std::size_t(k)] = p_start_W + R_WH * m.nodes_H[std::size_t(k)];
  const Eigen::Vector3d tip_tangent_W = R_WH * m.tip_tangent_H;

  // 2. Collision.
  const int raw_count = m.collision.Query(
      std::span<const Eigen::Vector3d>(m.nodes_W.data(), std::size_t(N) + 1), tip_tangent_W,
      std::span<RawContact>(m.raw.data(), m.raw.size()));

  // 3. PCs: a raw contact whose elements are boundaries of another's (same part) joins that PC.
  for (int i = 0; i < raw_count; ++i) {
    RawContact& a = m.raw[std::size_t(i)];
    for (int j = 0; j < raw_count; ++j) {
      const RawContact& b = m.raw[std::size_t(j)];
      if (i == j || a.part != b.part) continue;
      const bool part_bounds = (a.face_mask & b.face_mask) == b.face_mask;
      const bool tube_bounds = a.tube == b.tube || IsBoundaryOf(a.tube, b.tube);
      if (part_bounds && tube_bounds && (a.face_mask != b.face_mask || a.tube != b.tube)) {
        a.face_mask = b.face_mask;
        a.part_element = b.part_element;
        a.tube = b.tube;
        j = -1;  // its new element may itself be bounded by another's: look again
      }
    }
  }
  // Merge raw contacts of one element pair into one load point: the deepest one's distance and
  // normal, the depth-weighted mean arc position (the resultant of an extended contact).
  std::array<ContactState, kMaxContacts> pcs;
  std::array<double, kMaxContacts> weight{};
  int pc_count = 0;
  bool truncated = false;
  for (int i = 0; i < raw_count; ++i) {
    const RawContact& r = m.raw[std::size_t(i)];
    if (r.overlap) out.flags |= kPenetration;
    int k = 0;
    while (k < pc_count && !(pcs[std::size_t(k)].tube == r.tube &&
                             pcs[std::size_t(k)].part_element == r.part_element))
      ++k;
    const double w = eps - r.distance_m;  // > 0
    if (k == pc_count) {
      if (pc_count == kMaxContacts) {
        // Full: replace the shallowest if this one is deeper.
        int shallowest = 0;
        for (int q = 1; q < pc_count; ++q)
          if (pcs[std::size_t(q)].distance_m > pcs[std::size_t(shallowest)].distance_m)
            shallowest = q;
        truncated = true;
        if (r.distance_m >= pcs[std::size_t(shallowest)].distance_m) continue;
        k = shallowest;
        weight[std::size_t(k)] = 0.0;
      } else {
        ++pc_count;
        weight[std::size_t(k)] = 0.0;
      }
      ContactState& pc = pcs[std::size_t(k)];
      pc = ContactState{};
      pc.tube = r.tube;
      pc.part_element = r.part_element;
      pc.distance_m = r.distance_m;
      pc.normal_W = r.normal_W;
      pc.s_m = 0.0;
    }
    ContactState& pc = pcs[std::size_t(k)];
    if (r.distance_m < pc.distance_m) {
      pc.distance_m = r.distance_m;
      pc.normal_W = r.normal_W;
    }
    pc.s_m += w * r.s_m;
    weight[std::size_t(k)] += w;
  }
  if (truncated) out.flags |= kContactsTruncated;
  for (int k = 0; k < pc_count; ++k) {
    ContactState& pc = pcs[std::size_t(k)];
    pc.s_m = std::clamp(pc.s_m / weight[std::size_t(k)], 0.0, l);
    if (pc.tube != states::TubeElement::kSide) pc.s_m = l;
  }
  // Canonical order: by tube element, then part element (insertion sort: at most 6, stable).
  for (int i = 1; i < pc_count; ++i) {
    for (int j = i; j > 0; --j) {
      const ContactState& a = pcs[std::size_t(j - 1)];
      const ContactState& b = pcs[std::size_t(j)];
      const bool in_order =
          a.tube != b.tube ? a.tube < b.tube : a.part_element <= b.part_element;
      if (in_order) break;
      std::swap(pcs[std::size_t(j - 1)], pcs[std::size_t(j)]);
    }
  }

  // 4. Loads, anchors, and the beam's compliance.
  const auto find_prev = [&](const ContactState& pc) -> const ContactState* {
    for (int q = 0; q < m.prev_count; ++q)
      if (m.prev[std::size_t(q)].tube == pc.tube &&
          m.prev[std::size_t(q)].part_element == pc.part_element)
        return &m.prev[std::size_t(q)];
    return nullptr;
  };
  const auto interpolate_node = [&](double s_m) {
    const double u = std::clamp(s_m / l * N, 0.0, static_cast<double>(N));
    const int k = std::min(static_cast<int>(u), N - 1);
    const double t = u - k;
    return Eigen::Vector3d((1.0 - t) * m.nodes_H[std::size_t(k)] +
                           t * m.nodes_H[std::size_t(k) + 1]);
  };
  for (int i = 0; i < pc_count; ++i) {
    ContactState& pc = pcs[std::size_t(i)];
    Impl::Solve& sv = m.solve[std::size_t(i)];
    sv = Impl::Solve{};
    sv.x0_W = p_start_W + R_WH * interpolate_node(pc.s_m);
    const ContactState* before = find_prev(pc);
    pc.anchor_W_m = before ? before->anchor_W_m : sv.x0_W;
    sv.f_lin_H = before ? Eigen::Vector3d(R_WH.transpose() * before->force_W_N)
                        : Eigen::Vector3d::Zero();
    m.loads[std::size_t(i)] = BeamLoad{pc.s_m, sv.f_lin_H, 0.0, 0};
  }
  m.load_count = pc_count;
  m.group_count = m.beam.Assign(m.loads, pc_count, m.order);
  const bool want_elastica = scene_.model.beam == model::BeamModel::kElastica;
  bool use_elastica = want_elastica && pc_count > 0 &&
                      m.beam.ElasticaCovers(m.loads, pc_count, m.group_count);
  if (want_elastica && pc_count > 0 && !use_elastica) out.flags |= kLinearFallback;
  const Eigen::DiagonalMatrix<double, 3> lateral(1.0, 1.0, 0.0);
  for (int i = 0; i < pc_count; ++i) {
    for (int j = 0; j < pc_count; ++j) {
      m.J[std::size_t(i)][std::size_t(j)] =
          m.beam.Influence(m.loads[std::size_t(i)].s_m, m.loads[std::size_t(j)]) *
          Eigen::Matrix3d(lateral);
    }
    m.solve[std::size_t(i)].base_H = Eigen::Vector3d(0.0, 0.0, m.loads[std::size_t(i)].s_m);
  }
  if (use_elastica) {
    // Newton about last tick's forces: x(F) ~ x_el(F_lin) + J (F - F_lin), with the elastica's
    // own tangent for each segment's load and the linear influence for the loads before it.
    m.segment_count = m.beam.SolveElasticaChain(m.loads, pc_count, m.order, m.segments);
    for (int i = 0; i < pc_count; ++i) {
      const BeamLoad& li = m.loads[std::size_t(i)];
      const ElasticaSegment& seg = m.segments[std::size_t(li.group)];
      Eigen::Vector3d f_group = Eigen::Vector3d::Zero();
      for (int j = 0; j < pc_count; ++j)
        if (m.loads[std::size_t(j)].group == li.group) f_group += m.loads[std::size_t(j)].f_H_N;
      const Eigen::Matrix3d J_seg = m.beam.ElasticaCompliance(seg, f_group);
      for (int j = 0; j < pc_count; ++j)
        if (m.loads[std::size_t(j)].group == li.group) m.J[std::size_t(i)][std::size_t(j)] = J_seg;
    }
    for (int i = 0; i < pc_count; ++i) {
      Eigen::Vector3d x_el = m.beam.ElasticaPoint(m.segments, m.segment_count,
                                                  m.loads[std::size_t(i)].s_m);
      for (int j = 0; j < pc_count; ++j)
        x_el -= m.J[std::size_t(i)][std::size_t(j)] * m.loads[std::size_t(j)].f_H_N;
      m.solve[std::size_t(i)].base_H = x_el;
    }
  }

  // 5. Solve contacts, coupling and beam together. Unknowns: the contact forces F_i (W) and the
  // held-end position p. Contact i: F_i = K n (eps - d_i - n.(x_i - x0_i)) + Kt T (a_i - x_i)
  // (stuck) or + f_i (sliding), with x_i = p + R (base_i + sum_j J_ij R^T F_j). Coupling:
  // K_c (h - p) + B (v_h - (p - p_prev) / T) + sum F_i = 0 (the tube and proxy are massless).
  const double Kc = coupling_stiffness_;
  const double B = coupling_damping_;
  const double Kc_eff = Kc + B / T;
  const Eigen::Vector3d v_hand_W = (p_hand_W - m.p_hand_prev_W) / T;
  Eigen::Vector3d A = Kc * p_hand_W + B * v_hand_W + (B / T) * m.p_held_prev_W;
  const double max_force = scene_.device.max_force_N;
  std::array<int, kMaxContacts> slot{};
  Eigen::Vector3d p_W = p_start_W;
  bool solved = false;
  bool saturated = false;
  for (int pass = 0; pass < kMaxPasses; ++pass) {
    int n_active = 0;
    for (int i = 0; i < pc_count; ++i) slot[std::size_t(i)] = m.solve[std::size_t(i)].active ? n_active++ : -1;
    const int n = 3 * n_active + 3;
    m.M.setZero(n, n);
    m.rhs.setZero(n);
    for (int i = 0; i < pc_count; ++i) {
      const int si = slot[std::size_t(i)];
      if (si < 0) continue;
      const ContactState& pc = pcs[std::size_t(i)];
      const Impl::Solve& sv = m.solve[std::size_t(i)];
      const Eigen::Vector3d& nrm = pc.normal_W;
      const Eigen::Matrix3d NN = nrm * nrm.transpose();
      const Eigen::Matrix3d Tp = Eigen::Matrix3d::Identity() - NN;
      const bool frictional = !frictionless_scene &&
                              !scene::FrictionAt(scene_, elements_[std::size_t(pc.part_element)].part_index).IsFrictionless();
      const bool stuck = frictional && !sv.sliding;
      const Eigen::Matrix3d G = K * NN + (stuck ? Kt : 0.0) * Tp;
      Eigen::Vector3d b = K * nrm * (eps - pc.distance_m + nrm.dot(sv.x0_W));
      if (stuck) b += Kt * (Tp * pc.anchor_W_m);
      if (sv.sliding) b += sv.f_slide_W;
      const int r = 3 * si;
      m.M.block<3, 3>(r, r) += Eigen::Matrix3d::Identity();
      for (int j = 0; j < pc_count; ++j) {
        const int sj = slot[std::size_t(j)];
        if (sj < 0) continue;
        m.M.block<3, 3>(r, 3 * sj) +=
            G * R_WH * m.J[std::size_t(i)][std::size_t(j)] * R_WH.transpose();
      }
      m.M.block<3, 3>(r, n - 3) = G;
      m.rhs.segment<3>(r) = b - G * (R_WH * sv.base_H);
      m.M.block<3, 3>(n - 3, r) = -Eigen::Matrix3d::Identity();
    }
    m.M.block<3, 3>(n - 3, n - 3) = Kc_eff * Eigen::Matrix3d::Identity();
    m.rhs.segment<3>(n - 3) = A;
    m.lu.compute(m.M);
    m.z = m.lu.solve(m.rhs);
    if (!m.z.allFinite()) break;
    p_W = m.z.segment<3>(n - 3);

    // Decisions: release contacts that pull, slide those beyond the friction limit, saturate
    // the coupling at the device's force. Each changes the system: solve again.
    bool changed = false;
    for (int i = 0; i < pc_count && !changed; ++i) {
      const int si = slot[std::size_t(i)];
      if (si < 0) continue;
      ContactState& pc = pcs[std::size_t(i)];
      Impl::Solve& sv = m.solve[std::size_t(i)];
      const Eigen::Vector3d F = m.z.segment<3>(3 * si);
      const double normal_N = pc.normal_W.dot(F);
      if (normal_N < 0.0) {
        sv.active = false;
        changed = true;
        break;
      }
      const scene::Friction& friction =
          scene::FrictionAt(scene_, elements_[std::size_t(pc.part_element)].part_index);
      if (frictionless_scene || friction.IsFrictionless()) continue;
      const Eigen::Vector3d Ft = F - normal_N * pc.normal_W;
      if (!sv.sliding) {
        const FrictionResult fr = ReturnMap(friction, Ft, normal_N, Kt);
        if (!fr.sliding) continue;
        if (scene_.model.slip == scene::SlipRule::kPaper && !sv.shifted) {
          // The paper: the contact point moves with the held end's tangential motion, then the
          // force is computed again (and limited below if that is still not enough).
          const Eigen::Vector3d dp = p_W - m.p_held_prev_W;
          pc.anchor_W_m += dp - pc.normal_W * pc.normal_W.dot(dp);
          sv.shifted = true;
        } else {
          sv.sliding = true;
          sv.f_slide_W = fr.force_N;
        }
        changed = true;
      } else {
        // Keep the kinetic force consistent with the normal force it now presses with.
        const double fk = FrictionLimit(friction, friction.kinetic_coefficient, normal_N);
        const double now = sv.f_slide_W.norm();
        if (now > 0.0 && std::abs(fk - now) > 1e-9 * (1.0 + fk)) {
          sv.f_slide_W *= fk / now;
          changed = true;
        }
      }
    }
    if (!changed) {
      const Eigen::Vector3d coupling_W = A - Kc_eff * p_W;
      const double magnitude = coupling_W.norm();
      if (magnitude > max_force * (1.0 + 1e-12)) {
        // The spring cannot pull harder than the device can push: move its hand end towards
        // the proxy until it carries exactly the device's maximum; the proxy separates.
        A = Kc_eff * p_W + coupling_W * (max_force / magnitude);
        saturated = true;
        changed = true;
      }
    }
    if (!changed) {
      solved = true;
      break;
    }
  }
  if (saturated) out.flags |= kProxySeparated;
  if (!solved) {
    // Singular, not finite or undecided: nothing moves and nothing is sent this tick.
    out.flags |= kSolverFault;
    out.force_W_N.setZero();
    out.torque_W_Nm.setZero();
    out.contact_count = 0;
    m.p_hand_prev_W = p_hand_W;
    return out;
  }

  // 6. Results per contact; anchors of sliding contacts follow (the spring then carries f_k).
  Eigen::Vector3d force_W = Eigen::Vector3d::Zero(), torque_W = Eigen::Vector3d::Zero();
  int kept = 0;
  for (int i = 0; i < pc_count; ++i) {
    const int si = slot[std::size_t(i)];
    if (si < 0) continue;
    ContactState pc = pcs[std::size_t(i)];
    const Impl::Solve& sv = m.solve[std::size_t(i)];
    const Eigen::Vector3d F = m.z.segment<3>(3 * si);
    Eigen::Vector3d x_H = sv.base_H;
    for (int j = 0; j < pc_count; ++j) {
      const int sj = slot[std::size_t(j)];
      if (sj >= 0)
        x_H += m.J[std::size_t(i)][std::size_t(j)] * (R_WH.transpose() * m.z.segment<3>(3 * sj));
    }
    pc.p_WC_m = p_W + R_WH * x_H;
    pc.normal_force_N = std::max(0.0, pc.normal_W.dot(F));
    pc.friction_W_N = F - pc.normal_W.dot(F) * pc.normal_W;
    pc.force_W_N = F;
    pc.sliding = sv.sliding;
    pc.distance_m = pc.distance_m + pc.normal_W.dot(pc.p_WC_m - sv.x0_W);
    const scene::Friction& friction =
        scene::FrictionAt(scene_, elements_[std::size_t(pc.part_element)].part_index);
    pc.friction_limit_N = frictionless_scene || friction.IsFrictionless()
                              ? 0.0
                              : FrictionLimit(friction, friction.static_coefficient,
                                              pc.normal_force_N);
    if (sv.sliding) {
      pc.anchor_W_m = pc.p_WC_m + pc.friction_W_N / Kt;
    } else if (frictionless_scene || friction.IsFrictionless()) {
      pc.anchor_W_m = pc.p_WC_m;
    }
    force_W += F;
    torque_W += (pc.p_WC_m - p_W).cross(F);
    m.loads[std::size_t(kept)] = BeamLoad{pc.s_m, R_WH.transpose() * F, 0.0, 0};
    out.contacts[std::size_t(kept++)] = pc;
  }
  out.contact_count = kept;

  // 7. The shape under the solved loads: the next tick's capsules, energy, strain, markers.
  m.load_count = kept;
  m.group_count = m.beam.Assign(m.loads, kept, m.order);
  m.elastica_shape = want_elastica && kept > 0 &&
                     m.beam.ElasticaCovers(m.loads, kept, m.group_count);
  const double EI = m.beam.bending_stiffness_Nm2();
  const double r1 = scene_.tube.outer_radius_m;
  double energy_J = 0.0, strain = 0.0;
  if (m.elastica_shape) {
    m.segment_count = m.beam.SolveElasticaChain(m.loads, kept, m.order, m.segments);
    for (int k = 0; k <= N; ++k)
      m.nodes_H[std::size_t(k)] = m.beam.ElasticaPoint(m.segments, m.segment_count, l * k / N);
    m.tip_tangent_H = m.beam.ElasticaTipTangent(m.segments, m.segment_count);
    for (int g = 0; g < m.segment_count; ++g) {
      const ElasticaSegment& seg = m.segments[std::size_t(g)];
      if (!(seg.length_m > 0.0)) continue;
      energy_J += EI / seg.length_m * seg.solution.tip.energy;
      strain = std::max(strain, r1 * std::abs(seg.solution.tip.root_curvature) / seg.length_m);
    }
  } else {
    m.segment_count = 0;
    Eigen::Vector2d slope = Eigen::Vector2d::Zero();
    for (int k = 0; k <= N; ++k) {
      const double s = l * k / N;
      Eigen::Vector2d lateral_m = Eigen::Vector2d::Zero();
      for (int j = 0; j < kept; ++j)
        lateral_m += m.beam.Influence(s, m.loads[std::size_t(j)]) *
                     m.loads[std::size_t(j)].f_H_N.head<2>();
      m.nodes_H[std::size_t(k)] = Eigen::Vector3d(lateral_m.x(), lateral_m.y(), s);
    }
    for (int j = 0; j < kept; ++j)
      slope += m.beam.InfluenceSlope(l, m.loads[std::size_t(j)]) *
               m.loads[std::size_t(j)].f_H_N.head<2>();
    m.tip_tangent_H = Eigen::Vector3d(slope.x(), slope.y(), 1.0).normalized();
    // U = 1/2 sum over loads on the same cantilever of F_i . infl F_j (the compliance energy).
    for (int i = 0; i < kept; ++i)
      for (int j = 0; j < kept; ++j) {
        const BeamLoad& a = m.loads[std::size_t(i)];
        const BeamLoad& b = m.loads[std::size_t(j)];
        if (a.clamp_m != b.clamp_m) continue;
        energy_J += 0.5 * m.beam.Influence(a.s_m, b) * a.f_H_N.head<2>().dot(b.f_H_N.head<2>());
      }
    // The bending moment is piecewise linear between clamps and load points: its largest value
    // is at one of them.
    for (int c = 0; c < 2 * kept; ++c) {
      const double s = c < kept ? m.loads[std::size_t(c)].clamp_m : m.loads[std::size_t(c - kept)].s_m;
      Eigen::Vector2d moment = Eigen::Vector2d::Zero();
      for (int j = 0; j < kept; ++j) {
        const BeamLoad& b = m.loads[std::size_t(j)];
        if (b.clamp_m <= s && s < b.s_m) moment += (b.s_m - s) * b.f_H_N.head<2>();
      }
      strain = std::max(strain, r1 * moment.norm() / EI);
    }
  }
  out.energy_J = energy_J;
  out.max_strain = strain;
  out.tip_deflection_m = m.nodes_H[std::size_t(N)].head<2>().norm();

  // Markers (contact-states.md): no bending below the threshold; the end face and rim never
  // deform; a side contact is concave or convex by the side of the bend it touches, judged by
  // the bending moment midway along the cantilever piece that ends at it.
  const bool bends = out.tip_deflection_m > scene_.contact.bend_threshold_m;
  for (int i = 0; i < kept; ++i) {
    ContactState& pc = out.contacts[std::size_t(i)];
    if (!bends) {
      pc.marker = states::Marker::kNone;
      continue;
    }
    if (pc.tube != states::TubeElement::kSide) {
      pc.marker = states::Marker::kBent;
      continue;
    }
    const BeamLoad& own = m.loads[std::size_t(i)];
    double before_m = own.clamp_m;
    for (int j = 0; j < kept; ++j) {
      const double sj = m.loads[std::size_t(j)].s_m;
      if (sj < own.s_m - m.beam.group_tolerance_m()) before_m = std::max(before_m, sj);
    }
    const double mid = 0.5 * (before_m + own.s_m);
    Eigen::Vector2d moment = Eigen::Vector2d::Zero();
    for (int j = 0; j < kept; ++j) {
      const BeamLoad& b = m.loads[std::size_t(j)];
      if (b.clamp_m <= mid && mid < b.s_m) moment += (b.s_m - mid) * b.f_H_N.head<2>();
    }
    const Eigen::Vector2d n_H = (R_WH.transpose() * pc.normal_W).head<2>();
    const double side = moment.dot(n_H);
    // The tube curves towards `moment`: along the normal (away from the part) the part touches
    // the outside of the bend.
    if (side > 1e-12 * moment.norm())
      pc.marker = states::Marker::kConvex;
    else if (side < -1e-12 * moment.norm())
      pc.marker = states::Marker::kConcave;
    else
      pc.marker = states::Marker::kBent;
  }

  // 8. The operator's wrench, and the state for the next tick.
  out.X_WH = X_W_hand;
  out.X_WH.translation() = p_W;
  out.force_W_N = force_W;
  out.torque_W_Nm = torque_W;
  if (force_W.norm() > max_force * (1.0 + 1e-9) ||
      torque_W.norm() > scene_.device.max_torque_Nm)
    out.flags |= kForceClamped;
  const bool finite = AllFinite(force_W) && AllFinite(torque_W) && AllFinite(p_W) &&
                      std::isfinite(energy_J) && std::isfinite(strain);
  if (!finite) {
    out.flags |= kSolverFault;
    out.force_W_N.setZero();
    out.torque_W_Nm.setZero();
    out.contact_count = 0;
    Reset(Eigen::Isometry3d(X_W_hand));
    out.flags |= kSolverFault;
    return out;
  }
  m.p_hand_prev_W = p_hand_W;
  m.p_held_prev_W = p_W;
  m.prev = out.contacts;
  m.prev_count = kept;
  return out;
}

void Core::Centreline(std::span<Eigen::Vector3d> p_W_m) const {
  const Impl& m = *impl_;
  const double l = scene_.tube.length_m;
  const std::size_t count = p_W_m.size();
  const Eigen::Matrix3d R_WH = out_.X_WH.linear();
  const Eigen::Vector3d p_WH = out_.X_WH.translation();
  for (std::size_t k = 0; k < count; ++k) {
    const double s = count > 1 ? l * double(k) / double(count - 1) : l;
    Eigen::Vector3d x_H;
    if (m.elastica_shape) {
      x_H = m.beam.ElasticaPoint(m.segments, m.segment_count, s);
    } else {
      Eigen::Vector2d lateral_m = Eigen::Vector2d::Zero();
      for (int j = 0; j < m.load_count; ++j)
        lateral_m += m.beam.Influence(s, m.loads[std::size_t(j)]) *
                     m.loads[std::size_t(j)].f_H_N.head<2>();
      x_H = Eigen::Vector3d(lateral_m.x(), lateral_m.y(), s);
    }
    p_W_m[k] = p_WH + R_WH * x_H;
  }
}

states::ContactFormation Core::Formation() const {
  states::ContactFormation cf;
  for (const ContactState& pc : out_.Contacts())
    cf.contacts.push_back({pc.tube, pc.marker, elements_[std::size_t(pc.part_element)].name});
  states::Canonicalize(cf);
  return cf;
}

std::string Core::FormationText() const { return states::ToString(Formation()); }

}  // namespace tubeplan::core
