#pragma once
// Private to the core: the tube as a cantilever from the held end under several point loads on
// its centreline, by the paper's segmented rule or by influence coefficients (physics.md, eq. 6),
// with the linear model or the elastica. Everything in the held-end frame H (= the tube frame O
// of linear_beam.hpp: z along the undeformed axis). Fixed-size storage only.
//
// Both rules are one formula. A load j acts on the cantilever that starts at its clamp c_j: the
// held end (c_j = 0) for the coupled rule; for the segmented rule the cross-section of the
// previous cut, i.e. the previous group of loads (loads closer than a tube radius share a cut).
// A point at arc position s >= c_j moves by infl(s - c_j, s_j - c_j) F_j laterally, where
//     infl(a, b) = a^2 (3 b - a) / (6 E I)  for a <= b,   b^2 (3 a - b) / (6 E I)  for a >= b,
// the textbook influence coefficient; points before c_j do not move. For the segmented rule this
// is exactly the paper's chain: segment k is a cantilever loaded by its own load only, clamped at
// the cross-section where segment k - 1 ended, which carries it along rigidly (a point beyond a
// cantilever's load moves by the load point's deflection plus its rotation times the distance,
// which is the a >= b branch).

#include <array>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <tubeplan/core/core.hpp>
#include <tubeplan/model/elastica.hpp>

namespace tubeplan::core {

struct BeamLoad {
  double s_m = 0.0;                                    ///< arc position of the load point
  Eigen::Vector3d f_H_N = Eigen::Vector3d::Zero();     ///< force on the tube, frame H
  double clamp_m = 0.0;                                ///< c_j (set by BeamChain::Assign)
  int group = 0;                                       ///< cut group (set by Assign)
};

/// The solved shape of one elastica segment (a group's cantilever).
struct ElasticaSegment {
  model::ElasticaSolution solution;
  Eigen::Vector3d origin_H = Eigen::Vector3d::Zero();  ///< clamp cross-section centre
  Eigen::Matrix3d R_HS = Eigen::Matrix3d::Identity();  ///< clamp frame S (z along the tangent)
  Eigen::Vector3d bend_x_S = Eigen::Vector3d::UnitX(); ///< bending direction in S
  double clamp_m = 0.0, length_m = 0.0;
};

class BeamChain {
 public:
  BeamChain(const scene::Scene& scene);

  /// Sorts `order` (indices of loads) by arc position and sets each load's group and clamp.
  /// Returns the number of groups.
  int Assign(std::array<BeamLoad, kMaxContacts>& loads, int count,
             std::array<int, kMaxContacts>& order) const;

  /// Lateral influence coefficient [m/N] of load j on the point at arc position s_m.
  double Influence(double s_m, const BeamLoad& load) const;
  /// d/ds of Influence [1/N]: the rotation of the tangent per newton.
  double InfluenceSlope(double s_m, const BeamLoad& load) const;

  /// Whether the elastica can carry these loads: one group per cantilever (segmented), or a
  /// single group (coupled), and every segment's load parameter within the solver's range.
  bool ElasticaCovers(const std::array<BeamLoad, kMaxContacts>& loads, int count,
                      int groups) const;

  /// Solves the elastica chain: one segment per group, each loaded by its group's resultant at
  /// the group's last load point, clamped where the previous one ended. Loads must be Assigned.
  /// Returns the number of segments.
  int SolveElasticaChain(const std::array<BeamLoad, kMaxContacts>& loads, int count,
                         const std::array<int, kMaxContacts>& order,
                         std::array<ElasticaSegment, kMaxContacts>& segments) const;

  /// Position in H of the centreline at s_m of a solved elastica chain.
  Eigen::Vector3d ElasticaPoint(const std::array<ElasticaSegment, kMaxContacts>& segments,
                                int segment_count, double s_m) const;
  /// Unit tangent in H at the free end of a solved elastica chain.
  Eigen::Vector3d ElasticaTipTangent(const std::array<ElasticaSegment, kMaxContacts>& segments,
                                     int segment_count) const;
  /// 3x3 tangent compliance [m/N] of a segment's tip to its own load, frame H (finite
  /// differences of the elastica in the bending plane; rotational symmetry across it).
  Eigen::Matrix3d ElasticaCompliance(const ElasticaSegment& segment,
                                     const Eigen::Vector3d& f_H_N) const;

  double bending_stiffness_Nm2() const { return EI_; }
  double length_m() const { return length_m_; }
  double outer_radius_m() const { return r1_; }
  double group_tolerance_m() const { return group_tolerance_m_; }

 private:
  double EI_ = 0.0;
  double length_m_ = 0.0;
  double r1_ = 0.0;
  double group_tolerance_m_ = 0.0;
  scene::MultiContactRule rule_ = scene::MultiContactRule::kSegmented;
};

}  // namespace tubeplan::core
