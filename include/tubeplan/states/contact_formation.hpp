#pragma once
// Principal contacts (PCs) with deformation markers and contact formations (CFs), in the text
// form of docs/contact-states.md: a PC is three words "tube-element marker part-element"
// (e.g. "Fs u left.top_inner"), a CF is "{pc, pc, ...}" with its PCs sorted, "{}" for no contact.
// These are the "cold" types used in files, reports and on the command line; the core keeps a
// compact form of its own and converts only when asked.

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace tubeplan::states {

/// Surface elements of the tube (the held end is never a contact element).
enum class TubeElement : unsigned char {
  kEndFace,    ///< "Fe": the annulus at z = l
  kEndRim,     ///< "Ee": outer rim of the free end
  kSide,       ///< "Fs": outer side surface
  kInnerFace,  ///< "Fi": bore surface (only in scenes where a part can enter the bore)
  kInnerRim,   ///< "Ei": inner rim of the free end (same)
};

/// How the tube deforms at a PC (paper section III-B).
enum class Marker : unsigned char {
  kNone,     ///< "-": the tube does not bend
  kBent,     ///< "~": the tube bends but this element is undeformed
  kConcave,  ///< "u": the element deforms, its concave side touches
  kConvex,   ///< "n": the element deforms, its convex side touches
};

struct PrincipalContact {
  TubeElement tube = TubeElement::kEndFace;
  Marker marker = Marker::kNone;
  std::string part_element;  ///< "part.element", e.g. "left.top_inner"

  friend bool operator==(const PrincipalContact&, const PrincipalContact&) = default;
};

/// A set of PCs, kept sorted by their canonical text (so equal sets compare equal).
struct ContactFormation {
  std::vector<PrincipalContact> contacts;

  friend bool operator==(const ContactFormation&, const ContactFormation&) = default;
};

std::string_view ToString(TubeElement element);
std::string_view ToString(Marker marker);
std::string ToString(const PrincipalContact& pc);
/// Canonical text: "{}" or "{a, b}" with PCs sorted.
std::string ToString(const ContactFormation& cf);

/// Whether an element can carry a marker: the end face and rims never deform, so they take
/// only "-" and "~".
bool MarkerAllowed(TubeElement element, Marker marker);

struct ParseError {
  std::size_t offset = 0;  ///< byte offset into the parsed text where the problem starts
  std::string message;     ///< what is wrong and what was expected
};

struct ParseResult {
  std::optional<ContactFormation> cf;  ///< set on success
  std::optional<ParseError> error;     ///< set on failure
};

/// Parses a CF; accepts the canonical markers and also "⌣"/"concave" for u, "⌢"/"convex" for n.
/// Rejects a marker an element cannot carry, the same element pair twice, and stray text. Does
/// not check that part elements exist: that needs a scene (scene/elements.hpp).
ParseResult ParseContactFormation(std::string_view text);

/// Sorts the PCs into canonical order; ParseContactFormation already returns sorted sets.
void Canonicalize(ContactFormation& cf);

}  // namespace tubeplan::states
