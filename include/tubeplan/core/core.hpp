#pragma once
// The one force-and-deformation core (architecture.md): a fixed-step function from the pose of
// the operator's hand to the wrench the operator feels, the tube's state and its contact
// formation. Everything that moves the tube goes through Core::Step: replay, graph exploration,
// live haptics, the studies and the benchmarks. No I/O, no heap allocation per tick after
// construction, never NaN or Inf in what it returns.
//
// Model, in the order of one tick (docs/core.md has the derivations and every choice):
//  1. The held end H is a proxy coupled to the hand by the scene's spring K_c and damper B; it
//     turns with the hand (a rigid grip, as in the paper). Its position is where the coupling
//     force balances the contact forces on the massless tube. The spring saturates at the
//     device's force and the grip at its torque (then the held end lags the hand's turn), so
//     however hard the hand pushes or turns, the tube is not driven through a part.
//  2. The deformed tube is a chain of FCL capsules along its centreline, ending in an FCL
//     cylinder so that the free end has a flat end face and a rim; parts are FCL boxes. A broad
//     phase in each box's frame passes only the pairs that can be closer than epsilon to FCL's
//     GJK, which gives the distance, the nearest points and so the normal.
//  3. Each pair closer than epsilon is classified into a PC (tube element, part element) and PCs
//     of the same element pair merge into one load point on the centreline.
//  4. Normal force K (eps - d) and a tangential spring of the same stiffness to a stuck anchor
//     give each contact's force; the beam's compliance (the paper's segmented rule or the
//     coupled influence coefficients), the coupling and the contacts are solved together as one
//     small linear system (linearised in d); friction is decided per PC by the return mapping.
//  5. The bending shape under the solved loads (linear model or elastica) gives energy, strain,
//     markers and the next tick's capsules.

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <tubeplan/scene/elements.hpp>
#include <tubeplan/scene/scene.hpp>
#include <tubeplan/states/contact_formation.hpp>

