// The SVG chart module: the Pareto front against brute force, and the document's content.
#include <algorithm>
#include <cmath>
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

namespace {
std::size_t Count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}
}  // namespace

TEST_CASE("Nice ticks: 1, 2 or 5 times a power of ten, covering the range", "[report]") {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (int trial = 0; trial < 200; ++trial) {
    const double a = std::pow(10.0, u(rng)) * (u(rng) < 0 ? -1.0 : 1.0);
    const double lo = std::min(a, 0.0), hi = std::max(a, 0.0) + std::pow(10.0, u(rng));
    const std::vector<double> t = report::NiceTicks(lo, hi, 8);
    REQUIRE(t.size() >= 2);
    CHECK(t.size() <= 8 + 3);
    const double step = t[1] - t[0];
    const double mantissa = step / std::pow(10.0, std::floor(std::log10(step) + 1e-9));
    // The step's mantissa is 1, 2 or 5 up to rounding (1e-6: far below any other candidate).
    CHECK(std::min({std::abs(mantissa - 1), std::abs(mantissa - 2), std::abs(mantissa - 5)}) <
          1e-6);
    // Ticks within the range, at most one step from each end.
    CHECK(t.front() >= lo - 1e-9 * step);
    CHECK(t.back() <= hi + 1e-9 * step);
    CHECK(t.front() - lo < step * (1 + 1e-9));
    CHECK(hi - t.back() < step * (1 + 1e-9));
    if (lo <= 0.0 && hi >= 0.0) CHECK(std::find(t.begin(), t.end(), 0.0) != t.end());
  }
}

TEST_CASE("Line chart: a polyline per series, the limit and markers drawn, the peak inside",
          "[report]") {
  report::LinePlot plot;
  plot.title = "operator force <N>";
  plot.x_label = "t [s]";
  report::PlotSeries force{"|F|", "", {}};
  for (int i = 0; i <= 100; ++i) force.points.push_back({i * 0.01, i == 50 ? 12.0 : 1.0, ""});
  plot.series = {force, {"capacity", "#888", {{0.0, 2.0, ""}, {1.0, 2.0, ""}}}};
  plot.limits = {{8.5, "limit 8.5 N"}};
  plot.markers = {{0.5, 12.0, "12 N > 8.5 N at t = 0.5 s"}};
  plot.spans = {{0.45, 0.55, "infeasible"}};
  const std::string svg = report::RenderSvg(plot);
  CHECK(Count(svg, "<polyline class=\"series\"") == 2);
  CHECK(Count(svg, "class=\"limit\"") == 1);
  CHECK(Count(svg, "class=\"marker\"") == 1);
  CHECK(Count(svg, "class=\"span\"") == 1);
  CHECK(svg.find("operator force &lt;N&gt;") != std::string::npos);
  CHECK(svg.find("limit 8.5 N") != std::string::npos);
  // The peak's vertex lies within the plot area (top margin 34 px, so y >= 34): the y axis
  // covers the highest value with headroom.
  const std::size_t peak = svg.find(" 475.0,");  // x of t = 0.5 s: 70 + 0.5 * 810
  REQUIRE(peak != std::string::npos);
  CHECK(std::stod(svg.substr(peak + 7)) >= 34.0);
  CHECK(std::stod(svg.substr(peak + 7)) < 60.0);
}

TEST_CASE("Timeline: one bar per interval in its lane, escaped names", "[report]") {
  report::TimelinePlot plot;
  plot.lanes = {"{}", "{Ee - floor.top}", "a<b"};
  plot.bars = {{0, 0.0, 1.0, "#009E73", "{}", ""},
               {1, 1.0, 2.0, "#009E73", "{Ee - floor.top}", ""},
               {5, 0.0, 1.0, "#000", "no such lane", ""}};
  const std::string svg = report::RenderSvg(plot);
  CHECK(Count(svg, "class=\"bar\"") == 2);
  CHECK(svg.find("a&lt;b") != std::string::npos);
  CHECK(svg.find("no such lane") == std::string::npos);
}
