// libFuzzer target: the bytes as a scene file and, when `check` accepts it, 100 ticks of the core
// under a hand motion the same bytes choose (a move from the start pose, a turn, a jump). Any
// scene check accepts must run: every output stays finite and the force within the device's.
// 100 ticks keep a tube jammed at the solver's iteration cap well within tools/fuzz's 30 s timeout
// under ASan and coverage (about 35 ms a tick there, 1 ms in a release build).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <tubeplan/core/core.hpp>
#include <tubeplan/io/scene_yaml.hpp>

constexpr int kTicks = 100;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const tubeplan::io::SceneLoadResult loaded = tubeplan::io::LoadSceneText(text, "fuzz.yaml");
  if (!loaded.scene) return 0;
  const tubeplan::scene::Scene& s = *loaded.scene;
  // The motion: from the last bytes, a displacement of up to 0.2 m a side, a turn of up to a
  // half turn, and the tick of a jump.
  std::uint64_t h = 1469598103934665603ull;
  for (std::size_t i = 0; i < size; ++i) h = (h ^ data[i]) * 1099511628211ull;
  const auto take = [&h](double lo, double hi) {
    h = h * 6364136223846793005ull + 1442695040888963407ull;
    return lo + (hi - lo) * double(h >> 11) / double(1ull << 53);
  };
  const Eigen::Vector3d move(take(-0.2, 0.2), take(-0.2, 0.2), take(-0.2, 0.2));
  const Eigen::Vector3d axis = Eigen::Vector3d(take(-1, 1), take(-1, 1), take(-1, 1));
  const double turn = take(0.0, M_PI);
  const int jump_tick = int(take(0.0, double(kTicks)));
  tubeplan::core::Core core(s);
  core.Reset(s.X_WH_start);
  for (int k = 1; k <= kTicks; ++k) {
    const double u = k < jump_tick ? double(k) / kTicks : 1.0;
    Eigen::Isometry3d X = s.X_WH_start;
    X.translation() += u * move;
    if (axis.norm() > 1e-6)
      X.linear() = Eigen::AngleAxisd(u * turn, axis.normalized()).toRotationMatrix() * X.linear();
    const tubeplan::core::StepOutput& out = core.Step(k * s.model.time_step_s, X);
    if (!out.force_W_N.allFinite() || !out.torque_W_Nm.allFinite() ||
        !out.X_WH.translation().allFinite() || !std::isfinite(out.energy_J))
      __builtin_trap();
    if (out.force_W_N.norm() > s.device.max_force_N * (1.0 + 1e-9)) __builtin_trap();
  }
  return 0;
}
