#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include <tubeplan/report/svg_plot.hpp>

namespace tubeplan::report {
namespace {

// Colour-blind-safe palette (Okabe & Ito).
constexpr std::array<const char*, 8> kPalette = {"#0072B2", "#D55E00", "#009E73", "#CC79A7",
                                                 "#E69F00", "#56B4E9", "#000000", "#F0E442"};

bool Drawable(double v, bool log) { return std::isfinite(v) && (!log || v > 0.0); }

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

std::string Tick(double v, bool log) {
  char buf[32];
  if (log) {
    const int e = static_cast<int>(std::lround(std::log10(v)));
    if (e >= -2 && e <= 3)
      std::snprintf(buf, sizeof buf, "%g", std::pow(10.0, e));
    else
      std::snprintf(buf, sizeof buf, "1e%d", e);
  } else {
    std::snprintf(buf, sizeof buf, "%g", v);
  }
  return buf;
}

struct Axis {
  bool log = true;
  double lo = 0.0, hi = 1.0;  // in axis units (log10 for log axes)
  double px_lo = 0.0, px_hi = 1.0;
  double Map(double v) const {
    const double u = log ? std::log10(v) : v;
    return px_lo + (u - lo) / (hi - lo) * (px_hi - px_lo);
  }
};

Axis MakeAxis(const std::vector<double>& values, bool log, double px_lo, double px_hi) {
  Axis a;
  a.log = log;
  a.px_lo = px_lo;
  a.px_hi = px_hi;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const double v : values) {
    const double u = log ? std::log10(v) : v;
    lo = std::min(lo, u);
    hi = std::max(hi, u);
  }
  if (!std::isfinite(lo)) lo = 0.0, hi = 1.0;
  if (log) {
    lo = std::floor(lo);
    hi = std::ceil(hi);
    if (hi <= lo) hi = lo + 1.0;
  } else {
    const double pad = hi > lo ? 0.05 * (hi - lo) : 1.0;
    lo -= pad;
    hi += pad;
  }
  a.lo = lo;
  a.hi = hi;
  return a;
}

// The drawing area of a chart: the document's size and the margins around the plot.
struct Frame {
  double W = 0, H = 0, left = 0, right = 0, top = 0, bottom = 0;
};

// `x_axis`: given, the document carries its x axis (data-x="lo hi px_lo px_hi") so that a page's
// script can map a time to a pixel (the HTML report's cursor).
void OpenSvg(std::ostream& o, const Frame& f, const Axis* x_axis = nullptr) {
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << f.W << "\" height=\"" << f.H
    << "\" viewBox=\"0 0 " << f.W << ' ' << f.H << "\" font-family=\"sans-serif\" font-size=\"12\"";
  if (x_axis != nullptr)
    o << " data-x=\"" << x_axis->lo << ' ' << x_axis->hi << ' ' << x_axis->px_lo << ' '
      << x_axis->px_hi << "\"";
  o << ">\n";
  o << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
}

// Tick values of an axis: every decade on a log axis, nice values on a linear one.
std::vector<double> AxisTicks(const Axis& a) {
  std::vector<double> t;
  if (a.log) {
    for (double e = a.lo; e <= a.hi + 1e-9; e += 1.0) t.push_back(std::pow(10.0, e));
  } else {
    t = NiceTicks(a.lo, a.hi, 8);
  }
  return t;
}

// Grid, tick labels, the plot's border and the axis labels.
void DrawAxes(std::ostream& o, const Axis& ax, const Axis& ay, const Frame& f,
              const std::string& x_label, const std::string& y_label) {
  const double x_lo = f.left, x_hi = f.W - f.right, y_lo = f.H - f.bottom, y_hi = f.top;
  for (const double t : AxisTicks(ax)) {
    const double x = ax.Map(t);
    o << "<line x1=\"" << Num(x) << "\" y1=\"" << Num(y_hi) << "\" x2=\"" << Num(x) << "\" y2=\""
      << Num(y_lo) << "\" stroke=\"#ddd\"/>\n";
    o << "<text x=\"" << Num(x) << "\" y=\"" << Num(y_lo + 16) << "\" text-anchor=\"middle\">"
      << Tick(t, ax.log) << "</text>\n";
  }
  for (const double t : AxisTicks(ay)) {
    const double y = ay.Map(t);
    o << "<line x1=\"" << Num(x_lo) << "\" y1=\"" << Num(y) << "\" x2=\"" << Num(x_hi) << "\" y2=\""
      << Num(y) << "\" stroke=\"#ddd\"/>\n";
    o << "<text x=\"" << Num(x_lo - 6) << "\" y=\"" << Num(y + 4) << "\" text-anchor=\"end\">"
      << Tick(t, ay.log) << "</text>\n";
  }
  o << "<rect x=\"" << Num(x_lo) << "\" y=\"" << Num(y_hi) << "\" width=\"" << Num(x_hi - x_lo)
    << "\" height=\"" << Num(y_lo - y_hi) << "\" fill=\"none\" stroke=\"black\"/>\n";
  o << "<text x=\"" << Num((x_lo + x_hi) / 2) << "\" y=\"" << Num(f.H - 8)
    << "\" text-anchor=\"middle\">" << EscapeXml(x_label) << "</text>\n";
  if (!y_label.empty())
    o << "<text transform=\"translate(16," << Num((y_hi + y_lo) / 2)
      << ") rotate(-90)\" text-anchor=\"middle\">" << EscapeXml(y_label) << "</text>\n";
}

// A linear axis over [lo, hi] exactly (no padding), widened when degenerate.
Axis FixedAxis(double lo, double hi, double px_lo, double px_hi) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) lo = 0.0, hi = 1.0;
  if (hi <= lo) hi = lo + (lo == 0.0 ? 1.0 : std::abs(lo) * 0.1);
  Axis a;
  a.log = false;
  a.lo = lo;
  a.hi = hi;
  a.px_lo = px_lo;
  a.px_hi = px_hi;
  return a;
}

