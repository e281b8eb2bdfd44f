#include <algorithm>
#include <array>
#include <cmath>
#include <span>

#include <tubeplan/model/elastica.hpp>
#include <tubeplan/model/linear_beam.hpp>
#include <tubeplan/model/tip_response.hpp>

namespace tubeplan::model {
namespace {

// The bending frame of a tip load: e1 along the lateral force (or +x when there is none), and
// the load's angle psi from e1 towards the axis, as the elastica wants it.
struct BendingFrame {
  Eigen::Vector2d e1_O = Eigen::Vector2d::UnitX();
  double lateral_N = 0.0;
  double psi_rad = 0.0;
};

BendingFrame FrameOf(const Eigen::Vector3d& f_tip_O_N) {
  BendingFrame frame;
  const Eigen::Vector2d lateral = f_tip_O_N.head<2>();
  frame.lateral_N = lateral.norm();
  if (frame.lateral_N > 0.0) frame.e1_O = lateral / frame.lateral_N;
  frame.psi_rad = std::atan2(f_tip_O_N.z(), frame.lateral_N);
  return frame;
}

}  // namespace

std::string_view ToString(BeamModel model) {
  return model == BeamModel::kLinear ? "linear" : "elastica";
}

TipLoadResponse TipResponse(BeamModel model, const TubeSpec& spec,
                            const Eigen::Vector3d& f_tip_O_N) {
  const TubeSection section = ComputeSection(spec);
  const double l = spec.length_m;
  const double EI = section.bending_stiffness_Nm2;
  const BendingFrame frame = FrameOf(f_tip_O_N);
  TipLoadResponse r;
  r.alpha = f_tip_O_N.norm() * l * l / EI;
  if (model == BeamModel::kLinear) {
    const LinearBeam beam(spec);
    const double F = frame.lateral_N;
    r.tip_deflection_m = beam.TipDeflection(F);
    r.tip_angle_rad = beam.TipAngle(F);
    r.energy_J = beam.BendingEnergy(F);
    r.root_strain = beam.RootStrain(F);
    r.tip_displacement_O_m << r.tip_deflection_m * frame.e1_O, 0.0;
    return r;
  }
  const ElasticaSolution solution = SolveElastica(r.alpha, frame.psi_rad);
  r.tip_deflection_m = solution.tip.deflection * l;
  r.tip_shortening_m = solution.tip.shortening * l;
  r.tip_angle_rad = solution.tip.tip_angle_rad;
  r.energy_J = EI / l * solution.tip.energy;
  r.root_strain = spec.outer_radius_m * std::abs(solution.tip.root_curvature) / l;
  r.tip_displacement_O_m << r.tip_deflection_m * frame.e1_O, -r.tip_shortening_m;
  return r;
}

Eigen::Vector3d PointDisplacement(BeamModel model, const TubeSpec& spec,
                                  const Eigen::Vector3d& f_tip_O_N, const Eigen::Vector3d& p_OP_O) {
  if (model == BeamModel::kLinear) {
    return LinearBeam(spec).Displacement(p_OP_O, f_tip_O_N.head<2>());
  }
  const double l = spec.length_m;
  const TubeSection section = ComputeSection(spec);
  const BendingFrame frame = FrameOf(f_tip_O_N);
  const double alpha = f_tip_O_N.norm() * l * l / section.bending_stiffness_Nm2;
  const ElasticaSolution solution = SolveElastica(alpha, frame.psi_rad);
  // Coordinates of the point in the bending frame: a along e1, b along e2 = z x e1, arc s.
  const Eigen::Vector2d e2_O(-frame.e1_O.y(), frame.e1_O.x());
  const double a = p_OP_O.head<2>().dot(frame.e1_O);
  const double b = p_OP_O.head<2>().dot(e2_O);
  const std::array<double, 1> s = {std::clamp(p_OP_O.z() / l, 0.0, 1.0)};
  std::array<Eigen::Vector2d, 1> xz;
  std::array<double, 1> theta;
  ElasticaCentreline(solution, s, xz, theta);
  // Plane sections stay normal to the centreline: the section's e1 direction turns by theta.
  const double c = std::cos(theta[0]);
  const double sn = std::sin(theta[0]);
  const double along_e1 = l * xz[0].x() + a * c;
  const double along_z = l * xz[0].y() - a * sn;
  const Eigen::Vector3d deformed_O(along_e1 * frame.e1_O.x() + b * e2_O.x(),
                                   along_e1 * frame.e1_O.y() + b * e2_O.y(), along_z);
  return deformed_O - p_OP_O;
}

}  // namespace tubeplan::model
