#include <cstdio>
#include <sstream>

#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/graphviz.hpp>

#include <tubeplan/graph/dot.hpp>
#include <tubeplan/states/contact_formation.hpp>

namespace tubeplan::graph {

namespace {

// Quoted DOT string: only '"' and '\' need escaping.
std::string Quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string Html(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '&')
      out += "&amp;";
    else if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else
      out += c;
  }
  return out;
}

std::string TubeElement(states::TubeElement e, bool bent) {
  const std::string_view name = states::ToString(e);  // "Fe", "Ee", "Fs", ...
  // U&#771; puts a combining tilde over the letter: the paper's U-tilde for "bends, undeformed".
  return std::string(1, name[0]) + (bent ? "&#771;" : "") + "<SUB>" + std::string(name.substr(1)) +
         "</SUB>";
}

std::string Figures(const Node& n) {
  char buffer[128];
  std::snprintf(buffer, sizeof buffer, "E %.4g &#181;J &#183; f %.2g N &#183; d %.0f mm",
                n.energy_J * 1e6, n.friction_limit_N, std::max(n.distance_m, 0.0) * 1e3);
  return buffer;
}

// A short label for a dropped arc; the whole reason goes into its tooltip.
std::string ShortReason(const std::string& reason) {
  for (const char* prefix :
       {"dominated", "leads away", "leaves the goal", "returns to the start", "no path"})
    if (reason.rfind(prefix, 0) == 0) return prefix;
  return reason.substr(0, 24);
}

}  // namespace

std::string PaperNotation(const std::string& cf_text) {
  const states::ParseResult parsed = states::ParseContactFormation(cf_text);
  if (!parsed.cf) return Html(cf_text);
  if (parsed.cf->contacts.empty()) return "&#8709;";  // the empty set: no contact
  std::string out;
  for (const states::PrincipalContact& pc : parsed.cf->contacts) {
    if (!out.empty()) out += "<BR/>";
    out += TubeElement(pc.tube, pc.marker == states::Marker::kBent);
    switch (pc.marker) {
      case states::Marker::kNone:
      case states::Marker::kBent:
        out += " &#8211; ";  // en dash: plain contact
        break;
      case states::Marker::kConcave:
        out += " &#8995; ";  // the concave arc (smile)
        break;
      case states::Marker::kConvex:
        out += " &#8994; ";  // the convex arc (frown)
        break;
    }
    out += Html(pc.part_element);
  }
  return out;
}

