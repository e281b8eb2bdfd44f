// The per-tick series (docs/simulate-output.md): what a PC's friction state column says.
#include <cmath>
#include <string>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <tubeplan/core/core.hpp>
#include <tubeplan/report/series_format.hpp>

#include "../core/core_scenes.hpp"

using namespace tubeplan;

TEST_CASE("A PC's friction state is none on a frictionless part, stuck or sliding on one with",
          "[report]") {
  // The rubber tube held level along y, its side 0.9 mm above a floor: 0.1 mm into the band.
  const auto state_on = [](const scene::Friction& friction) {
    scene::Scene s = testing::RubberScene();
    s.friction = friction;
    scene::Part floor;
    floor.name = "floor";
    floor.size_m = {0.4, 0.4, 0.02};
    floor.X_WP = Eigen::Translation3d(0.0, 0.0, -0.01) * Eigen::Isometry3d::Identity();
    s.parts.push_back(floor);
    const double r1 = s.tube.outer_radius_m;
    s.X_WH_start = Eigen::Translation3d(0.0, 0.0, r1 + 0.9e-3) *
                   Eigen::AngleAxisd(-0.5 * M_PI, Eigen::Vector3d::UnitX());
    core::Core core(s);
    for (int k = 1; k <= 200; ++k) core.Step(1e-3 * k, s.X_WH_start);
    REQUIRE(core.last().contact_count > 0);
    report::SeriesWriter writer(report::SeriesFormat::kJsonLines, false);
    writer.Add(core, core.last(), core.FormationText());
    const nlohmann::json row = nlohmann::json::parse(writer.text());
    return row.at("contacts").at(0);
  };
  const nlohmann::json frictionless = state_on(scene::Friction{});
  CHECK(frictionless.at("limit") == 0.0);
  CHECK(frictionless.at("state") == "none");
  const nlohmann::json held = state_on(scene::Friction{0.7, 0.5, 1.0, 1.0});
  CHECK(held.at("limit").get<double>() > 0.0);
  CHECK(held.at("state") == "stuck");
}
