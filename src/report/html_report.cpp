#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <vector>

#include <nlohmann/json.hpp>

#include <tubeplan/report/html_report.hpp>
#include <tubeplan/report/svg_plot.hpp>
#include <tubeplan/report/text_report.hpp>

#include "report_assets.hpp"

namespace tubeplan::report {
namespace {

using batch::Evaluated;

void Take(ReplayRecording::Extremes& e, double t_s, double v, bool first) {
  if (first || v < e.min) e.min = v, e.t_min_s = t_s;
  if (first || v > e.max) e.max = v, e.t_max_s = t_s;
}

// Rounded for the page: 0.01 mm and 1 mN are far below what a picture shows, and the JSON stays
// small (nlohmann prints the shortest text that reads back the same double).
double Round(double v, double quantum) { return std::round(v / quantum) * quantum; }
nlohmann::json Mm(const Eigen::Vector3d& p_m) {
  return {Round(p_m.x() * 1e3, 0.01), Round(p_m.y() * 1e3, 0.01), Round(p_m.z() * 1e3, 0.01)};
}
nlohmann::json Newton(const Eigen::Vector3d& f_N) {
  return {Round(f_N.x(), 1e-3), Round(f_N.y(), 1e-3), Round(f_N.z(), 1e-3)};
}

std::string Fixed(double v, int digits) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

// A bin's width as the page says it: "20 ms", "2.56 s".
std::string Duration(double s) {
  char buf[48];
  if (s < 1.0)
    std::snprintf(buf, sizeof buf, "%.3g ms", s * 1e3);
  else
    std::snprintf(buf, sizeof buf, "%.3g s", s);
  return buf;
}

// Three significant digits: energies and work span many decades.
std::string Sig(double v) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

const char* VerdictColour(plan::Verdict v) {
  return v == plan::Verdict::kFeasible             ? "#009E73"
         : v == plan::Verdict::kFeasibleWithDetour ? "#E69F00"
         : v == plan::Verdict::kInfeasible         ? "#D55E00"
                                                   : "#999999";
}

// The plan's verdict as a badge: "FEASIBLE", "INFEASIBLE" or "NOT JUDGED" on its colour.
std::string Badge(const plan::Judgement& j) {
  const plan::Verdict overall = plan::Overall(j);
  return std::string("<span class=\"badge\" style=\"background:") + VerdictColour(overall) + "\">" +
         Headline(overall) + "</span>";
}

// Plot points of a bin series: each bin's minimum and maximum in the order they happened, so the
// polyline passes through every peak.
template <typename Member>
std::vector<PlotPoint> Envelope(const ReplayRecording& r, Member member) {
  std::vector<PlotPoint> points;
  points.reserve(r.bins.size() * 2);
  for (const ReplayRecording::Bin& b : r.bins) {
    if (b.ticks == 0) continue;
    const ReplayRecording::Extremes& e = b.*member;
    if (e.t_min_s <= e.t_max_s) {
      points.push_back({e.t_min_s, e.min, ""});
      if (e.t_max_s > e.t_min_s) points.push_back({e.t_max_s, e.max, ""});
    } else {
      points.push_back({e.t_max_s, e.max, ""});
      points.push_back({e.t_min_s, e.min, ""});
    }
  }
  return points;
}

// Where a series is above its limit: one shaded span per run of bins over it and a marker at the
// run's highest value.
template <typename Member>
void MarkExceeded(const ReplayRecording& r, Member member, double limit, const std::string& unit,
                  const std::string& what, LinePlot& plot) {
  for (std::size_t i = 0; i < r.bins.size();) {
    if (r.bins[i].ticks == 0 || !((r.bins[i].*member).max > limit)) {
      ++i;
      continue;
    }
    Span span{(r.bins[i].*member).t_max_s, 0.0, ""};
    PlotPoint peak{0.0, -1e300, ""};
    for (; i < r.bins.size() && r.bins[i].ticks > 0 && (r.bins[i].*member).max > limit; ++i) {
      const ReplayRecording::Extremes& e = r.bins[i].*member;
      span.x0 = std::min(span.x0, std::min(e.t_min_s, e.t_max_s));
      span.x1 = std::max(span.x1, e.t_max_s);
      if (e.max > peak.y) peak = {e.t_max_s, e.max, ""};
    }
    span.x1 = std::max(span.x1, span.x0);
    span.label =
        what + " over its limit from t = " + Fixed(span.x0, 3) + " to " + Fixed(span.x1, 3) + " s";
    peak.label = what + " " + Fixed(peak.y, 4) + " " + unit + " > limit " + Fixed(limit, 4) + " " +
                 unit + " at t = " + Fixed(peak.x, 3) + " s";
    plot.spans.push_back(span);
    plot.markers.push_back(peak);
  }
}

// One row of the verdict table: a planned transition, or the stretch after the goal.
std::string VerdictRow(const std::string& number, const plan::TransitionVerdict& v,
                       const std::string& what) {
  std::string why = EscapeXml(v.reason);
  if (!v.detour.empty()) {
    std::string via = v.reason.empty() ? "via" : "; via";
    for (const std::string& d : v.detour) via += " " + d;
    why += EscapeXml(via);
  }
  for (std::size_t i = 0; i < plan::kWarnedFlags.size(); ++i)
    if (v.flagged_s[i] > 0.0)
      why += "<div class=\"warning\">warning: " + EscapeXml(plan::FlagWarning(i, v.flagged_s[i])) +
             "</div>";
  std::ostringstream o;
  o << "<tr><td>" << number << "</td><td class=\"cf\">" << what
    << "</td><td><span class=\"badge\" style=\"background:" << VerdictColour(v.verdict) << "\">"
    << plan::ToString(v.verdict) << "</span></td><td>" << why << "</td>";
  if (v.started) {
    o << "<td class=\"num\">" << Fixed(v.t_start_s, 3) << " &ndash; " << Fixed(v.t_end_s, 3)
      << "</td><td class=\"num\">" << Fixed(v.peak_force_N, 3) << "</td><td class=\"num\">"
      << Sig(v.friction_work_J * 1e6) << "</td><td class=\"num\">" << Sig(v.energy_entry_J * 1e6)
      << " &rarr; " << Sig(v.energy_exit_J * 1e6) << "</td>";
  } else {
    // Not reached: no span and no figures.
    o << "<td class=\"num\">&ndash;</td><td class=\"num\">&ndash;</td>"
         "<td class=\"num\">&ndash;</td><td class=\"num\">&ndash;</td>";
  }
  o << "</tr>\n";
  return o.str();
}

std::string VerdictTable(const Evaluated& e) {
  std::ostringstream o;
  o << "<table class=\"verdicts\"><thead><tr><th>#</th><th>planned transition</th>"
       "<th>verdict</th><th>why / detour</th><th>t [s]</th><th>peak force [N]</th>"
       "<th>friction work [&micro;J]</th><th>bending energy [&micro;J]</th></tr></thead><tbody>\n";
  for (std::size_t k = 0; k < e.judgement.transitions.size(); ++k) {
    const plan::TransitionVerdict& v = e.judgement.transitions[k];
    o << VerdictRow(std::to_string(k + 1), v, EscapeXml(v.from) + " &rarr; " + EscapeXml(v.to));
  }
  if (e.judgement.after_goal.started)
    o << VerdictRow("", e.judgement.after_goal,
                    "after the goal, in " + EscapeXml(e.judgement.after_goal.to));
  o << "</tbody></table>\n";
  return o.str();
}

// The observed CFs (counted after the dwell) in lanes against the planned transitions' windows.
std::string Timeline(const Evaluated& e, const ReplayRecording& r, const std::vector<Span>& spans) {
  const plan::Judgement& j = e.judgement;
  TimelinePlot plot;
  plot.title = "Contact formations: planned windows and observed states";
  plot.x_label = "time [s]";
  plot.x_min = r.t_first_s;
  plot.x_max = r.t_last_s;
  plot.label_width_px = 250;
  plot.spans = spans;
  plot.lanes.push_back("planned transitions");
  std::map<std::string, int> lane;
  for (const std::string& s : e.plan.states)
    if (lane.emplace(s, int(plot.lanes.size())).second) plot.lanes.push_back(s);
  for (const plan::Observation& ob : j.observed)
    if (lane.emplace(ob.cf, int(plot.lanes.size())).second) plot.lanes.push_back(ob.cf);
  for (std::size_t k = 0; k < j.transitions.size(); ++k) {
    const plan::TransitionVerdict& v = j.transitions[k];
    if (!v.started) continue;  // never reached: no span
    plot.bars.push_back({0, v.t_start_s, v.t_end_s, VerdictColour(v.verdict),
                         std::to_string(k + 1) + " " + ToString(v.verdict),
                         std::to_string(k + 1) + ": " + v.from + " -> " + v.to + ": " +
                             ToString(v.verdict) +
                             (v.reason.empty() ? "" : " (" + v.reason + ")")});
  }
  if (const plan::TransitionVerdict& v = j.after_goal; v.started)
    plot.bars.push_back({0, v.t_start_s, v.t_end_s, VerdictColour(v.verdict),
                         std::string("after the goal: ") + ToString(v.verdict),
                         "after the goal, in " + v.to + ": " + ToString(v.verdict) +
                             (v.reason.empty() ? "" : " (" + v.reason + ")")});
  const std::vector<std::string>& planned = e.plan.states;
  for (std::size_t k = 0; k < j.observed.size(); ++k) {
    const plan::Observation& ob = j.observed[k];
    const double t1 = k + 1 < j.observed.size() ? j.observed[k + 1].t_s : r.t_last_s;
    const bool is_planned = std::find(planned.begin(), planned.end(), ob.cf) != planned.end();
    plot.bars.push_back({lane[ob.cf], ob.t_s, t1, is_planned ? "#0072B2" : "#CC79A7", "",
                         ob.cf + (is_planned ? " (planned)" : " (not planned)") +
                             ", t = " + Fixed(ob.t_s, 3) + " .. " + Fixed(t1, 3) + " s"});
  }
  return RenderSvg(plot);
}

std::string Plots(const Evaluated& e, const ReplayRecording& r, std::vector<Span>& spans) {
  const plan::Limits& limits = e.plan.limits;
  const auto base = [&](const std::string& title, const std::string& y_label) {
    LinePlot p;
    p.title = title;
    p.x_label = "time [s]";
    p.y_label = y_label;
    p.x_min = r.t_first_s;
    p.x_max = r.t_last_s;
    return p;
  };
  using Bin = ReplayRecording::Bin;
  LinePlot force = base("Operator force |F|", "N");
  force.series = {
      {"|F| (min/max per " + Duration(r.bin_s) + ")", "#0072B2", Envelope(r, &Bin::force_N)}};
  force.limits = {{limits.max_force_N, "limit " + Fixed(limits.max_force_N, 3) + " N"}};
  MarkExceeded(r, &Bin::force_N, limits.max_force_N, "N", "operator force", force);

  LinePlot friction = base("Friction force (sum over the contacts)", "N");
  friction.series = {
      {"|friction|", "#CC79A7", Envelope(r, &Bin::friction_N)},
      {"capacity f_max (slip above)", "#999999", Envelope(r, &Bin::friction_limit_N)}};

  LinePlot energy = base("Bending energy", "\u00b5J");
  std::vector<PlotPoint> energy_uJ = Envelope(r, &Bin::energy_J);
  for (PlotPoint& p : energy_uJ) p.y *= 1e6;
  energy.series = {{"bending energy", "#009E73", energy_uJ}};

  LinePlot strain = base("Largest bending strain", "-");
  strain.series = {{"strain", "#E69F00", Envelope(r, &Bin::strain)}};
  strain.limits = {{limits.max_strain, "limit " + Fixed(limits.max_strain, 3)}};
  MarkExceeded(r, &Bin::strain, limits.max_strain, "", "strain", strain);

  spans = force.spans;
  spans.insert(spans.end(), strain.spans.begin(), strain.spans.end());
  // The moment a transition was judged infeasible for another reason than a limit (those are
  // shaded above): another state reached, never reached, stalled. A thin line on every chart.
  const auto mark = [&](const plan::TransitionVerdict& v, const std::string& what) {
    if (!v.started || v.verdict != plan::Verdict::kInfeasible ||
        v.reason.find("limit exceeded") != std::string::npos)
      return;
    const Span moment{v.t_failed_s, v.t_failed_s,
                      what + " infeasible at t = " + Fixed(v.t_failed_s, 3) + " s: " + v.reason};
    spans.push_back(moment);
    for (LinePlot* p : {&force, &friction, &energy, &strain}) p->spans.push_back(moment);
  };
  for (std::size_t k = 0; k < e.judgement.transitions.size(); ++k)
    mark(e.judgement.transitions[k], "transition " + std::to_string(k + 1));
  mark(e.judgement.after_goal, "after the goal: the plan");
  std::string svg;
  for (const LinePlot* p : {&force, &friction, &energy, &strain})
    svg += "<div class=\"plot\">" + RenderSvg(*p) + "</div>\n";
  return svg;
}

const char* ShapeId(scene::PartShape shape) {
  return shape == scene::PartShape::kCylinder ? "cylinder"
         : shape == scene::PartShape::kMesh   ? "mesh"
                                              : "box";
}

// The mesh parts' surfaces, each written once for the page however many plans and parts show
// it: the same file loaded for several plans' scenes is one entry when its mesh is the same.
class PageMeshes {
 public:
  // The index in Json() of `mesh`, added if new.
  std::size_t IndexOf(const scene::PartMesh& mesh) {
    for (std::size_t i = 0; i < meshes_.size(); ++i)
      if (meshes_[i] == &mesh || (meshes_[i]->mesh.vertices_P_m == mesh.mesh.vertices_P_m &&
                                  meshes_[i]->mesh.triangles == mesh.mesh.triangles))
        return i;
    meshes_.push_back(&mesh);
    return meshes_.size() - 1;
  }

