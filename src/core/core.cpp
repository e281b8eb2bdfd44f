#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include <Eigen/LU>

#include <tubeplan/core/core.hpp>
#include <tubeplan/core/coupling.hpp>
#include <tubeplan/core/friction.hpp>
#include <tubeplan/model/tube.hpp>

#include "beam_chain.hpp"
#include "collision.hpp"
#include "contact_system.hpp"

namespace tubeplan::core {

namespace {

constexpr int kMaxUnknowns = 3 * kMaxLoads + 6;
using SystemMatrix =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxUnknowns, kMaxUnknowns>;
using SystemVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxUnknowns, 1>;
// Friction, release and saturation decisions re-solve the tick's system; each pass settles at
// least one contact, so kMaxContacts + 2 passes always suffice (the rest is a safety bound).
constexpr int kMaxPasses = 3 * kMaxLoads + 4;
// A beam tangent (the elastica's or the rod's) steers the Newton step only; it is renewed after
// this many ticks even while the loads stay within its reuse bounds. Ages saturate here, so a
// live session of weeks at 1 kHz never overflows them.
constexpr int kTangentReuseTicks = 50;

// The tick's system of n = kN unknowns by the fixed-size LU. Out of line: inlined into the
// tick, the 9 x 9 factorisation pushed Eigen's small helpers elsewhere in it out of line, and
// ticks of other sizes paid for it.
template <int kN>
[[gnu::noinline]] void SolveFixed(Eigen::PartialPivLU<Eigen::Matrix<double, kN, kN>>& lu,
                                  const Eigen::Matrix<double, kN, kN>& M,
                                  const Eigen::Matrix<double, kN, 1>& rhs, SystemVector& z) {
  lu.compute(M);
  z = lu.solve(rhs);
}

// W = R W R^T: a compliance block turned from the held frame into the world, with Eigen's own
// arithmetic for `W = R * W * R.transpose()` written out. Eigen evaluates the inner product R W
// first, rows 0 and 1 by packets, (a0 + a1) + a2, row 2 by its scalar path, a0 + (a1 + a2),
// then the outer product entry by entry, b0 + (b1 + b2). The same products and sums in the same
// order (nothing is contracted to FMA without -march; rows 0 and 1 here in packets too), so the
// same bits, the zeros' signs too: a million random blocks, some entries exact zeros, came out
// bit for bit Eigen's at -O2 and -O3. Eigen's went through its generic product into a temporary
// and the aliased result through another and a copy back (~390 instructions a three-PC tick).
void TurnBlock(const Eigen::Matrix3d& R, Eigen::Matrix3d& W) {
  Eigen::Matrix3d RW;
  for (int k = 0; k < 3; ++k) {
    RW.col(k).head<2>() = (R.col(0).head<2>() * W(0, k) + R.col(1).head<2>() * W(1, k)) +
                          R.col(2).head<2>() * W(2, k);
    RW(2, k) = R(2, 0) * W(0, k) + (R(2, 1) * W(1, k) + R(2, 2) * W(2, k));
  }
  for (int j = 0; j < 3; ++j) {
    W.col(j).head<2>() = RW.col(0).head<2>() * R(j, 0) +
                         (RW.col(1).head<2>() * R(j, 1) + RW.col(2).head<2>() * R(j, 2));
    W(2, j) = RW(2, 0) * R(j, 0) + (RW(2, 1) * R(j, 1) + RW(2, 2) * R(j, 2));
  }
}

// Whether every entry of a block is zero (of either sign): the bits of each but its sign clear.
// The same test as (B.array() == 0.0).all(), a NaN failing it too: its first entry compared (a
// block that is not zero mostly fails there), then one OR of the other eight entries' bits
// instead of a compare and branch each (~240 instructions a three-PC tick, nine pairs of blocks
// in the structured solve's test, most of them zero).
bool IsZeroBlock(const Eigen::Matrix3d& B) {
  if (!(B(0, 0) == 0.0)) return false;
  std::uint64_t bits = 0;
  for (int k = 1; k < 9; ++k) bits |= std::bit_cast<std::uint64_t>(B.data()[k]);
  return (bits << 1) == 0;
}

// f_k(N) = a + b N, tangent to mu_k N0 (N/N0)^beta at N (exact for beta = 1). At N = 0 with
// beta < 1 the slope is infinite: the chord to N = 1e-9 N0 stands in for it. A load point of a
// PC of several holds the share f_k(N_pc) N / N_pc (FrictionShare): its slope in its own N, the
// PC's other points held, is (f_k / N) (1 + (beta - 1) N / N_pc).
void LineariseKinetic(const scene::Friction& friction, double normal_N, double pc_normal_N,
                      double& a, double& b) {
  const double N = std::max(normal_N, 1e-9 * friction.reference_load_N);
  const double fk = FrictionShare(friction, friction.kinetic_coefficient, N, pc_normal_N);
  b = pc_normal_N > N ? fk / N * (1.0 + (friction.exponent - 1.0) * (N / pc_normal_N))
                      : friction.exponent * fk / N;
  a = fk - b * N;
}

bool IsBoundaryOf(states::TubeElement a, states::TubeElement b) {
  // The rim bounds both the end face and the side surface.
  return a == states::TubeElement::kEndRim &&
         (b == states::TubeElement::kEndFace || b == states::TubeElement::kSide);
}

}  // namespace

int ChainCapsuleCount(const scene::Scene& scene) {
  if (scene.model.capsules > 0)
    return std::clamp(scene.model.capsules, kMinCapsules, kMaxCapsules);  // the loader checks it
  const model::TubeSection section = model::ComputeSection(scene.tube);
  const double l = scene.tube.length_m;
  const double kappa = scene.device.max_force_N * l / section.bending_stiffness_Nm2;
  const double tolerance_m = 0.1 * scene.contact.threshold_m;
  // kappa (l/N)^2 / 8 <= tolerance  <=>  N >= l sqrt(kappa / (8 tolerance)).
  const double n = std::ceil(l * std::sqrt(kappa / (8.0 * tolerance_m)));
  return static_cast<int>(
      std::clamp(n, static_cast<double>(kMinCapsules), static_cast<double>(kMaxCapsules)));
}

// Everything a tick reads that an earlier tick wrote, and the tick's scratch: a Snapshot copies
// it whole. The scratch goes too (~40 of its ~70 kB): simpler and safer than proving each scratch
// array is written before it is read, and a snapshot is a driver's occasional act, not a tick's.
struct Core::State {
  // One load point of a PC in a tick.
  struct Load {
    int pc = 0;   // index into the tick's PCs
    int end = 0;  // 0, or 1 for the far end of an extended contact
    states::TubeElement tube = states::TubeElement::kSide;
    int part_element = -1;
    double s_m = 0.0;
    double distance_m = 0.0;  // d where x0 is
    Eigen::Vector3d normal_W = Eigen::Vector3d::UnitZ();
    Eigen::Vector3d x0_W = Eigen::Vector3d::Zero();          // surface point at the tick's start
    Eigen::Vector3d base_W = Eigen::Vector3d::Zero();        // x = base + p + R W R^T F
    Eigen::Vector3d stick_base_W = Eigen::Vector3d::Zero();  // the same for the stuck spring
    Eigen::Vector3d stick_x_W = Eigen::Vector3d::Zero();     // result: where the spring saw x
    // The centreline at s and its tangent at the tick's start (W), and whether the stuck spring
    // saw the turn of the point's offset this tick (section 5): the material's motion is judged
    // from them when the next tick continues this load.
    Eigen::Vector3d centre0_W = Eigen::Vector3d::Zero();
    Eigen::Vector3d tangent0_W = Eigen::Vector3d::UnitZ();
    bool turn_seen = true;
    Eigen::Vector3d anchor_W = Eigen::Vector3d::Zero();   // stuck: held here tangentially
    Eigen::Vector3d anchor0_W = Eigen::Vector3d::Zero();  // the anchor before the tick's solve
    Eigen::Vector3d f_lin_W = Eigen::Vector3d::Zero();    // what last tick's shape was drawn under
    // The force the shape step (8) drew the tube under: force_W, or the force that pinned the
    // rod's shape to the points the contacts held. The next tick linearises about that shape, so
    // about this force (f_lin_W of the load that continues this one).
    Eigen::Vector3d shape_force_W = Eigen::Vector3d::Zero();
    // Sliding: friction a + b N along slide_dir (f_k(N) linearised at the last normal force;
    // exact for beta = 1, where a = 0 and b = mu_k).
    Eigen::Vector3d slide_dir_W = Eigen::Vector3d::Zero();
    double slide_a = 0.0, slide_b = 0.0;
    Eigen::Vector3d force_W = Eigen::Vector3d::Zero();  // result
    Eigen::Vector3d x_W = Eigen::Vector3d::Zero();      // result
    const scene::Friction* friction = nullptr;          // null: frictionless here
    Eigen::Vector3d r_H_m = Eigen::Vector3d::Zero();    // surface point - centre, frame H
    bool active = true, released = false, sliding = false, shifted = false;
    bool matched = false, ghost = false;
    // The linear model's reference (step 5): where last tick's shape carried f_lin, i.e. the
    // arc position, offset and clamp of the load this one continues, and this load's clamp in
    // the shape step 8 draws.
    bool continues = false;
    double lin_s_m = 0.0, lin_clamp_m = 0.0, clamp_m = 0.0;
    Eigen::Vector3d lin_r_H_m = Eigen::Vector3d::Zero();
    // An end face's load point (its dome's lowest point; its centre of pressure before stop 36):
    // its offset from the face's centre (frame H), relaxed from tick to tick (below).
    bool pressure_centre = false;
    Eigen::Vector3d cop_H_m = Eigen::Vector3d::Zero();
    // Its dome's resistance to tilting is in the tick's system (the linear model; step 5).
    bool dome_spring = false;
    // Whether the collision found the tube's surface inside the part here.
    bool overlap = false;
    bool SameKey(const Load& o) const {
      return tube == o.tube && part_element == o.part_element && end == o.end;
    }
  };

  // State carried between ticks.
  std::array<Eigen::Vector3d, kMaxCapsules + 1> nodes_H{};  // centreline at s_k = k l / N
  Eigen::Vector3d tip_tangent_H = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d p_hand_prev_W = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_held_prev_W = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_held_prev_W = Eigen::Matrix3d::Identity();
  // Last tick's loads, load_sets[prev_set][0, prev_count), and the scratch for this tick's, the
  // other set: a tick ends by turning them over, not by copying its loads (~100 instructions a
  // load, six a tick with three PCs in the groove).
  std::array<std::array<Load, kMaxLoads>, 2> load_sets{};
  int prev_set = 0;
  int prev_count = 0;
  // The loads of the last tick as the beam saw them (the shape, and Centreline on request).
  std::array<BeamLoad, kMaxLoads> beam_loads{};
  std::array<int, kMaxLoads> order{};
  std::array<ElasticaSegment, kMaxLoads> segments{};
  int beam_count = 0, segment_count = 0;
  bool elastica_shape = false;
  // The elastica held off: its shape under a tick's solved loads put a load point far from where
  // the tick's system put it (a loading past a buckling load, whose first mode is not the state
  // the contacts hold). The linear model carries the tube until the loads fall below half of
  // those it failed at, or leave.
  bool elastica_held_off = false;
  // The rod chain where the elastica does not cover the loading (or is held off): its segments
  // (each root moment is the next solve's starting point) and whether it shaped the last tick.
  std::array<RodSegment, kMaxLoads> rod_segments{};
  int rod_segment_count = 0;
  bool rod_shape = false;
  // The rod's tangent compliance between the members (by their place in arc order), the loads
  // and segments it was computed for, and its age in ticks: reused as the elastica's is.
  std::array<Eigen::Matrix3d, kMaxLoads * kMaxLoads> rod_tangent{};
  std::array<Eigen::Vector3d, kMaxLoads> rod_tangent_force{};
  std::array<double, kMaxLoads> rod_tangent_s{};
  std::array<int, kMaxLoads> rod_tangent_segment{};
  int rod_tangent_members = 0, rod_tangent_age = 0;
  // With that tangent, where its last load is at the tube's end: what a moment on the end
  // section does (the dome's spring, build_compliance), frame H, for the members of the end's
  // segment by their place in arc order: the end's turn per force of each, each one's
  // displacement per moment, and the end's turn per moment.
  struct RodEndResponse {
    bool valid = false;
    int segment = 0;  // the end's segment
    Eigen::Matrix3d turn_per_moment = Eigen::Matrix3d::Zero();
    std::array<Eigen::Matrix3d, kMaxLoads> turn_per_force{}, moved_per_moment{};
  } rod_end;
  double held_off_load_N = 0.0;
  std::array<Eigen::Vector3d, kMaxLoads> predicted_H{};  // where the solve put each load's centre
  // The shape already went through a part (Collision::AxisThrough; a scene or a reset that
  // starts there): there is no state out of the part to hold the tube in, so none is held.
  bool axis_inside = false;
  // The flags of the shape last sent (linear fallback, beyond the linear range, rod, shape off
  // its contacts): a tick held back sends that shape again, with them.
  std::uint32_t shape_flags = 0;
  // The elastica's tangent compliance per segment and the loads it was computed for, its age in
  // ticks; the last two computed (`tangents[tangent_current]` the one used last). Two, because
  // a tip in stick-slip at the tick rate alternates between two loadings (the stuck and the
  // sliding force, 59 and 5 mN in `tubeplan bench`'s core.end_sliding): with one kept, each
  // tick's tangent missed the other's loading and was computed again, on 60 % of the ticks.
  struct ElasticaTangent {
    std::array<Eigen::Matrix3d, kMaxLoads> J{};
    std::array<Eigen::Vector3d, kMaxLoads> force{};
    std::array<double, kMaxLoads> length{};
    int count = 0, age = 0;
  };
  std::array<ElasticaTangent, 2> tangents{};
  int tangent_current = 0;

  // Per-tick scratch (kept here so that Step allocates nothing).
  // Query's entries, then the pieces of strips among them that a PC takes
  // (RawContact::strip_pieces): three a PC at most.
  std::array<RawContact, kMaxRawContacts + 3 * kMaxContacts> raw{};
  std::array<Eigen::Vector3d, kMaxCapsules + 1> nodes_W{};
  std::array<std::array<Eigen::Matrix3d, kMaxLoads>, kMaxLoads> W{};  // world frame
  // The part of W_ij that is the turn of load i's section moving its offset surface point,
  // where the beam does not carry the offsets' moments (the elastica), for loads with friction:
  // the stuck spring does not see it (section 5).
  std::array<std::array<Eigen::Matrix3d, kMaxLoads>, kMaxLoads> W_turn{};  // world frame
  // The rod's tangent at the shape's loads (frame H), where the shape is pinned (section 8).
  std::array<std::array<Eigen::Matrix3d, kMaxLoads>, kMaxLoads> W_pin{};
  // The dead-load shape, kept while a pin is tried and put back if the pin is refused.
  std::array<RodSegment, kMaxLoads> rod_segments_dead{}, rod_segments_step{};
  std::array<Eigen::Vector3d, kMaxCapsules + 1> nodes_dead_H{};
  SystemMatrix M;
  SystemVector rhs, z;
  Eigen::PartialPivLU<SystemMatrix> lu;
  Eigen::PartialPivLU<Eigen::Matrix3d> lu3;
  Eigen::PartialPivLU<Eigen::Matrix<double, 6, 6>> lu6;
  Eigen::PartialPivLU<Eigen::Matrix<double, 9, 9>> lu9;
};

// The set-up that ticks only read (Collision's GJK solver carries nothing between queries: its
// cached guess is off; the distances Collision keeps from earlier queries save evaluations and
// never change a result; the dome's radius each tick sets comes from the state's last loads, so
// a restored state sets it again), over the state.
struct Core::Impl : Core::State {
  Impl(const scene::Scene& scene, std::span<const std::uint32_t> parts, int capsules,
       std::vector<std::array<int, 64>> element_of)
      : collision(scene, parts, capsules, std::move(element_of)),
        beam(scene),
        may_leave_out(scene.parts.size(), 0) {}

  Collision collision;
  BeamChain beam;
  // Idle parts (Step): whether to leave them out, the per-part permission handed to the query,
  // and what the last tick did. Counts, not state: a snapshot does not carry them.
  bool leave_out_idle = true;
  std::vector<std::uint8_t> may_leave_out;
  int idle_left_out = 0;
  long idle_retries = 0;
  // The beam's tangents and starting guesses as the tick found them, copied before a tick with
  // parts left out first changes them: a tick solved again starts from them, as it would have
  // (a tangent computed for the first try would otherwise stay in the cache in place of an
  // older one, and a later tick that fits the older one would compute a new one: the same
  // physics, other last bits). Most ticks change none of them (the tangents are reused). Each of
  // its three parts is copied only when the tick is about to change it: the choice of tangent
  // (an int; a tip in stick-slip flips it every other tick), the elastica's tangents and starting
  // guesses (~4 kB), the rod's (~17 kB). Copying all of it on every flip cost 1.7 k instructions a
  // tick sliding.
  struct BeamCache {
    std::array<ElasticaTangent, 2> tangents{};
    int tangent_current = 0;
    std::array<ElasticaSegment, kMaxLoads> segments{};
    std::array<RodSegment, kMaxLoads> rod_segments{};
    std::array<Eigen::Matrix3d, kMaxLoads * kMaxLoads> rod_tangent{};
    std::array<Eigen::Vector3d, kMaxLoads> rod_tangent_force{};
    std::array<double, kMaxLoads> rod_tangent_s{};
    std::array<int, kMaxLoads> rod_tangent_segment{};
    int rod_tangent_members = 0, rod_tangent_age = 0;
    RodEndResponse rod_end;
  } beam_cache;
  bool tangent_choice_saved = false, elastica_cache_saved = false, rod_cache_saved = false;
  // What a tick changes of the last tick's shape and output, copied before it first changes
  // them, once a Step: a tick whose shape would go through a part is not taken, and the tube
  // stays as this says (docs/core.md, "Through a part"). The loads, the segments and the rod's
  // are copied as far as they are used (a few hundred bytes; the rod's only when it shaped).
  struct ShapeSave {
    std::array<Eigen::Vector3d, kMaxCapsules + 1> nodes_H{};
    Eigen::Vector3d tip_tangent_H = Eigen::Vector3d::UnitZ();
    std::array<BeamLoad, kMaxLoads> beam_loads{};
    std::array<int, kMaxLoads> order{};
    std::array<Eigen::Vector3d, kMaxLoads> predicted_H{};
    std::array<ElasticaSegment, kMaxLoads> segments{};
    std::array<RodSegment, kMaxLoads> rod_segments{};
    int beam_count = 0, segment_count = 0, rod_segment_count = 0;
    bool elastica_shape = false, elastica_held_off = false, rod_shape = false;
    double held_off_load_N = 0.0;
    // The output's shape figures and PCs (its pose and wrench are not written before step 9).
    std::array<ContactState, kMaxContacts> contacts{};
    int contact_count = 0;
    double energy_J = 0.0, max_strain = 0.0, tip_deflection_m = 0.0, segmentation_error_m = 0.0;
  } shape_save;
  bool shape_saved = false;
  bool hold_out_of_parts = true;
  void SaveShape(std::size_t node_count, const StepOutput& out) {
    if (shape_saved) return;
    shape_saved = true;
    // The nodes as their doubles, which std::copy_n moves in one memmove: Eigen's vectors are
    // not trivially copyable, so copied as vectors they went one by one (49 nodes: ~0.22 k
    // instructions a three-PC tick, every tick, for a save a tick rarely restores). The same
    // bytes either way.
    static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double));
    std::copy_n(nodes_H.data()->data(), 3 * node_count, shape_save.nodes_H.data()->data());
    CopyShape(shape_save, static_cast<const State&>(*this), 0);
    CopyShapeFigures(shape_save, out);
  }
  void RestoreShape(std::size_t node_count, StepOutput& out) {
    CopyShape(static_cast<State&>(*this), shape_save, node_count);
    CopyShapeFigures(out, shape_save);
  }
  // The one list of what a tick's shape is, either way (the arrays as far as they are used).
  template <typename To, typename From>
  static void CopyShape(To& to, const From& from, std::size_t node_count) {
    std::copy_n(from.nodes_H.begin(), node_count, to.nodes_H.begin());
    to.tip_tangent_H = from.tip_tangent_H;
    const std::size_t load_n = std::size_t(from.beam_count);
    std::copy_n(from.beam_loads.begin(), load_n, to.beam_loads.begin());
    std::copy_n(from.order.begin(), load_n, to.order.begin());
    std::copy_n(from.predicted_H.begin(), load_n, to.predicted_H.begin());
    if (from.elastica_shape)
      std::copy_n(from.segments.begin(), std::size_t(from.segment_count), to.segments.begin());
    if (from.rod_shape)
      std::copy_n(from.rod_segments.begin(), std::size_t(from.rod_segment_count),
                  to.rod_segments.begin());
    to.beam_count = from.beam_count;
    to.segment_count = from.segment_count;
    to.rod_segment_count = from.rod_segment_count;
    to.elastica_shape = from.elastica_shape;
    to.elastica_held_off = from.elastica_held_off;
    to.rod_shape = from.rod_shape;
    to.held_off_load_N = from.held_off_load_N;
  }
  template <typename To, typename From>
  static void CopyShapeFigures(To& to, const From& from) {
    std::copy_n(from.contacts.begin(), std::size_t(from.contact_count), to.contacts.begin());
    to.contact_count = from.contact_count;
    to.energy_J = from.energy_J;
    to.max_strain = from.max_strain;
    to.tip_deflection_m = from.tip_deflection_m;
    to.segmentation_error_m = from.segmentation_error_m;
  }
  void SaveTangentChoice() {
    if (tangent_choice_saved) return;
    tangent_choice_saved = true;
    beam_cache.tangent_current = tangent_current;
  }
  void SaveElasticaCache() {
    if (elastica_cache_saved) return;
    elastica_cache_saved = true;
    CopyElasticaCache(beam_cache, static_cast<const State&>(*this));
  }
  void SaveRodCache() {
    if (rod_cache_saved) return;
    rod_cache_saved = true;
    CopyRodCache(beam_cache, static_cast<const State&>(*this));
  }
  // Puts back what was saved, and forgets it.
  void RestoreBeamCache() {
    if (tangent_choice_saved) tangent_current = beam_cache.tangent_current;
    if (elastica_cache_saved) CopyElasticaCache(static_cast<State&>(*this), beam_cache);
    if (rod_cache_saved) CopyRodCache(static_cast<State&>(*this), beam_cache);
    tangent_choice_saved = elastica_cache_saved = rod_cache_saved = false;
  }
  // The one list of what each part of the beam's cache is, either way.
  template <typename To, typename From>
  static void CopyElasticaCache(To& to, const From& from) {
    to.tangents = from.tangents;
    to.segments = from.segments;
  }
  template <typename To, typename From>
  static void CopyRodCache(To& to, const From& from) {
    to.rod_segments = from.rod_segments;
    to.rod_tangent = from.rod_tangent;
    to.rod_tangent_force = from.rod_tangent_force;
    to.rod_tangent_s = from.rod_tangent_s;
    to.rod_tangent_segment = from.rod_tangent_segment;
    to.rod_tangent_members = from.rod_tangent_members;
    to.rod_tangent_age = from.rod_tangent_age;
    to.rod_end = from.rod_end;
  }
};

