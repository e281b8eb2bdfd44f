#pragma once
// Private to the report library: the HTML report's web assets, embedded at build time
// (tools/report-web/embed.mjs writes their definitions; CMakeLists.txt has the rule, and writes
// empty ones for a build without the report).

#include <string_view>

namespace tubeplan::report::assets {

/// False in a build without the HTML report (TUBEPLAN_HTML_REPORT off, or node not found when
/// it was configured): the assets below are then empty.
bool Available();
std::string_view ThreeJs();       ///< three.js and OrbitControls, minified (sets window.THREE)
std::string_view ThreeVersion();  ///< e.g. "0.187.0"
std::string_view ReportJs();      ///< src/report/web/report.js: the 3D replay and its controls
std::string_view ReportCss();     ///< src/report/web/report.css

}  // namespace tubeplan::report::assets
