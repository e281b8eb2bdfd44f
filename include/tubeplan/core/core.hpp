#pragma once
// The one force-and-deformation core (docs/core.md): a fixed-step function from the pose of the
// operator's hand to the wrench the operator feels, the tube's shape and its contact formation.
// Everything that moves the tube goes through Core::Step: replay, graph exploration, live
// haptics, the studies and the benchmarks. No I/O, no heap allocation per tick after
// construction, never NaN or Inf in what it returns.
//
// One tick solves one equilibrium: the tube as a discrete Kirchhoff rod (N straight elements,
// inextensible, bending only), its held end on the coupling spring and damper to the hand, the
// penalty K (eps - d)+ of its surface against every part at the actual surface points, and
// friction as a stick spring returned to the kinetic limit, all minimised together by Newton's
// method from the last tick's shape. The contact formation is read off the solved shape.

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

/// Most principal contacts (PCs) a tick reports; further PCs, the shallowest, are left out of
/// the output (their forces still act) and the tick is flagged kContactsTruncated.
inline constexpr int kMaxContacts = 8;

/// Bits of StepOutput::flags.
enum StepFlag : std::uint32_t {
  kForceClamped = 1u << 0,  ///< the coupling force or torque reached the device's maximum
  kPenetration = 1u << 1,   ///< a point of the tube's surface is inside a part (d < 0)
  /// The coupling spring is stretched beyond the device's force: the hand is farther from the
  /// held end than the device can pull, the tube no longer follows the hand.
  kProxySeparated = 1u << 2,
  kContactsTruncated = 1u << 3,  ///< more contact points or PCs than the core carries
  /// The tick's Newton solve reached its iteration cap before its tolerance: there is no
  /// equilibrium near the last one (the tube snaps through, or the hand jumped). The tube is
  /// where the last iteration left it, with less energy than before; the next tick goes on.
  kNotConverged = 1u << 4,
  /// The hand's pose was not finite, or the solve gave a state that was not: the tube and the
  /// held end stayed where they were and the force is zero.
  kSolverFault = 1u << 5,
  /// The paper's linear beam (model.beam: linear) drew the tube with a tip deflection beyond
  /// l / 3, where it is ~10 % off the exact elastica and stretches the tube.
  kBeyondLinearRange = 1u << 6,
  /// A straight equilibrium was unstable (a direction of negative curvature was followed): the
  /// tube buckled this tick.
  kBuckled = 1u << 7,
};
/// How many StepFlag bits there are (bits 0 .. kStepFlagCount - 1).
inline constexpr int kStepFlagCount = 8;
static_assert(kBuckled == 1u << (kStepFlagCount - 1),
              "kStepFlagCount must follow the last StepFlag bit");

