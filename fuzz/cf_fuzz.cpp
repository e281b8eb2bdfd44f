// libFuzzer target: the bytes as a contact-formation text, through the parser scene goals, plan
// states and `graph --verdicts` use. A parsed CF must print as canonical text that parses back
// to the same CF.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include <tubeplan/states/contact_formation.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace tubeplan::states;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const ParseResult parsed = ParseContactFormation(text);
  if (parsed.cf.has_value() == parsed.error.has_value()) __builtin_trap();
  if (parsed.error && parsed.error->offset > size) __builtin_trap();
  if (parsed.cf) {
    const std::string canonical = ToString(*parsed.cf);
    const ParseResult again = ParseContactFormation(canonical);
    if (!again.cf || !(*again.cf == *parsed.cf) || ToString(*again.cf) != canonical)
      __builtin_trap();
  }
  return 0;
}
