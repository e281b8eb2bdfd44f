#include <algorithm>
#include <cmath>
#include <limits>

#include <tubeplan/core/core.hpp>

#if defined(__SSE__)
#include <xmmintrin.h>
#endif

#include <tubeplan/core/coupling.hpp>
#include <tubeplan/model/tube.hpp>

#include "core/classify.hpp"
#include "core/data.hpp"
#include "core/model.hpp"
#include "core/solve.hpp"
#include "core/stick_slip.hpp"
#include "core/tick.hpp"

namespace tubeplan::core {
namespace {

// Friction passes a tick at most: a solve, then again while points change between stick and
// slip or their loads move their limits.
constexpr int kFrictionPasses = 4;

// Flushes denormal numbers to zero for the scope of a tick: a rod at rest accumulates
// vanishing increments whose arithmetic is a hundred times slower (the thread's own setting is
// put back at the end).
class FlushDenormals {
 public:
#if defined(__SSE__)
  FlushDenormals() : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | 0x8040); }
  ~FlushDenormals() { _mm_setcsr(saved_); }

 private:
  unsigned saved_;
#endif
};

bool StateFinite(const Data& d) {
  for (const Eigen::Vector3d& x : d.state.x_W)
    if (!x.allFinite()) return false;
  return true;
}

}  // namespace

int ElementCount(const scene::Scene& scene) {
  constexpr int kDefault = 24;
  const int n = scene.model.elements > 0 ? scene.model.elements : kDefault;
  // Elements at least r1 long: the side's sphere at the last inner node then stays within the
  // end face (docs/core.md, "Contact points").
  const int longest = int(scene.tube.length_m / scene.tube.outer_radius_m);
  return std::clamp(std::min(n, longest), kMinElementCount, kMaxElementCount);
}

void InitData(const Model& model, const Eigen::Isometry3d& X_WH, Data& d) {
  const int n = model.rod.elements;
  const std::size_t nodes = std::size_t(n) + 1, parts = model.parts.size();
  d.state.x_W.assign(nodes, Eigen::Vector3d::Zero());
  d.state.section_direction_W.assign(parts * nodes, X_WH.linear().col(0));
  d.state.entry_element.assign(parts * nodes, kNoElement);
  d.scratch.x_trial_W.assign(nodes, Eigen::Vector3d::Zero());
  d.scratch.x_start_W.assign(nodes, Eigen::Vector3d::Zero());
  const int unknowns = 3 * (n + 1);
  for (Eigen::VectorXd* v : {&d.scratch.unknowns, &d.scratch.unknowns_trial, &d.scratch.gradient,
                             &d.scratch.step, &d.scratch.direction, &d.scratch.work})
    v->setZero(unknowns);
  for (HessianFactors* f : {&d.scratch.factors, &d.state.kept.factors}) {
    for (int k = 0; k < kMaxSideGroups; ++k) {
      f->low_rank_u[std::size_t(k)].setZero(unknowns);
      f->low_rank_z[std::size_t(k)].setZero(unknowns);
    }
    f->low_rank_count = 0;
    f->band = BandLdlt(unknowns);
  }
  d.scratch.factors_current = false;
  d.state.kept.valid = false;
  d.scratch.hessian = BandMatrix(unknowns);
  d.scratch.parts_near.assign(parts, 0);
  d.scratch.clearance_m.assign(nodes, 0.0);
  d.scratch.entry_seen.assign(parts * nodes, 0);
  std::size_t most_edges = 0;
  for (const PartModel& part : model.parts)
    most_edges = std::max(most_edges, part.geometry.edges().size());
  d.scratch.edges_near.assign(most_edges, 0);
  d.scratch.section_chosen.assign(parts * nodes, 0);
  d.scratch.section_side_W.assign(parts * nodes, Eigen::Vector3d::Zero());
  d.scratch.tangents.Resize(int(nodes));
  // The tube straight along the held end's z, the hand at the held end.
  for (int k = 0; k <= n; ++k)
    d.state.x_W[std::size_t(k)] =
        X_WH.translation() + (k * model.rod.segment_m) * X_WH.linear().col(2);
  d.state.x_prev_W = d.state.x_W;
  d.state.R_WH = X_WH.linear();
  d.state.p_hand_prev_W = d.state.p_held_prev_W = X_WH.translation();
  d.state.friction_count = 0;
  d.state.bends = false;
  d.input = TickInput{};
  d.input.p_hand_W = X_WH.translation();
  d.input.X_W_hand = X_WH;
  d.input.tangent_held_W = X_WH.linear().col(2);
  d.scratch.sample_count = 0;
  d.solve = SolveReport{};
  d.out = StepOutput{};
  d.out.X_W_hand = X_WH;
  d.out.X_WH = X_WH;
}

