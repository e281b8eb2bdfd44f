#pragma once
// The friction law of one principal contact (docs/core.md, "Friction"): the load-dependent limit
// of static friction and the stick/slip decision with a return mapping. Part of the core: no I/O,
// no allocation, never NaN for finite inputs.

#include <Eigen/Core>

#include <tubeplan/scene/scene.hpp>

namespace tubeplan::core {

/// f_max = coefficient * N0 * (N / N0)^beta [N] for a normal load normal_N >= 0 [N]. Zero for
/// N <= 0 (a contact that does not press holds nothing); exactly coefficient * N when beta = 1.
/// For beta < 1 the limit has an infinite slope at N = 0 but its value tends to 0: no special
/// case is needed beyond N <= 0, and denormal loads give denormal limits, never NaN.
double FrictionLimit(const scene::Friction& friction, double coefficient, double normal_N);

/// The limit is the PC's (docs/core.md, "Friction"): a PC carried by several load points (a
/// line contact's two ends) holds f_max at their total normal force pc_normal_N, and a load point
/// pressed with normal_N holds the share normal_N / pc_normal_N of it. The shares add up to the
/// PC's limit, so the PC's friction, the sum of its points', stays within it; a limit taken per
/// point would not for beta < 1, where f_max is concave and two points at their own limits hold
/// up to 2^(1 - beta) times the PC's. Exactly FrictionLimit(normal_N) for a PC of one point
/// (pc_normal_N <= normal_N) and for beta = 1.
double FrictionShare(const scene::Friction& friction, double coefficient, double normal_N,
                     double pc_normal_N);
/// FrictionShare with the PC's limit FrictionLimit(friction, coefficient, pc_normal_N) given as
/// pc_limit_N, found once for all of a PC's points (the same bits).
double FrictionShare(const scene::Friction& friction, double coefficient, double normal_N,
                     double pc_normal_N, double pc_limit_N);

struct FrictionResult {
  Eigen::Vector3d force_N = Eigen::Vector3d::Zero();  ///< friction force on the tube [N]
  /// How far the stuck point must move along the contact plane so that the spring that produced
  /// the trial force carries exactly the kinetic limit [m]; zero when stuck.
  Eigen::Vector3d slip_m = Eigen::Vector3d::Zero();
  bool sliding = false;
};

/// Stick first, then slide (return mapping), for a load point pressed with normal_N [N] of its
/// PC's pc_normal_N (its limits are FrictionShare's). `trial_force_N` is the tangential force the
/// contact would carry if the contact point stayed stuck, produced by a tangential spring of
/// stiffness `tangential_stiffness_N_per_m` (> 0) stretched by trial_force / stiffness. If the
/// trial is within the static share the point sticks and the friction is the trial force.
/// Otherwise it slides: the friction is the kinetic share f_k along the trial force, and the
/// point slips by (|trial| minus f_k) / stiffness along it, after which the spring carries
/// exactly f_k. Either way |force| <= the static share. A frictionless contact returns zero force
/// and full slip without evaluating the law (no friction work without friction).
FrictionResult ReturnMap(const scene::Friction& friction, const Eigen::Vector3d& trial_force_N,
                         double normal_N, double pc_normal_N, double tangential_stiffness_N_per_m);

}  // namespace tubeplan::core