/// One principal contact in a tick: every contact point of one tube element on one part
/// element, summed.
struct ContactState {
  states::TubeElement tube = states::TubeElement::kSide;
  states::Marker marker = states::Marker::kNone;
  int part_element = -1;    ///< index into Core::elements()
  int points = 0;           ///< contact points carrying it
  double s_m = 0.0;         ///< arc position of its deepest point along the centreline [m]
  double distance_m = 0.0;  ///< smallest distance d between the two elements [m]
  Eigen::Vector3d normal_W = Eigen::Vector3d::UnitZ();     ///< unit, from the part into the tube
  Eigen::Vector3d p_WC_m = Eigen::Vector3d::Zero();        ///< deepest contact point on the tube
  double normal_force_N = 0.0;                             ///< sum over its points, >= 0
  Eigen::Vector3d friction_W_N = Eigen::Vector3d::Zero();  ///< tangential force on the tube
  Eigen::Vector3d force_W_N = Eigen::Vector3d::Zero();     ///< total force on the tube
  Eigen::Vector3d moment_W_Nm = Eigen::Vector3d::Zero();   ///< its moment about the held end
  /// |friction| / f_max(mu_s, N) of its points, the largest (<= 1), and f_max at its total
  /// normal force.
  double friction_ratio = 0.0;
  double friction_limit_N = 0.0;
  /// Work its friction dissipated this tick [J], >= 0: the kinetic force times the slip of its
  /// sliding points' anchors over the part (a stuck point's spring stores, it does not dissipate).
  double friction_work_J = 0.0;
  bool sliding = false;  ///< its points bearing more than half its normal force slide
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
  double energy_J = 0.0;          ///< elastic (bending) energy of the tube
  double max_strain = 0.0;        ///< largest bending strain (outer fibre) [-]
  double tip_deflection_m = 0.0;  ///< lateral deflection of the free end from the straight tube
  int iterations = 0;             ///< Newton iterations of the tick's solve (kept steps too)
  double residual_N = 0.0;        ///< largest generalised force left unbalanced [N]
  std::uint32_t flags = 0;        ///< StepFlag bits
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

/// The free end's rim against one part (docs/core.md, "The contact law"): kRimSamples points
/// round the rim, the nearest and the others equally spaced, press as one contact whose distance
/// is the smooth minimum of theirs, of width kRimSoftness times epsilon, so that a flat end bears
/// on its whole rim until its points' distances differ by a few widths.
inline constexpr int kRimSamples = 8;
inline constexpr double kRimSoftness = 2e-4;

/// Fewest and most rod elements a scene may ask for (model.elements).
inline constexpr int kMinElementCount = 4;
inline constexpr int kMaxElementCount = 96;

/// The rod's element count for a scene: scene.model.elements when set, else 24; at most the
/// tube's length over its outer radius (18 for the shipped groove; `tubeplan accuracy` measures
/// what a count costs in error, docs/accuracy.md).
int ElementCount(const scene::Scene& scene);

struct Model;
struct Data;
struct SnapshotData;

class Core {
 public:
  /// Set-up (allocates): the parts the tube can reach, their elements, the rod, the coupling.
  /// The scene must be valid (the loader checks it); the tube starts straight at
  /// scene.X_WH_start with the hand there.
  explicit Core(const scene::Scene& scene);
  ~Core();
  Core(const Core&) = delete;
  Core& operator=(const Core&) = delete;

  /// Starts over at the held-end pose X_WH: the tube straight, no contacts, hand at the same pose.
  void Reset(const Eigen::Isometry3d& X_WH);

  /// One tick of scene.model.time_step at time t_s with the hand at X_W_hand. No allocation.
  const StepOutput& Step(double t_s, const Eigen::Isometry3d& X_W_hand);

  /// Everything the core carries from one tick to the next. Restore puts a core made from the
  /// same scene back where Save found it, bit for bit: the ticks after it are those that followed
  /// the Save. Graph exploration branches from a tick with it instead of replaying the motion up
  /// to there. Cold path: Save allocates when the snapshot is empty, Restore never.
  class Snapshot {
   public:
    Snapshot();
    ~Snapshot();
    Snapshot(const Snapshot& other);
    Snapshot& operator=(const Snapshot& other);
    bool empty() const { return data_ == nullptr; }

   private:
    friend class Core;
    std::unique_ptr<SnapshotData> data_;
  };
  void Save(Snapshot& snapshot) const;
  /// False, the core untouched, if the snapshot is empty or from a core of another shape (its
  /// element or part count differs; a snapshot of another scene of the same shape is the
  /// caller's error).
  bool Restore(const Snapshot& snapshot);

  /// The deformed centreline at `count` points equally spaced in arc length, in W. Computed only
  /// when asked; no allocation.
  void Centreline(std::span<Eigen::Vector3d> p_W_m) const;

  /// The contact formation of the last tick (cold path: allocates its strings).
  states::ContactFormation Formation() const;
  std::string FormationText() const;

  const StepOutput& last() const;
  const scene::Scene& scene() const { return scene_; }
  /// The elements the tube can reach (unreachable parts and elements are left out).
  const std::vector<scene::PartElement>& elements() const { return elements_; }
  const std::vector<std::uint32_t>& reachable_parts() const { return reachable_parts_; }
  /// The rod's elements (segments).
  int element_count() const;
  double coupling_stiffness_N_per_m() const;
  double coupling_damping_Ns_per_m() const;

 private:
  scene::Scene scene_;
  std::vector<scene::PartElement> elements_;
  std::vector<std::uint32_t> reachable_parts_;
  std::unique_ptr<Model> model_;
  std::unique_ptr<Data> data_;
};

}  // namespace tubeplan::core