std::string FormatDot(const ContactGraph& graph, const DotOptions& options) {
  using G = boost::adjacency_list<boost::vecS, boost::vecS, boost::directedS, boost::no_property,
                                  boost::property<boost::edge_index_t, std::size_t>>;
  // The nodes drawn: all of them; or, for the pruned graph, those a plan from the start can pass
  // through (reachable from the start along kept arcs) and the goal.
  std::vector<bool> drawn(graph.nodes.size(), options.dropped_arcs);
  if (graph.start >= 0) drawn[std::size_t(graph.start)] = true;
  if (graph.goal >= 0) drawn[std::size_t(graph.goal)] = true;
  if (!options.dropped_arcs) {
    // Forward from the start and backward from the goal along kept arcs; draw the nodes on both.
    std::vector<bool> from_start(graph.nodes.size(), false), to_goal(graph.nodes.size(), false);
    if (graph.start >= 0) from_start[std::size_t(graph.start)] = true;
    if (graph.goal >= 0) to_goal[std::size_t(graph.goal)] = true;
    for (bool grew = true; grew;) {
      grew = false;
      for (const Arc& a : graph.arcs) {
        if (!a.kept) continue;
        if (from_start[std::size_t(a.from)] && !from_start[std::size_t(a.to)])
          from_start[std::size_t(a.to)] = grew = true;
        if (to_goal[std::size_t(a.to)] && !to_goal[std::size_t(a.from)])
          to_goal[std::size_t(a.from)] = grew = true;
      }
    }
    for (std::size_t i = 0; i < graph.nodes.size(); ++i)
      drawn[i] = drawn[i] || (from_start[i] && to_goal[i]);
    // With batch results, also what the replays went through.
    for (const Arc& a : graph.arcs) {
      if (a.batch == BatchResult::kUntried) continue;
      drawn[std::size_t(a.from)] = drawn[std::size_t(a.to)] = true;
    }
  }
  std::vector<int> vertex_of(graph.nodes.size(), -1);
  std::vector<std::size_t> node_of;
  for (std::size_t i = 0; i < graph.nodes.size(); ++i) {
    if (!drawn[i]) continue;
    vertex_of[i] = static_cast<int>(node_of.size());
    node_of.push_back(i);
  }
  std::vector<std::size_t> arc_of;
  for (std::size_t i = 0; i < graph.arcs.size(); ++i) {
    const Arc& a = graph.arcs[i];
    if ((options.dropped_arcs || a.kept || a.batch != BatchResult::kUntried) &&
        drawn[std::size_t(a.from)] && drawn[std::size_t(a.to)])
      arc_of.push_back(i);
  }
  G g(node_of.size());
  for (std::size_t k = 0; k < arc_of.size(); ++k) {
    const Arc& a = graph.arcs[arc_of[k]];
    boost::add_edge(std::size_t(vertex_of[std::size_t(a.from)]),
                    std::size_t(vertex_of[std::size_t(a.to)]), k, g);
  }

  auto vertex_writer = [&](std::ostream& os, std::size_t v) {
    const Node& n = graph.nodes[node_of[v]];
    std::string label;
    if (n.start) label += "<B>start</B><BR/>";
    if (n.goal) label += "<B>goal</B><BR/>";
    label += PaperNotation(n.cf) + "<BR/><FONT POINT-SIZE=\"9\">" +
             (n.from_replay ? std::string("<I>seen in replays, not explored</I>") : Figures(n)) +
             "</FONT>";
    os << "[label=<" << label << ">, tooltip=" << Quoted(n.cf);
    if (n.from_replay) os << ", style=\"rounded,dashed\", color=\"#d62728\"";
    if (n.start) os << ", fillcolor=\"#dbe9f6\", style=\"rounded,filled\"";
    if (n.goal) os << ", fillcolor=\"#d9f2d9\", style=\"rounded,filled\", peripheries=2";
    os << "]";
  };
  const auto edge_index = boost::get(boost::edge_index, g);
  auto edge_writer = [&](std::ostream& os, const boost::graph_traits<G>::edge_descriptor& e) {
    const Arc& a = graph.arcs[arc_of[boost::get(edge_index, e)]];
    std::string label = a.simultaneous ? "simultaneous" : "";
    if (a.batch != BatchResult::kUntried) {
      // What batch replays found overrides the pruning's colours.
      const bool ok = a.batch == BatchResult::kFeasible;
      os << "[color=\"" << (ok ? "#2ca02c" : "#d62728") << "\", penwidth=2.2"
         << (a.from_replay ? ", style=dashed" : "") << ", tooltip="
         << Quoted(std::string(ok ? "feasible in a batch replay" : "infeasible in a batch replay") +
                   (a.kept ? "" : "; pruning: " + a.reason));
    } else if (a.kept) {
      os << "[color=\"#e8850c\", penwidth=1.6";
    } else {
      if (!label.empty()) label += ", ";
      label += ShortReason(a.reason);
      os << "[color=\"grey60\", style=dashed, fontcolor=\"grey40\", tooltip=" << Quoted(a.reason);
    }
    if (!label.empty()) os << ", label=" << Quoted(label);
    os << "]";
  };
  auto graph_writer = [&](std::ostream& os) {
    os << "rankdir=TB;\n"
       << "node [shape=box, style=rounded, fontname=\"Helvetica\", fontsize=11];\n"
       << "edge [fontname=\"Helvetica\", fontsize=9];\n";
    if (!options.title.empty()) os << "label=" << Quoted(options.title) << ";\nlabelloc=t;\n";
  };
  std::ostringstream os;
  boost::write_graphviz(os, g, vertex_writer, edge_writer, graph_writer);
  return os.str();
}

}  // namespace tubeplan::graph
