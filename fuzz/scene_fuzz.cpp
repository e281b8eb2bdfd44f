// libFuzzer target: the bytes as a scene file, through the loader `check`, `simulate`, `graph`
// and `plans` use (LoadSceneFile reads the file and hands its text to LoadSceneText).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <tubeplan/io/scene_yaml.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const tubeplan::io::SceneLoadResult result = tubeplan::io::LoadSceneText(text, "fuzz.yaml");
  // A scene is set exactly when there is no error: anything else would let a half-checked scene
  // reach the core.
  if (result.scene.has_value() == result.diagnostics.HasErrors()) __builtin_trap();
  (void)result.diagnostics.FormatAll();
  return 0;
}
