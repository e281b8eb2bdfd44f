// libFuzzer target: the bytes as a quantity ("5 mm", "10 N/mm"), through the parser scene and
// plan files, trajectory metadata and command-line options use. A parsed quantity is finite;
// an error points inside the text.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <tubeplan/io/units.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace tubeplan::io;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  for (const Dimension expected : {dim::kNone, dim::kLength, dim::kStiffness, dim::kAngle}) {
    const QuantityResult r = ParseQuantityAs(text, expected);
    if (r.quantity.has_value() == r.error.has_value()) __builtin_trap();
    if (r.error && r.error->offset > size) __builtin_trap();
    if (r.quantity && !std::isfinite(r.quantity->value_si)) __builtin_trap();
    if (r.quantity && !(r.quantity->dimension == expected)) __builtin_trap();
  }
  const QuantityResult plain = ParseQuantity(text);
  if (plain.quantity && !std::isfinite(plain.quantity->value_si)) __builtin_trap();
  (void)Describe(plain.quantity ? plain.quantity->dimension : dim::kNone);
  return 0;
}
