// libFuzzer target: the bytes as a mesh file, through the reader scenes will load parts with.
// The first byte chooses the format ('S': STL, ASCII or binary; anything else: OBJ); the rest is
// the file.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <tubeplan/io/mesh_file.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const char* name = data[0] == 'S' ? "fuzz.stl" : "fuzz.obj";
  const std::string_view bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  const tubeplan::io::MeshLoadResult result = tubeplan::io::LoadMeshBytes(bytes, name, 1e-3);
  // A mesh is set exactly when there is no error, and its elements with it: a half-checked mesh
  // must not reach the core.
  if (result.mesh.has_value() == result.diagnostics.HasErrors()) __builtin_trap();
  if (result.mesh.has_value() != result.elements.has_value()) __builtin_trap();
  (void)result.diagnostics.FormatAll();
  return 0;
}
