#pragma once
// The core's constant model: everything a tick reads and never writes, built once from a scene
// (docs/core.md has the derivations). The changing data is in data.hpp.

#include <array>
#include <cstdint>
#include <vector>

#include <tubeplan/scene/elements.hpp>
#include <tubeplan/scene/scene.hpp>

#include "core/part_geometry.hpp"

namespace tubeplan::core {

struct RodModel {
  int elements = 0;                    ///< N segments, N + 1 nodes
  double length_m = 0.0;               ///< l
  double segment_m = 0.0;              ///< rest length l / N
  double outer_radius_m = 0.0;         ///< r1
  double inner_radius_m = 0.0;         ///< r2
  double bending_stiffness_Nm2 = 0.0;  ///< EI
  double stretch_stiffness_N = 0.0;    ///< the axial stiffness EA the rod is given [N]
  bool linear = false;                 ///< the paper's small-deflection beam instead of the rod
};

struct ContactModel {
  double stiffness_N_per_m = 0.0;  ///< K, per contact point
  double threshold_m = 0.0;        ///< epsilon
  double bend_threshold_m = 0.0;   ///< tip deflection above which the tube "bends"
};

struct CouplingModel {
  double stiffness_N_per_m = 0.0;  ///< K_c
  double damping_Ns_per_m = 0.0;   ///< B
  double max_force_N = 0.0;        ///< the device's force: the spring saturates there
  double max_torque_Nm = 0.0;
  double time_step_s = 0.0;
};

struct SolverModel {
  int max_iterations = 0;    ///< Newton iterations a tick at most
  double tolerance_N = 0.0;  ///< converged when no generalised force exceeds it
  double step_cap_m = 0.0;   ///< no point moves farther than this in one iteration
};

struct PartModel {
  PartGeometry geometry;
  std::uint32_t scene_index = 0;
  scene::Friction friction;
  /// Index into Core::elements() of the part's first element: its element i is first_element + i.
  int first_element = 0;
};

struct Model {
  RodModel rod;
  ContactModel contact;
  CouplingModel coupling;
  SolverModel solver;
  std::vector<PartModel> parts;  ///< the parts the tube can reach, in scene order
  bool frictionless = true;      ///< no part has friction: no friction state at all
};

/// The model of `scene`, with the part elements of the parts the tube can reach (their indices
/// are PartModel::element_of's) and those parts' indices in the scene.
void BuildModel(const scene::Scene& scene, Model& model, std::vector<scene::PartElement>& elements,
                std::vector<std::uint32_t>& reachable_parts);

}  // namespace tubeplan::core