namespace tubeplan::core {

/// Most load points (merged PCs) the core resolves at once; further PCs, the shallowest, are
/// dropped for that tick and flagged kContactsTruncated.
inline constexpr int kMaxContacts = 6;
/// Most load points at once: a PC whose contact region is longer than a tube radius (a side lying
/// along a face) is carried by two, at the ends of the region, so that its resultant can move
/// and its moment is carried; others by one.
inline constexpr int kMaxLoads = 8;
/// Fewest and most capsules in the tube's chain (the count is chosen per scene, see
/// ChainCapsuleCount, or set by the scene's model.capsules).
inline constexpr int kMinCapsules = 8;
inline constexpr int kMaxCapsules = 48;

/// Bits of StepOutput::flags.
enum StepFlag : std::uint32_t {
  kForceClamped = 1u << 0,       ///< the coupling force reached the device's maximum
  kPenetration = 1u << 1,        ///< a tube and a part overlap (d <= 0)
  kProxySeparated = 1u << 2,     ///< the held end is more than epsilon from the hand
  kContactsTruncated = 1u << 3,  ///< more than kMaxContacts PCs; the shallowest were dropped
  /// Elastica asked for, the loading is not one it covers, and the rod did not converge either:
  /// the linear model shaped the tube.
  kLinearFallback = 1u << 4,
  kSolverFault = 1u << 5,  ///< the tick's system was singular or not finite: held still
  /// The linear model drew the tube (a linear scene, or the fallback) with a tip deflection
  /// beyond l/3, where it is ~10 % off the exact elastica and no longer keeps the tube's length.
  kBeyondLinearRange = 1u << 6,
  /// Elastica asked for, but the loading is not one it covers (several loads on one cantilever,
  /// a line contact, a push past buckling): the discrete rod (model/rod.hpp), which keeps the
  /// tube's length under any load, shaped the tube and gave the tick's compliance.
  kRodShape = 1u << 7,
  /// The shape drawn under the tick's loads (the rod's, or the linear fallback's) puts a load
  /// point farther from where the tick's system put it than the elastica's hold-off tolerance,
  /// max(2 eps, r1 / 4): the tick's forces were solved with a compliance the shape does not
  /// follow, and the next tick starts from a shape its contacts did not hold. Where the core's
  /// known failures start (docs/accuracy.md): a replay through such ticks is not the tube's
  /// motion.
  kShapeOffContacts = 1u << 8,
  /// The tick's solution would have put a point of the tube's centreline more than r1 / 2 inside
  /// a part, or the centreline across a part thinner than r1 (the tube going through it), from a
  /// state where neither was: the tube and the held end were kept where they were, and the
  /// operator feels the coupling's spring and damper stretched to the hand (docs/core.md,
  /// "Through a part").
  kHeldBack = 1u << 9,
  /// The paper's segmented rule, with loads on more than one segment, left out more than eps / 10
  /// of displacement at a load point (StepOutput::segmentation_error_m): the rule bends each
  /// segment by its own loads only, so the loads beyond a side contact do not move it. There the
  /// rule is outside its range: a displacement error of eps / 10 is a force error of K eps / 10
  /// (the capsule count's tolerance, docs/core.md), and the rule's one-way compliance can make
  /// energy (the stability sweep's squeeze). The coupled rule has no such error.
  kSegmentationOff = 1u << 10,
};
/// How many StepFlag bits there are (bits 0 .. kStepFlagCount - 1).
inline constexpr int kStepFlagCount = 11;
static_assert(kSegmentationOff == 1u << (kStepFlagCount - 1),
              "kStepFlagCount must follow the last StepFlag bit");

/// One principal contact in a tick, in the core's compact form.
struct ContactState {
  states::TubeElement tube = states::TubeElement::kSide;
  states::Marker marker = states::Marker::kNone;
  int part_element = -1;    ///< index into Core::elements()
  int loads = 0;            ///< load points carrying it (1 or 2)
  double s_m = 0.0;         ///< arc position of its (deepest) load point on the centreline [m]
  double distance_m = 0.0;  ///< smallest distance d between the two elements [m]
  Eigen::Vector3d normal_W = Eigen::Vector3d::UnitZ();     ///< unit, from the part into the tube
  Eigen::Vector3d p_WC_m = Eigen::Vector3d::Zero();        ///< deepest contact point on the tube
  double normal_force_N = 0.0;                             ///< sum over its load points, >= 0
  Eigen::Vector3d friction_W_N = Eigen::Vector3d::Zero();  ///< tangential force on the tube
  Eigen::Vector3d force_W_N = Eigen::Vector3d::Zero();     ///< total force on the tube
  Eigen::Vector3d moment_W_Nm = Eigen::Vector3d::Zero();   ///< its moment about the held end
  /// Largest |friction| / f_max(mu_s, N) over its load points (<= 1 always; 1 when sliding
  /// with mu_k = mu_s) and f_max of the total normal force.
  double friction_ratio = 0.0;
  double friction_limit_N = 0.0;
  /// Work its friction dissipated this tick [J], >= 0: over its sliding load points, the kinetic
  /// force times the slip of the stuck spring's anchor over the part (a stuck point dissipates
  /// nothing: its spring holds the energy). Not the motion of p_WC_m, which jumps when the
  /// deepest of a line contact's two points changes.
  double friction_work_J = 0.0;
  bool sliding = false;  ///< any of its load points slides
};

/// What one tick returns. Plain data; valid until the next Step.
struct StepOutput {
  double t_s = 0.0;
  Eigen::Isometry3d X_W_hand = Eigen::Isometry3d::Identity();  ///< hand pose given
  Eigen::Isometry3d X_WH = Eigen::Isometry3d::Identity();      ///< held end (proxy)
  Eigen::Vector3d force_W_N = Eigen::Vector3d::Zero();         ///< on the operator, at the held end
  Eigen::Vector3d torque_W_Nm = Eigen::Vector3d::Zero();       ///< on the operator, about H
  std::array<ContactState, kMaxContacts> contacts{};           ///< sorted by (tube, part element)
  int contact_count = 0;
  double energy_J = 0.0;          ///< bending energy
  double max_strain = 0.0;        ///< largest bending strain (outer fibre at a clamp) [-]
  double tip_deflection_m = 0.0;  ///< lateral deflection of the free end from the straight tube
  /// Under the segmented rule, the largest displacement [m] it leaves out at a load point: what
  /// the solved loads on later segments would move that point by on the one cantilever from the
  /// held end (linear influence coefficients, an estimate of the rule's error). Zero under the
  /// coupled rule, and with loads on one segment.
  double segmentation_error_m = 0.0;
  std::uint32_t flags = 0;  ///< StepFlag bits
  std::span<const ContactState> Contacts() const {
    return {contacts.data(), static_cast<std::size_t>(contact_count)};
  }
};

/// The contact formation of a tick in a compact form: the PC count, then (part element, tube
/// element, marker) of each PC in the output's order. Equal keys are equal CFs; comparing keys
/// each tick costs nothing, so drivers make the CF's text only when the key changes.
using FormationKey = std::array<std::uint32_t, kMaxContacts + 1>;
inline FormationKey KeyOf(const StepOutput& out) {
  FormationKey key{};
  key[0] = static_cast<std::uint32_t>(out.contact_count);
  for (int i = 0; i < out.contact_count; ++i) {
    const ContactState& c = out.contacts[std::size_t(i)];
    key[std::size_t(i) + 1] = (static_cast<std::uint32_t>(c.part_element) << 8) |
                              (static_cast<std::uint32_t>(c.tube) << 4) |
                              static_cast<std::uint32_t>(c.marker);
  }
  return key;
}

/// Capsule count of the chain: the chord of a segment of length l/N on an arc of curvature
/// kappa lies inside the arc by kappa (l/N)^2 / 8; the largest curvature the core can produce is
/// at the root under the device's largest force, kappa = F_max l / (E I). N is the smallest count
/// that keeps that error below epsilon / 10, clamped to [kMinCapsules, kMaxCapsules]. A scene
/// that sets model.capsules gets that count instead.
int ChainCapsuleCount(const scene::Scene& scene);

class Core {
 public:
  struct State;  // what ticks carry, and their scratch (src/core)