// Shaded spans, clipped to the axis, with their tooltip; a span of no width (a moment) is a solid
// line.
void DrawSpans(std::ostream& o, const std::vector<Span>& spans, const Axis& ax, double y_top,
               double y_bottom) {
  for (const Span& s : spans) {
    if (!std::isfinite(s.x0) || !std::isfinite(s.x1)) continue;
    const double x0 = ax.Map(std::clamp(std::min(s.x0, s.x1), ax.lo, ax.hi));
    const double x1 = ax.Map(std::clamp(std::max(s.x0, s.x1), ax.lo, ax.hi));
    o << "<rect class=\"span\" x=\"" << Num(x0) << "\" y=\"" << Num(y_top) << "\" width=\""
      << Num(std::max(x1 - x0, 2.0)) << "\" height=\"" << Num(y_bottom - y_top)
      << "\" fill=\"#D55E00\" fill-opacity=\"" << (s.x1 > s.x0 ? "0.15" : "0.8") << "\"><title>"
      << EscapeXml(s.label) << "</title></rect>\n";
  }
}

}  // namespace

std::vector<double> NiceTicks(double lo, double hi, int target) {
  if (!std::isfinite(lo) || !std::isfinite(hi) || hi <= lo || target < 1) return {lo};
  const double raw = (hi - lo) / target;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  double step = magnitude;
  for (const double m : {1.0, 2.0, 5.0, 10.0})
    if (m * magnitude >= raw) {
      step = m * magnitude;
      break;
    }
  std::vector<double> ticks;
  // Integer multiples of the step, so that 0 is exactly 0 and no rounding error accumulates.
  for (double k = std::ceil(lo / step - 1e-9); k * step <= hi + step * 1e-9; k += 1.0)
    ticks.push_back(k * step == 0.0 ? 0.0 : k * step);
  return ticks;
}

