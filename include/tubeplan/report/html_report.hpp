#pragma once
// The HTML report of `evaluate --html` (docs/report.md). One self-contained page: per plan the
// verdict table, a timeline of the observed CFs against the planned ones, plots over time (SVG by
// report/svg_plot) and a 3D replay (three.js, embedded). Everything it draws is recorded from the
// judged replay itself (plan::Judge's TickWatcher): no second run of the core, no second physics.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include <tubeplan/batch/evaluate.hpp>
#include <tubeplan/core/core.hpp>
#include <tubeplan/plan/plan.hpp>
#include <tubeplan/scene/scene.hpp>

namespace tubeplan::report {

/// The tube's colour in the 3D replay (the browser test counts pixels of it).
inline constexpr const char* kTubeColour = "#f07814";

/// One replay decimated for a page, bounded whatever its length: at most `max_bins` bins (50 Hz,
/// 20 ms bins, until a replay is longer than max_bins of them; then the bins double in width as
/// often as needed, pairs merged). Plots keep each bin's minimum and maximum (with when they
/// happened), so a one-tick spike stays visible at any length; the 3D replay keeps one frame per
/// bin (its first tick) and the frame of the replay's largest operator force.
struct ReplayRecording {
  static constexpr int kCentrelinePoints = 24;
  /// Bins a page keeps at most per plan (a page of plots 900 px wide needs no more).
  static constexpr std::size_t kMaxBins = 2048;
  struct Extremes {
    double t_min_s = 0.0, min = 0.0, t_max_s = 0.0, max = 0.0;
  };
  struct Bin {
    long ticks = 0;             ///< 0: no tick fell in it (a step longer than a bin)
    Extremes force_N;           ///< |force on the operator|
    Extremes friction_N;        ///< sum over PCs of |friction force|
    Extremes friction_limit_N;  ///< sum over PCs of the friction capacity f_max
    Extremes energy_J;          ///< bending energy
    Extremes strain;            ///< largest bending strain
  };
  struct Contact {
    Eigen::Vector3d p_W_m, normal_force_W_N, friction_W_N;
    bool sliding = false;
  };
  struct Frame {
    double t_s = 0.0;
    std::size_t bin = 0;   ///< the bin it is the first tick of
    int cf = 0;            ///< index into cfs
    double force_N = 0.0;  ///< |force on the operator|, exact
    std::array<Eigen::Vector3d, kCentrelinePoints> centreline_W_m;
    Eigen::Vector3d p_WH_m, p_W_hand_m, force_W_N;
    std::vector<Contact> contacts;
  };
  double bin_s = 0.02;
  double t_first_s = 0.0, t_last_s = 0.0;
  std::vector<Bin> bins;
  std::vector<Frame> frames;   ///< in time order; the peak's among them
  std::size_t peak_frame = 0;  ///< the frame of the largest operator force (the first such tick)
  /// The CFs the frames name, in order of first appearance; a tick the core flagged as a fault
  /// is named kFaultCf (its formation there reads {}, which is not the tube's state).
  std::vector<std::string> cfs;
};
inline constexpr const char* kFaultCf = "{} (solver fault: the core held the tube still)";

/// Records a replay tick by tick (plan::TickWatcher): bins of `bin_s` (50 Hz by default), at most
/// `max_bins` of them (wider bins beyond).
class ReplayRecorder {
 public:
  explicit ReplayRecorder(double bin_s = 0.02, std::size_t max_bins = ReplayRecording::kMaxBins);
  void operator()(double t_s, const core::Core& core);
  ReplayRecording Finish();

 private:
  void Halve();  // bins of twice the width: pairs merged, one frame kept per pair
  ReplayRecording::Frame FrameOf(double t_s, const core::Core& core) const;

  ReplayRecording rec_;
  std::size_t max_bins_;
  long ticks_ = 0;
  core::FormationKey key_{};
  bool key_valid_ = false;
  int cf_ = 0;
  std::optional<ReplayRecording::Frame> peak_;
};

struct HtmlPlan {
  const batch::Evaluated* evaluated = nullptr;
  const scene::Scene* scene = nullptr;
  std::string scene_path;
  ReplayRecording recording;
};

struct HtmlOptions {
  std::string command;  ///< how the report was made, shown in its header
  /// The contact-state graph section: Graphviz SVG of each scene's graph with this run's
  /// verdicts, or a sentence saying why there is none.
  std::vector<std::pair<std::string, std::string>> graphs;  ///< (title, SVG)
  std::string graph_note;
};

/// False in a build without the HTML report (TUBEPLAN_HTML_REPORT off, or node not found when
/// it was configured): the page cannot be written, and `evaluate --html` says so.
bool HtmlReportAvailable();

/// The page, complete (three.js, the page's script and style, the data inline).
std::string FormatHtmlReport(const std::vector<HtmlPlan>& plans, const HtmlOptions& options);

}  // namespace tubeplan::report
