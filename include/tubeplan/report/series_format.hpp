#pragma once
// The per-tick series of `simulate` (and of later replays) as CSV or JSON Lines. The columns are
// documented in docs/simulate-output.md; keep the two in step.

#include <string>
#include <string_view>

#include <tubeplan/core/core.hpp>

namespace tubeplan::report {

enum class SeriesFormat { kNone, kCsv, kJsonLines };

/// Name of one StepFlag bit: "clamped", "penetration", "separated", "truncated",
/// "unconverged", "fault", "beyond_linear", "buckled".
std::string_view FlagName(std::uint32_t bit);

class SeriesWriter {
 public:
  SeriesWriter(SeriesFormat format, bool mesh);
  /// Appends one tick. `cf_text` is core.FormationText() for that tick.
  void Add(const core::Core& core, const core::StepOutput& out, const std::string& cf_text);
  const std::string& text() const { return text_; }
  /// Forgets the text written so far (after the caller saved it), keeping the buffer's memory.
  void Clear() { text_.clear(); }

  /// Points of the centreline written with --mesh.
  static constexpr int kMeshPoints = 21;

 private:
  SeriesFormat format_;
  bool mesh_;
  std::string text_;
};

}  // namespace tubeplan::report
