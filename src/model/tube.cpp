#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include <tubeplan/model/tube.hpp>

namespace tubeplan::model {

std::vector<std::string> ValidateTubeSpec(const TubeSpec& spec) {
  std::vector<std::string> problems;
  auto finite_positive = [&](double value, const char* name) {
    if (!std::isfinite(value) || value <= 0.0) {
      std::ostringstream out;
      out << name << " (" << value << ") must be a finite number greater than zero";
      problems.push_back(out.str());
      return false;
    }
    return true;
  };
  const bool r1_ok = finite_positive(spec.outer_radius_m, "outer_radius");
  if (!std::isfinite(spec.inner_radius_m) || spec.inner_radius_m < 0.0) {
    std::ostringstream out;
    out << "inner_radius (" << spec.inner_radius_m
        << ") must be a finite number, zero (a solid rod) or greater";
    problems.push_back(out.str());
  } else if (r1_ok && spec.inner_radius_m >= spec.outer_radius_m) {
    std::ostringstream out;
    out << "inner_radius (" << spec.inner_radius_m * 1e3
        << " mm) must be smaller than outer_radius (" << spec.outer_radius_m * 1e3 << " mm)";
    problems.push_back(out.str());
  }
  finite_positive(spec.length_m, "length");
  finite_positive(spec.youngs_modulus_Pa, "youngs_modulus");
  if (!std::isfinite(spec.poisson_ratio) || spec.poisson_ratio < 0.0 || spec.poisson_ratio > 0.5) {
    std::ostringstream out;
    out << "poisson_ratio (" << spec.poisson_ratio << ") must be in [0, 0.5]";
    problems.push_back(out.str());
  }
  if (problems.empty()) {
    // Each field can be in range while their product is not: radii of 1e-100 m underflow I to
    // zero, and a zero or infinite E I would make every load parameter NaN or infinite.
    const double r1 = spec.outer_radius_m, r2 = spec.inner_radius_m, l = spec.length_m;
    const double ei = spec.youngs_modulus_Pa * std::numbers::pi * (r1 - r2) * (r1 + r2) *
                      (r1 * r1 + r2 * r2) / 4.0;
    const double k = 3.0 * ei / (l * l * l);
    if (!(ei > 0.0) || !std::isfinite(ei) || !(k > 0.0) || !std::isfinite(k)) {
      std::ostringstream out;
      out << "section: the bending stiffness E I (" << ei << " N m^2) or the tip stiffness "
          << "3 E I / l^3 (" << k << " N/m) is not a finite number greater than zero; "
          << "expected physical sizes and modulus";
      problems.push_back(out.str());
    }
  }
  return problems;
}

TubeSection ComputeSection(const TubeSpec& spec) {
  if (const auto problems = ValidateTubeSpec(spec); !problems.empty()) {
    std::string all = "invalid tube:";
    for (const auto& p : problems) all += " " + p + ";";
    throw std::invalid_argument(all);
  }
  const double r1 = spec.outer_radius_m;
  const double r2 = spec.inner_radius_m;
  TubeSection section;
  // r1^4 - r2^4 factored as (r1^2 - r2^2)(r1^2 + r2^2) keeps digits for thin walls (r2 -> r1).
  section.second_moment_m4 = std::numbers::pi * (r1 - r2) * (r1 + r2) * (r1 * r1 + r2 * r2) / 4.0;
  section.bending_stiffness_Nm2 = spec.youngs_modulus_Pa * section.second_moment_m4;
  const double l = spec.length_m;
  section.tip_stiffness_N_per_m = 3.0 * section.bending_stiffness_Nm2 / (l * l * l);
  return section;
}

double LoadParameter(const TubeSpec& spec, double force_N) {
  const TubeSection section = ComputeSection(spec);
  return force_N * spec.length_m * spec.length_m / section.bending_stiffness_Nm2;
}

}  // namespace tubeplan::model
