// Graphviz through its `dot` program (graph --svg, the HTML report's graph): the SVG it draws,
// and clear errors when the program is missing or fails.
#include <filesystem>
#include <fstream>
#include <sstream>

#include <catch2/catch.hpp>

#include <tubeplan/report/graphviz.hpp>

#include "run_tool.hpp"

namespace {

using namespace tubeplan;
using testing::RunTool;
using testing::Slurp;
using testing::SourcePath;

}  // namespace

TEST_CASE("Graphviz: SVG from dot, and clear errors when dot is missing or fails",
          "[cli][graphviz]") {
  const report::SvgFromDot ok = report::RenderDot("digraph { a -> b }");
  INFO(ok.error);
  CHECK(ok.error.empty());
  CHECK(ok.svg.find("<svg") != std::string::npos);
  CHECK(ok.svg.find("</svg>") != std::string::npos);

  const report::SvgFromDot missing =
      report::RenderDot("digraph { a -> b }", "tubeplan-no-such-dot");
  CHECK(missing.svg.empty());
  CHECK(missing.error.find("`tubeplan-no-such-dot` program was not found on PATH") !=
        std::string::npos);

  const report::SvgFromDot bad = report::RenderDot("digraph { a -> ");
  CHECK(bad.svg.empty());
  CHECK(bad.error.find("Graphviz's `dot` failed (exit 1)") != std::string::npos);
  CHECK(bad.error.find("syntax error") != std::string::npos);
}

TEST_CASE("graph --svg writes the picture Graphviz draws of the DOT", "[cli][graphviz][explore]") {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / "tubeplan-graph-svg-test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string svg = (dir / "g.svg").string(), dot = (dir / "g.dot").string();
  // A small budget: the picture is what is tested here, not the exploration.
  const testing::Outcome r =
      RunTool({"graph", SourcePath("scenes/groove.yaml"), "--budget", "20", "--time-limit", "0",
               "--svg", svg, "--dot", dot, "--jobs", "1"});
  INFO(r.err);
  REQUIRE(r.exit_code <= 1);
  CHECK(r.out.find("SVG (Graphviz dot) written to " + svg) != std::string::npos);
  const std::string picture = Slurp(svg);
  CHECK(picture.find("<svg") != std::string::npos);
  // The same DOT through dot here gives the same picture.
  CHECK(picture == report::RenderDot(Slurp(dot)).svg);
  std::filesystem::remove_all(dir);
}
