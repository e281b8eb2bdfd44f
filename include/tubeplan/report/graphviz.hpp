#pragma once
// DOT to SVG with Graphviz's `dot` program (graph --svg, the HTML report's graph). The program, not
// libgvc: `dot` is what tools/render-graph and the tests already use, it isolates Graphviz's own
// crashes and global state from our process, and its plugins (the SVG renderer) are configured by
// the Debian package.

#include <string>

namespace tubeplan::report {

struct SvgFromDot {
  std::string svg;       ///< the picture; empty on failure
  std::string error;     ///< empty on success, else a sentence saying what failed
  std::string warnings;  ///< what `dot` printed on stderr while succeeding (it warns there)
};

/// Runs `program -Tsvg` (default `dot`, looked up on PATH) on `dot_text` through temporary files
/// (no pipe can fill up and block either side). A missing program, a failure to start it, a
/// non-zero exit or a signal is an error that names the program and quotes its stderr.
SvgFromDot RenderDot(const std::string& dot_text, const std::string& program = "dot");

}  // namespace tubeplan::report
