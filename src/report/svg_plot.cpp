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

}  // namespace

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
  const double W = plot.width_px, H = plot.height_px;
  const double left = 80, right = 220, top = 40, bottom = 60;
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
  const Axis ay = MakeAxis(ys, plot.log_y, H - bottom, top);

  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << W << "\" height=\"" << H
    << "\" viewBox=\"0 0 " << W << ' ' << H << "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  o << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  o << "<text x=\"" << Num(W / 2) << "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">"
    << EscapeXml(plot.title) << "</text>\n";
  // Grid and ticks: every decade on log axes, ten steps on linear ones.
  const auto ticks = [](const Axis& a) {
    std::vector<double> t;
    if (a.log) {
      for (double e = a.lo; e <= a.hi + 1e-9; e += 1.0) t.push_back(std::pow(10.0, e));
    } else {
      for (int i = 0; i <= 10; ++i) t.push_back(a.lo + (a.hi - a.lo) * i / 10.0);
    }
    return t;
  };
  for (const double t : ticks(ax)) {
    const double x = ax.Map(t);
    o << "<line x1=\"" << Num(x) << "\" y1=\"" << Num(top) << "\" x2=\"" << Num(x) << "\" y2=\""
      << Num(H - bottom) << "\" stroke=\"#ddd\"/>\n";
    o << "<text x=\"" << Num(x) << "\" y=\"" << Num(H - bottom + 16) << "\" text-anchor=\"middle\">"
      << Tick(t, ax.log) << "</text>\n";
  }
  for (const double t : ticks(ay)) {
    const double y = ay.Map(t);
    o << "<line x1=\"" << Num(left) << "\" y1=\"" << Num(y) << "\" x2=\"" << Num(W - right)
      << "\" y2=\"" << Num(y) << "\" stroke=\"#ddd\"/>\n";
    o << "<text x=\"" << Num(left - 6) << "\" y=\"" << Num(y + 4) << "\" text-anchor=\"end\">"
      << Tick(t, ay.log) << "</text>\n";
  }
  o << "<rect x=\"" << Num(left) << "\" y=\"" << Num(top) << "\" width=\"" << Num(W - right - left)
    << "\" height=\"" << Num(H - bottom - top) << "\" fill=\"none\" stroke=\"black\"/>\n";
  o << "<text x=\"" << Num((left + W - right) / 2) << "\" y=\"" << Num(H - 18)
    << "\" text-anchor=\"middle\">" << EscapeXml(plot.x_label) << "</text>\n";
  o << "<text transform=\"translate(20," << Num((top + H - bottom) / 2)
    << ") rotate(-90)\" text-anchor=\"middle\">" << EscapeXml(plot.y_label) << "</text>\n";

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
