#pragma once
// Small, dependency-free SVG charts for reports (the accuracy study's error-vs-time plot; HTML
// reports embed the same markup). A chart is plain data; rendering returns the whole document.

#include <string>
#include <vector>

namespace tubeplan::report {

struct PlotPoint {
  double x = 0.0;
  double y = 0.0;
  std::string label;  ///< shown next to the marker (and as its tooltip)
};

struct PlotSeries {
  std::string name;    ///< the legend's entry
  std::string colour;  ///< any SVG colour; empty: from a fixed palette by index
  std::vector<PlotPoint> points;
};

struct ScatterPlot {
  std::string title;
  std::string x_label;
  std::string y_label;
  bool log_x = true;
  bool log_y = true;
  /// Draw the Pareto front of all points (smallest x and y) as a step line.
  bool pareto_front = true;
  int width_px = 880;
  int height_px = 600;
  std::vector<PlotSeries> series;
};

/// Indices (into `points`) of the points not dominated in (x, y), both minimised, sorted by x.
/// Points with a non-finite or (for log axes) non-positive coordinate are left out.
std::vector<std::size_t> ParetoFront(const std::vector<PlotPoint>& points);

/// The chart as a standalone SVG document (no scripts, no external resources). Non-finite
/// points, and non-positive ones on a log axis, are not drawn (they are counted in a note).
std::string RenderSvg(const ScatterPlot& plot);

/// Text escaped for SVG/XML content and attributes.
std::string EscapeXml(const std::string& text);

}  // namespace tubeplan::report