void BuildModel(const scene::Scene& scene, Model& m, std::vector<scene::PartElement>& elements,
                std::vector<std::uint32_t>& reachable_parts) {
  const model::TubeSpec& tube = scene.tube;
  const model::TubeSection section = model::ComputeSection(tube);
  m.rod.elements = ElementCount(scene);
  m.rod.length_m = tube.length_m;
  m.rod.segment_m = tube.length_m / m.rod.elements;
  m.rod.outer_radius_m = tube.outer_radius_m;
  m.rod.inner_radius_m = tube.inner_radius_m;
  m.rod.bending_stiffness_Nm2 = section.bending_stiffness_Nm2;
  m.rod.linear = scene.model.tube == scene::TubeModel::kLinear;
  m.contact.stiffness_N_per_m = scene.contact.stiffness_N_per_m;
  m.contact.threshold_m = scene.contact.threshold_m;
  m.contact.bend_threshold_m = scene.contact.bend_threshold_m;
  // Inextensible, as the paper's tube and Kirchhoff's rod: the axial stiffness is the tube's own
  // or, when that is softer, a hundred times the contact's over the tube's length, so that the
  // rod's stretch under any load is a hundredth of the contact's give (docs/core.md).
  const double area_m2 = M_PI * (tube.outer_radius_m * tube.outer_radius_m -
                                 tube.inner_radius_m * tube.inner_radius_m);
  m.rod.stretch_stiffness_N = std::max(tube.youngs_modulus_Pa * area_m2,
                                       100.0 * m.contact.stiffness_N_per_m * tube.length_m);
  const Coupling coupling = ResolveCoupling(scene.device, scene.model.time_step_s);
  m.coupling.stiffness_N_per_m = coupling.stiffness_N_per_m;
  m.coupling.damping_Ns_per_m = coupling.damping_Ns_per_m;
  m.coupling.max_force_N = scene.device.max_force_N;
  m.coupling.max_torque_Nm = scene.device.max_torque_Nm;
  m.coupling.time_step_s = scene.model.time_step_s;

  // Reachable parts: those whose box meets the hand's workspace grown by everything the tube can
  // reach from it (its length, its radius and epsilon). Others are left out of the core entirely.
  Eigen::Vector3d lo, hi;
  const double reach = tube.length_m + tube.outer_radius_m + scene.contact.threshold_m;
  if (scene.workspace) {
    lo = scene.workspace->min_W_m.array() - reach;
    hi = scene.workspace->max_W_m.array() + reach;
  } else {
    lo.setConstant(-std::numeric_limits<double>::infinity());
    hi.setConstant(std::numeric_limits<double>::infinity());
  }
  const std::vector<scene::PartElement> all = scene::EnumerateElements(scene);
  double thinnest = tube.outer_radius_m;
  std::size_t next_element = 0;
  for (std::uint32_t p = 0; p < scene.parts.size(); ++p) {
    PartModel part;
    part.geometry = PartGeometry(scene.parts[p]);
    const PartGeometry& g = part.geometry;
    // All elements of a part are consecutive in `all`, in part order.
    while (next_element < all.size() && all[next_element].part_index < p) ++next_element;
    if ((g.min_W().array() > hi.array()).any() || (g.max_W().array() < lo.array()).any()) continue;
    part.scene_index = p;
    part.friction = scene::FrictionAt(scene, p);
    part.first_element = static_cast<int>(elements.size());
    for (std::size_t e = next_element; e < all.size() && all[e].part_index == p; ++e)
      elements.push_back(all[e]);
    thinnest = std::min(thinnest, g.thinnest_m());
    reachable_parts.push_back(p);
    m.parts.push_back(std::move(part));
  }
  m.frictionless = std::all_of(m.parts.begin(), m.parts.end(),
                               [](const PartModel& p) { return p.friction.IsFrictionless(); });
  // No point moves more than a quarter of the tube's radius or of the thinnest part in one
  // iteration: a point pushed into a part meets its penalty before it could pass its middle.
  m.solver.step_cap_m = 0.25 * thinnest;
  // A tick's Newton iterations at most, over its friction passes: a snap through spreads over
  // ticks (each moving every point at most this many step caps) instead of stalling one.
  m.solver.max_iterations = 24;
  // A tenth of what a haptic device resolves (docs/core.md, "Convergence").
  m.solver.tolerance_N = 1e-4;
}