Core::Snapshot::Snapshot() = default;
Core::Snapshot::~Snapshot() = default;
Core::Snapshot::Snapshot(const Snapshot& other)
    : state_(other.state_ ? std::make_unique<State>(*other.state_) : nullptr),
      out_(other.out_),
      capsules_(other.capsules_),
      elements_(other.elements_) {}
Core::Snapshot& Core::Snapshot::operator=(const Snapshot& other) {
  if (this != &other) {
    if (!other.state_) {
      state_.reset();
    } else if (state_) {
      *state_ = *other.state_;
    } else {
      state_ = std::make_unique<State>(*other.state_);
    }
    out_ = other.out_;
    capsules_ = other.capsules_;
    elements_ = other.elements_;
  }
  return *this;
}

void Core::Save(Snapshot& snapshot) const {
  if (snapshot.state_) {
    *snapshot.state_ = static_cast<const State&>(*impl_);
  } else {
    snapshot.state_ = std::make_unique<State>(static_cast<const State&>(*impl_));
  }
  snapshot.out_ = out_;
  snapshot.capsules_ = capsule_count_;
  snapshot.elements_ = elements_.size();
}

bool Core::Restore(const Snapshot& snapshot) {
  // A core of another scene would read the state with other sizes: refused where it shows.
  if (!snapshot.state_ || snapshot.capsules_ != capsule_count_ ||
      snapshot.elements_ != elements_.size())
    return false;
  static_cast<State&>(*impl_) = *snapshot.state_;
  impl_->collision.ForgetDistances();
  out_ = snapshot.out_;
  return true;
}

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
  m.R_held_prev_W = X_WH.linear();
  m.prev_count = 0;
  m.beam_count = m.segment_count = 0;
  for (State::ElasticaTangent& t : m.tangents) t.count = t.age = 0;
  m.tangent_current = 0;
  m.elastica_shape = false;
  m.elastica_held_off = false;
  m.held_off_load_N = 0.0;
  // The elastica's and the rod's starting guesses (their last solutions) go too: a replay from
  // here must not depend on what came before.
  m.segments = {};
  m.rod_segments = {};
  m.rod_segment_count = 0;
  m.rod_shape = false;
  m.rod_tangent_members = 0;
  m.rod_end.valid = false;
  m.collision.ForgetDistances();
  m.shape_flags = 0;
  m.axis_inside = m.collision.AxisThrough(
      std::span<const Eigen::Vector3d>(m.nodes_H.data(), std::size_t(capsule_count_) + 1),
      X_WH.linear(), X_WH.translation(), 0.5 * scene_.tube.outer_radius_m);
  out_ = StepOutput{};
  out_.X_W_hand = X_WH;
  out_.X_WH = X_WH;
}

namespace {

// A PC found this tick: its elements and the raw contacts that bound its region.
struct PcFound {
  states::TubeElement tube = states::TubeElement::kSide;
  int part_element = -1;
  int deepest = -1, first = -1, last = -1;  // raw contacts: smallest d, smallest s, largest s
  // Where one of those is a strip's entry (RawContact::strip_pieces), its piece.
  int deepest_piece = 0, first_piece = 0, last_piece = 0;
  double deepest_m = 0.0;  // the deepest's distance (read for every contact)
};

}  // namespace

const StepOutput& Core::Step(double t_s, const Eigen::Isometry3d& X_W_hand) {
  Impl& m = *impl_;
  // Idle parts left out, unless a pass of the solve may have moved the tube into reach of one:
  // then the tick again with every part (docs/core.md, "Idle parts").
  m.tangent_choice_saved = m.elastica_cache_saved = m.rod_cache_saved = false;
  m.shape_saved = false;
  if (!Tick(t_s, X_W_hand, m.leave_out_idle)) {
    ++m.idle_retries;
    m.RestoreBeamCache();
    Tick(t_s, X_W_hand, false);
  }
  return out_;
}

