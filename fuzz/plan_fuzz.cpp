// libFuzzer target: the bytes as a plan file, through the loader `check` and `evaluate` use
// (LoadPlanFile reads the file and hands its text to LoadPlanText with the plan's directory).
// The directory is a copy of the shipped scenes and a short trajectory made at configure time
// (fuzz/CMakeLists.txt), so that plans naming ../scenes/groove.yaml load their files quickly.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <tubeplan/io/plan_file.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const tubeplan::io::PlanLoadResult result =
      tubeplan::io::LoadPlanText(text, "fuzz.yaml", TUBEPLAN_FUZZ_PLAN_DIR);
  if (result.plan.has_value() == result.diagnostics.HasErrors()) __builtin_trap();
  if (result.plan && (!result.scene || !result.trajectory)) __builtin_trap();
  (void)result.diagnostics.FormatAll();
  return 0;
}
