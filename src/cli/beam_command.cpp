// `tubeplan beam`: what-if questions about the tube's bending under a tip load (the answer's
// text and JSON: report/beam_report.hpp).
#include <cmath>
#include <memory>

#include <tubeplan/io/scene_yaml.hpp>
#include <tubeplan/model/elastica.hpp>
#include <tubeplan/model/tip_response.hpp>
#include <tubeplan/report/beam_report.hpp>

#include "app.hpp"
#include "commands.hpp"

namespace tubeplan::cli {
namespace {

struct BeamOptions {
  std::string scene_path;
  std::string outer_radius, inner_radius, length, youngs_modulus, poisson_ratio;
  std::string tip_force = "0";
  std::optional<model::BeamModel> model;
  std::vector<std::string> at;
  bool json = false;
};

// The tube, model, tip force and points the options give over the scene's; every problem, one
// message each.
std::vector<std::string> ReadLoad(const BeamOptions& o, report::BeamAnswer& a) {
  std::vector<std::string> errors;
  auto quantity = [&](const std::string& text, const char* option, io::Dimension dim,
                      double& target) {
    if (text.empty()) return;
    std::string error;
    if (auto v = ParseQuantityList(option, text, 1, 1, dim, error)) {
      target = (*v)[0];
    } else {
      errors.push_back(error);
    }
  };
  model::TubeSpec& spec = a.spec;
  quantity(o.outer_radius, "--outer-radius", io::dim::kLength, spec.outer_radius_m);
  quantity(o.inner_radius, "--inner-radius", io::dim::kLength, spec.inner_radius_m);
  quantity(o.length, "--length", io::dim::kLength, spec.length_m);
  quantity(o.youngs_modulus, "--youngs-modulus", io::dim::kPressure, spec.youngs_modulus_Pa);
  quantity(o.poisson_ratio, "--poisson-ratio", io::dim::kNone, spec.poisson_ratio);
  if (o.model) a.model = *o.model;

  std::string error;
  if (auto f = ParseQuantityList("--tip-force", o.tip_force, 1, 3, io::dim::kForce, error)) {
    for (std::size_t i = 0; i < f->size(); ++i) a.f_tip_O_N[static_cast<Eigen::Index>(i)] = (*f)[i];
  } else {
    errors.push_back(error);
  }
  for (const std::string& at : o.at) {
    if (auto p = ParseQuantityList("--at", at, 3, 3, io::dim::kLength, error)) {
      a.points_O_m.emplace_back((*p)[0], (*p)[1], (*p)[2]);
    } else {
      errors.push_back(error);
    }
  }
  if (o.scene_path.empty() &&
      (o.outer_radius.empty() || o.inner_radius.empty() || o.length.empty() ||
       o.youngs_modulus.empty() || o.poisson_ratio.empty())) {
    errors.push_back(
        "the tube: give --scene FILE, or all of --outer-radius --inner-radius --length "
        "--youngs-modulus --poisson-ratio");
  } else {
    for (const std::string& problem : model::ValidateTubeSpec(spec))
      errors.push_back("the tube: " + problem);
  }
  return errors;
}

int RunBeam(const BeamOptions& o, Streams io) {
  report::BeamAnswer a;
  if (!o.scene_path.empty()) {
    const io::SceneLoadResult loaded = io::LoadSceneFile(o.scene_path);
    io.err << loaded.diagnostics.FormatAll();
    if (!loaded.scene) return kExitBadInput;
    a.spec = loaded.scene->tube;
    // The rod's large-deflection limit is the elastica.
    a.model = loaded.scene->model.tube == scene::TubeModel::kLinear ? model::BeamModel::kLinear
                                                                    : model::BeamModel::kElastica;
  }
  const std::vector<std::string> errors = ReadLoad(o, a);
  if (!errors.empty()) {
    for (const std::string& e : errors) io.err << "tubeplan beam: error: " << e << "\n";
    return kExitBadInput;
  }
  // Loads the models cannot answer are bad input, not internal errors: say which limit.
  const double alpha = model::LoadParameter(a.spec, a.f_tip_O_N.norm());
  if (a.model == model::BeamModel::kElastica && !(alpha <= model::kMaxElasticaAlpha)) {
    io.err << "tubeplan beam: error: --tip-force: the load parameter alpha = F l^2 / (E I) = "
           << alpha << " is beyond the elastica's range (at most " << model::kMaxElasticaAlpha
           << "), expected a smaller force or a stiffer tube\n";
    return kExitBadInput;
  }
  if (!report::ComputeBeamAnswer(a)) {
    io.err << "tubeplan beam: error: --tip-force: the results overflow a double for this load "
              "(alpha = "
           << alpha << "), expected a smaller force\n";
    return kExitBadInput;
  }
  if (o.json)
    io.out << report::BeamJson(a).dump(2) << "\n";
  else
    report::PrintBeam(io.out, a);
  return kExitOk;
}

}  // namespace

Command AddBeamCommand(CLI::App& app, Streams streams) {
  auto options = std::make_shared<BeamOptions>();
  CLI::App* sub = app.add_subcommand(
      "beam",
      "Bending of the tube under a tip load: tip deflection, shortening, angle, energy, "
      "root strain, and the displacement of material points.");
  // No CLI::ExistingFile check: the loader reports a missing file as "file: error: ..." like
  // every other file problem.
  sub->add_option("--scene", options->scene_path, "take the tube (and model) from a scene file");
  sub->add_option("--outer-radius", options->outer_radius, "r1, e.g. 5mm (plain numbers are SI)");
  sub->add_option("--inner-radius", options->inner_radius, "r2, 0 for a solid rod");
  sub->add_option("--length", options->length, "l, e.g. 0.2m");
  sub->add_option("--youngs-modulus", options->youngs_modulus, "E, e.g. 200GPa");
  sub->add_option("--poisson-ratio", options->poisson_ratio, "nu, in [0, 0.5]");
  sub->add_option("--tip-force", options->tip_force,
                  "FX[,FY[,FZ]] in the tube frame (z along the axis), N or with a unit")
      ->capture_default_str();
  const std::map<std::string, model::BeamModel> models = {
      {"linear", model::BeamModel::kLinear}, {"elastica", model::BeamModel::kElastica}};
  sub->add_option("--model", options->model, "linear (the paper's) or elastica (large deflection)")
      ->transform(CLI::CheckedTransformer(models, CLI::ignore_case));
  sub->add_option("--at", options->at,
                  "x,y,z: a material point (tube frame) whose displacement to print; repeatable")
      ->allow_extra_args(false);
  sub->add_flag("--json", options->json, "print one JSON document (SI units)");
  return {sub, [options, streams] { return RunBeam(*options, streams); }};
}

}  // namespace tubeplan::cli