bool Core::Tick(double t_s, const Eigen::Isometry3d& X_W_hand, bool leave_out_idle) {
  Impl& m = *impl_;
  using Load = Impl::Load;
  const std::array<Load, kMaxLoads>& prev = m.load_sets[std::size_t(m.prev_set)];
  std::array<Load, kMaxLoads>& loads = m.load_sets[std::size_t(1 - m.prev_set)];
  const double T = scene_.model.time_step_s;
  const double K = scene_.contact.stiffness_N_per_m;
  const double eps = scene_.contact.threshold_m;
  const double Kt = K;  // tangential stiffness of a stuck contact: as stiff as the normal one
  const double l = scene_.tube.length_m;
  const int N = capsule_count_;

  // The end frame of the shape last tick sent, if the rod drew it, for the pin (step 8), which
  // starts from it: taken now, because the tick's compliance (step 5) may solve the rod's segments
  // again at other loads (the squeeze's four loads against the shape's three: 1.2 rad apart).
  const Eigen::Matrix3d rod_start_end_R = m.rod_shape && m.rod_segment_count > 0
                                              ? m.rod_segments[0].solution.end_R
                                              : Eigen::Matrix3d::Identity();

  StepOutput& out = out_;
  out.t_s = t_s;
  out.X_W_hand = X_W_hand;
  out.flags = 0;
  const Eigen::Matrix3d R_W_hand = X_W_hand.linear();
  const Eigen::Vector3d p_hand_W = X_W_hand.translation();
  if (!p_hand_W.allFinite() || !R_W_hand.allFinite()) {
    // A non-finite hand pose: hold everything where it was and send nothing.
    out.flags |= kSolverFault;
    out.force_W_N.setZero();
    out.torque_W_Nm.setZero();
    return true;
  }

  // 1. The tube where it is: last tick's held-end pose and shape.
  const Eigen::Vector3d p_start_W = m.p_held_prev_W;
  const Eigen::Matrix3d R_WH = m.R_held_prev_W;
  for (int k = 0; k <= N; ++k)
    m.nodes_W[std::size_t(k)] = p_start_W + R_WH * m.nodes_H[std::size_t(k)];
  const Eigen::Vector3d tip_tangent_W = R_WH * m.tip_tangent_H;

  // 2. Collision, in a band of 2 epsilon: a contact that closes during this tick is then in this
  // tick's system (its force comes out zero if it stays open), and one that opens fades out.
  // The band also grows by how far the tube can move rigidly this tick (speculative contacts, as
  // Box2D v3 does it): the proxy moves at most as far as it would with no contact (the coupling
  // pulling it towards the hand, its damper against the motion: the displacement of step 6's
  // system without loads), and the grip turns the tube by at most the hand's turn, which moves a
  // point at most (l + r1) times that angle. A part that the tube could reach during the tick is
  // then in the tick's system with its distance linearised along its normal, so a fast hand
  // (2 m/s: 2 mm a tick) cannot carry the tube through a wall thinner than its step; at hand
  // speeds the growth is micrometres and costs nothing.
  // The hand's turn from the held end, log(R_hand R_held^T): made once here, for its angle, and
  // read again as the grip's error in step 6 (R_hand and R_held do not change in between), which
  // had made it again from the same matrices: a quaternion from their product and an AngleAxis
  // from that, whose stableNorm a grip holding the hand's orientation takes (~300 instructions
  // a three-PC tick).
  const Eigen::AngleAxisd hand_turn(R_W_hand * R_WH.transpose());
  const double turn_bound_rad = hand_turn.angle();
  const double sweep_m = (coupling_stiffness_ * (p_hand_W - m.p_held_prev_W) +
                          (coupling_damping_ / T) * (p_hand_W - m.p_hand_prev_W))
                                 .norm() /
                             (coupling_stiffness_ + coupling_damping_ / T) +
                         turn_bound_rad * (l + scene_.tube.outer_radius_m);
  //
  // A part that carried no load last tick and whose pieces in the band are all, by distances
  // kept from earlier ticks, farther than epsilon plus the sweep is left out (the groove's walls
  // beside a tube centred in it: half the tick, docs/core.md). Its loads would be open loads,
  // which change nothing unless a pass of the solve closes one; each pass checks below that its
  // motion could not have.
  IdleParts idle;
  if (leave_out_idle) {
    std::fill(m.may_leave_out.begin(), m.may_leave_out.end(), std::uint8_t{1});
    for (int q = 0; q < m.prev_count; ++q) {
      // A load that carried force is in this tick's system; an end face's relaxed load point is
      // carried to the next tick even while open.
      const Load& before = prev[std::size_t(q)];
      if (before.part_element >= 0 &&
          (before.active || before.pressure_centre || !before.force_W.isZero(0.0)))
        m.may_leave_out[elements_[std::size_t(before.part_element)].part_index] = 0;
    }
    idle.may_leave_out = m.may_leave_out;
    idle.floor_m = eps + sweep_m;
  }
  // The end face's dome (collision.cpp) for this tick. Within the band a face is the paper's
  // point law, and its dome has the tolerance's height. Pressed through the part's surface, by
  // p = N / K - eps at the force its end pressed with last tick, the face is a bed of springs
  // over the depth p + tilt x across it, whose centre of pressure moves I / (A p) =
  // (r1^2 + r2^2) / (4 p) per radian of tilt: the dome with that radius has its lowest point
  // there (the force on it stays the paper's K (eps - d), so the face resists its tilt by
  // N R = K I / A (1 + eps / p), the bed's stiffness where eps << p). The
  // tolerance's dome (32 m at eps = 1e-5 m) reached the rim at a tilt of 2.5e-4 rad, which a
  // stuck tip passes in one tick of a slide: the load point jumped 8 mm to the rim and the tube
  // took 4.6 mJ of bending in that tick (`stability --only "slide along a wall eps=1e-05m"`,
  // the face pressed 0.38 mm in). Its radius at 0.38 mm is 59 mm. It is taken at last tick's
  // force, as the dome's spring is (step 5): the face is a convex body within the tick, and its
  // radius changes with the force from tick to tick, never beyond the tolerance's.
  {
    double pressed_N = 0.0;
    for (int q = 0; q < m.prev_count; ++q) {
      const Load& before = prev[std::size_t(q)];
      if (before.active && before.s_m >= l && before.tube != states::TubeElement::kSide &&
          before.part_element >= 0 &&
          IsFaceMask(elements_[std::size_t(before.part_element)].face_mask))
        pressed_N = std::max(pressed_N, before.shape_force_W.dot(before.normal_W));
    }
    const double r1 = scene_.tube.outer_radius_m, r2 = scene_.tube.inner_radius_m;
    const double through_m = pressed_N / K - eps;
    m.collision.set_dome_radius_m(through_m > 0.0 ? (r1 * r1 + r2 * r2) / (4.0 * through_m)
                                                  : m.collision.tolerance_dome_radius_m());
  }
  const int raw_count =
      m.collision.Query(std::span<const Eigen::Vector3d>(m.nodes_W.data(), std::size_t(N) + 1),
                        tip_tangent_W, 2.0 * eps + sweep_m,
                        std::span<RawContact>(m.raw.data(), std::size_t(kMaxRawContacts)), &idle);
  m.idle_left_out = idle.left_out;

  // 3. PCs: a raw contact whose elements are boundaries of another's (same part) joins that
  // one's PC (an edge of the face a side lies on, the rim of an end face lying flat).
  // Only an edge, a vertex or the rim bounds another element: a face touched by the end face or
  // the side joins nothing (most pairs of a tube lying in a groove; this loop is quadratic in
  // them). That is tested before the scan and again after each join, the only change to it.
  const auto joins_nothing = [](const RawContact& r) {
    return IsFaceMask(r.face_mask) && r.tube != states::TubeElement::kEndRim;
  };
  // Query gives each part's contacts in one run (its parts are distinct, each queried once), so
  // a contact's partners are in its run: the scan covers that run, not every contact (the tube
  // lying in the groove: a hundred contacts over three parts, and edges among them).
  // The run's bounds are found only for a contact that may join (a tube lying in the groove has
  // none): back from it to the run's first, on to its last.
  int run_begin = 0, run_end = 0;
  for (int i = 0; i < raw_count; ++i) {
    RawContact& a = m.raw[std::size_t(i)];
    if (joins_nothing(a)) continue;
    if (i >= run_end) {
      run_begin = i;
      while (run_begin > 0 && m.raw[std::size_t(run_begin) - 1].part == a.part) --run_begin;
      run_end = i + 1;
      while (run_end < raw_count && m.raw[std::size_t(run_end)].part == a.part) ++run_end;
    }
    for (int j = run_begin; j < run_end; ++j) {
      const RawContact& b = m.raw[std::size_t(j)];
      if (i == j || a.part != b.part) continue;
      const bool part_bounds = (a.face_mask & b.face_mask) == b.face_mask;
      const bool tube_bounds = a.tube == b.tube || IsBoundaryOf(a.tube, b.tube);
      if (part_bounds && tube_bounds && (a.face_mask != b.face_mask || a.tube != b.tube)) {
        a.face_mask = b.face_mask;
        a.part_element = b.part_element;
        a.tube = b.tube;
        if (joins_nothing(a)) break;
        j = run_begin - 1;  // its new element may itself be bounded by another's: look again
      }
    }
  }
  std::array<PcFound, kMaxContacts> found{};
  // Each raw contact's PC, -1 past kMaxContacts: written for each before it is read (not
  // cleared: 4 kB a tick).
  std::array<int, kMaxRawContacts> pc_of;
  int found_count = 0;
  bool truncated = false;
  // The PC of the run of contacts at hand, and its deepest so far, kept here while the run
  // lasts and written back when it ends: read and written through `found` for every contact,
  // they made a chain of store-to-load forwarding a contact long.
  // A strip's entry (RawContact::strip_pieces) stands for its pieces: its distance is their
  // least, at strip_deepest, the first of equals, as the scan of each would have found.
  int run_k = -1, run_deepest = -1, run_deepest_piece = 0;  // run_k is pc_of[i - 1]
  double run_deepest_m = 0.0;
  const auto end_run = [&] {
    if (run_k < 0) return;
    found[std::size_t(run_k)].deepest = run_deepest;
    found[std::size_t(run_k)].deepest_piece = run_deepest_piece;
    found[std::size_t(run_k)].deepest_m = run_deepest_m;
  };
  for (int i = 0; i < raw_count; ++i) {
    const RawContact& r = m.raw[std::size_t(i)];
    // Query gives a part's pieces in a run, so most raw contacts have the elements of the one
    // before: its PC is theirs (a PC's elements are no other's, so the search finds that one).
    if (run_k >= 0 && m.raw[std::size_t(i) - 1].tube == r.tube &&
        m.raw[std::size_t(i) - 1].part_element == r.part_element) {
      pc_of[std::size_t(i)] = run_k;
      if (r.distance_m < run_deepest_m) {
        run_deepest = i;
        run_deepest_piece = r.strip_deepest;
        run_deepest_m = r.distance_m;
      }
      continue;
    }
    end_run();
    int k = 0;
    while (k < found_count && !(found[std::size_t(k)].tube == r.tube &&
                                found[std::size_t(k)].part_element == r.part_element))
      ++k;
    pc_of[std::size_t(i)] = k;
    run_k = k;
    if (k == found_count) {
      if (found_count == kMaxContacts) {
        truncated = true;
        pc_of[std::size_t(i)] = run_k = -1;
        continue;
      }
      PcFound& pc = found[std::size_t(found_count++)];
      pc = PcFound{r.tube, r.part_element};
      pc.deepest = pc.first = pc.last = i;
      pc.deepest_piece = r.strip_deepest;
      pc.deepest_m = r.distance_m;
    }
    run_deepest = found[std::size_t(k)].deepest;
    run_deepest_piece = found[std::size_t(k)].deepest_piece;
    run_deepest_m = found[std::size_t(k)].deepest_m;
    if (r.distance_m < run_deepest_m) {
      run_deepest = i;
      run_deepest_piece = r.strip_deepest;
      run_deepest_m = r.distance_m;
    }
  }
  end_run();
  // The region a PC spans: its pieces within the static band 2 epsilon, or within epsilon of
  // its deepest when that is itself only in the speculative sweep (at speed). The whole band
  // spanned a tube crossing an edge at 2 m/s (a band of 3.75 mm: the pieces either side, 3.2 mm
  // off, while the deepest was 1.25 mm off): its two load points went to those ends, too far off
  // to close in the tick, and the tube went through the edge with no force (`stability --only
  // "roll over an edge speed=2m/s"`, tick 2). It grows from the deepest piece: the piece that
  // opened the PC may lie outside it.
  // Per PC, the largest distance of a piece in its region: made once, not once a raw contact.
  std::array<double, kMaxContacts> region_m{};
  // A capsule over a face spans the stretch of its axis over it (RawContact::line): the region
  // runs from the lo end of its first piece to the hi end of its last. Its nearest point is one
  // of those ends, which by the sign of its tilt to the face: a stiff tube pinched in a groove
  // rocked between them from tick to tick, the region's end jumping 6.5 mm each time (the
  // squeeze with E = 2e8 Pa, frictionless and linear too, made energy from tick 34). Query gives
  // a part's pieces in order along the tube, and a PC is one part's: its first and last raw
  // contacts within the region are its first and last pieces, whose stretches alone are worked
  // out (a tube lying in the groove has a hundred pieces over the walls and the floor).
  for (int k = 0; k < found_count; ++k) {
    PcFound& pc = found[std::size_t(k)];
    pc.first = pc.last = -1;
    region_m[std::size_t(k)] = std::max(2.0 * eps, m.raw[std::size_t(pc.deepest)].distance_m + eps);
  }
  // (Which PCs have their first: a bit each, not pc.first read back for every contact.)
  static_assert(kMaxContacts <= 32);
  std::uint32_t has_first = 0;
  // A strip's pieces in the region: from the first to the last within it (all of them when its
  // farthest is; its least distance is the one tested first).
  for (int i = 0; i < raw_count; ++i) {
    const int k = pc_of[std::size_t(i)];
    const RawContact& r = m.raw[std::size_t(i)];
    if (k < 0 || r.distance_m > region_m[std::size_t(k)]) continue;
    int lo = r.piece, hi = r.piece + r.strip_pieces - 1;
    if (r.strip_pieces > 1 && !(r.strip_farthest_m <= region_m[std::size_t(k)])) {
      while (m.collision.StripPieceDistance(r, lo) > region_m[std::size_t(k)]) ++lo;
      while (m.collision.StripPieceDistance(r, hi) > region_m[std::size_t(k)]) --hi;
    }
    PcFound& pc = found[std::size_t(k)];
    if ((has_first & (1u << k)) == 0) {
      has_first |= 1u << k;
      pc.first = i;
      pc.first_piece = lo;
    }
    pc.last = i;
    pc.last_piece = hi;
  }
  // The pieces of strips a PC takes, each made whole after the entries (one contact made once
  // however many of deepest, first and last it is): from here on a PC's contacts are single.
  // (The piece figures are compared only where they matter: `single` returns a single entry
  // itself, whatever piece was noted for it.)
  int piece_slot = raw_count;
  for (int k = 0; k < found_count; ++k) {
    PcFound& pc = found[std::size_t(k)];
    const auto single = [&](int i, int piece) {
      if (m.raw[std::size_t(i)].strip_pieces == 1) return i;
      m.raw[std::size_t(piece_slot)] = m.collision.StripPiece(m.raw[std::size_t(i)], piece);
      return piece_slot++;
    };
    const bool first_deepest = pc.first == pc.deepest && pc.first_piece == pc.deepest_piece;
    const bool last_deepest = pc.last == pc.deepest && pc.last_piece == pc.deepest_piece;
    const bool last_first = pc.last == pc.first && pc.last_piece == pc.first_piece;
    const int deepest = single(pc.deepest, pc.deepest_piece);
    const int first = first_deepest ? deepest : single(pc.first, pc.first_piece);
    pc.last = last_deepest ? deepest : last_first ? first : single(pc.last, pc.last_piece);
    pc.deepest = deepest;
    pc.first = first;
  }
  const std::span<const Eigen::Vector3d> query_nodes_W(m.nodes_W.data(), std::size_t(N) + 1);
  for (int k = 0; k < found_count; ++k) {
    const PcFound& pc = found[std::size_t(k)];
    // Query leaves most contacts' points to be made for those that become loads (step 4).
    for (const int i : {pc.deepest, pc.first, pc.last})
      m.collision.Complete(m.raw[std::size_t(i)], query_nodes_W);
    m.collision.LineEnds(m.raw[std::size_t(pc.first)], query_nodes_W);
    if (pc.last != pc.first) m.collision.LineEnds(m.raw[std::size_t(pc.last)], query_nodes_W);
  }
  const auto lo_s = [](const RawContact& r) { return r.line ? r.s_lo_m : r.s_m; };
  const auto hi_s = [](const RawContact& r) { return r.line ? r.s_hi_m : r.s_m; };

  // 4. Load points: one per PC, or two at the ends of a region longer than a tube radius.
  // How far a shape may draw a load point from where the tick's system put it: the contact
  // band's width, at least a quarter radius (the elastica's hold-off, the shape_off flag, and
  // the stuck stretch's correction all use it).
  const double shape_tolerance_m = std::max(2.0 * eps, 0.25 * scene_.tube.outer_radius_m);
  const auto interpolate_node = [&](double s_m) {
    const double u = std::clamp(s_m / l * N, 0.0, static_cast<double>(N));
    const int k = std::min(static_cast<int>(u), N - 1);
    const double t = u - k;
    return Eigen::Vector3d((1.0 - t) * m.nodes_H[std::size_t(k)] +
                           t * m.nodes_H[std::size_t(k) + 1]);
  };
  // Whether this tick's shape puts every load point where the tick's system put it.
  const auto shape_follows_loads = [&](int count) {
    for (int j = 0; j < count; ++j) {
      const double s_j = m.beam_loads[std::size_t(j)].s_m;
      if (!((interpolate_node(s_j) - m.predicted_H[std::size_t(j)]).norm() <= shape_tolerance_m))
        return false;
    }
    return true;
  };
  int load_count = 0;
  // `at`: 0 the nearest point, -1 and 1 the lo and hi end of a capsule over a face.
  const auto add_load = [&](int pc, int end, const RawContact& r, int at) {
    if (load_count == kMaxLoads) {
      truncated = true;
      return;
    }
    Load& ld = loads[std::size_t(load_count++)];
    ld = Load{};
    ld.pc = pc;
    ld.end = end;
    ld.tube = r.tube;
    ld.part_element = r.part_element;
    const bool lo = r.line && at < 0, hi = r.line && at > 0;
    const double s_m = lo ? r.s_lo_m : hi ? r.s_hi_m : r.s_m;
    ld.s_m = r.tube == states::TubeElement::kSide ? std::clamp(s_m, 0.0, l) : l;
    ld.distance_m = lo ? r.d_lo_m : hi ? r.d_hi_m : r.distance_m;
    ld.normal_W = r.normal_W;
    // An end face pressed on a face presses at its dome's lowest point (collision.cpp: the face's
    // centre when it lies flat, moving towards the rim as it tilts), wherever GJK put its
    // nearest point.
    ld.x0_W = lo   ? LineSurfacePoint(r, r.t_lo, m.nodes_W, scene_.tube.outer_radius_m)
              : hi ? LineSurfacePoint(r, r.t_hi, m.nodes_W, scene_.tube.outer_radius_m)
                   : r.p_W_m;
    ld.pressure_centre = r.pressure_centre;
    ld.overlap = r.overlap;
    const scene::Friction& friction =
        scene::FrictionAt(scene_, elements_[std::size_t(r.part_element)].part_index);
    ld.friction = friction.IsFrictionless() ? nullptr : &friction;
    ld.anchor_W = ld.x0_W;
    // In the band but not within epsilon: in the system only if this tick's motion closes it.
    ld.active = ld.distance_m < eps;
    if (r.overlap) out.flags |= kPenetration;
  };
  for (int k = 0; k < found_count; ++k) {
    const PcFound& pc = found[std::size_t(k)];
    const RawContact& first = m.raw[std::size_t(pc.first)];
    const RawContact& last = m.raw[std::size_t(pc.last)];
    if (hi_s(last) - lo_s(first) > m.beam.group_tolerance_m()) {
      add_load(k, 0, first, -1);
      add_load(k, 1, last, 1);
    } else {
      add_load(k, 0, m.raw[std::size_t(pc.deepest)], 0);
    }
  }
  // Each load continues last tick's load of the same element pair and end; failing that, the
  // nearest one (within a tube radius) on the same part element, whatever the tube element:
  // a rim contact that becomes a side contact as the tube lays down keeps its force and its
  // stick.
  //
  // A stuck contact's state is its tangential stretch: the slip of the tube's material at the
  // contact relative to the part, accumulated while stuck (the spring Kt carries Kt times it).
  // Between ticks the load point is found again, the tube's point nearest the part, which need
  // not be the same material point: a tube bending or rolling over an edge touches it with
  // another point each tick, a tube drawn along its axis over an edge touches it at the same place
  // in the world with new material. A world anchor compared with the point found again took that
  // migration for slip: on the side pressed on an edge (`stability --only "roll over an edge
  // base"`) 19 um a tick, 0.19 N of friction from no slip, energy the hand never put in. So the
  // stretch is carried with the contact instead (the tangential spring of the discrete element
  // method, Cundall and Strack 1979): last tick's final stretch, turned with the contact's normal
  // into the new tangent plane, plus what the material under last tick's point moved that the
  // tick's system did not see (its motion in the shape drawn from the solved loads, less the
  // motion the system predicted and the spring already counted; e.g. the bending by an end
  // face's moment as its load point moves). Within the tick the point moves with the
  // material (x = x0 + the tick's motion), so the stretch grows by the material's tangential
  // motion there and by nothing else.
  const auto tangent_at = [&](double s_m) {
    if (s_m >= l) return Eigen::Vector3d(R_WH * m.tip_tangent_H);
    const double u = std::clamp(s_m / l * N, 0.0, static_cast<double>(N));
    const std::size_t k = std::size_t(std::min(static_cast<int>(u), N - 1));
    return Eigen::Vector3d(R_WH * (m.nodes_H[k + 1] - m.nodes_H[k]).normalized());
  };
  // The rotation taking unit a to unit b about a x b, applied to v.
  const auto rotate_onto = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                              const Eigen::Vector3d& v) {
    const double c = a.dot(b);
    if (!(c > -0.5)) return v;  // turned over: not a tick's motion (nothing carried)
    const Eigen::Vector3d k = a.cross(b);
    return Eigen::Vector3d(v + k.cross(v) + k.cross(k.cross(v)) / (1.0 + c));
  };
  const auto carried_stretch = [&](const Load& before, const Load& now) {
    const Eigen::Vector3d& n0 = before.normal_W;
    const Eigen::Vector3d& n1 = now.normal_W;
    const Eigen::Vector3d offset = before.anchor_W - before.stick_x_W;
    // Turning keeps the stretch's length, the spring's energy.
    const Eigen::Vector3d stretch = rotate_onto(n0, n1, offset - n0 * n0.dot(offset));
    // Where the material of last tick's point went: its centre, and its offset turned with the
    // section where the spring saw that turn.
    const Eigen::Vector3d centre_W = p_start_W + R_WH * interpolate_node(before.s_m);
    Eigen::Vector3d moved = centre_W - before.centre0_W;
    if (before.turn_seen) {
      const Eigen::Vector3d r_W = before.x0_W - before.centre0_W;
      moved += rotate_onto(before.tangent0_W, tangent_at(before.s_m), r_W) - r_W;
    }
    const Eigen::Vector3d unseen = moved - (before.stick_x_W - before.x0_W);
    // A tick whose system put the point farther from the shape than the contact band (the
    // elastica's hold-off tolerance, section 8; an undecided tick's last guards) predicted
    // nothing to correct: the difference is slip, not stretch.
    if (!(unseen.norm() <= shape_tolerance_m)) return stretch;
    return Eigen::Vector3d(stretch - (unseen - n1 * n1.dot(unseen)));
  };
  // The face tilted past where its load point (its centre of pressure before stop 36, its dome's
  // lowest point since) reaches the rim: the collision calls the contact the rim (or, the rim
  // joined to the side beside it in the band, the side), but last tick's relaxed point lagged
  // behind it, and the load point jumped to the rim, turning the end by the moment's jump in one
  // tick (the rubber tube slid along a wall, ticks 604-605: the point jumped 1.1 mm at 3.9 N,
  // matched as the side the lateral force fell from 0.105 to 0.036 N, and the next tick's shape was
  // 14 mm off its contact). Such a rim, on a face, continues the active relaxed point before any
  // other load, and the point goes on relaxing towards the rim (below) until the last step to it
  // changes the load's force by at most 1 %: within min(eps/10, 0.01 N / K) of it (within eps/10,
  // a K = 1e7 N/m slide's continuation ended with its distance stepping by 0.093 mm, 930 N of
  // penalty; the contact opened and the tube sprang into the wall, held back for the last 97
  // ticks). A rim overlapping the face continues it too since stop 43: a face pressed through has
  // the bed of springs' dome, whose rim overlaps wherever it is reached (before, an overlapping
  // face had no dome, and an overlapping rim ended the continuation; the sweep passes the same
  // cases either way, three outside the model's validity with other figures).
  // Not a face lying flat, loaded at its centre: with a stiff penalty (K = 1e7 N/m) its load then
  // sat near the centre for hundreds of ticks, the relaxation's step being 1 / (1 + g) with g in
  // the thousands, while the end pivoted freely and its rim sank into the wall; a fixed step of a
  // fifth of the way jumped 1.6 mm in the first tick and snapped the tube as before.
  const double rim_close_m = 0.1 * eps;
  // What the load itself must be to continue a face's centre (a rim or side at the end, on a
  // face) or a rim (an end face's pressure centre): pass 0 asks it once a load before scanning
  // last tick's loads for it.
  const auto may_continue_centre = [&](const Load& ld) {
    return ld.tube != states::TubeElement::kEndFace && !(ld.s_m < l) &&
           IsFaceMask(elements_[std::size_t(ld.part_element)].face_mask);
  };
  const auto may_continue_rim = [](const Load& ld) {
    return ld.pressure_centre && ld.tube == states::TubeElement::kEndFace;
  };
  const auto continues_centre = [&](const Load& ld, const Load& before) {
    if (!before.active || !before.pressure_centre || !may_continue_centre(ld)) return false;
    const Eigen::Vector3d rim_H = R_WH.transpose() * (ld.x0_W - m.nodes_W[std::size_t(N)]);
    const double N_before = before.shape_force_W.dot(before.normal_W);
    const double close_m =
        N_before > 0.0 ? std::min(rim_close_m, 0.01 * N_before / K) : rim_close_m;
    return (rim_H - before.cop_H_m).norm() > close_m;
  };
  // And back: the face tilting back under the dome's range while the rim carried the load (a
  // slide reversed). The rim's load, matched by its key, went to the last capsule's side in the
  // band, and the face's new point started from nothing at its target, unrelaxed: the tube
  // snapped (the base slide driven back, tick 1494, 2.3 mJ over the slack; found in review). The
  // face continues the rim's active load, its point relaxing from the rim's.
  const auto continues_rim = [&](const Load& ld, const Load& before) {
    return may_continue_rim(ld) && before.active && !before.pressure_centre && !before.ghost &&
           before.s_m >= l;
  };
  std::array<bool, kMaxLoads> taken{};
  // Loads that continue a face's point with the rim as its target (pass 0, above).
  std::array<bool, kMaxLoads> on_rim{};
  // Faces whose point starts from a rim's (pass 0, below; not from a face lying flat).
  std::array<bool, kMaxLoads> from_rim{};
  for (int pass = 0; pass < 3; ++pass) {
    for (int i = 0; i < load_count; ++i) {
      Load& ld = loads[std::size_t(i)];
      if (ld.matched) continue;
      // Pass 0: what the load itself rules out needs no scan of last tick's loads (most loads,
      // each against every one of them).
      if (pass == 0 && !may_continue_centre(ld) && !may_continue_rim(ld)) continue;
      int best = -1;
      double best_ds = m.beam.group_tolerance_m();
      for (int q = 0; q < m.prev_count; ++q) {
        const Load& before = prev[std::size_t(q)];
        if (taken[std::size_t(q)] || before.part_element != ld.part_element) continue;
        if (pass == 0 && !continues_centre(ld, before) && !continues_rim(ld, before)) continue;
        if (pass == 1 && !before.SameKey(ld)) continue;
        const double ds = std::abs(before.s_m - ld.s_m);
        if (pass < 2 || ds <= best_ds) best = q, best_ds = ds;
        if (pass < 2) break;
      }
      if (best < 0) continue;
      const Load& before = prev[std::size_t(best)];
      taken[std::size_t(best)] = true;
      ld.matched = true;
      ld.continues = true;
      ld.lin_s_m = before.s_m;
      ld.lin_r_H_m = before.r_H_m;
      ld.lin_clamp_m = before.clamp_m;
      if (before.active && ld.friction) ld.anchor_W = ld.x0_W + carried_stretch(before, ld);
      ld.f_lin_W = before.shape_force_W;
      // A load that pressed last tick starts in the system if it lies within eps and the capsule
      // chain's own tolerance, eps / 10 (ChainCapsuleCount). Only the system's release then lets
      // it go. The point is found again on the drawn shape, which lies within the shape tolerance
      // of where the system held it. Where the contact's depth N / K is smaller than that error, a
      // pressing contact reads just beyond eps. An open load closes only if the tick's prediction
      // brings it within eps. That prediction takes the load's whole force out along the beam's
      // tangent, far beyond where the tangent holds. At K = 1e7 N/m the rim's point read
      // 2.3 um beyond eps for 50 ticks, 3.1 N on it, and the old tangent closed it each tick.
      // At tick 974 the rod's tangent was renewed. Its prediction of the unloaded tube moved away
      // from the wall, so the load stayed open. The tube then sprang straight, 3.5 mm into the wall
      // (`stability --only "slide along a wall K=1e+07N/m"`).
      if (!ld.active && before.active && before.normal_W.dot(before.force_W) > 0.0 &&
          ld.distance_m < 1.1 * eps)
        ld.active = true;
      if (pass == 0 && !ld.pressure_centre) {
        // Keyed as the face it continues, so that the next tick's face finds it again and the
        // side beside it, in the band, does not.
        ld.pressure_centre = true;
        ld.tube = before.tube;
        on_rim[std::size_t(i)] = true;
      } else if (pass == 0) {
        ld.cop_H_m = before.r_H_m;  // a face continuing the rim: from the rim's point
        from_rim[std::size_t(i)] = before.tube != states::TubeElement::kEndFace;
      }
      if (ld.pressure_centre && before.pressure_centre) ld.cop_H_m = before.cop_H_m;
    }
  }
  // An end face's load point (the lowest point of its dome, collision.cpp) follows its tilt,
  // e = R sin(tilt), and the offset moment N e it carries tilts the end in turn: computed from
  // last tick's tilt that loop has the gain
  //     g = N R * l / (E I)
  // (the dome's rotational stiffness under the load N over the tube's at its end), and with
  // g > 1 it oscillates with a growing amplitude. Moving the load point only 1 / (1 + g) of the
  // way from last tick's offset to this tick's target is the Newton step of that linear loop:
  // it settles in one tick when g is right, and stays stable for any true gain up to 1 + 2 g.
  // N is the force the shape was drawn under (none for a new contact: it starts at its target).
  // The linear model and the rod instead put the dome's resistance in the tick's system (step 5,
  // "the dome's spring"): the point starts at its target, and moves with the end's turn within
  // the tick. Which model this tick's compliance comes from is decided there, after the loads
  // are set: the rod's is expected where it drew last tick's shape (where the elastica or the
  // linear fallback takes the tick after all, the point went to its target unrelaxed, once).
  // Not for a point continuing a rim's, or a rim continuing a face's: the dome's law does not
  // hold over that way, and the relaxation stays.
  const bool linear_beam = scene_.model.beam == model::BeamModel::kLinear;
  {
    const double tilt_compliance = m.collision.dome_radius_m() * l / m.beam.bending_stiffness_Nm2();
    const double half_by_radius = 0.5 / m.collision.dome_radius_m();
    const Eigen::Vector3d& tip_W = m.nodes_W[std::size_t(N)];
    const Eigen::Vector3d end_axis_W = tangent_at(l);
    for (int i = 0; i < load_count; ++i) {
      Load& ld = loads[std::size_t(i)];
      if (!ld.pressure_centre || ld.ghost) continue;
      ld.dome_spring =
          (linear_beam || m.rod_shape) && !on_rim[std::size_t(i)] && !from_rim[std::size_t(i)];
      const double relax =
          ld.dome_spring
              ? 1.0
              : 1.0 / (1.0 + std::max(0.0, ld.f_lin_W.dot(ld.normal_W)) * tilt_compliance);
      const Eigen::Vector3d target_H = R_WH.transpose() * (ld.x0_W - tip_W);
      const Eigen::Vector3d step_H = relax * (target_H - ld.cop_H_m);
      ld.cop_H_m += step_H;
      const Eigen::Vector3d x0_W = tip_W + R_WH * ld.cop_H_m;
      // The distance at the dome's point there: the face plane's change along the normal, and
      // the dome's fall from its apex, |x|^2 / (2 R) along the axis (cos(tilt) along the
      // normal), at the new point less at the old.
      // A rim continuing the face's point keeps the rim's own distance: the face plane's at the
      // lagging point lies farther by the lag times sin(tilt), to first order (0.13 mm, 1.3 N of
      // 3.7 N, in the base slide; found in review), where the dome's is within |lag|^2 / 2R.
      if (!on_rim[std::size_t(i)])
        ld.distance_m += ld.normal_W.dot(x0_W - ld.x0_W) +
                         std::abs(ld.normal_W.dot(end_axis_W)) *
                             (ld.cop_H_m.squaredNorm() - target_H.squaredNorm()) * half_by_radius;
      // The pressure moves over the face, the material does not slip: the stretch stays.
      ld.anchor_W += x0_W - ld.x0_W;
      ld.x0_W = x0_W;
    }
  }
  // A load of last tick that nothing continues but that carried force is still in the shape:
  // it stays in this tick as a ghost, open, so that its force is taken out of the shape.
  for (int q = 0; q < m.prev_count; ++q) {
    const Load& before = prev[std::size_t(q)];
    if (taken[std::size_t(q)] || before.force_W.isZero(0.0)) continue;
    if (load_count == kMaxLoads) {
      truncated = true;
      break;
    }
    Load& ghost = loads[std::size_t(load_count++)];
    ghost = before;
    ghost.pc = -1;
    ghost.f_lin_W = before.shape_force_W;
    ghost.active = false;
    ghost.released = true;
    ghost.sliding = ghost.shifted = false;
    ghost.ghost = true;
    ghost.continues = true;  // its force is taken out where last tick's shape had it
    ghost.lin_s_m = before.s_m;
    ghost.lin_r_H_m = before.r_H_m;
    ghost.lin_clamp_m = before.clamp_m;
  }
  if (truncated) out.flags |= kContactsTruncated;
  // Truncated, the set kept depends on what came before it: take the tick with every part.
  if (truncated && idle.left_out > 0) return false;

  // 5. The beam's compliance between the load points, about last tick's forces.
  m.SaveShape(std::size_t(N) + 1, out);
  for (int i = 0; i < load_count; ++i) {
    Load& ld = loads[std::size_t(i)];
    if (!ld.ghost) {
      const Eigen::Vector3d centre_W = p_start_W + R_WH * interpolate_node(ld.s_m);
      ld.r_H_m = R_WH.transpose() * (ld.x0_W - centre_W);
      ld.centre0_W = centre_W;
    }
    m.beam_loads[std::size_t(i)] =
        BeamLoad{ld.s_m, R_WH.transpose() * ld.f_lin_W, ld.r_H_m, 0.0, 0, ld.pc};
  }
  // The cantilever's structure (cuts, clamps) comes from the loads that carry force: those in
  // contact now and those that carried force last tick (their force is in the current shape).
  // A load merely in the band must not cut the tube. Rebuilt when a load closes in a pass.
  const bool want_elastica = scene_.model.beam == model::BeamModel::kElastica;
  const Eigen::Matrix3d lateral = Eigen::Vector3d(1.0, 1.0, 0.0).asDiagonal();
  std::array<bool, kMaxLoads> member{};
  // The members' indices in increasing order (the sums over them keep the order of a scan of
  // every load), for the loops over member columns: scanning all six loads for the three
  // members of three PCs in the groove, in each of five loops, cost ~800 instructions a tick.
  std::array<int, kMaxLoads> member_index{};
  int member_count = 0;
  bool use_elastica = false;
  // The linear model's reference (build_compliance): load j's force f_lin as last tick's shape
  // carried it, at the arc position, offset and cut of the load it continues (a ghost: its own).
  // False if load j carries no f_lin.
  const auto reference_of = [&](int j, BeamLoad& then_j) {
    const Load& lj = loads[std::size_t(j)];
    if (!lj.continues || lj.f_lin_W.isZero(0.0)) return false;
    then_j = m.beam_loads[std::size_t(j)];
    then_j.s_m = lj.lin_s_m;
    then_j.r_H_m = lj.lin_r_H_m;
    then_j.clamp_m = lj.lin_clamp_m;
    return true;
  };
  // Whether load j sits elsewhere than its reference: another arc position, offset or cut.
  const auto moved = [&](int j, const BeamLoad& then_j) {
    const BeamLoad& now_j = m.beam_loads[std::size_t(j)];
    return !(then_j.s_m == now_j.s_m && then_j.r_H_m == now_j.r_H_m &&
             then_j.clamp_m == now_j.clamp_m);
  };
  // The dome's spring (the linear model and the rod; docs/core.md). An end face pressed on a face
  // carries its load at its dome's lowest point, e = R sin(tilt) off its centre: as the end turns
  // by theta (lateral, frame H) the point moves by -R theta x z, and the load N's moment by -N R
  // theta, a rotational spring k_r = N R on the end section. Left to the next tick, that spring is
  // a loop of gain N R l / (E I) (the relaxation above; a stuck tip stepped sideways reached its
  // force over ten ticks). In the system it is condensed into the compliance: with T_j the end's
  // turn per force of load j, C_i load i's displacement per moment on the end and t_M the end's
  // turn per moment, the moment is M = -kappa L (sum_j T_j F_j - theta_0), kappa = k_r / (1 + k_r
  // t_M), L the lateral projection and theta_0 the end's turn in last tick's shape, and
  //     x_i += C_i M:  W_ij -= kappa C_i L T_j,  base_i += kappa C_i L theta_0
  // (Q in place of L below)
  // (C_i = T_i^T where the clamps agree: W stays symmetric, and a stuck spring on it conservative).
  // k_r is taken at the force last tick's shape was drawn under, N's change within the tick
  // being second order in the moment. The held end's own turn within the tick is left to the
  // next tick's point.
  //
  // The rim pressed on a face, beyond the dome's range, has such a spring too, about one axis:
  // its point is the rim's lowest, r1 u with u the direction the face tilts to, and a turn about
  // u moves it round the rim by r1 cot(tilt) times the turn (R, to the dome's height, where the
  // dome meets the rim), a turn across u not at all. Left out, that loop made the linear model's
  // slide off the plane (stability sweep, `slide along a wall off-plane=0.1mm`) buzz at 500 Hz once
  // its dome had reached the rim: the rim's point swung 3 mm round it and back each tick. So the
  // spring is k_r Q with Q = L for the dome and Q = u u^T for the rim, R_e = R or r1 cot(tilt), and
  // kappa = k_r / (1 + k_r t_M) along Q. The rod's t_M is a matrix (build_compliance).
  struct DomeSpring {
    int load = -1;  // the end face's load, or none
    double kappa = 0.0, radius_m = 0.0, k_r = 0.0, turn_per_moment = 0.0;
    // The turns it resists (the rod: the moment per turn, K, with kappa 1).
    Eigen::Matrix3d Q_H = Eigen::Matrix3d::Zero();
    Eigen::Matrix3d turn_of_turn_H = Eigen::Matrix3d::Zero();  // the rod: Q (I - t_M K)
    Eigen::Vector3d axis_H = Eigen::Vector3d::UnitZ();         // the end's
    Eigen::Vector3d theta0_H = Eigen::Vector3d::Zero();
    std::array<Eigen::Matrix3d, kMaxLoads> T_H;  // the end's turn per force of each member
    std::array<Eigen::Matrix3d, kMaxLoads> C_H;  // kappa times each load's motion per moment
  } dome;
  const auto build_compliance = [&] {
    // The cantilever's members. The nonlinear models' tangents are taken about last tick's
    // forces, so a load that carried force then is one (its force is taken out through its
    // column). The linear model takes last tick's shape out whole (below): its members are the
    // loads in contact, and the cuts are the ones step 8 draws the shape with.
    for (int i = 0; i < load_count; ++i) {
      const Load& ld = loads[std::size_t(i)];
      member[std::size_t(i)] = ld.active || (want_elastica && !ld.f_lin_W.isZero(0.0));
    }
    member_count = 0;
    for (int i = 0; i < load_count; ++i)
      if (member[std::size_t(i)]) member_index[std::size_t(member_count++)] = i;
    int members = 0;
    const int groups = m.beam.Assign(m.beam_loads, load_count, member, m.order, members);
    use_elastica = want_elastica && !m.elastica_held_off && members > 0 &&
                   m.beam.ElasticaCovers(m.beam_loads, m.order, members, groups);
    // A load that is not a member moves nothing, and is in no sum or system as one (a load that
    // closes in a pass becomes a member first, and the compliances are built again): its column
    // is left unwritten and is never read (most of the loads of a tube lying in the groove, in
    // the band of a wall it does not touch).
    const auto linear_compliance = [&] {
      for (int i = 0; i < load_count; ++i)
        for (int k = 0; k < member_count; ++k) {
          const int j = member_index[std::size_t(k)];
          m.beam.Compliance(m.beam_loads[std::size_t(i)], m.beam_loads[std::size_t(j)],
                            !use_elastica, m.W[std::size_t(i)][std::size_t(j)]);
        }
    };
    linear_compliance();
    bool rod_end_spring = false;  // the rod's tangent, with the end's response to a moment
    // The rod's segment of the k-th member in arc order: one for the coupled rule.
    const bool coupled = scene_.model.multi_contact == scene::MultiContactRule::kCoupled;
    const auto segment_of = [&](int k) {
      return coupled ? 0 : m.beam_loads[std::size_t(m.order[std::size_t(k)])].group;
    };
    // The dome's spring, or the rim's (below): the load it is on, chosen before the rod's
    // tangent, which then also gives the end's response to a moment. None for the elastica.
    dome.load = -1;
    for (int e = 0; e < load_count && (!want_elastica || (!use_elastica && members > 0)); ++e) {
      const Load& ld = loads[std::size_t(e)];
      const double N0 = ld.f_lin_W.dot(ld.normal_W);
      if (!member[std::size_t(e)] || !(N0 > 0.0)) continue;
      const BeamLoad& at = m.beam_loads[std::size_t(e)];
      const double R = m.collision.dome_radius_m();
      // The end's axis: the linear model's is the held frame's z, to its order; the rod's,
      // bent, is its shape's.
      dome.axis_H = want_elastica ? Eigen::Vector3d(R_WH.transpose() * tangent_at(l))
                                  : Eigen::Vector3d::UnitZ();
      const Eigen::Matrix3d across_H =
          Eigen::Matrix3d::Identity() - dome.axis_H * dome.axis_H.transpose();
      if (ld.dome_spring) {
        dome.radius_m = R;
        dome.Q_H = across_H;
      } else {
        // The rim on a face: the load at the end, on the rim circle, not overlapping.
        const Eigen::Vector3d u_H = across_H * at.r_H_m;
        const Eigen::Vector3d axis_W = tangent_at(l);
        const double sin_tilt = axis_W.cross(ld.normal_W).norm();
        const double cos_tilt = std::abs(axis_W.dot(ld.normal_W));
        const double r1 = scene_.tube.outer_radius_m;
        // A turn theta about u moves the rim circle's lowest point along u x axis by
        // r1 cot(tilt) theta (stop 40 had r1 / sin(tilt): the same where the dome meets the rim,
        // but a spring r1 N on a side lying along the face, whose point a turn about u does not
        // move). Where that is within the dome's height h (the tick's, set before the query) for a
        // turn of a radian, the point does not move: no spring (the tube lying in the groove,
        // its end's side on the floor).
        if (ld.pressure_centre || ld.ghost || at.s_m < l ||
            !IsFaceMask(elements_[std::size_t(ld.part_element)].face_mask) ||
            !(u_H.norm() > 0.99 * r1) || !(sin_tilt * R > r1) ||
            !(r1 * cos_tilt > m.collision.dome_height_m() * sin_tilt))
          continue;
        dome.radius_m = r1 * cos_tilt / sin_tilt;
        dome.Q_H = u_H * u_H.transpose() / u_H.squaredNorm();
      }
      dome.load = e;
      break;  // one end face
    }
    if (want_elastica && !use_elastica && members > 0) {
      // The elastica does not cover these loads: the rod's tangent, at last tick's forces,
      // replaces the linear compliance between the loads of each of its segments (a load moves
      // a later segment's points rigidly with its clamp: linear, as for the elastica). If the rod
      // does not converge, the linear model stands (flagged at the shape). The tangent only
      // steers the tick's Newton step, like the elastica's: one computed for loads within 10 %
      // and arc positions within 1 % of l of these, on the same segments, in the last 50 ticks,
      // is used again (it costs 4 + 3 n integrations of the rod).
      const double scale_N = m.beam.bending_stiffness_Nm2() / (l * l);
      // With the dome's or the rim's spring (above) the rod's tangent also gives the end's
      // response to a moment there (three more directions of the compliance's integration).
      const bool end_loaded = dome.load >= 0;
      bool reuse = m.rod_tangent_members == members && m.rod_tangent_age < kTangentReuseTicks &&
                   (!end_loaded || m.rod_end.valid);
      for (int k = 0; k < members && reuse; ++k) {
        const BeamLoad& b = m.beam_loads[std::size_t(m.order[std::size_t(k)])];
        const std::size_t kk = std::size_t(k);
        reuse = segment_of(k) == m.rod_tangent_segment[kk] &&
                std::abs(b.s_m - m.rod_tangent_s[kk]) <= 0.01 * l &&
                (b.f_H_N - m.rod_tangent_force[kk]).norm() <=
                    0.1 * m.rod_tangent_force[kk].norm() + 1e-3 * scale_N;
      }
      // The end's turn per moment t_M is not only a Newton step's guide: the dome's (or the
      // rim's) spring is condensed with it, k_r / (1 + k_r t_M) (below). Near a buckling load of
      // the end's segment it changes by far more than its loads: the straight column's
      // t_M = tan(kL) / (k E I), k^2 = P / (E I), P the segment's axial push, L its length, has a
      // pole at each kL = (2 n + 1) pi / 2 and a zero at each kL = n pi (near which the condensed
      // spring has its own pole). The rubber tube pushed onto a wall at 2 m/s passed its free
      // end's 8.1 N (kL = 3 pi / 2) between 7.7 and 8.5 N, and the tangent of 7.7 N, reused,
      // kept t_M = +40 rad/(N m) where it was -30: the dome's point drifted 1.6 times further
      // each tick (`stability --only "fast pass off-plane"`). So with the end's spring the
      // straight column's t_M at the segment's push now must also be within 10 % of its value at
      // the tangent's, or the tangent is computed again.
      if (reuse && end_loaded) {
        const int end_segment = segment_of(members - 1);
        double push_now_N = 0.0, push_then_N = 0.0, length_m = 0.0;
        for (int k = 0; k < members; ++k) {
          if (segment_of(k) != end_segment) continue;
          const BeamLoad& b = m.beam_loads[std::size_t(m.order[std::size_t(k)])];
          push_now_N -= b.f_H_N.z();
          push_then_N -= m.rod_tangent_force[std::size_t(k)].z();
          length_m = std::max(length_m, b.s_m - b.clamp_m);
        }
        const double EI = m.beam.bending_stiffness_Nm2();
        const auto column_turn = [EI, length_m](double push_N) {
          const double k = std::sqrt(std::abs(push_N) / EI), kL = k * length_m;
          if (!(kL > 1e-4)) return length_m / EI;
          return (push_N > 0.0 ? std::tan(kL) : std::tanh(kL)) / (k * EI);
        };
        const double then = column_turn(push_then_N);
        reuse = std::abs(column_turn(push_now_N) - then) <= 0.1 * std::abs(then);
      }
      bool ok = true;
      if (!reuse && idle.left_out > 0) m.SaveRodCache();
      if (!reuse) {
        // Last tick's shape was the rod's, solved at last tick's forces, which are this tick's
        // f_lin: if its loads are these members, at arc positions within 1 % of l, on the same
        // segments, its solution is already a tangent point as good as the reuse rule above
        // accepts, and its compliance is taken there (its loads renumbered to this tick's).
        // Solving again at this tick's positions cost as much as the shape's own solve (the
        // positions and offsets move the end by ~0.01 rad a tick), 40 % of the rod's work in the
        // groove's graph. (That solve stepped through the nodes, this integration through the
        // loads: two discrete rods whose equilibria differ within the discretisation error,
        // ~1e-6 l for a line contact, far below the 10 % this reuse already allows.)
        bool last_shape = m.rod_shape && m.rod_segment_count > 0;
        int k = 0;  // members are taken in `order`, a segment's loads a run of one segment_of
        for (int g = 0; g < m.rod_segment_count && last_shape; ++g) {
          RodSegment& seg = m.rod_segments[std::size_t(g)];
          const int first = k;
          last_shape = first + seg.load_count <= members &&
                       (first + seg.load_count == members ||
                        segment_of(first + seg.load_count) != segment_of(first));
          for (int q = 0; q < seg.load_count && last_shape; ++q, ++k) {
            const BeamLoad& b = m.beam_loads[std::size_t(m.order[std::size_t(k)])];
            last_shape =
                segment_of(k) == segment_of(first) &&
                std::abs(b.s_m - (seg.clamp_m + seg.loads_S[std::size_t(q)].s_m)) <= 0.01 * l;
            seg.index[std::size_t(q)] = m.order[std::size_t(k)];
          }
        }
        last_shape = last_shape && k == members;
        const int segments =
            last_shape ? m.rod_segment_count
                       : m.beam.SolveRodChain(m.beam_loads, members, m.order, m.rod_segments);
        ok = segments > 0;
        model::RodEndMoment end_moment;
        for (int g = 0; g < segments && ok; ++g)
          ok = m.beam.RodCompliance(m.rod_segments[std::size_t(g)], m.W,
                                    end_loaded && g + 1 == segments ? &end_moment : nullptr);
        m.rod_tangent_members = 0;
        m.rod_end.valid = false;
        if (ok && end_loaded) {
          // The end's segment is the last; its loads by their place in arc order.
          const RodSegment& seg = m.rod_segments[std::size_t(segments - 1)];
          m.rod_end.valid = true;
          m.rod_end.segment = segment_of(members - 1);
          m.rod_end.turn_per_moment = end_moment.turn_per_Nm;
          for (int q = 0; q < seg.load_count; ++q) {
            const int i = seg.index[std::size_t(q)];
            int a = members - 1;
            while (a > 0 && m.order[std::size_t(a)] != i) --a;
            m.rod_end.turn_per_force[std::size_t(a)] =
                seg.R_HS * seg.end_turn_per_N[std::size_t(q)] * seg.R_HS.transpose();
            m.rod_end.moved_per_moment[std::size_t(a)] = end_moment.w_per_Nm[std::size_t(i)];
          }
        }
        if (ok) {
          m.rod_tangent_members = members;
          m.rod_tangent_age = 0;
          for (int a = 0; a < members; ++a) {
            const BeamLoad& b = m.beam_loads[std::size_t(m.order[std::size_t(a)])];
            m.rod_tangent_force[std::size_t(a)] = b.f_H_N;
            m.rod_tangent_s[std::size_t(a)] = b.s_m;
            m.rod_tangent_segment[std::size_t(a)] = segment_of(a);
            for (int c = 0; c < members; ++c)
              m.rod_tangent[std::size_t(a * kMaxLoads + c)] =
                  m.W[std::size_t(m.order[std::size_t(a)])][std::size_t(m.order[std::size_t(c)])];
          }
        }
      }
      rod_end_spring = ok && end_loaded && m.rod_end.valid;
      if (ok) {
        for (int a = 0; a < members; ++a)
          for (int c = 0; c < members; ++c)
            if (segment_of(a) == segment_of(c))
              m.W[std::size_t(m.order[std::size_t(a)])][std::size_t(m.order[std::size_t(c)])] =
                  m.rod_tangent[std::size_t(a * kMaxLoads + c)];
      } else {
        linear_compliance();
      }
    }
    if (use_elastica) {
      // Within a segment the elastica's own tangent replaces the linear force compliance; the
      // rotation terms and the loads of earlier segments keep their linear values.
      // The tangent costs three elastica solves a segment. It only steers this tick's Newton
      // step (the solution is where the elastica's shape and the contacts agree, whatever the
      // tangent), so one computed for loads within 10 % and lengths within 1 % of these, in the
      // last 50 ticks, is used again: the last one used, else the one before it.
      // (Eigen's vectors are not zeroed by {}: fill them.)
      std::array<Eigen::Vector3d, kMaxLoads> f_group;
      f_group.fill(Eigen::Vector3d::Zero());
      std::array<double, kMaxLoads> length_m{};
      for (int k = 0; k < members; ++k) {
        const BeamLoad& b = m.beam_loads[std::size_t(m.order[std::size_t(k)])];
        f_group[std::size_t(b.group)] += b.f_H_N;
        length_m[std::size_t(b.group)] = b.s_m - b.clamp_m;  // the group's last load: its end
      }
      const double scale_N = m.beam.bending_stiffness_Nm2() / (l * l);
      const auto fits = [&](const State::ElasticaTangent& t) {
        bool ok = t.count == groups && t.age < kTangentReuseTicks;
        for (int g = 0; g < groups && ok; ++g) {
          const std::size_t gi = std::size_t(g);
          ok = (f_group[gi] - t.force[gi]).norm() <= 0.1 * t.force[gi].norm() + 1e-3 * scale_N &&
               std::abs(length_m[gi] - t.length[gi]) <= 0.01 * l;
        }
        return ok;
      };
      if (!fits(m.tangents[std::size_t(m.tangent_current)])) {
        if (idle.left_out > 0) m.SaveTangentChoice();
        // The other one, or a new one in its place.
        m.tangent_current = 1 - m.tangent_current;
        State::ElasticaTangent& t = m.tangents[std::size_t(m.tangent_current)];
        if (!fits(t)) {
          if (idle.left_out > 0) m.SaveElasticaCache();
          m.beam.SolveElasticaChain(m.beam_loads, members, m.order, m.segments);
          for (int g = 0; g < groups; ++g) {
            const std::size_t gi = std::size_t(g);
            t.J[gi] = m.beam.ElasticaCompliance(m.segments[gi], f_group[gi]);
            t.force[gi] = f_group[gi];
            t.length[gi] = length_m[gi];
          }
          t.count = groups;
          t.age = 0;
        }
      }
      const State::ElasticaTangent& tangent = m.tangents[std::size_t(m.tangent_current)];
      for (int g = 0; g < groups; ++g) {
        const Eigen::Matrix3d& J = tangent.J[std::size_t(g)];
        for (int ki = 0; ki < members; ++ki) {
          const int i = m.order[std::size_t(ki)];
          if (m.beam_loads[std::size_t(i)].group != g) continue;
          for (int kj = 0; kj < members; ++kj) {
            const int j = m.order[std::size_t(kj)];
            if (m.beam_loads[std::size_t(j)].group != g) continue;
            const double uF =
                m.beam.Influence(m.beam_loads[std::size_t(i)].s_m, m.beam_loads[std::size_t(j)]);
            m.W[std::size_t(i)][std::size_t(j)] += J - uF * lateral;
          }
        }
      }
    }
    // A load that is not a member: its column is not read (linear_compliance).
    for (int i = 0; i < load_count; ++i)
      for (int k = 0; k < member_count; ++k) {
        // A zero block (a load at the held end neither moves nor is moved) stays as it is: its
        // turn would only give zeros of R's signs. Those reach nothing but sums with other terms
        // (a zero's sign shows only in a sum of zeros), and two of three PCs' loads lie at the
        // held end: 8 of its 9 blocks (~1 k instructions a tick).
        Eigen::Matrix3d& W = m.W[std::size_t(i)][std::size_t(member_index[std::size_t(k)])];
        if (!IsZeroBlock(W)) TurnBlock(R_WH, W);
      }
    // In a pass of its own, after the turns: read back right after it was written, a block's
    // column (24 bytes) straddles the 16-byte stores that wrote it, and such a load waits for
    // them to reach the cache (`perf` had a third of this function's time on that load).
    for (int i = 0; i < load_count; ++i) {
      Load& ld = loads[std::size_t(i)];
      ld.base_W = ld.x0_W - p_start_W;
      if (!want_elastica) continue;  // the linear model's base: below
      for (int k = 0; k < member_count; ++k) {
        const int j = member_index[std::size_t(k)];
        // (noalias: the product goes straight into the sum. Eigen otherwise assumes aliasing
        // and makes a temporary, in an out-of-line call here: 18 calls a tick with three PCs.)
        ld.base_W.noalias() -= m.W[std::size_t(i)][std::size_t(j)] * loads[std::size_t(j)].f_lin_W;
      }
    }
    // The linear model: x0 is last tick's shape, x_straight plus what last tick's forces bent it
    // by where last tick's loads were. The tick's shape is x_straight + W F (step 8), so
    //     x = x0 - sum_j W(s_i, s_j last tick) F_lin_j + sum_j W_ij F_j,
    // the tick's system then the drawn shape's (exactly while the held end keeps its orientation:
    // F_lin is taken out in this tick's frame H, the shape drew it in last tick's; docs/core.md).
    // The incremental form the nonlinear models use, x = x0 + W (F - F_lin), takes F_lin as
    // already acting at this tick's arc positions, offsets and cuts. Where a load moves along the
    // tube that is far off: the end of a side's region jumping 9.4 mm with 5 N on it moved the
    // rubber tube's tip by 64 mm that the system did not see, and the tube pinched in a groove went
    // into its walls and was held back (the stability sweep's squeeze motion under the linear model
    // and the coupled rule: held in 441 of its 480 ticks, now none). The nonlinear models' tangents
    // are not their shapes' compliance: there the incremental form stays (the linear coefficients
    // as an estimate of the moved loads' term left the elastica's sweep at 66 of 80, other cases
    // failing; docs/core.md).
    if (!want_elastica) {
      for (int j = 0; j < load_count; ++j) {
        BeamLoad then_j;
        if (!reference_of(j, then_j)) continue;
        // A member whose load has not moved: its column, just computed, is W(s_i, s_j then).
        const bool same = member[std::size_t(j)] && !moved(j, then_j);
        for (int i = 0; i < load_count; ++i)
          loads[std::size_t(i)].base_W -=
              same ? Eigen::Vector3d(m.W[std::size_t(i)][std::size_t(j)] *
                                     loads[std::size_t(j)].f_lin_W)
                   : Eigen::Vector3d(
                         R_WH *
                         (m.beam.Compliance(m.beam_loads[std::size_t(i)], then_j) * then_j.f_H_N));
      }
    }
    if (dome.load >= 0 && want_elastica && !rod_end_spring) dome.load = -1;
    if (dome.load >= 0) {
      const int e = dome.load;
      const Load& ld = loads[std::size_t(e)];
      const double N0 = ld.f_lin_W.dot(ld.normal_W);
      const BeamLoad& at = m.beam_loads[std::size_t(e)];
      dome.k_r = N0 * dome.radius_m;
      dome.theta0_H.setZero();
      if (!want_elastica) {
        dome.turn_per_moment = m.beam.TurnPerMoment(at);
        dome.kappa = dome.k_r / (1.0 + dome.k_r * dome.turn_per_moment);
        BeamLoad then_j;
        for (int j = 0; j < load_count; ++j) {
          if (reference_of(j, then_j))
            dome.theta0_H += m.beam.TurnCompliance(at.s_m, then_j) * then_j.f_H_N;
          dome.T_H[std::size_t(j)] =
              member[std::size_t(j)] ? m.beam.TurnCompliance(at.s_m, m.beam_loads[std::size_t(j)])
                                     : Eigen::Matrix3d::Zero();
        }
        for (int i = 0; i < load_count; ++i)
          dome.C_H[std::size_t(i)] =
              dome.kappa * m.beam.MomentCompliance(m.beam_loads[std::size_t(i)], at);
      } else {
        // The rod's end turns by t_M M under a moment, a matrix (it is bent): the spring's
        // moment is M = -K (turn), K = (I + k_r Q t_M)^-1 k_r Q, and the end then turns by
        // Q (I - t_M K) of the forces' turn. Within the end's segment the rod's own responses
        // (its tangent's, reused with it); a load of an earlier segment moves the end's clamp, as
        // in its compliance, linearly. The rod's shape is incremental (x = x0 + W (F - F_lin)), so
        // the turn resisted is the forces' change's: theta_0 = sum_j T_j F_lin,j.
        const Eigen::Matrix3d& t_M = m.rod_end.turn_per_moment;
        const Eigen::Matrix3d kQ = dome.k_r * dome.Q_H;
        const Eigen::Matrix3d K_spring =
            (Eigen::Matrix3d::Identity() + kQ * t_M).partialPivLu().solve(kQ);
        dome.turn_of_turn_H = dome.Q_H * (Eigen::Matrix3d::Identity() - t_M * K_spring);
        dome.kappa = 1.0;
        dome.Q_H = K_spring;
        std::array<int, kMaxLoads> place{};
        place.fill(-1);
        for (int a = 0; a < members; ++a)
          if (segment_of(a) == m.rod_end.segment) place[std::size_t(m.order[std::size_t(a)])] = a;
        for (int j = 0; j < load_count; ++j) {
          const int a = place[std::size_t(j)];
          const BeamLoad& bj = m.beam_loads[std::size_t(j)];
          dome.T_H[std::size_t(j)] = !member[std::size_t(j)] ? Eigen::Matrix3d::Zero()
                                     : a >= 0 ? m.rod_end.turn_per_force[std::size_t(a)]
                                              : m.beam.TurnCompliance(at.s_m, bj);
          if (member[std::size_t(j)]) dome.theta0_H += dome.T_H[std::size_t(j)] * bj.f_H_N;
          dome.C_H[std::size_t(j)] =
              a >= 0 ? m.rod_end.moved_per_moment[std::size_t(a)]
                     : m.beam.MomentCompliance(m.beam_loads[std::size_t(j)], at);
        }
        // The dome's point itself moved since last tick's shape (to its target, above): its
        // force F_lin's moment about the end changed by (r - r_then) x F_lin, which the
        // incremental form does not see (the linear model's reference does). It moves the loads
        // by C and turns the end by t_M, which the spring then resists as any turn. (Not the
        // rim's: its point is the rim's lowest, not relaxed towards it, and a jump there from the
        // face's centre stays out of the system, as before the spring.)
        BeamLoad then_e;
        if (ld.dome_spring && reference_of(e, then_e) && then_e.s_m == at.s_m) {
          const Eigen::Vector3d moved_H = (at.r_H_m - then_e.r_H_m).cross(then_e.f_H_N);
          dome.theta0_H -= t_M * moved_H;
          for (int i = 0; i < load_count; ++i)
            loads[std::size_t(i)].base_W += R_WH * (dome.C_H[std::size_t(i)] * moved_H);
        }
      }
      for (int i = 0; i < load_count; ++i) {
        Load& li = loads[std::size_t(i)];
        const Eigen::Matrix3d CL = dome.C_H[std::size_t(i)] * dome.Q_H;
        li.base_W += R_WH * (CL * dome.theta0_H);
        for (int j = 0; j < load_count; ++j)
          if (member[std::size_t(j)])
            m.W[std::size_t(i)][std::size_t(j)] -=
                R_WH * (CL * dome.T_H[std::size_t(j)]) * R_WH.transpose();
      }
    }
  };
  // What a stuck contact's tangential spring sees of the compliance.
  //
  // A force at load j turns load i's section, which moves i's surface point, offset from the
  // centreline by r_i, by -r_i x (turn): along the axis for a side contact. Where the beam
  // carries the offsets' moments (the linear model) the converse holds too, a tangential force
  // at an offset bends the tube (W_ij = W_ji^T, Maxwell-Betti), and a stuck spring on that
  // compliance is conservative. The elastica carries tip forces only: an axial friction at the
  // surface bends nothing, yet the surface point still slides along the axis by r1 times the
  // turn the normal force makes. A stuck spring on such a one-way compliance is a pump: on the
  // side pressed on an edge the turn stretches it, its force drags the tube along its axis
  // against the coupling, and the energy the coupling then holds was never paid for by the hand
  // (the moment that would have made the tube stiffer is not there). So where the moments are
  // left out the stuck spring sees the point move with the centreline and the held end only,
  // not with its section's own turn: the one-way term is taken out, the spring stays
  // conservative. (The normal rows keep it: for a side contact it has no normal part, and an
  // end face's tilt is the penalty's, not the spring's.)
  //
  // The turn is slope_ij (e_z x f_j) in H, so D_ij f = -r_i x (slope_ij e_z x f) = slope_ij (r_iz f
  // - e_z (r_i . f)): in W, D_ij = slope_ij (r_iz I - t_W r_i_W^T) with t_W the clamp's axis,
  // formed once per load i (it was R (-[r_i]x (slope [e_z]x)) R^T per pair: 6 % of a tick with
  // three PCs).
  const auto build_stick_compliance = [&] {
    const Eigen::Vector3d t_W = R_WH.col(2);
    for (int i = 0; i < load_count; ++i) {
      Load& ld = loads[std::size_t(i)];
      ld.stick_base_W = ld.base_W;
      ld.turn_seen = !use_elastica;
      // The row of a load that is not a member is not built either: only a load in the system
      // reads its stuck spring's (an open load closing in a pass becomes a member, and this is
      // built again), and an open load's point is not computed after the solve (step 7).
      if (!ld.friction || !member[std::size_t(i)]) continue;
      const BeamLoad& bi = m.beam_loads[std::size_t(i)];
      const Eigen::Matrix3d M_i =
          bi.r_H_m.z() * Eigen::Matrix3d::Identity() - t_W * (R_WH * bi.r_H_m).transpose();
      for (int k = 0; k < member_count; ++k) {
        // A load that is not a member is in no sum or system as one (a load that closes in a
        // pass becomes a member first, and the compliances are built again): its block is not
        // read.
        const int j = member_index[std::size_t(k)];
        Eigen::Matrix3d& Dij = m.W_turn[std::size_t(i)][std::size_t(j)];
        if (!use_elastica) {
          Dij.setZero();
          continue;
        }
        Dij = m.beam.InfluenceSlope(bi.s_m, m.beam_loads[std::size_t(j)]) * M_i;
      }
    }
    // The sums in a pass of their own, as the compliance's base (build_compliance).
    for (int i = 0; i < load_count; ++i) {
      Load& ld = loads[std::size_t(i)];
      if (!ld.friction || !use_elastica || !member[std::size_t(i)]) continue;
      for (int k = 0; k < member_count; ++k) {
        const int j = member_index[std::size_t(k)];
        ld.stick_base_W.noalias() +=
            m.W_turn[std::size_t(i)][std::size_t(j)] * loads[std::size_t(j)].f_lin_W;
      }
    }
  };
  build_compliance();
  build_stick_compliance();

  // 6. Solve contacts, coupling and beam together. Unknowns: the load forces F_i (W) and the
  // held-end position p. Load i: F_i = K n (eps - d_i - n.(x_i - x0_i)) + Kt T (a_i - x_i) when
  // stuck, + f_i when sliding; its point x_i = base_i + p + sum_j W_ij F_j. Coupling:
  // K_c (h - p) + B (v_h - (p - p_prev) / T) + sum F_i = 0 (tube and proxy are massless).
  const double Kc_eff = coupling_stiffness_ + coupling_damping_ / T;
  const Eigen::Vector3d v_hand_W = (p_hand_W - m.p_hand_prev_W) / T;
  const Eigen::Vector3d A_free = coupling_stiffness_ * p_hand_W + coupling_damping_ * v_hand_W +
                                 (coupling_damping_ / T) * m.p_held_prev_W;
  Eigen::Vector3d A = A_free;
  const double max_force = scene_.device.max_force_N;
  // The grip is rigid (the paper's held end turns with the device) up to the device's torque:
  // omega turns the held end onto the hand's orientation, e = log(R_hand R_held^T) (W), unless
  // the contacts' moment about the held end would exceed the maximum torque; then the grip
  // carries exactly that torque and the contacts decide omega.
  const double max_torque = scene_.device.max_torque_Nm;
  const Eigen::AngleAxisd& error = hand_turn;  // step 2's
  const Eigen::Vector3d e_hand = error.angle() * error.axis();
  bool torque_saturated = false;
  Eigen::Vector3d torque_sat_W = Eigen::Vector3d::Zero();  // the grip's torque on the tube
  // A saturated grip lets the contacts turn the held end, and the tick's system is linearised
  // about the tick's start: a turn that moves the tip by more than epsilon can carry it past
  // contacts the band never saw. The steel tube rolled off an edge turned by 2.2 rad in one tick
  // and came out on the far side of the part (`stability --only "roll over an edge E=2e+11Pa"`).
  // So the slipping grip turns at most epsilon / (l + r1) a tick (the tip's rim moves at most
  // epsilon); the held end then follows the contacts over several ticks, the grip's torque above
  // the device's limit meanwhile (flagged clamped; the device's own limiter bounds what it is
  // sent). A rigid grip follows the hand, which is the operator's motion, and is not capped.
  Eigen::Vector3d e_grip = e_hand;  // the held end's turn this tick while the grip holds
  bool turn_limited = false;
  const double max_turn_rad = eps / (l + scene_.tube.outer_radius_m);
  std::array<int, kMaxLoads> slot{};
  // The load in each slot (the active loads in increasing order), for the loops over the
  // solved forces: the sums over them keep the order of a scan of every load for its slot,
  // which cost three PCs in the groove (three slots of six loads) ~140 instructions a tick.
  std::array<int, kMaxLoads> slot_load{};
  int slot_count = 0;
  Eigen::Vector3d p_W = p_start_W;
  Eigen::Vector3d omega_W = Eigen::Vector3d::Zero();
  bool solved = false, saturated = false, force_saturated = false;
  // After a torque-saturated solve: if it turned too far, hold the grip at the capped turn.
  const auto cap_turn = [&] {
    if (!torque_saturated || !(omega_W.norm() > max_turn_rad)) return false;
    e_grip = omega_W * (max_turn_rad / omega_W.norm());
    torque_saturated = false;
    return true;
  };
  // Assembles and solves the tick's system for the current decisions; false if not finite.
  //
  // With the grip rigid (not torque-saturated) omega is the hand's turn e and the coupling's
  // row gives p = (A + sum F) / Kc_eff: both are substituted, and only the forces are solved
  // for (3 n unknowns instead of 3 n + 6: the factorisation, the largest cost of a pass, falls
  // by half for two loads). A saturated grip keeps the full system: its omega row carries
  // 1 / k_reg, which substituted would swamp the rest.
  const auto solve_system = [&]() {
    int n_active = 0;
    for (int i = 0; i < load_count; ++i) {
      slot[std::size_t(i)] = loads[std::size_t(i)].active ? n_active : -1;
      if (loads[std::size_t(i)].active) slot_load[std::size_t(n_active++)] = i;
    }
    slot_count = n_active;
    const bool reduced = !torque_saturated;
    const int n = 3 * n_active + (reduced ? 0 : 6);
    const int ip = n - 6, iw = n - 3;  // columns of p and omega (full system)
    // Load i's rows: F_i + sum_j (G W_ij - [stuck] Gt W_turn_ij) F_j + G_p sum_j F_j = rhs, and,
    // for the full system, G and G Rx on p and omega. Reduced, p = (A + sum F) / Kc_eff adds
    // G_p = G / Kc_eff to every force's column, and the held end's given turn and A go to rhs.
    struct Rows {
      Eigen::Matrix3d G, Gt, Rx, G_p;
      Eigen::Vector3d rhs;
      bool stuck;
    };
    const auto rows_of = [&](const Load& ld, Rows& rw) {
      const Eigen::Vector3d& nrm = ld.normal_W;
      const Eigen::Matrix3d NN = nrm * nrm.transpose();
      const Eigen::Matrix3d Tp = Eigen::Matrix3d::Identity() - NN;
      rw.stuck = ld.friction && !ld.sliding;
      // The normal force is N = K (eps - d - n.(x - x0)); sliding adds (a + b N) along the
      // slide direction, so the law stays linear in x: F = (n + b t) N + a t.
      const Eigen::Vector3d n_eff =
          ld.sliding ? Eigen::Vector3d(nrm + ld.slide_b * ld.slide_dir_W) : nrm;
      // The normal part and the stuck spring (which sees the point without the one-way turn of
      // its offset, section 5).
      const Eigen::Matrix3d Gn = K * n_eff * nrm.transpose();
      rw.Gt = (rw.stuck ? Kt : 0.0) * Tp;
      rw.G = Gn + rw.Gt;
      Eigen::Vector3d b = K * n_eff * (eps - ld.distance_m + nrm.dot(ld.x0_W));
      if (rw.stuck) b += Kt * (Tp * ld.anchor_W);
      if (ld.sliding) b += ld.slide_a * ld.slide_dir_W;
      // The held end's turn omega moves the point by omega x r, r from the held end.
      rw.Rx = Skew(ld.x0_W - p_start_W);
      rw.rhs = b - Gn * ld.base_W - rw.Gt * ld.stick_base_W;
      rw.G_p = reduced ? Eigen::Matrix3d(rw.G / Kc_eff) : Eigen::Matrix3d::Zero();
      if (reduced) rw.rhs += rw.G * (rw.Rx * e_grip) - rw.G_p * A;
    };
    // Into a zeroed M and rhs of n rows: the dynamic system's, or a fixed-size one's (below).
    const auto assemble = [&](auto& M, auto& rhs) {
      Rows rw;
      for (int si = 0; si < slot_count; ++si) {
        const int i = slot_load[std::size_t(si)];
        rows_of(loads[std::size_t(i)], rw);
        const Eigen::Matrix3d& G = rw.G;
        const int r = 3 * si;
        M.template block<3, 3>(r, r) += Eigen::Matrix3d::Identity();
        const Eigen::Matrix3d& G_p = rw.G_p;
        for (int sj = 0; sj < slot_count; ++sj) {
          const int j = slot_load[std::size_t(sj)];
          const Eigen::Matrix3d& Wij = m.W[std::size_t(i)][std::size_t(j)];
          M.template block<3, 3>(r, 3 * sj) += G * Wij + G_p;
          if (rw.stuck)
            M.template block<3, 3>(r, 3 * sj) -= rw.Gt * m.W_turn[std::size_t(i)][std::size_t(j)];
        }
        rhs.template segment<3>(r) = rw.rhs;
        if (reduced) continue;
        M.template block<3, 3>(r, ip) = G;
        M.template block<3, 3>(r, iw) = -G * rw.Rx;
        M.template block<3, 3>(ip, r) = -Eigen::Matrix3d::Identity();
        M.template block<3, 3>(iw, r) = rw.Rx;  // the contacts' moment sum r x F
      }
    };
    if (reduced) {
      // Where the only non-zero compliance block is one load's own (or none is), the system is
      // solved by its structure (contact_system.hpp): a tube lying in the groove touches floor
      // and walls at the held end, whose blocks are zero, and at its tip. Its blocks are tested
      // as they are, not inferred: the structure holds exactly when they are zero.
      int moving = -1;
      bool split = n_active >= 2;
      for (int si = 0; si < slot_count && split; ++si) {
        const int i = slot_load[std::size_t(si)];
        const Load& ld = loads[std::size_t(i)];
        const bool stuck = ld.friction && !ld.sliding;
        for (int sj = 0; sj < slot_count && split; ++sj) {
          const int j = slot_load[std::size_t(sj)];
          if (IsZeroBlock(m.W[std::size_t(i)][std::size_t(j)]) &&
              (!stuck || IsZeroBlock(m.W_turn[std::size_t(i)][std::size_t(j)])))
            continue;
          if (si != sj || moving >= 0)
            split = false;
          else
            moving = si;
        }
      }
      if (split) {
        std::array<Eigen::Matrix3d, kMaxLoads> C;
        std::array<Eigen::Vector3d, kMaxLoads> b;
        Eigen::Matrix3d A_moving = Eigen::Matrix3d::Identity();
        Rows rw;
        for (int si = 0; si < slot_count; ++si) {
          const int i = slot_load[std::size_t(si)];
          rows_of(loads[std::size_t(i)], rw);
          C[std::size_t(si)] = rw.G_p;
          b[std::size_t(si)] = rw.rhs;
          if (si != moving) continue;
          A_moving += rw.G * m.W[std::size_t(i)][std::size_t(i)];
          if (rw.stuck) A_moving -= rw.Gt * m.W_turn[std::size_t(i)][std::size_t(i)];
        }
        m.z.resize(n);
        SolveOneMoving(n_active, moving, A_moving, C, b, m.z);
      } else if (n == 3) {
        // Otherwise one load, two or three (most ticks) are assembled and factorised at fixed size,
        // the same partial pivoting in the same order (the same bits) without the dynamic one's
        // blocking and bookkeeping, which cost a 3 x 3 system ~700 instructions (and a 9 x 9 one,
        // three PCs in the groove, ~1500); the blocks' addresses then are constants too (assembled
        // into the dynamic matrix, the 9 x 9 system's assembly took ~500 instructions more).
        Eigen::Matrix3d M3 = Eigen::Matrix3d::Zero();
        Eigen::Vector3d rhs3 = Eigen::Vector3d::Zero();
        assemble(M3, rhs3);
        m.lu3.compute(M3);
        m.z = m.lu3.solve(rhs3);
      } else if (n == 6) {
        Eigen::Matrix<double, 6, 6> M6 = Eigen::Matrix<double, 6, 6>::Zero();
        Eigen::Matrix<double, 6, 1> rhs6 = Eigen::Matrix<double, 6, 1>::Zero();
        assemble(M6, rhs6);
        m.lu6.compute(M6);
        m.z = m.lu6.solve(rhs6);
      } else if (n == 9) {
        Eigen::Matrix<double, 9, 9> M9 = Eigen::Matrix<double, 9, 9>::Zero();
        Eigen::Matrix<double, 9, 1> rhs9 = Eigen::Matrix<double, 9, 1>::Zero();
        assemble(M9, rhs9);
        SolveFixed(m.lu9, M9, rhs9, m.z);
      } else if (n > 0) {
        m.M.setZero(n, n);
        m.rhs.setZero(n);
        assemble(m.M, m.rhs);
        m.lu.compute(m.M);
        m.z = m.lu.solve(m.rhs);
      } else {
        m.z.resize(0);
      }
      if (!m.z.allFinite()) return false;
      Eigen::Vector3d sum_F = Eigen::Vector3d::Zero();
      for (int k = 0; k < n_active; ++k) sum_F += m.z.segment<3>(3 * k);
      p_W = (A + sum_F) / Kc_eff;
      omega_W = e_grip;
      return p_W.allFinite();
    }
    m.M.setZero(n, n);
    m.rhs.setZero(n);
    assemble(m.M, m.rhs);
    m.M.block<3, 3>(ip, ip) = Kc_eff * Eigen::Matrix3d::Identity();
    m.rhs.segment<3>(ip) = A;
    {
      // Torque balance: sum r x F + tau = 0 with the grip's tau = tau_sat + k_reg (e - omega);
      // the weak k_reg (1e-3 of the full torque per radian) keeps omega defined about axes the
      // contacts do not hold, and adds at most k_reg times the lag to the torque.
      const double k_reg = 1e-3 * max_torque;
      m.M.block<3, 3>(iw, iw) = -k_reg * Eigen::Matrix3d::Identity();
      m.rhs.segment<3>(iw) = -torque_sat_W - k_reg * e_hand;
    }
    m.lu.compute(m.M);
    m.z = m.lu.solve(m.rhs);
    if (!m.z.allFinite()) return false;
    p_W = m.z.segment<3>(ip);
    omega_W = m.z.segment<3>(iw);
    return true;
  };
  // Whether this pass's motion keeps every left-out part's pieces beyond epsilon: then none of
  // their open loads would have closed in it (the open-load test below), and the tick is the
  // one it would have been with them in. A load point x moves by
  //     x - x0 = (p - p0) + omega x (x0 - p0) + sum_j W_ij (F_j - F_lin_j),
  // bounded with |x0 - p0| at most the farthest node plus the end piece and r1, and W_ij, for
  // a load that is not a member (an open one of an idle part: the linear compliance whatever
  // the model), by the tube's end (DisplacementBound). The offset of a load point from the
  // centreline at its arc position is r1 on a capsule; on the end cylinder, whose axis leaves
  // the centreline's chords within the end piece, at most r1 + 2 (end piece).
  double reach_m = 0.0, offset_m = 0.0;
  if (idle.group_count > 0) {
    double farthest_sq = 0.0;
    for (int k = 0; k <= N; ++k)
      farthest_sq = std::max(farthest_sq, m.nodes_H[std::size_t(k)].squaredNorm());
    const double end_m = m.collision.end_length_m();
    reach_m = std::sqrt(farthest_sq) + end_m + scene_.tube.outer_radius_m;
    offset_m = scene_.tube.outer_radius_m + 2.0 * end_m;
  }
  // How far this pass's motion may move a left-out group's pieces along their normals, per
  // group (IdleParts::Group); computed from the pass's solve, judged after its decisions.
  std::array<Eigen::Vector3d, kMaxLoads> df_H;
  std::array<double, IdleParts::kMaxGroups> idle_moved_m{};
  // The end's turn, frame H, under this pass's forces (slot, z), less last tick's: what the
  // dome's spring resists.
  const auto forces_turn = [&] {
    Eigen::Vector3d turn_H = -dome.theta0_H;
    for (int j = 0; j < load_count; ++j) {
      const int sj = slot[std::size_t(j)];
      if (sj >= 0 && member[std::size_t(j)])
        turn_H += dome.T_H[std::size_t(j)] * (R_WH.transpose() * m.z.segment<3>(3 * sj));
    }
    return turn_H;
  };
  // Along Q (the rod: the spring's moment, less).
  const auto dome_turn = [&] { return Eigen::Vector3d(dome.Q_H * forces_turn()); };
  const auto bound_idle_motion = [&] {
    if (idle.group_count == 0) return;
    // The dome's moment moves every point of the tube by C M (build_compliance).
    const double dome_moment_Nm = dome.load >= 0 ? dome.kappa * dome_turn().norm() : 0.0;
    for (int j = 0; j < load_count; ++j) {
      const int sj = slot[std::size_t(j)];
      const Eigen::Vector3d F =
          sj >= 0 ? Eigen::Vector3d(m.z.segment<3>(3 * sj)) : Eigen::Vector3d::Zero();
      df_H[std::size_t(j)] = R_WH.transpose() * (F - loads[std::size_t(j)].f_lin_W);
    }
    const Eigen::Vector3d dp_W = p_W - p_start_W;
    const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
    for (int g = 0; g < idle.group_count; ++g) {
      // The group's normals n (unit): P projects onto their span; |n . dp| <= |P dp|, and
      // |n . (omega x r)| = |r . (n x omega)| <= |r| |Q omega|, Q taking out omega's part along
      // n when n is one direction.
      // The projections are made from the axis in the held frame, a_H a_H^T, not turned there as
      // R^T P R: two 3x3 products a group and a pass fewer (sliding's tick, 3 % of it). Their
      // last bits may differ, which can only move a bound's last bits: a pass judged otherwise
      // at the margin is solved again with every part in, to the same bits.
      const IdleParts::Group& group = idle.groups[std::size_t(g)];
      const Eigen::Vector3d a_H = R_WH.transpose() * group.axis_W;
      const Eigen::Matrix3d aa_H = a_H * a_H.transpose();
      const Eigen::Matrix3d P_H = group.dims == 1   ? aa_H
                                  : group.dims == 2 ? Eigen::Matrix3d(I - aa_H)
                                                    : I;
      const Eigen::Matrix3d Q_H = group.dims == 1 ? Eigen::Matrix3d(I - aa_H) : I;
      const auto projected_norm = [&](const Eigen::Vector3d& v_W, bool onto_axis) {
        const double along = group.axis_W.dot(v_W);
        return onto_axis ? std::abs(along) : (v_W - along * group.axis_W).norm();
      };
      const double dp_m = group.dims == 3 ? dp_W.norm() : projected_norm(dp_W, group.dims == 1);
      const double omega_n = group.dims == 1 ? projected_norm(omega_W, false) : omega_W.norm();
      double moved_m = dp_m + omega_n * reach_m;
      // The linear model (build_compliance) takes last tick's shape out where its loads were:
      // W(i, now) F - W(i, then) F_lin is W(i, now) (F - F_lin) plus, where the load moved,
      // (W(i, now) - W(i, then)) F_lin; a load out of contact adds -W(i, then) F_lin.
      BeamLoad then_j;
      for (int j = 0; j < load_count; ++j) {
        const BeamLoad& now_j = m.beam_loads[std::size_t(j)];
        if (!want_elastica && !member[std::size_t(j)]) {
          if (reference_of(j, then_j))
            moved_m += m.beam.DisplacementBound(then_j, then_j.f_H_N, true, offset_m, group.s_max_m,
                                                P_H, Q_H);
          continue;
        }
        if (!df_H[std::size_t(j)].isZero(0.0))
          moved_m += m.beam.DisplacementBound(now_j, df_H[std::size_t(j)], !use_elastica, offset_m,
                                              group.s_max_m, P_H, Q_H);
        if (!want_elastica && reference_of(j, then_j) && moved(j, then_j))
          moved_m += m.beam.DisplacementChangeBound(now_j, then_j, then_j.f_H_N, true, offset_m,
                                                    group.s_max_m, P_H, Q_H);
      }
      if (dome.load >= 0)
        moved_m += m.beam.MomentDisplacementBound(m.beam_loads[std::size_t(dome.load)],
                                                  dome_moment_Nm, offset_m, group.s_max_m);
      idle_moved_m[std::size_t(g)] = moved_m;
    }
  };
  // Whether the pass's decisions would have been the same with the left-out parts in: their
  // loads would have come after the loads of the parts before them in the query and before the
  // rest (and the ghosts), and the decisions stop at the first load that changes. So a group is
  // judged when that load is of a later part, or none changed; it passes while its pieces stay
  // farther than epsilon.
  const auto idle_parts_stay_open = [&](int changed_load) {
    const std::uint32_t changed_part =
        changed_load < 0 || loads[std::size_t(changed_load)].ghost ||
                loads[std::size_t(changed_load)].part_element < 0
            ? std::numeric_limits<std::uint32_t>::max()
            : elements_[std::size_t(loads[std::size_t(changed_load)].part_element)].part_index;
    for (int g = 0; g < idle.group_count; ++g) {
      const IdleParts::Group& group = idle.groups[std::size_t(g)];
      if (group.first_part < changed_part &&
          !(idle_moved_m[std::size_t(g)] < group.gap_m - eps))  // NaN too
        return false;
    }
    return true;
  };
  // The normal force of load i's PC in the current solve: its points' together (a point that
  // pulls counts nothing; a ghost is a PC of its own). Friction is the PC's (FrictionShare).
  const auto pc_normal_of = [&](int i) {
    const Load& li = loads[std::size_t(i)];
    double total_N = 0.0;
    for (int sj = 0; sj < slot_count; ++sj) {
      const int j = slot_load[std::size_t(sj)];
      const Load& lj = loads[std::size_t(j)];
      if (j != i && (li.pc < 0 || lj.pc != li.pc)) continue;
      total_N += std::max(0.0, lj.normal_W.dot(m.z.segment<3>(3 * sj)));
    }
    return total_N;
  };
  // Where the anchors were before the solve: a sliding point's slip is its anchor's travel.
  for (int i = 0; i < load_count; ++i) {
    Load& ld = loads[std::size_t(i)];
    if (ld.friction) ld.anchor0_W = ld.anchor_W;
  }
  bool finite = true;
  for (int pass = 0; pass < kMaxPasses; ++pass) {
    finite = solve_system();
    if (!finite) break;
    bound_idle_motion();

    // Decisions: release a load that pulls, slide one beyond its friction limit, saturate the
    // coupling at the device's force. Each changes the system: solve again.
    bool changed = false;
    int changed_load = -1;  // the first load whose decision changed
    for (int i = 0; i < load_count && !changed; ++i) {
      const int si = slot[std::size_t(i)];
      Load& ld = loads[std::size_t(i)];
      if (si < 0) {
        if (ld.released) continue;
        // An open load: does this tick's motion bring it within epsilon?
        Eigen::Vector3d x = ld.base_W + p_W + omega_W.cross(ld.x0_W - p_start_W);
        for (int sj = 0; sj < slot_count; ++sj)
          x +=
              m.W[std::size_t(i)][std::size_t(slot_load[std::size_t(sj)])] * m.z.segment<3>(3 * sj);
        if (ld.distance_m + ld.normal_W.dot(x - ld.x0_W) < eps) {
          ld.active = true;
          changed = true;
          changed_load = i;
          if (!member[std::size_t(i)]) {
            build_compliance();  // it cuts the tube now
            build_stick_compliance();
          }
        }
        continue;
      }
      const Eigen::Vector3d F = m.z.segment<3>(3 * si);
      const double normal_N = ld.normal_W.dot(F);
      if (normal_N < 0.0 && ld.friction && !ld.sliding &&
          scene_.model.slip == scene::SlipRule::kReturnMapping) {
        // A stuck load that pulls slides first, and is released only if it still pulls then.
        // Its stuck spring may be what pulls it off: a tick starts stuck, and a trial friction far
        // beyond the limit (which is zero at N <= 0) drags the point away from the part. Released
        // for the rest of the tick, the tube then springs back through the part: the rim of a
        // tube drawn over an edge with mu = 2, bent 4 mm onto it, came off its corner this way
        // and straightened 2.4 mm into the part's far face (`stability --only "roll over an edge
        // mu=2"`); sliding, the contact kept pressing.
        const Eigen::Vector3d Ft = F - normal_N * ld.normal_W;
        if (Ft.norm() > 0.0) {
          ld.sliding = true;
          ld.slide_dir_W = Ft / Ft.norm();
          LineariseKinetic(*ld.friction, 0.0, 0.0, ld.slide_a, ld.slide_b);
          changed = true;
          changed_load = i;
          continue;
        }
      }
      if (normal_N < 0.0) {
        ld.active = false;
        ld.released = true;  // once released in a tick it stays open: no cycling
        changed = true;
        changed_load = i;
        // The linear model's cuts are the loads in contact; the nonlinear models' are those that
        // carried force last tick too, so only a load that joined this tick leaves them.
        if (!want_elastica || ld.f_lin_W.isZero(0.0)) {
          build_compliance();
          build_stick_compliance();
        }
        break;
      }
      if (!ld.friction) continue;
      const Eigen::Vector3d Ft = F - normal_N * ld.normal_W;
      const double pc_normal_N = pc_normal_of(i);
      if (!ld.sliding) {
        const FrictionResult fr = ReturnMap(*ld.friction, Ft, normal_N, pc_normal_N, Kt);
        if (!fr.sliding) continue;
        if (scene_.model.slip == scene::SlipRule::kPaper && !ld.shifted) {
          // The paper: the contact point moves with the held end's tangential motion, then the
          // force is computed again (and limited below if that is still not enough).
          const Eigen::Vector3d dp = p_W - m.p_held_prev_W;
          ld.anchor_W += dp - ld.normal_W * ld.normal_W.dot(dp);
          ld.shifted = true;
        } else {
          ld.sliding = true;
          ld.slide_dir_W = Ft / Ft.norm();  // |Ft| > f_s >= 0
          LineariseKinetic(*ld.friction, normal_N, pc_normal_N, ld.slide_a, ld.slide_b);
        }
        changed = true;
        changed_load = i;
      } else {
        // Newton on the kinetic law: relinearise f_k where the normal force now is.
        const double fk =
            FrictionShare(*ld.friction, ld.friction->kinetic_coefficient, normal_N, pc_normal_N);
        if (std::abs(fk - (ld.slide_a + ld.slide_b * normal_N)) > 1e-9 * (1.0 + fk)) {
          LineariseKinetic(*ld.friction, normal_N, pc_normal_N, ld.slide_a, ld.slide_b);
          changed = true;
          changed_load = i;
        }
      }
    }
    if (!idle_parts_stay_open(changed_load)) return false;
    if (changed) {
      // The contact set changed: saturation is decided again on the new solution.
      A = A_free;
      torque_saturated = false;
      saturated = force_saturated = false;
      e_grip = e_hand;
      turn_limited = false;
    } else if (cap_turn()) {
      turn_limited = true;
      changed = true;
    } else if (!torque_saturated && !turn_limited) {
      Eigen::Vector3d moment_W = Eigen::Vector3d::Zero();
      for (int si = 0; si < slot_count; ++si) {
        const Load& ld = loads[std::size_t(slot_load[std::size_t(si)])];
        moment_W += (ld.x0_W - p_start_W).cross(m.z.segment<3>(3 * si));
      }
      if (moment_W.norm() > max_torque * (1.0 + 1e-12)) {
        // The grip cannot hold more than the device's torque: the held end turns until the
        // contacts' moment is exactly that.
        torque_sat_W = -moment_W * (max_torque / moment_W.norm());
        torque_saturated = true;
        saturated = true;
        changed = true;
      }
    }
    if (!changed) {
      const Eigen::Vector3d coupling_W = A - Kc_eff * p_W;
      const double magnitude = coupling_W.norm();
      if (magnitude > max_force * (1.0 + 1e-12)) {
        // The spring cannot pull harder than the device can push: its hand end moves towards
        // the proxy until it carries exactly the device's maximum; the proxy separates.
        A = Kc_eff * p_W + coupling_W * (max_force / magnitude);
        saturated = force_saturated = true;
        changed = true;
      }
    }
    if (!changed) {
      solved = true;
      break;
    }
  }
  // Decisions that keep changing (a contact cycling between open and closed within one tick,
  // which only pinched, stiff states do) stop after kMaxPasses: the last decisions stand and the
  // system is solved once more for them.
  if (!solved && finite) {
    solved = solve_system();
    if (solved && cap_turn()) solved = solve_system();
    // The device's force still bounds the coupling, whatever the contacts decided: saturate on
    // these decisions (a few passes: each moves the proxy, which changes the stretch).
    for (int pass = 0; solved && pass < 4; ++pass) {
      const Eigen::Vector3d coupling_W = A - Kc_eff * p_W;
      const double magnitude = coupling_W.norm();
      if (!(magnitude > max_force * (1.0 + 1e-12))) break;
      A = Kc_eff * p_W + coupling_W * (max_force / magnitude);
      saturated = force_saturated = true;
      solved = solve_system();
    }
  }
  // A solve that carries the held end farther in one tick than the coupling alone would (the
  // sweep, step 2) plus the tube's length describes no motion of the tube: its system was near
  // singular. Seen with three PCs, the rod's shape off its contacts and a soft penalty (the
  // accuracy study's two PCs at K = 1e3 N/m): the held end went to 1.6e23 m, finite, and every
  // later tick started from there. Treated as singular.
  if (solved && !((p_W - p_start_W).norm() <= sweep_m + scene_.tube.length_m)) solved = false;
  if (saturated) out.flags |= kProxySeparated;
  if (!solved) {
    // Singular, not finite or undecided: nothing moves and nothing is sent this tick.
    out.flags |= kSolverFault;
    out.force_W_N.setZero();
    out.torque_W_Nm.setZero();
    out.contact_count = 0;
    m.p_hand_prev_W = p_hand_W;
    m.prev_count = 0;  // start the next tick afresh rather than repeat this one
    return true;
  }

  // The held end's new orientation: last tick's turned by omega.
  const double turn = omega_W.norm();
  const Eigen::Matrix3d R_WH_new =
      Eigen::Quaterniond((turn > 0.0 ? Eigen::AngleAxisd(turn, omega_W / turn).toRotationMatrix()
                                     : Eigen::Matrix3d::Identity()) *
                         R_WH)
          .normalized()
          .toRotationMatrix();

  // Last guards, for decisions that did not settle (a settled tick passes both unchanged).
  // A stuck load left beyond its friction limit has its friction cut to the limit. Then, if the
  // sum of the contact forces (the operator's force) is above the device's maximum that the
  // saturation aims at, every contact force is scaled down by one factor: the wrench stays the
  // sum of the contact wrenches, each normal force within its penalty law and each friction
  // within its limit (f_max grows no faster than N when beta <= 1). Flagged kForceClamped.
  std::array<Eigen::Vector3d, kMaxLoads> f_load_W;
  Eigen::Vector3d total_W = Eigen::Vector3d::Zero();
  for (int i = 0; i < load_count; ++i) {
    Load& ld = loads[std::size_t(i)];
    const int si = slot[std::size_t(i)];
    Eigen::Vector3d& F = f_load_W[std::size_t(i)];
    F = si >= 0 ? Eigen::Vector3d(m.z.segment<3>(3 * si)) : Eigen::Vector3d::Zero();
    if (si >= 0 && ld.normal_W.dot(F) < 0.0) {
      // A load still pulling is released, as a decision would have: a penalty contact cannot
      // pull, and its friction limit is zero. Kept, it was a PC of no normal force that pulled
      // (2.3 N, 1.55 mm off its part, with 2e-14 N of friction over its limit of zero: the random
      // states' invariants test).
      F.setZero();
      ld.active = false;
      ld.released = true;
    } else if (ld.friction && si >= 0) {
      const double normal_N = std::max(0.0, ld.normal_W.dot(F));
      const Eigen::Vector3d Ft = F - ld.normal_W.dot(F) * ld.normal_W;
      const double limit_N =
          FrictionShare(*ld.friction, ld.friction->static_coefficient, normal_N, pc_normal_of(i));
      if (Ft.norm() > limit_N) F -= Ft * (1.0 - limit_N / Ft.norm());
    }
    total_W += F;
  }
  if (total_W.norm() > max_force * (1.0 + 1e-9)) {
    const double scale = max_force / total_W.norm();
    for (int i = 0; i < load_count; ++i) f_load_W[std::size_t(i)] *= scale;
    force_saturated = true;
  }

  // 7. Results per load; a sliding load's anchor follows it (the spring then carries f_k).
  Eigen::Vector3d force_W = Eigen::Vector3d::Zero(), torque_W = Eigen::Vector3d::Zero();
  // The dome's point moves with the end's turn under its spring, -R turn x z (build_compliance),
  // kept on the face (within r1 of its centre, where the dome meets the rim).
  Eigen::Vector3d dome_shift_H = Eigen::Vector3d::Zero();
  if (dome.load >= 0 && loads[std::size_t(dome.load)].active) {
    // The end's turn along Q under the spring (its turn across Q is not resisted, and does not
    // move the point: the rim's radial direction).
    const Eigen::Vector3d turn_H =
        want_elastica ? Eigen::Vector3d(dome.turn_of_turn_H * forces_turn())
                      : Eigen::Vector3d(dome_turn() / (1.0 + dome.k_r * dome.turn_per_moment));
    const Load& ld = loads[std::size_t(dome.load)];
    const Eigen::Vector3d from_H = ld.r_H_m - dome.axis_H.dot(ld.r_H_m) * dome.axis_H;
    Eigen::Vector3d to_H = from_H - dome.radius_m * turn_H.cross(dome.axis_H);
    const double r1 = scene_.tube.outer_radius_m;
    const double to_m = to_H.norm();
    if (to_m > r1 || (ld.tube != states::TubeElement::kEndFace && to_m > 0.0)) to_H *= r1 / to_m;
    dome_shift_H = to_H - from_H;
  }
  int beam_count = 0;
  for (int i = 0; i < load_count; ++i) {
    Load& ld = loads[std::size_t(i)];
    // An open load's point, where the stuck spring saw it, its distance and its anchor are not
    // computed: nothing reads them. The next tick takes a stretch only from a load that was
    // active (carried_stretch), and an open load carries no force, so it leaves no ghost (three
    // of the six loads of three PCs in the groove, ~600 instructions a tick).
    if (ld.active) {
      ld.x_W = ld.base_W + p_W + omega_W.cross(ld.x0_W - p_start_W);
      for (int sj = 0; sj < slot_count; ++sj)
        ld.x_W +=
            m.W[std::size_t(i)][std::size_t(slot_load[std::size_t(sj)])] * m.z.segment<3>(3 * sj);
      // Where the stuck spring saw the point (section 5): without the one-way turn of its offset.
      ld.stick_x_W = ld.x_W + (ld.stick_base_W - ld.base_W);
      for (int sj = 0; sj < slot_count && ld.friction; ++sj)
        ld.stick_x_W -= m.W_turn[std::size_t(i)][std::size_t(slot_load[std::size_t(sj)])] *
                        m.z.segment<3>(3 * sj);
      // The tangent at the tick's start (the shape is drawn again only in step 8), which the next
      // tick turns the point's offset with: read only of an active load whose spring saw the
      // turn (carried_stretch). Taken for every load in step 5 it cost three PCs in the groove,
      // whose elastica's spring sees no turn, ~410 instructions a tick.
      if (ld.turn_seen) ld.tangent0_W = tangent_at(ld.s_m);
    }
    if (i == dome.load) {
      // The pressure moves over the face, the material does not slip: the point, where it
      // started and its anchor move together, and the stretch stays.
      const Eigen::Vector3d shift_W = R_WH * dome_shift_H;
      ld.cop_H_m += dome_shift_H;
      ld.r_H_m += dome_shift_H;
      ld.x0_W += shift_W;
      ld.x_W += shift_W;
      ld.stick_x_W += shift_W;
      ld.anchor_W += shift_W;
    }
    ld.force_W = f_load_W[std::size_t(i)];
    ld.shape_force_W = ld.force_W;
    if (!ld.active) continue;
    ld.distance_m += ld.normal_W.dot(ld.x_W - ld.x0_W);
    if (!ld.friction) {
      ld.anchor_W = ld.stick_x_W;
    } else if (ld.sliding) {
      const Eigen::Vector3d Ft = ld.force_W - ld.normal_W.dot(ld.force_W) * ld.normal_W;
      ld.anchor_W = ld.stick_x_W + Ft / Kt;
    }
    force_W += ld.force_W;
    torque_W += (ld.x_W - p_W).cross(ld.force_W);
    m.predicted_H[std::size_t(beam_count)] = R_WH_new.transpose() * (ld.x_W - p_W) - ld.r_H_m;
    m.beam_loads[std::size_t(beam_count++)] =
        BeamLoad{ld.s_m, R_WH.transpose() * ld.force_W, ld.r_H_m, 0.0, 0, ld.pc};
  }

  // PCs: those with an active load, aggregated over their loads, in canonical order.
  int kept = 0;
  for (int k = 0; k < found_count; ++k) {
    ContactState pc;
    pc.tube = found[std::size_t(k)].tube;
    pc.part_element = found[std::size_t(k)].part_element;
    pc.distance_m = std::numeric_limits<double>::infinity();
    const scene::Friction* friction = nullptr;
    double pc_normal_N = 0.0;  // the share each point's friction ratio is taken against
    for (int i = 0; i < load_count; ++i) {
      const Load& ld = loads[std::size_t(i)];
      if (ld.pc == k && ld.active) pc_normal_N += std::max(0.0, ld.normal_W.dot(ld.force_W));
    }
    for (int i = 0; i < load_count; ++i) {
      const Load& ld = loads[std::size_t(i)];
      if (ld.pc != k || !ld.active) continue;
      ++pc.loads;
      friction = ld.friction;
      const double normal_N = std::max(0.0, ld.normal_W.dot(ld.force_W));
      const Eigen::Vector3d Ft = ld.force_W - ld.normal_W.dot(ld.force_W) * ld.normal_W;
      pc.normal_force_N += normal_N;
      pc.friction_W_N += Ft;
      pc.force_W_N += ld.force_W;
      pc.moment_W_Nm += (ld.x_W - p_W).cross(ld.force_W);
      pc.sliding = pc.sliding || ld.sliding;
      // The kinetic force on the tube opposes the point's slip, along which the anchor follows.
      if (ld.sliding) pc.friction_work_J += std::max(0.0, -Ft.dot(ld.anchor_W - ld.anchor0_W));
      if (ld.friction) {
        const double limit =
            FrictionShare(*ld.friction, ld.friction->static_coefficient, normal_N, pc_normal_N);
        const double ratio = limit > 0.0 ? Ft.norm() / limit : (Ft.norm() > 0.0 ? 1.0 : 0.0);
        pc.friction_ratio = std::max(pc.friction_ratio, ratio);
      }
      if (ld.distance_m < pc.distance_m) {
        pc.distance_m = ld.distance_m;
        pc.normal_W = ld.normal_W;
        pc.p_WC_m = ld.x_W;
        pc.s_m = ld.s_m;
      }
    }
    if (pc.loads == 0) continue;
    pc.friction_limit_N =
        friction ? FrictionLimit(*friction, friction->static_coefficient, pc.normal_force_N) : 0.0;
    int at = kept++;
    while (at > 0) {
      const ContactState& before = out.contacts[std::size_t(at - 1)];
      const bool in_order =
          before.tube != pc.tube ? before.tube < pc.tube : before.part_element < pc.part_element;
      if (in_order) break;
      out.contacts[std::size_t(at)] = before;
      --at;
    }
    out.contacts[std::size_t(at)] = pc;
  }
  out.contact_count = kept;

  for (State::ElasticaTangent& t : m.tangents) t.age = std::min(t.age + 1, kTangentReuseTicks);
  m.rod_tangent_age = std::min(m.rod_tangent_age + 1, kTangentReuseTicks);

  // 8. The shape under the solved loads: the next tick's capsules, energy, strain, markers.
  m.beam_count = beam_count;
  std::array<bool, kMaxLoads> all{};
  all.fill(true);
  int members = 0;
  const int groups = m.beam.Assign(m.beam_loads, beam_count, all, m.order, members);
  for (int i = 0, k = 0; i < load_count; ++i)
    if (loads[std::size_t(i)].active)
      loads[std::size_t(i)].clamp_m = m.beam_loads[std::size_t(k++)].clamp_m;
  double load_N = 0.0;
  for (int j = 0; j < beam_count; ++j) load_N += m.beam_loads[std::size_t(j)].f_H_N.norm();
  if (m.elastica_held_off && load_N < 0.5 * m.held_off_load_N) m.elastica_held_off = false;
  m.elastica_shape = want_elastica && !m.elastica_held_off && beam_count > 0 &&
                     m.beam.ElasticaCovers(m.beam_loads, m.order, beam_count, groups);
  if (m.elastica_shape) {
    m.segment_count = m.beam.SolveElasticaChain(m.beam_loads, beam_count, m.order, m.segments);
    m.beam.ElasticaNodes(m.segments, m.segment_count,
                         std::span<Eigen::Vector3d>(m.nodes_H.data(), std::size_t(N) + 1));
    // The tick's system moved each load point with the elastica's tangent; the elastica itself
    // must put it there too, within the contact band. Past a buckling load (the tube pushed
    // along its axis onto a wall, or pinched) the first mode the elastica solves for is not the
    // state the contacts hold: it swings the tip away by centimetres, the contact opens, the
    // tube springs back straight through the wall and the cycle repeats. The linear model, which
    // carries an axial push as a strut, takes over (flagged) until the loads fall back.
    if (!shape_follows_loads(beam_count)) {
      m.elastica_shape = false;
      m.elastica_held_off = true;
      m.held_off_load_N = load_N;
    }
  }
  // Where the elastica does not cover the loading, or is held off, the rod shapes the tube.
  m.rod_shape = false;
  if (want_elastica && beam_count > 0 && !m.elastica_shape) {
    // The solve draws the nodes on its way (a converged chain's shape, as RodNodes would).
    m.rod_segment_count =
        m.beam.SolveRodChain(m.beam_loads, beam_count, m.order, m.rod_segments,
                             std::span<Eigen::Vector3d>(m.nodes_H.data(), std::size_t(N) + 1));
    m.rod_shape = m.rod_segment_count > 0;
  }
  if (m.rod_shape) {
    // The rod draws the shape under the tick's forces as dead loads. Past the free end's Euler
    // load a cantilever under a dead axial load is unstable: its points move by metres per newton
    // sideways, and a force within the solve's rounding puts the shape off the points the tick's
    // system held, though the contacts pin it there (the rubber tube pushed onto a wall 0.1 mm
    // off its axis: 0.07, 0.75, 6.3 mm in three ticks, `stability --only "push into a wall
    // off-plane"`). Where the shape is off sideways by more than eps / 10 (the capsule count's
    // tolerance), the loads the shape is drawn under are corrected by Newton with the rod's
    // tangent (each step backtracked until it brings the shape closer) until it passes through
    // those points, if that takes a small change, 1 % of the loads: the shape the tick's system
    // solved for, under the forces it solved within that. The tick's forces stay as solved,
    // but the next tick linearises about this shape, so about the forces it was drawn under
    // (shape_force_W): linearised about the solved forces instead, x = x0 + W (F - F_lin) took
    // a shape and a force that do not belong together, and the two drifted apart tick by tick
    // (the rubber tube slid along a wall with its tip stuck and 4 N on it: the pin's change of
    // the lateral load grew from 0.036 to 0.040 N in four ticks, a quarter of that load, until
    // it passed the 1 % bound, the pin was refused and the tube snapped, tick 550).
    // Where that is refused and the chain is one segment, the rod is solved with the load points'
    // sideways forces unknown (model::Rod::SolvePinned), from last tick's end frame: Newton on the
    // end's turn and those forces together, under the same bound. At the free end's Euler load
    // the dead-load solve lands on its buckled branch, 13.9 mm off (the push 0.1 mm off its axis,
    // tick 82), and the Newton on the forces alone, stepping from that shape, got it to 6.5 mm
    // and was refused; held, the column stays straight to its own buckling load (7.3 N, tick
    // 415), the loads changed by 0.04-0.6 mN a tick.
    // Refused (the dead-load shape kept, flagged shape_off as before): a snap, whose shape no
    // small change reaches, such as the held column's own buckling.
    const auto worst_off = [&] {
      double off_m = 0.0;
      for (int j = 0; j < beam_count; ++j) {
        const double here_m =
            (interpolate_node(m.beam_loads[std::size_t(j)].s_m) - m.predicted_H[std::size_t(j)])
                .head<2>()
                .norm();
        // NaN is off, not passed over (std::max would keep the finite one).
        off_m = here_m <= off_m
                    ? off_m
                    : (std::isnan(here_m) ? std::numeric_limits<double>::infinity() : here_m);
      }
      return off_m;
    };
    const double pin_tolerance_m = 0.1 * eps;
    const double dead_off_m = worst_off();
    if (dead_off_m > pin_tolerance_m) {
      std::array<Eigen::Vector3d, kMaxLoads> f_dead_H;
      double f_total_N = 0.0;
      for (int j = 0; j < beam_count; ++j) {
        f_dead_H[std::size_t(j)] = m.beam_loads[std::size_t(j)].f_H_N;
        f_total_N += f_dead_H[std::size_t(j)].norm();
      }
      m.rod_segments_dead = m.rod_segments;
      m.nodes_dead_H = m.nodes_H;
      const int segments_dead = m.rod_segment_count;
      bool pinned = false;
      double change_N = 0.0, last_off_m = dead_off_m;
      const double change_bound_N = 1e-2 * f_total_N;
      const int n = 2 * beam_count;
      for (int iteration = 0; iteration < 4 && !pinned; ++iteration) {
        for (auto& row : m.W_pin) row.fill(Eigen::Matrix3d::Zero());
        bool ok = true;
        for (int g = 0; g < m.rod_segment_count && ok; ++g)
          ok = m.beam.RodCompliance(m.rod_segments[std::size_t(g)], m.W_pin);
        if (!ok) break;
        // Sideways only (x, y of H): the rod does not stretch, so where its length puts a point
        // along the axis no force moves it (the system's linearised shortening differs from the
        // rod's by the step's second order).
        m.M.setZero(n, n);
        m.rhs.setZero(n);
        for (int i = 0; i < beam_count; ++i) {
          for (int j = 0; j < beam_count; ++j)
            m.M.block<2, 2>(2 * i, 2 * j) =
                m.W_pin[std::size_t(i)][std::size_t(j)].topLeftCorner<2, 2>();
          m.rhs.segment<2>(2 * i) =
              (m.predicted_H[std::size_t(i)] - interpolate_node(m.beam_loads[std::size_t(i)].s_m))
                  .head<2>();
        }
        m.lu.compute(m.M);
        m.z = m.lu.solve(m.rhs);
        if (!m.z.allFinite()) break;
        // The step, or a half, a quarter or an eighth of it, each solved from the rod's solution
        // before it, must bring the shape closer: at the free end's buckling load the full step
        // can land the rod on its buckled branch, centimetres off.
        std::array<Eigen::Vector3d, kMaxLoads> f_step_H;
        for (int j = 0; j < beam_count; ++j)
          f_step_H[std::size_t(j)] = m.beam_loads[std::size_t(j)].f_H_N;
        m.rod_segments_step = m.rod_segments;
        const int segments_step = m.rod_segment_count;
        double off_m = last_off_m;
        bool closer = false;
        for (const double fraction : {1.0, 0.5, 0.25, 0.125}) {
          m.rod_segments = m.rod_segments_step;
          m.rod_segment_count = segments_step;
          for (int j = 0; j < beam_count; ++j) {
            m.beam_loads[std::size_t(j)].f_H_N = f_step_H[std::size_t(j)];
            m.beam_loads[std::size_t(j)].f_H_N.head<2>() += fraction * m.z.segment<2>(2 * j);
          }
          m.rod_segment_count = m.beam.SolveRodChain(
              m.beam_loads, beam_count, m.order, m.rod_segments,
              std::span<Eigen::Vector3d>(m.nodes_H.data(), std::size_t(N) + 1));
          if (m.rod_segment_count <= 0) continue;
          off_m = worst_off();
          if (off_m < last_off_m) {
            closer = true;
            break;
          }
        }
        if (!closer) break;
        change_N = 0.0;
        for (int j = 0; j < beam_count; ++j)
          change_N += (m.beam_loads[std::size_t(j)].f_H_N - f_dead_H[std::size_t(j)]).norm();
        // A change beyond the bound is not a shape within reach of the tick's forces (a snap).
        if (!(change_N <= change_bound_N)) break;
        last_off_m = off_m;
        pinned = off_m <= pin_tolerance_m;
      }
      const auto restore_dead = [&] {
        for (int j = 0; j < beam_count; ++j)
          m.beam_loads[std::size_t(j)].f_H_N = f_dead_H[std::size_t(j)];
        m.rod_segments = m.rod_segments_dead;
        m.nodes_H = m.nodes_dead_H;
        m.rod_segment_count = segments_dead;
      };
      pinned = pinned && change_N <= change_bound_N;
      if (!pinned) {
        restore_dead();
        // The pinned solve (above): from last tick's end frame, where the column still stood.
        if (m.beam.SolveRodPinned(
                m.beam_loads, beam_count, m.order, m.rod_segments, rod_start_end_R, m.predicted_H,
                std::span<Eigen::Vector3d>(m.nodes_H.data(), std::size_t(N) + 1))) {
          m.rod_segment_count = 1;
          change_N = 0.0;
          for (int j = 0; j < beam_count; ++j)
            change_N += (m.beam_loads[std::size_t(j)].f_H_N - f_dead_H[std::size_t(j)]).norm();
          pinned = worst_off() <= pin_tolerance_m && change_N <= change_bound_N;
          if (!pinned) restore_dead();
        }
      }
      if (pinned) {
        for (int i = 0, k = 0; i < load_count; ++i)
          if (loads[std::size_t(i)].active)
            loads[std::size_t(i)].shape_force_W = R_WH * m.beam_loads[std::size_t(k++)].f_H_N;
      }
    }
  }
  const double EI = m.beam.bending_stiffness_Nm2();
  const double r1 = scene_.tube.outer_radius_m;
  double energy_J = 0.0, strain = 0.0;
  const auto bend_at = [&](double s) {
    // Where the tube curves to at s (lateral, H): the loads beyond s on its cantilever, each
    // force by its lever and each offset moment turned into the direction it bends towards.
    Eigen::Vector3d bend = Eigen::Vector3d::Zero();
    for (int j = 0; j < beam_count; ++j) {
      const BeamLoad& b = m.beam_loads[std::size_t(j)];
      if (!(b.clamp_m <= s && s < b.s_m)) continue;
      const Eigen::Vector3d moment = b.r_H_m.cross(b.f_H_N);
      // (L F and (L M) x e_z written out: the lateral projection's products add only zeros,
      // which change no sum but a zero's sign, which neither the bend's norm (the strain) nor
      // its comparisons with zero (the markers) see; ~390 instructions a three-PC tick.)
      const double lever_m = b.s_m - s;
      bend += Eigen::Vector3d(lever_m * b.f_H_N.x() + moment.y(),
                              lever_m * b.f_H_N.y() - moment.x(), 0.0);
    }
    return bend;
  };
  if (m.elastica_shape) {
    m.tip_tangent_H = m.beam.ElasticaTipTangent(m.segments, m.segment_count);
    for (int g = 0; g < m.segment_count; ++g) {
      const ElasticaSegment& seg = m.segments[std::size_t(g)];
      if (!(seg.length_m > 0.0)) continue;
      energy_J += EI / seg.length_m * seg.solution.tip.energy;
      strain = std::max(strain, r1 * std::abs(seg.solution.tip.root_curvature) / seg.length_m);
    }
  } else if (m.rod_shape) {
    m.segment_count = 0;
    m.tip_tangent_H = m.beam.RodTipTangent(m.rod_segments, m.rod_segment_count);
    for (int g = 0; g < m.rod_segment_count; ++g) {
      const model::RodSolution& solution = m.rod_segments[std::size_t(g)].solution;
      energy_J += solution.energy_J;
      strain = std::max(strain, r1 * solution.max_moment_Nm / EI);
    }
  } else {
    m.segment_count = 0;
    Eigen::Vector3d rotation = Eigen::Vector3d::Zero();
    for (int k = 0; k <= N; ++k) {
      const double s = l * k / N;
      Eigen::Vector3d x = Eigen::Vector3d(0.0, 0.0, s);
      for (int j = 0; j < beam_count; ++j)
        x += m.beam.CentreDisplacement(s, m.beam_loads[std::size_t(j)]);
      m.nodes_H[std::size_t(k)] = x;
    }
    for (int j = 0; j < beam_count; ++j)
      rotation += m.beam.SectionRotation(l, m.beam_loads[std::size_t(j)]);
    m.tip_tangent_H =
        (Eigen::Vector3d::UnitZ() + rotation.cross(Eigen::Vector3d::UnitZ())).normalized();
    // U = 1/2 sum over loads on one cantilever of F_i . W_ij F_j: the work of the loads.
    for (int i = 0; i < beam_count; ++i)
      for (int j = 0; j < beam_count; ++j) {
        const BeamLoad& a = m.beam_loads[std::size_t(i)];
        const BeamLoad& b = m.beam_loads[std::size_t(j)];
        if (a.clamp_m == b.clamp_m)
          energy_J += 0.5 * a.f_H_N.dot(m.beam.Compliance(a, b) * b.f_H_N);
      }
    // The bending moment is piecewise linear between clamps and load points (with jumps at the
    // offset moments): its largest value is at one of them, from either side.
    for (int c = 0; c < 2 * beam_count; ++c) {
      const BeamLoad& at = m.beam_loads[std::size_t(c % beam_count)];
      const double s = c < beam_count ? at.clamp_m : at.s_m;
      for (const double side : {s, s - 1e-9 * l}) {
        if (side < 0.0) continue;
        strain = std::max(strain, r1 * bend_at(side).norm() / EI);
      }
    }
  }
  if (m.rod_shape) out.flags |= kRodShape;
  if (want_elastica && beam_count > 0 && !m.elastica_shape && !m.rod_shape)
    out.flags |= kLinearFallback;
  // The elastica's shape is held to the tick's system above; the rod's and the fallback's are
  // only checked. Past this tolerance the tick's compliance was not the shape's: measured, the
  // first failing tick of the stability sweep's squeeze and slide cases (docs/accuracy.md).
  if (want_elastica && !m.elastica_shape && !shape_follows_loads(beam_count))
    out.flags |= kShapeOffContacts;
  if (beam_count == 0) m.elastica_held_off = false;
  out.energy_J = energy_J;
  out.max_strain = strain;
  out.tip_deflection_m = m.nodes_H[std::size_t(N)].head<2>().norm();
  // The linear shape is a small-deflection model: at a tip deflection of l/3 (a tip load's
  // alpha = F l^2 / (E I) = 1) it is 10 % off the exact elastica, and beyond it the deflection
  // grows without bound, the tube drawn longer than it is (docs/core.md). Flagged, so that a
  // replay that went there is not taken for the tube's motion.
  if (!m.elastica_shape && !m.rod_shape && out.tip_deflection_m > l / 3.0)
    out.flags |= kBeyondLinearRange;
  // The segmented rule's error: a load on a later segment bends no segment before it, so the
  // displacement it causes at an earlier load point on the one cantilever from the held end is
  // left out. Estimated with the linear influence coefficients (whatever model shapes the tube:
  // the estimate of an error, as the capsule count's sagitta is), and compared with eps / 10.
  out.segmentation_error_m = 0.0;
  if (scene_.model.multi_contact == scene::MultiContactRule::kSegmented && groups > 1) {
    for (int i = 0; i < beam_count; ++i) {
      const BeamLoad& at = m.beam_loads[std::size_t(i)];
      Eigen::Vector3d left_out_m = Eigen::Vector3d::Zero();
      for (int j = 0; j < beam_count; ++j) {
        // (Copied only past the test: most loads share the clamp.)
        if (!(m.beam_loads[std::size_t(j)].clamp_m > at.clamp_m)) continue;
        BeamLoad beyond = m.beam_loads[std::size_t(j)];
        beyond.clamp_m = 0.0;
        left_out_m += m.beam.CentreDisplacement(at.s_m, beyond);
      }
      out.segmentation_error_m = std::max(out.segmentation_error_m, left_out_m.norm());
    }
    if (out.segmentation_error_m > 0.1 * eps) out.flags |= kSegmentationOff;
  }

  // Markers (contact-states.md): no bending below the threshold; the end face and rim never
  // deform; a side contact is concave or convex by the side of the bend it touches, judged by
  // where the tube curves midway along the piece of cantilever that ends at it.
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
    // Judged from the PC's far end: for a side along a face, carried at both ends of its region,
    // midway between the two. From its deepest point, the lo end when the tube's held end lies
    // lowest, the bend was read at the clamp, where it is the small difference of the loads'
    // moments: the shipped insertion's side on the floor flipped between convex and concave
    // there from tick to tick.
    double end_m = pc.s_m;
    for (int j = 0; j < load_count; ++j) {
      const Load& ld = loads[std::size_t(j)];
      if (ld.active && ld.tube == pc.tube && ld.part_element == pc.part_element)
        end_m = std::max(end_m, ld.s_m);
    }
    double before_m = 0.0;
    for (int j = 0; j < beam_count; ++j) {
      const double sj = m.beam_loads[std::size_t(j)].s_m;
      if (sj < end_m - m.beam.group_tolerance_m()) before_m = std::max(before_m, sj);
    }
    const Eigen::Vector3d bend = bend_at(0.5 * (before_m + end_m));
    const Eigen::Vector3d normal_H = R_WH.transpose() * pc.normal_W;
    const Eigen::Vector3d n_H(normal_H.x(), normal_H.y(), 0.0);  // lateral, as the bend
    const double side = bend.dot(n_H);
    // Curving along the normal (away from the part): the part touches the outside of the bend.
    if (side > 1e-9 * bend.norm())
      pc.marker = states::Marker::kConvex;
    else if (side < -1e-9 * bend.norm())
      pc.marker = states::Marker::kConcave;
    else
      pc.marker = states::Marker::kBent;
  }

  // Through a part: the tick's shape puts a centreline point more than r1 / 2 inside a part
  // (there the tube is going through it: the penalty pressed its surface in by 1.5 r1), or its
  // centreline across a sheet thinner than r1 (the fast pass's 1 mm wall, which has no such
  // inside: a buckled tube that snapped back straight went through it), from a shape that did
  // not. The proxy is placed where the contacts allow (issue 3): the tube is not
  // moved there. It stays as it was, the held end too, and the operator feels the coupling's
  // spring and damper stretched from the held end to the hand, up to the device's force: a wall.
  // The tick's loads were solved with a compliance its shape did not follow (the segmented
  // rule's cut bending the tube with one of two pinching loads, a piece with no load in the tick
  // bent into a part: docs/accuracy.md); the next ticks try again from the state kept.
  // The elastica's and the rod's shapes keep the tube's length: their nodes are at most l / N
  // apart (chords of arcs that long; 10 % more allows for the elastica's Hermite interpolation
  // between exact samples, whose error is far below that), which lets the check bound them by
  // every fourth. The linear model's nodes need not be: all are taken.
  const double spacing_m = (m.elastica_shape || m.rod_shape) ? 1.1 * l / N : 0.0;
  // Judged whether or not the guard is on, so that a shape already inside when it is turned on
  // (or restored from a snapshot of a core without it) is not held.
  const bool inside = m.collision.AxisThrough(
      std::span<const Eigen::Vector3d>(m.nodes_H.data(), std::size_t(N) + 1), R_WH_new, p_W,
      0.5 * scene_.tube.outer_radius_m, spacing_m);
  if (m.hold_out_of_parts && inside && !m.axis_inside && p_W.allFinite() && R_WH_new.allFinite()) {
    m.RestoreShape(std::size_t(N) + 1, out);
    Eigen::Vector3d hold_W =
        -(coupling_stiffness_ * (p_hand_W - m.p_held_prev_W) + coupling_damping_ * v_hand_W);
    // The shape sent is last tick's, with its flags; the contact set's are this tick's. Nothing
    // slipped: the next tick continues last tick's loads and their anchors.
    out.flags = kHeldBack | m.shape_flags | (out.flags & (kPenetration | kContactsTruncated));
    for (int k = 0; k < out.contact_count; ++k) out.contacts[std::size_t(k)].friction_work_J = 0.0;
    if (hold_W.norm() > max_force) {
      // The spring saturated at the device's force, the held end apart from the hand: as in a
      // tick that moves (a driver counts such ticks as the tube stalled).
      hold_W *= max_force / hold_W.norm();
      out.flags |= kForceClamped | kProxySeparated;
    }
    if (out.torque_W_Nm.norm() > scene_.device.max_torque_Nm) out.flags |= kForceClamped;
    out.force_W_N = hold_W;  // the torque and the held end's pose stay last tick's
    m.p_hand_prev_W = p_hand_W;
    return true;
  }
  m.axis_inside = inside;

  // 9. The operator's wrench, and the state for the next tick.
  out.X_WH = Eigen::Isometry3d::Identity();
  out.X_WH.linear() = R_WH_new;
  out.X_WH.translation() = p_W;
  out.force_W_N = force_W;
  out.torque_W_Nm = torque_W;
  if (force_saturated || torque_W.norm() > scene_.device.max_torque_Nm) out.flags |= kForceClamped;
  const bool all_finite = force_W.allFinite() && torque_W.allFinite() && p_W.allFinite() &&
                          std::isfinite(energy_J) && std::isfinite(strain) &&
                          std::isfinite(out.segmentation_error_m);
  if (!all_finite) {
    Reset(X_W_hand);
    out.flags |= kSolverFault;
    return true;
  }
  m.p_hand_prev_W = p_hand_W;
  m.p_held_prev_W = p_W;
  m.R_held_prev_W = R_WH_new;
  m.shape_flags = out.flags & (kLinearFallback | kBeyondLinearRange | kRodShape |
                               kShapeOffContacts | kSegmentationOff);
  // Ghosts have done their work; the next tick continues this tick's real loads (ghosts are
  // added after them, so the loop moves none in practice).
  int real_count = 0;
  for (int i = 0; i < load_count; ++i) {
    if (loads[std::size_t(i)].ghost) continue;
    if (real_count != i) loads[std::size_t(real_count)] = loads[std::size_t(i)];
    ++real_count;
  }
  m.prev_count = real_count;
  m.prev_set = 1 - m.prev_set;
  return true;
}

