#pragma once
// A tip load's answer as `tubeplan beam` prints it (docs/models.md): the tube and its section, the
// model, the load, the tip's response and the displacement of the material points asked about,
// as text or as one JSON document (SI units).

#include <ostream>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <tubeplan/model/tip_response.hpp>
#include <tubeplan/model/tube.hpp>

namespace tubeplan::report {

/// One tip load and what the model answers for it (tube frame O-xyz, z along the axis).
struct BeamAnswer {
  model::BeamModel model = model::BeamModel::kLinear;
  model::TubeSpec spec;
  model::TubeSection section;
  Eigen::Vector3d f_tip_O_N = Eigen::Vector3d::Zero();
  model::TipLoadResponse response;
  std::vector<Eigen::Vector3d> points_O_m;         ///< material points, undeformed [m]
  std::vector<Eigen::Vector3d> displacements_O_m;  ///< of points_O_m, one each [m]
};

/// Fills the answer's section, response and the points' displacements from its model, tube, tip
/// force and points; false when a figure overflows a double.
bool ComputeBeamAnswer(BeamAnswer& answer);

/// The answer as one JSON document: model, tube, tip_force, the response's figures and points.
nlohmann::json BeamJson(const BeamAnswer& answer);

/// The answer as text, one figure a line, and a note when the linear model is used beyond where
/// it is close to the elastica.
void PrintBeam(std::ostream& out, const BeamAnswer& answer);

}  // namespace tubeplan::report