std::string RenderSvg(const LinePlot& plot) {
  const Frame f{double(plot.width_px), double(plot.height_px), 70, 20, 34, 42};
  double x_lo = std::numeric_limits<double>::infinity(), x_hi = -x_lo;
  double y_lo = 0.0, y_hi = 0.0;  // zero always shown
  const auto take_y = [&](double y) {
    if (std::isfinite(y)) y_lo = std::min(y_lo, y), y_hi = std::max(y_hi, y);
  };
  for (const PlotSeries& s : plot.series)
    for (const PlotPoint& p : s.points) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;
      x_lo = std::min(x_lo, p.x);
      x_hi = std::max(x_hi, p.x);
      take_y(p.y);
    }
  for (const LimitLine& l : plot.limits) take_y(l.y);
  for (const PlotPoint& m : plot.markers) take_y(m.y);
  if (plot.x_min) x_lo = *plot.x_min;
  if (plot.x_max) x_hi = *plot.x_max;
  // Headroom above the highest value so that a limit line and a peak stay visible.
  const double pad = 0.08 * (y_hi - y_lo);
  const Axis ax = FixedAxis(x_lo, x_hi, f.left, f.W - f.right);
  const Axis ay = FixedAxis(y_lo - (y_lo < 0.0 ? pad : 0.0), y_hi + pad, f.H - f.bottom, f.top);

  std::ostringstream o;
  OpenSvg(o, f, &ax);
  o << "<text x=\"" << Num(f.left) << "\" y=\"20\" font-size=\"14\" font-weight=\"bold\">"
    << EscapeXml(plot.title) << "</text>\n";
  DrawSpans(o, plot.spans, ax, f.top, f.H - f.bottom);
  DrawAxes(o, ax, ay, f, plot.x_label, plot.y_label);
  // Legend on the title's line, right-aligned: series, then the limit style.
  double lx = f.W - f.right;
  const auto legend = [&](const std::string& name, const std::string& colour, bool dashed) {
    lx -= 7.0 * static_cast<double>(name.size()) + 34.0;
    o << "<line x1=\"" << Num(lx) << "\" y1=\"16\" x2=\"" << Num(lx + 18)
      << "\" y2=\"16\" stroke=\"" << colour << "\" stroke-width=\"2\""
      << (dashed ? " stroke-dasharray=\"6,3\"" : "") << "/><text x=\"" << Num(lx + 22)
      << "\" y=\"20\">" << EscapeXml(name) << "</text>\n";
  };
  if (!plot.limits.empty()) legend("limit", "#D00000", true);
  for (std::size_t si = plot.series.size(); si-- > 0;) {
    const PlotSeries& s = plot.series[si];
    legend(s.name, s.colour.empty() ? kPalette[si % kPalette.size()] : s.colour, false);
  }
  for (std::size_t si = 0; si < plot.series.size(); ++si) {
    const PlotSeries& s = plot.series[si];
    const std::string colour = s.colour.empty() ? kPalette[si % kPalette.size()] : s.colour;
    o << "<polyline class=\"series\" fill=\"none\" stroke=\"" << colour
      << "\" stroke-width=\"1.5\" stroke-linejoin=\"round\" points=\"";
    for (const PlotPoint& p : s.points)
      if (std::isfinite(p.x) && std::isfinite(p.y) && p.x >= ax.lo && p.x <= ax.hi)
        o << Num(ax.Map(p.x)) << ',' << Num(ay.Map(p.y)) << ' ';
    o << "\"><title>" << EscapeXml(s.name) << "</title></polyline>\n";
  }
  for (const LimitLine& l : plot.limits) {
    if (!std::isfinite(l.y)) continue;
    const double y = ay.Map(l.y);
    o << "<line class=\"limit\" x1=\"" << Num(f.left) << "\" y1=\"" << Num(y) << "\" x2=\""
      << Num(f.W - f.right) << "\" y2=\"" << Num(y)
      << "\" stroke=\"#D00000\" stroke-width=\"1.5\" stroke-dasharray=\"6,3\"/>\n";
    o << "<text x=\"" << Num(f.W - f.right - 4) << "\" y=\"" << Num(y - 4)
      << "\" text-anchor=\"end\" fill=\"#D00000\">" << EscapeXml(l.label) << "</text>\n";
  }
  for (const PlotPoint& m : plot.markers) {
    if (!std::isfinite(m.x) || !std::isfinite(m.y) || m.x < ax.lo || m.x > ax.hi) continue;
    const double x = ax.Map(m.x), y = ay.Map(m.y);
    o << "<path class=\"marker\" d=\"M" << Num(x) << ',' << Num(y - 2) << " l-5,-9 h10 z\" "
      << "fill=\"#D00000\"><title>" << EscapeXml(m.label) << "</title></path>\n";
  }
  o << "</svg>\n";
  return o.str();
}