Core::Core(const scene::Scene& scene) : scene_(scene), model_(std::make_unique<Model>()) {
  BuildModel(scene_, *model_, elements_, reachable_parts_);
  data_ = std::make_unique<Data>();
  InitData(*model_, scene_.X_WH_start, *data_);
}

Core::~Core() = default;

void Core::Reset(const Eigen::Isometry3d& X_WH) { InitData(*model_, X_WH, *data_); }

const StepOutput& Core::Step(double t_s, const Eigen::Isometry3d& X_W_hand) {
  const Model& m = *model_;
  Data& d = *data_;
  const FlushDenormals flush;
  // The hand, the held end turned with it, the tube where the solve starts.
  if (!StartTick(m, t_s, X_W_hand, d)) {
    HoldStill(m, d);
    return d.out;
  }
  // One equilibrium of the rod, the coupling, the contacts and friction; again while friction
  // changes between stick and slip.
  for (int pass = 1;; ++pass) {
    SolveEquilibrium(m, d);
    d.solve.friction_passes = pass;
    if (pass == kFrictionPasses || !ReturnFrictionToLimits(m, d)) break;
  }
  if (!StateFinite(d)) {
    HoldStill(m, d);
    return d.out;
  }
  // Friction forces and work, and the anchors the next tick starts from.
  CarryFriction(m, d);
  // The contact formation read off the solved shape.
  Classify(m, d);
  // The wrench on the operator, energies and flags.
  WriteOutput(m, d);
  EndTick(m, d);
  return d.out;
}

Core::Snapshot::Snapshot() = default;
Core::Snapshot::~Snapshot() = default;
Core::Snapshot::Snapshot(const Snapshot& other)
    : data_(other.data_ ? std::make_unique<SnapshotData>(*other.data_) : nullptr) {}
Core::Snapshot& Core::Snapshot::operator=(const Snapshot& other) {
  if (this == &other) return *this;
  if (!other.data_)
    data_.reset();
  else if (data_)
    *data_ = *other.data_;
  else
    data_ = std::make_unique<SnapshotData>(*other.data_);
  return *this;
}

void Core::Save(Snapshot& snapshot) const {
  if (!snapshot.data_) snapshot.data_ = std::make_unique<SnapshotData>();
  snapshot.data_->state = data_->state;
  snapshot.data_->out = data_->out;
  snapshot.data_->p_hand_W = data_->input.p_hand_W;
  snapshot.data_->sample_count = data_->scratch.sample_count;
}

bool Core::Restore(const Snapshot& snapshot) {
  if (!snapshot.data_) return false;
  const SnapshotData& s = *snapshot.data_;
  if (s.state.x_W.size() != data_->state.x_W.size() ||
      s.state.entry_element.size() != data_->state.entry_element.size() ||
      s.state.section_direction_W.size() != data_->state.section_direction_W.size())
    return false;
  data_->state = s.state;
  data_->out = s.out;
  data_->input.p_hand_W = s.p_hand_W;
  data_->input.tangent_held_W = s.state.R_WH.col(2);
  // The free-motion guess reads whether the last tick touched anything.
  data_->scratch.sample_count = s.sample_count;
  return true;
}

void Core::Centreline(std::span<Eigen::Vector3d> p_W_m) const {
  const auto& x = data_->state.x_W;
  const int n = model_->rod.elements;
  const std::size_t count = p_W_m.size();
  for (std::size_t i = 0; i < count; ++i) {
    const double u = count > 1 ? double(i) * n / double(count - 1) : 0.0;
    const int k = std::min(int(u), n - 1);
    const double w = u - k;
    p_W_m[i] = (1.0 - w) * x[std::size_t(k)] + w * x[std::size_t(k + 1)];
  }
}

states::ContactFormation Core::Formation() const {
  states::ContactFormation cf;
  for (const ContactState& c : data_->out.Contacts())
    cf.contacts.push_back(
        {c.tube, c.marker, elements_[static_cast<std::size_t>(c.part_element)].name});
  states::Canonicalize(cf);
  return cf;
}

std::string Core::FormationText() const { return states::ToString(Formation()); }

const StepOutput& Core::last() const { return data_->out; }
int Core::element_count() const { return model_->rod.elements; }
double Core::coupling_stiffness_N_per_m() const { return model_->coupling.stiffness_N_per_m; }
double Core::coupling_damping_Ns_per_m() const { return model_->coupling.damping_Ns_per_m; }

}  // namespace tubeplan::core