void Core::Centreline(std::span<Eigen::Vector3d> p_W_m) const {
  const Impl& m = *impl_;
  const double l = scene_.tube.length_m;
  const std::size_t count = p_W_m.size();
  const auto s_at = [&](std::size_t k) {
    return count > 1 ? l * double(k) / double(count - 1) : l;
  };
  if (m.elastica_shape) {
    m.beam.ElasticaEvenPoints(m.segments, m.segment_count, p_W_m);
    for (Eigen::Vector3d& p : p_W_m) p = out_.X_WH * p;
    return;
  }
  for (std::size_t k = 0; k < count; ++k) {
    const double s = s_at(k);
    Eigen::Vector3d x_H(0.0, 0.0, s);
    if (m.rod_shape) {
      // The rod's nodes, joined by chords: the capsule count keeps a chord within epsilon / 10
      // of the arc (ChainCapsuleCount), the accuracy the contacts already work to.
      const double u = std::clamp(s / l * capsule_count_, 0.0, double(capsule_count_));
      const int node = std::min(static_cast<int>(u), capsule_count_ - 1);
      x_H = (1.0 - (u - node)) * m.nodes_H[std::size_t(node)] +
            (u - node) * m.nodes_H[std::size_t(node) + 1];
    } else {
      for (int j = 0; j < m.beam_count; ++j)
        x_H += m.beam.CentreDisplacement(s, m.beam_loads[std::size_t(j)]);
    }
    p_W_m[k] = out_.X_WH * x_H;
  }
}

states::ContactFormation Core::Formation() const {
  states::ContactFormation cf;
  for (const ContactState& pc : out_.Contacts())
    cf.contacts.push_back({pc.tube, pc.marker, elements_[std::size_t(pc.part_element)].name});
  states::Canonicalize(cf);
  return cf;
}

int Core::narrow_phase_calls() const { return impl_->collision.last_narrow_phase_calls(); }
int Core::idle_parts_left_out() const { return impl_->idle_left_out; }
long Core::idle_retries() const { return impl_->idle_retries; }
void Core::set_leave_out_idle_parts(bool on) { impl_->leave_out_idle = on; }
void Core::set_hold_out_of_parts(bool on) { impl_->hold_out_of_parts = on; }

std::string Core::FormationText() const { return states::ToString(Formation()); }

}  // namespace tubeplan::core
