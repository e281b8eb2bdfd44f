// The SVG chart module: the Pareto front against brute force, and the document's content.
#include <algorithm>
#include <random>
#include <string>

#include <catch2/catch.hpp>

#include <tubeplan/report/svg_plot.hpp>

using namespace tubeplan;

TEST_CASE("Pareto front: exactly the points no other point dominates", "[report]") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<report::PlotPoint> pts;
    for (int i = 0; i < 30; ++i) pts.push_back({u(rng), u(rng), ""});
    const std::vector<std::size_t> front = report::ParetoFront(pts);
    // Brute force: i is on the front when no j is at least as good in both and better in one.
    std::vector<std::size_t> expected;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      bool dominated = false;
      for (std::size_t j = 0; j < pts.size(); ++j)
        if (j != i && pts[j].x <= pts[i].x && pts[j].y <= pts[i].y &&
            (pts[j].x < pts[i].x || pts[j].y < pts[i].y))
          dominated = true;
      if (!dominated) expected.push_back(i);
    }
    std::sort(expected.begin(), expected.end(),
              [&](std::size_t a, std::size_t b) { return pts[a].x < pts[b].x; });
    CHECK(front == expected);
  }
}

TEST_CASE("SVG chart: one marker per drawable point, escaped labels, the front drawn", "[report]") {
  report::ScatterPlot plot;
  plot.title = "error <vs> time";
  plot.series.push_back({"linear", "", {{1.0, 0.1, "a&b"}, {10.0, 0.01, "c"}}});
  plot.series.push_back({"elastica", "", {{100.0, 0.001, "d"}, {0.0, 1.0, "zero time"}}});
  const std::string svg = report::RenderSvg(plot);
  const auto count = [&](const std::string& what) {
    std::size_t n = 0;
    for (std::size_t at = svg.find(what); at != std::string::npos; at = svg.find(what, at + 1)) ++n;
    return n;
  };
  // Three drawable points plus one legend marker per series; x = 0 cannot be drawn on a log axis.
  CHECK(count("<circle") == 3 + 2);
  CHECK(count("<polyline") == 1);
  CHECK(svg.find("error &lt;vs&gt; time") != std::string::npos);
  CHECK(svg.find("a&amp;b") != std::string::npos);
  CHECK(svg.find("1 point(s) not drawable") != std::string::npos);
  CHECK(svg.rfind("</svg>") != std::string::npos);
}
