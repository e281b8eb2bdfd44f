#pragma once
// A plan (format version 1, docs/plan-format.md): a scene, a hand trajectory, the contact
// formations it is meant to pass through from start to goal, and the limits a replay must keep.
// Plain data; paths are as written in the file (relative to the plan file).

#include <string>
#include <vector>

namespace tubeplan::plan {

struct Limits {
  double max_force_N = 8.5;         ///< operator force
  double max_strain = 0.2;          ///< bending strain of the tube [-]
  double max_penetration_m = 2e-4;  ///< how far the tube may go into a part
  double dwell_s = 0.020;           ///< a state counts once held this long
  double stall_s = 1.0;             ///< no planned progress for this long: stalled
};

struct Plan {
  std::string name;
  std::string scene;                ///< path of the scene file
  std::string trajectory;           ///< path of the trajectory CSV
  std::vector<std::string> states;  ///< canonical CF texts, start first, goal last
  Limits limits;
  std::string comment;  ///< written as '#' lines at the top (who made it, how)
};

}  // namespace tubeplan::plan