  // Per mesh: its vertices in the part's frame [mm], rounded as every position on the page, and
  // flat index lists of its triangles (counter-clockwise from outside) and of its feature edges'
  // segments (pairs).
  nlohmann::json Json() const {
    nlohmann::json out = nlohmann::json::array();
    for (const scene::PartMesh* m : meshes_) {
      nlohmann::json vertices = nlohmann::json::array(), triangles = nlohmann::json::array(),
                     edges = nlohmann::json::array();
      for (const Eigen::Vector3d& v : m->mesh.vertices_P_m)
        for (const double c : Mm(v)) vertices.push_back(c);
      for (const std::array<int, 3>& t : m->mesh.triangles)
        for (const int i : t) triangles.push_back(i);
      for (const scene::MeshEdge& e : m->elements.edges)
        for (const std::array<int, 2>& segment : e.segments)
          for (const int i : segment) edges.push_back(i);
      out.push_back({{"file", m->file},
                     {"vertices_mm", std::move(vertices)},
                     {"triangles", std::move(triangles)},
                     {"edges", std::move(edges)}});
    }
    return out;
  }

 private:
  std::vector<const scene::PartMesh*> meshes_;
};

nlohmann::json PlanJson(const HtmlPlan& p, PageMeshes& meshes) {
  const ReplayRecording& r = p.recording;
  const scene::Scene& s = *p.scene;
  nlohmann::json parts = nlohmann::json::array();
  for (const scene::Part& b : s.parts) {
    const Eigen::Quaterniond q(b.X_WP.linear());
    nlohmann::json part = {
        {"name", b.name},
        {"shape", ShapeId(b.shape)},
        {"size_mm", Mm(b.size_m)},
        {"p_mm", Mm(b.X_WP.translation())},
        {"q_wxyz",
         {Round(q.w(), 1e-6), Round(q.x(), 1e-6), Round(q.y(), 1e-6), Round(q.z(), 1e-6)}}};
    if (b.shape == scene::PartShape::kMesh && b.mesh) part["mesh"] = meshes.IndexOf(*b.mesh);
    parts.push_back(std::move(part));
  }
  nlohmann::json t = nlohmann::json::array(), cf = nlohmann::json::array(),
                 line = nlohmann::json::array(), held = nlohmann::json::array(),
                 hand = nlohmann::json::array(), force = nlohmann::json::array(),
                 force_abs = nlohmann::json::array(), contacts = nlohmann::json::array();
  for (const ReplayRecording::Frame& f : r.frames) {
    t.push_back(Round(f.t_s, 1e-4));
    cf.push_back(f.cf);
    force_abs.push_back(f.force_N);  // exact: the readout shows the summary's figure
    nlohmann::json c = nlohmann::json::array();
    for (const Eigen::Vector3d& q : f.centreline_W_m)
      for (const double v : Mm(q)) c.push_back(v);
    line.push_back(std::move(c));
    held.push_back(Mm(f.p_WH_m));
    hand.push_back(Mm(f.p_W_hand_m));
    force.push_back(Newton(f.force_W_N));
    nlohmann::json fc = nlohmann::json::array();
    for (const ReplayRecording::Contact& k : f.contacts)
      fc.push_back({{"p_mm", Mm(k.p_W_m)},
                    {"normal_N", Newton(k.normal_force_W_N)},
                    {"friction_N", Newton(k.friction_W_N)},
                    {"sliding", k.sliding}});
    contacts.push_back(std::move(fc));
  }
  const Evaluated& e = *p.evaluated;
  return {{"name", e.plan.name},
          {"file", e.file},
          {"scene", p.scene_path},
          {"feasible", e.judgement.feasible},
          {"max_force_N", e.plan.limits.max_force_N},
          {"tube",
           {{"outer_radius_mm", s.tube.outer_radius_m * 1e3},
            {"inner_radius_mm", s.tube.inner_radius_m * 1e3},
            {"length_mm", s.tube.length_m * 1e3}}},
          {"parts", parts},
          {"cfs", r.cfs},
          {"bin_s", r.bin_s},
          {"peak_frame", r.peak_frame},
          {"frames",
           {{"t_s", t},
            {"cf", cf},
            {"force_abs_N", force_abs},
            {"centreline_mm", line},
            {"held_mm", held},
            {"hand_mm", hand},
            {"force_N", force},
            {"contacts", contacts}}}};
}

// JSON inside <script type="application/json">: a '<' would let "</script>" or "<!--" end or
// confuse the element, so every one is written as \u003c (only strings can hold one).
std::string ScriptSafe(const std::string& json) {
  std::string out;
  out.reserve(json.size());
  for (const char c : json) {
    if (c == '<')
      out += "\\u003c";
    else
      out += c;
  }
  return out;
}

}  // namespace

ReplayRecorder::ReplayRecorder(double bin_s, std::size_t max_bins)
    : max_bins_(std::max<std::size_t>(2, max_bins)) {
  rec_.bin_s = bin_s;
}

ReplayRecording::Frame ReplayRecorder::FrameOf(double t_s, const core::Core& core) const {
  const core::StepOutput& out = core.last();
  ReplayRecording::Frame f;
  f.t_s = t_s;
  f.cf = cf_;
  f.force_N = out.force_W_N.norm();
  core.Centreline(f.centreline_W_m);
  f.p_WH_m = out.X_WH.translation();
  f.p_W_hand_m = out.X_W_hand.translation();
  f.force_W_N = out.force_W_N;
  for (const core::ContactState& c : out.Contacts())
    f.contacts.push_back({c.p_WC_m, c.normal_W * c.normal_force_N, c.friction_W_N, c.sliding});
  return f;
}

void ReplayRecorder::Halve() {
  using Bin = ReplayRecording::Bin;
  const auto merge = [](ReplayRecording::Extremes& into, const ReplayRecording::Extremes& e) {
    if (e.min < into.min) into.min = e.min, into.t_min_s = e.t_min_s;
    if (e.max > into.max) into.max = e.max, into.t_max_s = e.t_max_s;
  };
  std::vector<Bin> bins((rec_.bins.size() + 1) / 2);
  for (std::size_t i = 0; i < rec_.bins.size(); ++i) {
    const Bin& b = rec_.bins[i];
    Bin& into = bins[i / 2];
    if (b.ticks == 0) continue;
    if (into.ticks == 0) {
      into = b;
      continue;
    }
    into.ticks += b.ticks;
    merge(into.force_N, b.force_N);
    merge(into.friction_N, b.friction_N);
    merge(into.friction_limit_N, b.friction_limit_N);
    merge(into.energy_J, b.energy_J);
    merge(into.strain, b.strain);
  }
  rec_.bins = std::move(bins);
  // A merged bin's frame is its first tick's: the first frame of the pair.
  std::size_t kept = 0;
  for (std::size_t i = 0; i < rec_.frames.size(); ++i) {
    ReplayRecording::Frame& f = rec_.frames[i];
    f.bin /= 2;
    if (kept > 0 && rec_.frames[kept - 1].bin == f.bin) continue;
    if (kept != i) rec_.frames[kept] = std::move(f);
    ++kept;
  }
  rec_.frames.resize(kept);
  rec_.bin_s *= 2.0;
}

void ReplayRecorder::operator()(double t_s, const core::Core& core) {
  const core::StepOutput& out = core.last();
  if (ticks_++ == 0) rec_.t_first_s = t_s;
  rec_.t_last_s = t_s;
  auto bin = static_cast<std::size_t>(std::floor((t_s - rec_.t_first_s) / rec_.bin_s));
  while (bin >= max_bins_) {
    Halve();
    bin = static_cast<std::size_t>(std::floor((t_s - rec_.t_first_s) / rec_.bin_s));
  }
  if (rec_.bins.size() <= bin) rec_.bins.resize(bin + 1);
  ReplayRecording::Bin& b = rec_.bins[bin];
  const bool new_bin = b.ticks++ == 0;
  double friction_N = 0.0, friction_limit_N = 0.0;
  for (const core::ContactState& c : out.Contacts()) {
    friction_N += c.friction_W_N.norm();
    friction_limit_N += c.friction_limit_N;
  }
  const double force_N = out.force_W_N.norm();
  Take(b.force_N, t_s, force_N, new_bin);
  Take(b.friction_N, t_s, friction_N, new_bin);
  Take(b.friction_limit_N, t_s, friction_limit_N, new_bin);
  Take(b.energy_J, t_s, out.energy_J, new_bin);
  Take(b.strain, t_s, out.max_strain, new_bin);

  // The CF's text only when it changes (it allocates); its index for every frame. A fault tick
  // shows no state of the tube: it is named so.
  const auto index_of = [&](const std::string& text) {
    const int i = int(std::find(rec_.cfs.begin(), rec_.cfs.end(), text) - rec_.cfs.begin());
    if (i == int(rec_.cfs.size())) rec_.cfs.push_back(text);
    return i;
  };
  if (out.flags & core::kSolverFault) {
    cf_ = index_of(kFaultCf);
    key_valid_ = false;
  } else if (const core::FormationKey key = core::KeyOf(out); !key_valid_ || key != key_) {
    key_ = key;
    key_valid_ = true;
    cf_ = index_of(core.FormationText());
  }
  // The peak's frame: made again whenever the force passes the largest so far.
  if (!peak_ || force_N > peak_->force_N) {
    peak_ = FrameOf(t_s, core);
    peak_->bin = bin;
  }
  if (!new_bin) return;
  rec_.frames.push_back(FrameOf(t_s, core));
  rec_.frames.back().bin = bin;
}

ReplayRecording ReplayRecorder::Finish() {
  if (peak_) {
    // The bins' frames are in time order; the peak's goes among them (it may be one of them).
    const auto at =
        std::lower_bound(rec_.frames.begin(), rec_.frames.end(), peak_->t_s,
                         [](const ReplayRecording::Frame& f, double t) { return f.t_s < t; });
    if (at != rec_.frames.end() && at->t_s == peak_->t_s) {
      rec_.peak_frame = std::size_t(at - rec_.frames.begin());
    } else {
      peak_->bin = at == rec_.frames.begin() ? 0 : std::prev(at)->bin;
      rec_.peak_frame = std::size_t(at - rec_.frames.begin());
      rec_.frames.insert(at, std::move(*peak_));
    }
    peak_.reset();
  }
  return std::move(rec_);
}

bool HtmlReportAvailable() { return assets::Available(); }

std::string FormatHtmlReport(const std::vector<HtmlPlan>& plans, const HtmlOptions& options) {
  std::ostringstream o;
  long feasible = 0;
  for (const HtmlPlan& p : plans) feasible += p.evaluated->judgement.feasible;
  o << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
       "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
       // Nothing may be fetched: the page is complete, and a browser enforces that here.
       "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; "
       "script-src 'unsafe-inline'; style-src 'unsafe-inline'; img-src data:\">\n"
       "<title>tubeplan report: "
    << plans.size() << " plan" << (plans.size() == 1 ? "" : "s") << "</title>\n<style>\n"
    << assets::ReportCss() << "</style>\n</head>\n<body>\n";
  o << "<header><h1>tubeplan: feasibility of assembly plans</h1><p class=\"summary\">"
    << plans.size() << " plan" << (plans.size() == 1 ? "" : "s") << ": <b class=\"ok\">" << feasible
    << " feasible</b>, <b class=\"bad\">" << long(plans.size()) - feasible
    << " infeasible</b></p><p class=\"command\"><code>" << EscapeXml(options.command)
    << "</code></p></header>\n";

  o << "<section id=\"summary\"><table class=\"plans\"><thead><tr><th>plan</th><th>file</th>"
       "<th>verdict</th><th>transitions</th><th>replayed [s]</th><th>peak force [N]</th>"
       "</tr></thead><tbody>\n";
  for (std::size_t i = 0; i < plans.size(); ++i) {
    const Evaluated& e = *plans[i].evaluated;
    // The whole replay's peak: the figure the 3D readout shows at the frame it opens on.
    const double peak = e.judgement.peak_force_N;
    o << "<tr><td><a href=\"#plan-" << i << "\">" << EscapeXml(e.plan.name) << "</a></td><td>"
      << EscapeXml(e.file) << "</td><td>" << Badge(e.judgement) << "</td><td class=\"num\">"
      << e.judgement.transitions.size() << "</td><td class=\"num\">"
      << Fixed(e.judgement.replayed_s, 3) << "</td><td class=\"num\">" << Fixed(peak, 3)
      << "</td></tr>\n";
  }
  o << "</tbody></table></section>\n";

  o << "<section id=\"replay\"><h2>3D replay</h2>\n"
       "<div class=\"controls\"><label>plan <select id=\"plan-select\"></select></label>"
       "<button id=\"play\" type=\"button\">&#9654; play</button>"
       "<input id=\"scrub\" type=\"range\" min=\"0\" max=\"0\" value=\"0\" step=\"1\">"
       "<span id=\"clock\" class=\"num\"></span>"
       "<label>speed <select id=\"speed\"><option value=\"0.25\">0.25&times;</option>"
       "<option value=\"0.5\">0.5&times;</option><option value=\"1\" selected>1&times;</option>"
       "<option value=\"2\">2&times;</option></select></label></div>\n"
       "<div class=\"viewer\"><canvas id=\"view\"></canvas><div id=\"hud\"></div>"
       "<div class=\"legend\"><span style=\"color:"
    << kTubeColour
    << "\">&#9632; tube</span> <span class=\"c-contact\">&#9679; contact (sliding: "
       "faded)</span> <span class=\"c-normal\">&#8594; normal force</span> "
       "<span class=\"c-friction\">&#8594; friction</span> <span class=\"c-operator\">&#8594; "
       "force on the operator</span> <span class=\"c-hand\">&#9679; hand</span></div></div>\n"
       "<p class=\"note\">Drag to orbit, wheel to zoom, right-drag to pan. Frames every 20 ms "
       "of the judged replay (every 20 ms or wider for a long one: a page holds at most "
    << ReplayRecording::kMaxBins
    << " frames a plan, the plan's own spacing in its section), the core's own tube shape "
       "(Core::Centreline), and the tick of the largest operator force, which the view opens "
       "at; the arrows' scale is in the corner box. Click a plot below to jump there.</p>"
       "</section>\n";

  for (std::size_t i = 0; i < plans.size(); ++i) {
    const HtmlPlan& p = plans[i];
    const Evaluated& e = *p.evaluated;
    o << "<section class=\"plan\" id=\"plan-" << i << "\" data-plan=\"" << i << "\"><h2>"
      << EscapeXml(e.plan.name) << " " << Badge(e.judgement) << "</h2>\n"
      << "<p class=\"meta\">" << EscapeXml(e.file) << " on " << EscapeXml(p.scene_path) << "; "
      << Fixed(e.judgement.replayed_s, 3) << " s replayed, " << e.judgement.ticks
      << " core ticks; limits: force " << Fixed(e.plan.limits.max_force_N, 3) << " N, strain "
      << Fixed(e.plan.limits.max_strain, 3) << ", penetration "
      << Fixed(e.plan.limits.max_penetration_m * 1e3, 3) << " mm, dwell "
      << Fixed(e.plan.limits.dwell_s * 1e3, 1) << " ms; plots and 3D frames every "
      << Duration(p.recording.bin_s) << "</p>\n";
    if (!e.judgement.strain_warning.empty())
      o << "<p class=\"warning\">warning: " << EscapeXml(e.judgement.strain_warning) << "</p>\n";
    o << VerdictTable(e);
    std::vector<Span> spans;
    const std::string plots = Plots(e, p.recording, spans);
    o << "<div class=\"plot timeline\">" << Timeline(e, p.recording, spans) << "</div>\n"
      << plots << "</section>\n";
  }

  o << "<section id=\"graph\"><h2>Contact-state graph with this run's verdicts</h2>\n";
  if (!options.graph_note.empty()) o << "<p class=\"note\">" << options.graph_note << "</p>\n";
  for (const auto& [title, svg] : options.graphs) {
    const std::size_t start = svg.find("<svg");
    o << "<h3>" << EscapeXml(title) << "</h3><div class=\"graph\">"
      << (start == std::string::npos ? std::string() : svg.substr(start)) << "</div>\n";
  }
  o << "</section>\n";
  o << "<footer>Made by tubeplan evaluate --html. 3D view: three.js " << assets::ThreeVersion()
    << " (MIT licence), embedded. Plots: tubeplan's SVG charts. No network access needed."
       "</footer>\n";

  nlohmann::json data = {{"tube_colour", kTubeColour}, {"plans", nlohmann::json::array()}};
  PageMeshes meshes;
  for (const HtmlPlan& p : plans) data["plans"].push_back(PlanJson(p, meshes));
  data["meshes"] = meshes.Json();
  o << "<script type=\"application/json\" id=\"tubeplan-data\">" << ScriptSafe(data.dump())
    << "</script>\n<script>\n"
    << assets::ThreeJs() << "\n</script>\n<script>\n"
    << assets::ReportJs() << "\n</script>\n</body>\n</html>\n";
  return o.str();
}

}  // namespace tubeplan::report
