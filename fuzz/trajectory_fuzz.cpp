// libFuzzer target: the bytes as a trajectory CSV, through the loader `check`, `simulate` and
// the plan loader use (LoadTrajectoryFile reads the file and hands its text to
// LoadTrajectoryText).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <tubeplan/io/trajectory_csv.hpp>

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
  return 0;
}
