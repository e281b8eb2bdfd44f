// The text form of contact formations (docs/contact-states.md): canonical printing, parsing of
// the accepted spellings, round trips, and the exact errors.
#include <random>

#include <catch2/catch.hpp>

#include <tubeplan/states/contact_formation.hpp>

using tubeplan::states::ContactFormation;
using tubeplan::states::Marker;
using tubeplan::states::ParseContactFormation;
using tubeplan::states::PrincipalContact;
using tubeplan::states::ToString;
using tubeplan::states::TubeElement;

namespace {

ContactFormation MustParse(std::string_view text) {
  auto result = ParseContactFormation(text);
  INFO(text << " -> " << (result.error ? result.error->message : ""));
  REQUIRE(result.cf.has_value());
  return *result.cf;
}

}  // namespace

TEST_CASE("The empty contact formation prints and parses as {}", "[states]") {
  CHECK(ToString(ContactFormation{}) == "{}");
  CHECK(MustParse("{}").contacts.empty());
  CHECK(MustParse("  {  }  ").contacts.empty());
}

TEST_CASE("PCs are printed as three words and sorted by their text", "[states]") {
  const ContactFormation cf = MustParse("{Fs u left.top_inner, Fe ~ left.inner}");
  REQUIRE(cf.contacts.size() == 2);
  CHECK(cf.contacts[0] == PrincipalContact{TubeElement::kEndFace, Marker::kBent, "left.inner"});
  CHECK(cf.contacts[1] == PrincipalContact{TubeElement::kSide, Marker::kConcave, "left.top_inner"});
  CHECK(ToString(cf) == "{Fe ~ left.inner, Fs u left.top_inner}");
  // The same set written in another order is the same CF.
  CHECK(MustParse("{Fe ~ left.inner,Fs u left.top_inner}") == cf);
}

TEST_CASE("The paper's arc symbols and plain words parse to the canonical markers", "[states]") {
  CHECK(ToString(MustParse("{Fs \u2323 floor.top}")) == "{Fs u floor.top}");
  CHECK(ToString(MustParse("{Fs \u2322 floor.top}")) == "{Fs n floor.top}");
  CHECK(ToString(MustParse("{Fs concave floor.top}")) == "{Fs u floor.top}");
  CHECK(ToString(MustParse("{Fs convex floor.top}")) == "{Fs n floor.top}");
}

TEST_CASE("Random contact formations round-trip print -> parse -> equal", "[states]") {
  const std::vector<std::string> elements = {"left.top",  "left.top_inner",      "right.inner",
                                             "floor.top", "floor.top_xpos_ypos", "b2.xneg"};
  std::mt19937 rng(12345);
  int checked = 0;
  for (int trial = 0; trial < 500; ++trial) {
    ContactFormation cf;
    const int n = std::uniform_int_distribution<int>(0, 4)(rng);
    for (int i = 0; i < n; ++i) {
      PrincipalContact pc;
      pc.tube = static_cast<TubeElement>(std::uniform_int_distribution<int>(0, 4)(rng));
      pc.marker = static_cast<Marker>(std::uniform_int_distribution<int>(0, 3)(rng));
      pc.part_element = elements[std::uniform_int_distribution<std::size_t>(0, 5)(rng)];
      const bool duplicate_pair =
          std::any_of(cf.contacts.begin(), cf.contacts.end(), [&](const PrincipalContact& o) {
            return o.tube == pc.tube && o.part_element == pc.part_element;
          });
      if (tubeplan::states::MarkerAllowed(pc.tube, pc.marker) && !duplicate_pair)
        cf.contacts.push_back(pc);
    }
    tubeplan::states::Canonicalize(cf);
    const std::string text = ToString(cf);
    const ContactFormation parsed = MustParse(text);
    CHECK(parsed == cf);
    CHECK(ToString(parsed) == text);
    ++checked;
  }
  CHECK(checked == 500);
}

TEST_CASE("Bad contact formations get exact messages at the right offset", "[states]") {
  struct Row {
    const char* text;
    std::size_t offset;
    const char* message;
  };
  const Row rows[] = {
      {"Fe ~ left.inner", 0,
       "expected '{' to open a contact formation, e.g. \"{Fe ~ left.inner}\""},
      {"{Fx ~ left.inner}", 1, "unknown tube element \"Fx\", expected one of Fe, Ee, Fs, Fi, Ei"},
      {"{Fe * left.inner}", 4,
       "unknown deformation marker \"*\", expected one of - ~ u n (or concave, convex)"},
      {"{Fe ~ inner}", 6,
       "expected a part element \"part.element\" (e.g. left.top_inner), got \"inner\""},
      {"{Fe u left.inner}", 4,
       "Fe never deforms, so it cannot carry marker \"u\"; expected - or ~"},
      {"{Ee concave left.top}", 4,
       "Ee never deforms, so it cannot carry marker \"concave\"; expected - or ~"},
      {"{Fe ~ left.inner, Fe - left.inner}", 18,
       "the pair Fe / left.inner appears twice; a pair is one principal contact"},
      {"{Fe ~ left.inner Fs - floor.top}", 17, "expected ',' or '}' after a principal contact"},
      {"{Fe ~ left.inner} x", 18, "unexpected text after the closing '}'"},
      {"{Fe ~ left.inner", 16, "expected ',' or '}' after a principal contact"},
  };
  for (const Row& row : rows) {
    INFO(row.text);
    const auto result = ParseContactFormation(row.text);
    REQUIRE_FALSE(result.cf.has_value());
    REQUIRE(result.error.has_value());
    CHECK(result.error->message == row.message);
    CHECK(result.error->offset == row.offset);
  }
}
