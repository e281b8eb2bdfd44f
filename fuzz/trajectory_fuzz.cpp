// libFuzzer target: the bytes as a trajectory CSV, through the in-memory loader (the plan loader
// for `evaluate --monte-carlo` and `live`, LoadTrajectoryText), and through the input checks as
// the streamed passes of `check`, `simulate` and `evaluate` run them (in pieces, cut where a
// 64 KiB chunk would end): the same text must get the same messages.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <tubeplan/io/trajectory_csv.hpp>

#include "io/text_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const tubeplan::io::TrajectoryLoadResult result =
      tubeplan::io::LoadTrajectoryText(text, "fuzz.csv");
  if (result.trajectory.has_value() == result.diagnostics.HasErrors()) __builtin_trap();
  if (result.trajectory) {
    // What the loader promises the core: at least two samples, strictly increasing finite
    // times, finite positions, unit quaternions.
    const auto& samples = result.trajectory->samples;
    if (samples.size() < 2) __builtin_trap();
    for (std::size_t i = 0; i < samples.size(); ++i) {
      if (!std::isfinite(samples[i].t_s) || !samples[i].p_WH_m.allFinite()) __builtin_trap();
      if (std::abs(samples[i].q_WH.norm() - 1.0) > 1e-9) __builtin_trap();
      if (i > 0 && !(samples[i].t_s > samples[i - 1].t_s)) __builtin_trap();
    }
  }
  (void)result.diagnostics.FormatAll();

  // The checks fed in three pieces, cut at places the input chooses (its first two bytes).
  const std::size_t cut1 = size > 0 ? data[0] % (size + 1) : 0;
  const std::size_t cut2 = size > 1 ? cut1 + data[1] % (size - cut1 + 1) : cut1;
  tubeplan::io::InputTextCheck check;
  check.Feed(text.substr(0, cut1));
  check.Feed(text.substr(cut1, cut2 - cut1));
  check.Feed(text.substr(cut2));
  tubeplan::io::Diagnostics pieces, whole;
  const bool pieces_ok = check.Finish("fuzz.csv", "a trajectory", pieces);
  const bool whole_ok = tubeplan::io::CheckInputText(text, "fuzz.csv", "a trajectory", whole);
  if (pieces_ok != whole_ok || pieces.FormatAll() != whole.FormatAll()) __builtin_trap();
  return 0;
}
