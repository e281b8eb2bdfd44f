#include <algorithm>
#include <array>
#include <cctype>

#include <tubeplan/states/contact_formation.hpp>

namespace tubeplan::states {
namespace {

struct Word {
  std::string_view text;
  int value;
};

constexpr std::array<Word, 5> kTubeWords = {{{"Fe", static_cast<int>(TubeElement::kEndFace)},
                                             {"Ee", static_cast<int>(TubeElement::kEndRim)},
                                             {"Fs", static_cast<int>(TubeElement::kSide)},
                                             {"Fi", static_cast<int>(TubeElement::kInnerFace)},
                                             {"Ei", static_cast<int>(TubeElement::kInnerRim)}}};

// Canonical markers first; the paper's arc symbols and plain words are accepted on input.
constexpr std::array<Word, 8> kMarkerWords = {{{"-", static_cast<int>(Marker::kNone)},
                                               {"~", static_cast<int>(Marker::kBent)},
                                               {"u", static_cast<int>(Marker::kConcave)},
                                               {"n", static_cast<int>(Marker::kConvex)},
                                               {"\u2323", static_cast<int>(Marker::kConcave)},
                                               {"\u2322", static_cast<int>(Marker::kConvex)},
                                               {"concave", static_cast<int>(Marker::kConcave)},
                                               {"convex", static_cast<int>(Marker::kConvex)}}};

// A small cursor over the text; every error records where it happened.
class Cursor {
 public:
  explicit Cursor(std::string_view text) : text_(text) {}
  void SkipSpace() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }
  bool AtEnd() const { return pos_ >= text_.size(); }
  char Peek() const { return AtEnd() ? '\0' : text_[pos_]; }
  bool Consume(char c) {
    if (Peek() != c) return false;
    ++pos_;
    return true;
  }
  // A run of characters up to white space, ',' or '}' (a word of the PC grammar).
  std::string_view Word() {
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_])) &&
           text_[pos_] != ',' && text_[pos_] != '}' && text_[pos_] != '{')
      ++pos_;
    return text_.substr(start, pos_ - start);
  }
  std::size_t pos() const { return pos_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
};

bool IsIdentifier(std::string_view s) {
  if (s.empty() || !std::isalpha(static_cast<unsigned char>(s[0]))) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
}

bool IsPartElementName(std::string_view s) {
  const std::size_t dot = s.find('.');
  if (dot == std::string_view::npos) return false;
  return IsIdentifier(s.substr(0, dot)) && IsIdentifier(s.substr(dot + 1));
}

ParseResult Fail(std::size_t offset, std::string message) {
  return ParseResult{std::nullopt, ParseError{offset, std::move(message)}};
}

// A word as it appears in a message; a word of a megabyte is cut (never inside a UTF-8
// sequence) so that the message stays a line.
std::string Quote(std::string_view s) {
  constexpr std::size_t kMaxShown = 40;
  if (s.size() <= kMaxShown) return "\"" + std::string(s) + "\"";
  std::size_t cut = kMaxShown;
  while (cut > 0 && (static_cast<unsigned char>(s[cut]) & 0xC0) == 0x80) --cut;
  return "\"" + std::string(s.substr(0, cut)) + "...\"";
}

}  // namespace

std::string_view ToString(TubeElement element) {
  return kTubeWords[static_cast<std::size_t>(element)].text;
}

std::string_view ToString(Marker marker) {
  return kMarkerWords[static_cast<std::size_t>(marker)].text;
}

std::string ToString(const PrincipalContact& pc) {
  std::string text(ToString(pc.tube));
  text += ' ';
  text += ToString(pc.marker);
  text += ' ';
  text += pc.part_element;
  return text;
}

std::string ToString(const ContactFormation& cf) {
  std::string text = "{";
  for (std::size_t i = 0; i < cf.contacts.size(); ++i) {
    if (i > 0) text += ", ";
    text += ToString(cf.contacts[i]);
  }
  text += "}";
  return text;
}

bool MarkerAllowed(TubeElement element, Marker marker) {
  const bool deforms = marker == Marker::kConcave || marker == Marker::kConvex;
  return !deforms || element == TubeElement::kSide || element == TubeElement::kInnerFace;
}

void Canonicalize(ContactFormation& cf) {
  std::sort(cf.contacts.begin(), cf.contacts.end(),
            [](const PrincipalContact& a, const PrincipalContact& b) {
              return ToString(a) < ToString(b);
            });
}

ParseResult ParseContactFormation(std::string_view text) {
  Cursor cursor(text);
  cursor.SkipSpace();
  if (!cursor.Consume('{'))
    return Fail(cursor.pos(),
                "expected '{' to open a contact formation, e.g. \"{Fe ~ left.inner}\"");
  ContactFormation cf;
  cursor.SkipSpace();
  if (!cursor.Consume('}')) {
    while (true) {
      cursor.SkipSpace();
      const std::size_t tube_at = cursor.pos();
      const std::string_view tube_word = cursor.Word();
      const auto tube = std::find_if(kTubeWords.begin(), kTubeWords.end(),
                                     [&](const auto& w) { return w.text == tube_word; });
      if (tube == kTubeWords.end())
        return Fail(tube_at, "unknown tube element " + Quote(tube_word) +
                                 ", expected one of Fe, Ee, Fs, Fi, Ei");
      cursor.SkipSpace();
      const std::size_t marker_at = cursor.pos();
      const std::string_view marker_word = cursor.Word();
      const auto marker = std::find_if(kMarkerWords.begin(), kMarkerWords.end(),
                                       [&](const auto& w) { return w.text == marker_word; });
      if (marker == kMarkerWords.end())
        return Fail(marker_at, "unknown deformation marker " + Quote(marker_word) +
                                   ", expected one of - ~ u n (or concave, convex)");
      cursor.SkipSpace();
      const std::size_t part_at = cursor.pos();
      const std::string_view part_word = cursor.Word();
      if (!IsPartElementName(part_word))
        return Fail(part_at,
                    "expected a part element \"part.element\" (e.g. left.top_inner), got " +
                        Quote(part_word));
      PrincipalContact pc{static_cast<TubeElement>(tube->value), static_cast<Marker>(marker->value),
                          std::string(part_word)};
      if (!MarkerAllowed(pc.tube, pc.marker))
        return Fail(marker_at, std::string(ToString(pc.tube)) +
                                   " never deforms, so it cannot carry marker " +
                                   Quote(marker_word) + "; expected - or ~");
      for (const auto& other : cf.contacts)
        if (other.tube == pc.tube && other.part_element == pc.part_element)
          return Fail(tube_at, "the pair " + std::string(ToString(pc.tube)) + " / " +
                                   pc.part_element +
                                   " appears twice; a pair is one principal contact");
      cf.contacts.push_back(std::move(pc));
      cursor.SkipSpace();
      if (cursor.Consume(',')) continue;
      if (cursor.Consume('}')) break;
      return Fail(cursor.pos(), "expected ',' or '}' after a principal contact");
    }
  }
  cursor.SkipSpace();
  if (!cursor.AtEnd()) return Fail(cursor.pos(), "unexpected text after the closing '}'");
  Canonicalize(cf);
  return ParseResult{std::move(cf), std::nullopt};
}

}  // namespace tubeplan::states
