#pragma once
// The accuracy study: how wrong each model and setting of the core is, and what it costs.
// Tip loads are judged against the exact elastica (closed form, model/elastica.hpp) and the
// elastica itself against the independent reference rod (reference/planar_rod.hpp); contact
// scenarios drive core::Core::Step with scenes built in memory and are judged against the
// reference rod with the same contacts, solved to convergence. Run time is measured with the
// steady clock and reported, never judged.

#include <string>
#include <vector>

#include <tubeplan/reference/planar_rod.hpp>
#include <tubeplan/scene/scene.hpp>

namespace tubeplan::study {

struct AccuracyRow {
  std::string setting;      ///< e.g. "rod N=24 dt=0.25ms"
  std::string scenario;     ///< e.g. "tip load alpha=1", "side on an edge"
  std::string metric;       ///< what `error` measures
  double error = 0.0;       ///< relative [-]
  double time_us = 0.0;     ///< per core tick (contact scenarios) or per solve (tip loads) [us]
  std::string detail;       ///< further figures, one line
  bool is_default = false;  ///< the scene's own setting
};

/// The reference's own convergence on one problem: the quantity at N segments, its error
/// (against an exact value, or the Richardson extrapolation of the two finest when there is
/// none) and the observed order log2(e_N / e_2N).
struct ConvergenceStudy {
  std::string problem;
  std::string quantity;
  std::string against;  ///< "closed-form elastica" or "Richardson extrapolation"
  std::vector<int> segments;
  std::vector<double> value;
  std::vector<double> error;
  std::vector<double> order;  ///< one fewer than segments
  std::vector<double> time_ms;
};

/// One contact scenario's reference: the force on the operator per load step.
struct ScenarioReference {
  std::string scenario;
  std::string contact;       ///< "same law" or "rigid"
  int segments = 0;          ///< the finer of the two solves extrapolated
  std::vector<double> step;  ///< the load step's hand coordinate [m]
  std::vector<double> force_x_N, force_z_N;
  std::vector<double> tip_x_m, tip_z_m;
  double uncertainty = 0.0;  ///< largest |Richardson - finest| / largest |F| [-]
  double time_ms = 0.0;      ///< per solve at the finer N
};

struct AccuracyReport {
  std::string scene;
  int elements = 0;  ///< the rod's elements for this scene
  std::vector<AccuracyRow> rows;
  std::vector<ConvergenceStudy> convergence;
  std::vector<ScenarioReference> references;
  std::vector<std::string> notes;
};

struct AccuracyOptions {
  bool quick = false;  ///< fewer load steps and a coarser reference (for tests)
};

/// Runs the whole study on the tube, contact, friction and device of `base` (its parts and pose
/// are not used: every scenario builds its own parts around a tube held at the origin along +z).
AccuracyReport RunAccuracy(const scene::Scene& base, const AccuracyOptions& options);

/// The reference's convergence on a tip load alpha (l = 1, EI = 1) for N = 16 .. max_segments.
ConvergenceStudy TipLoadConvergence(double alpha, int max_segments);

}  // namespace tubeplan::study