  /// Set-up (allocates): elements, reachable parts, FCL shapes, the coupling. The scene must be
  /// valid (the loader checks it); the held end starts at scene.X_WH_start with the hand there.
  explicit Core(const scene::Scene& scene);
  ~Core();
  Core(const Core&) = delete;
  Core& operator=(const Core&) = delete;

  /// Starts over at the held-end pose X_WH: no contacts, no anchors, hand at the same pose.
  void Reset(const Eigen::Isometry3d& X_WH);

  /// One tick of scene.model.time_step at time t_s with the hand at X_W_hand. No allocation.
  const StepOutput& Step(double t_s, const Eigen::Isometry3d& X_W_hand);

  /// Everything the core carries from one tick to the next. Restore puts a core made from the
  /// same scene back where Save found it, bit for bit: the ticks after it are those that followed
  /// the Save. Graph exploration branches from a tick with it instead of replaying the motion up
  /// to there. Cold path: Save allocates when the snapshot is empty (~70 kB), Restore never.
  class Snapshot {
   public:
    Snapshot();
    ~Snapshot();
    Snapshot(const Snapshot& other);
    Snapshot& operator=(const Snapshot& other);
    bool empty() const { return state_ == nullptr; }

   private:
    friend class Core;
    std::unique_ptr<State> state_;
    StepOutput out_;
    int capsules_ = 0;
    std::size_t elements_ = 0;
  };
  void Save(Snapshot& snapshot) const;
  /// False, the core untouched, if the snapshot is empty or from a core of another shape (its
  /// capsule or element count differs; a snapshot of another scene of the same shape is the
  /// caller's error).
  bool Restore(const Snapshot& snapshot);

  /// The deformed centreline at `count` points equally spaced in arc length, in W. Computed only
  /// when asked (the "shape only when a consumer asks" rule); no allocation.
  void Centreline(std::span<Eigen::Vector3d> p_W_m) const;

  /// The contact formation of the last tick (cold path: allocates its strings).
  states::ContactFormation Formation() const;
  std::string FormationText() const;

  const StepOutput& last() const { return out_; }
  const scene::Scene& scene() const { return scene_; }
  /// The elements the tube can reach (unreachable parts and elements are left out).
  const std::vector<scene::PartElement>& elements() const { return elements_; }
  const std::vector<std::uint32_t>& reachable_parts() const { return reachable_parts_; }
  int capsule_count() const { return capsule_count_; }
  /// Narrow-phase queries in the last tick: the main cost of a tick, for the benchmarks. Pairs
  /// settled by a distance kept from an earlier tick (collision.cpp) are not counted.
  int narrow_phase_calls() const;
  /// Idle parts the last tick left out (docs/core.md, "Idle parts"), and the ticks since
  /// construction that had to be solved again with every part in.
  int idle_parts_left_out() const;
  long idle_retries() const;
  /// Leaving idle parts out never changes a tick's result; off, every part in the band is
  /// queried every tick (the tests compare the two; the bench shows the difference).
  void set_leave_out_idle_parts(bool on);
  /// On (the default), a tick whose solution would carry the centreline into a part is not taken
  /// (kHeldBack); off, it is (the tests show what the guard prevents).
  void set_hold_out_of_parts(bool on);
  double coupling_stiffness_N_per_m() const { return coupling_stiffness_; }
  double coupling_damping_Ns_per_m() const { return coupling_damping_; }

  struct Impl;  // State, and the collision and beam set-up (src/core)

 private:
  // Step's tick; false, with nothing carried to the next tick, when a left-out idle part might
  // have been reached (then Step runs it again with leave_out_idle false).
  bool Tick(double t_s, const Eigen::Isometry3d& X_W_hand, bool leave_out_idle);
  scene::Scene scene_;
  std::vector<scene::PartElement> elements_;
  std::vector<std::uint32_t> reachable_parts_;
  int capsule_count_ = 0;
  double coupling_stiffness_ = 0.0;
  double coupling_damping_ = 0.0;
  std::unique_ptr<Impl> impl_;
  StepOutput out_;
};

}  // namespace tubeplan::core