std::string RenderSvg(const TimelinePlot& plot) {
  const double lane_h = plot.lane_height_px;
  const Frame f{double(plot.width_px),
                34 + lane_h * double(std::max<std::size_t>(plot.lanes.size(), 1)) + 40,
                double(plot.label_width_px),
                20,
                34,
                40};
  double x_lo = std::numeric_limits<double>::infinity(), x_hi = -x_lo;
  for (const TimelineBar& b : plot.bars)
    if (std::isfinite(b.x0) && std::isfinite(b.x1))
      x_lo = std::min({x_lo, b.x0, b.x1}), x_hi = std::max({x_hi, b.x0, b.x1});
  if (plot.x_min) x_lo = *plot.x_min;
  if (plot.x_max) x_hi = *plot.x_max;
  const Axis ax = FixedAxis(x_lo, x_hi, f.left, f.W - f.right);
  std::ostringstream o;
  OpenSvg(o, f, &ax);
  o << "<text x=\"" << Num(f.left) << "\" y=\"20\" font-size=\"14\" font-weight=\"bold\">"
    << EscapeXml(plot.title) << "</text>\n";
  const double bottom = f.H - f.bottom;
  DrawSpans(o, plot.spans, ax, f.top, bottom);
  for (const double t : AxisTicks(ax)) {
    const double x = ax.Map(t);
    o << "<line x1=\"" << Num(x) << "\" y1=\"" << Num(f.top) << "\" x2=\"" << Num(x) << "\" y2=\""
      << Num(bottom) << "\" stroke=\"#ddd\"/>\n";
    o << "<text x=\"" << Num(x) << "\" y=\"" << Num(bottom + 16) << "\" text-anchor=\"middle\">"
      << Tick(t, false) << "</text>\n";
  }
  for (std::size_t i = 0; i < plot.lanes.size(); ++i) {
    const double y = f.top + lane_h * double(i);
    if (i % 2 == 1)
      o << "<rect x=\"" << Num(f.left) << "\" y=\"" << Num(y) << "\" width=\""
        << Num(f.W - f.right - f.left) << "\" height=\"" << Num(lane_h)
        << "\" fill=\"#000\" fill-opacity=\"0.04\"/>\n";
    o << "<text x=\"" << Num(f.left - 6) << "\" y=\"" << Num(y + lane_h / 2 + 4)
      << "\" text-anchor=\"end\" font-family=\"monospace\" font-size=\"11\">"
      << EscapeXml(plot.lanes[i]) << "</text>\n";
  }
  for (const TimelineBar& b : plot.bars) {
    if (b.lane < 0 || std::size_t(b.lane) >= plot.lanes.size() || !std::isfinite(b.x0) ||
        !std::isfinite(b.x1))
      continue;
    const double x0 = ax.Map(std::clamp(b.x0, ax.lo, ax.hi));
    const double x1 = ax.Map(std::clamp(b.x1, ax.lo, ax.hi));
    const double y = f.top + lane_h * b.lane + 3;
    const double w = std::max(x1 - x0, 1.5);
    o << "<rect class=\"bar\" x=\"" << Num(x0) << "\" y=\"" << Num(y) << "\" width=\"" << Num(w)
      << "\" height=\"" << Num(lane_h - 6) << "\" rx=\"2\" fill=\"" << b.colour << "\"><title>"
      << EscapeXml(b.tooltip.empty() ? b.label : b.tooltip) << "</title></rect>\n";
    // About 6.5 px per character at 11 px.
    if (!b.label.empty() && w > 6.5 * double(b.label.size()) + 6)
      o << "<text x=\"" << Num(x0 + 4) << "\" y=\"" << Num(y + lane_h / 2 + 1)
        << "\" font-size=\"11\" fill=\"white\">" << EscapeXml(b.label) << "</text>\n";
  }
  o << "<rect x=\"" << Num(f.left) << "\" y=\"" << Num(f.top) << "\" width=\""
    << Num(f.W - f.right - f.left) << "\" height=\"" << Num(bottom - f.top)
    << "\" fill=\"none\" stroke=\"black\"/>\n";
  o << "<text x=\"" << Num((f.left + f.W - f.right) / 2) << "\" y=\"" << Num(f.H - 8)
    << "\" text-anchor=\"middle\">" << EscapeXml(plot.x_label) << "</text>\n";
  o << "</svg>\n";
  return o.str();
}

std::string EscapeXml(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::vector<std::size_t> ParetoFront(const std::vector<PlotPoint>& points) {
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (std::isfinite(points[i].x) && std::isfinite(points[i].y)) order.push_back(i);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return points[a].x != points[b].x ? points[a].x < points[b].x : points[a].y < points[b].y;
  });
  std::vector<std::size_t> front;
  double best_y = std::numeric_limits<double>::infinity();
  for (const std::size_t i : order) {
    if (points[i].y < best_y) {
      front.push_back(i);
      best_y = points[i].y;
    }
  }
  return front;
}

