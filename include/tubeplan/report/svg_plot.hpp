#pragma once
// Small, dependency-free SVG charts for reports: scatter charts (the accuracy study's
// error-vs-time plot), line charts over time with limits and marked moments, and timelines of
// states (the HTML report of `evaluate --html`). All share one axis and frame code. A chart is
// plain data; rendering returns the whole document (no scripts, no external resources), which
// HTML reports embed as it is.

#include <optional>
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

/// A horizontal line across a line chart: a limit.
struct LimitLine {
  double y = 0.0;
  std::string label;  ///< e.g. "limit 8.5 N"
};

/// An interval of x shaded across the chart: a time something was wrong (x0 == x1: a moment, drawn
/// as a solid line).
struct Span {
  double x0 = 0.0, x1 = 0.0;
  std::string label;  ///< tooltip
};

/// A line chart (linear axes): series drawn as polylines in x order, limits as dashed red lines,
/// spans shaded red, markers as red triangles (e.g. where a series exceeds its limit). The y axis
/// always shows zero, every limit and every marker.
struct LinePlot {
  std::string title;
  std::string x_label;
  std::string y_label;
  int width_px = 900;
  int height_px = 250;
  std::optional<double> x_min, x_max;  ///< unset: the data's range
  std::vector<PlotSeries> series;      ///< points in x order; labels unused
  std::vector<LimitLine> limits;
  std::vector<Span> spans;
  std::vector<PlotPoint> markers;  ///< label: tooltip
};

/// A timeline (Gantt chart): named lanes, bars in them over x, and vertical marks.
struct TimelineBar {
  int lane = 0;
  double x0 = 0.0, x1 = 0.0;
  std::string colour;
  std::string label;    ///< drawn inside the bar when it fits
  std::string tooltip;  ///< empty: the label
};

struct TimelinePlot {
  std::string title;
  std::string x_label;
  int width_px = 900;
  int lane_height_px = 22;
  int label_width_px = 220;            ///< room for the lanes' names on the left
  std::optional<double> x_min, x_max;  ///< unset: the bars' range
  std::vector<std::string> lanes;      ///< top to bottom
  std::vector<TimelineBar> bars;
  std::vector<Span> spans;  ///< shaded across all lanes
};

/// Indices (into `points`) of the points not dominated in (x, y), both minimised, sorted by x.
/// Points with a non-finite or (for log axes) non-positive coordinate are left out.
std::vector<std::size_t> ParetoFront(const std::vector<PlotPoint>& points);

/// The chart as a standalone SVG document. Non-finite points, and non-positive ones on a log
/// axis, are not drawn (they are counted in a note).
std::string RenderSvg(const ScatterPlot& plot);
std::string RenderSvg(const LinePlot& plot);
std::string RenderSvg(const TimelinePlot& plot);

/// Axis ticks at "nice" values (1, 2 or 5 times a power of ten) covering [lo, hi], at most about
/// `target` + 1 of them; a degenerate or non-finite range gives {lo}.
std::vector<double> NiceTicks(double lo, double hi, int target);

/// Text escaped for SVG/XML content and attributes.
std::string EscapeXml(const std::string& text);

}  // namespace tubeplan::report