std::string RenderSvg(const ScatterPlot& plot) {
  const Frame f{double(plot.width_px), double(plot.height_px), 80, 220, 40, 60};
  const double W = f.W, H = f.H, left = f.left, right = f.right, top = f.top;
  std::vector<double> xs, ys;
  int hidden = 0;
  std::vector<PlotPoint> all;
  for (const PlotSeries& s : plot.series)
    for (const PlotPoint& p : s.points) {
      if (Drawable(p.x, plot.log_x) && Drawable(p.y, plot.log_y)) {
        xs.push_back(p.x);
        ys.push_back(p.y);
        all.push_back(p);
      } else {
        ++hidden;
      }
    }
  const Axis ax = MakeAxis(xs, plot.log_x, left, W - right);
  const Axis ay = MakeAxis(ys, plot.log_y, H - f.bottom, top);

  std::ostringstream o;
  OpenSvg(o, f);
  o << "<text x=\"" << Num(W / 2) << "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">"
    << EscapeXml(plot.title) << "</text>\n";
  DrawAxes(o, ax, ay, f, plot.x_label, plot.y_label);

  if (plot.pareto_front && all.size() > 1) {
    const std::vector<std::size_t> front = ParetoFront(all);
    o << "<polyline fill=\"none\" stroke=\"#888\" stroke-width=\"1.5\" stroke-dasharray=\"5,3\" "
         "points=\"";
    for (std::size_t k = 0; k < front.size(); ++k) {
      const PlotPoint& p = all[front[k]];
      if (k > 0) o << Num(ax.Map(p.x)) << ',' << Num(ay.Map(all[front[k - 1]].y)) << ' ';
      o << Num(ax.Map(p.x)) << ',' << Num(ay.Map(p.y)) << ' ';
    }
    o << "\"/>\n";
  }
  for (std::size_t si = 0; si < plot.series.size(); ++si) {
    const PlotSeries& s = plot.series[si];
    const std::string colour = s.colour.empty() ? kPalette[si % kPalette.size()] : s.colour;
    for (const PlotPoint& p : s.points) {
      if (!Drawable(p.x, plot.log_x) || !Drawable(p.y, plot.log_y)) continue;
      const double x = ax.Map(p.x), y = ay.Map(p.y);
      o << "<circle cx=\"" << Num(x) << "\" cy=\"" << Num(y) << "\" r=\"4.5\" fill=\"" << colour
        << "\" fill-opacity=\"0.8\"><title>" << EscapeXml(s.name + ": " + p.label)
        << "</title></circle>\n";
      if (!p.label.empty())
        o << "<text x=\"" << Num(x + 6) << "\" y=\"" << Num(y - 5) << "\" font-size=\"9\" fill=\""
          << colour << "\">" << EscapeXml(p.label) << "</text>\n";
    }
    const double ly = top + 16 + 18 * static_cast<double>(si);
    o << "<circle cx=\"" << Num(W - right + 18) << "\" cy=\"" << Num(ly - 4)
      << "\" r=\"4.5\" fill=\"" << colour << "\"/><text x=\"" << Num(W - right + 28) << "\" y=\""
      << Num(ly) << "\">" << EscapeXml(s.name) << "</text>\n";
  }
  if (plot.pareto_front) {
    const double ly = top + 16 + 18 * static_cast<double>(plot.series.size());
    o << "<line x1=\"" << Num(W - right + 10) << "\" y1=\"" << Num(ly - 4) << "\" x2=\""
      << Num(W - right + 26) << "\" y2=\"" << Num(ly - 4)
      << "\" stroke=\"#888\" stroke-dasharray=\"5,3\"/><text x=\"" << Num(W - right + 28)
      << "\" y=\"" << Num(ly) << "\">Pareto front</text>\n";
  }
  if (hidden > 0)
    o << "<text x=\"" << Num(left) << "\" y=\"" << Num(H - 4) << "\" font-size=\"10\">" << hidden
      << " point(s) not drawable on these axes (zero or not finite)</text>\n";
  o << "</svg>\n";
  return o.str();
}

}  // namespace tubeplan::report
