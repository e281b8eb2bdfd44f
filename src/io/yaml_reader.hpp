#pragma once
// Private to the io library: reading YAML with every problem reported at its file:line:col, and
// the pieces of a message (suggestions for misspelt names). Used by the scene and plan loaders.

#include <algorithm>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <tubeplan/io/diagnostics.hpp>
#include <tubeplan/io/units.hpp>
#include <tubeplan/scene/elements.hpp>
#include <tubeplan/states/contact_formation.hpp>

#include "text_file.hpp"

namespace tubeplan::io {

inline std::size_t EditDistance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0u : 1u)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

/// ", did you mean 'x'?" for the closest candidate within a third of the word's length (at least
/// two edits), or "" when nothing is close: a far-fetched suggestion is worse than none.
inline std::string Suggestion(std::string_view word, const std::vector<std::string>& candidates) {
  const std::size_t limit = std::max<std::size_t>(2, word.size() / 3);
  std::size_t best = limit + 1;
  std::string best_name;
  for (const std::string& c : candidates) {
    const std::size_t d = EditDistance(word, c);
    if (d < best) {
      best = d;
      best_name = c;
    }
  }
  return best_name.empty() ? std::string() : ", did you mean '" + best_name + "'?";
}

inline std::string Join(const std::vector<std::string>& words) {
  std::string text;
  for (const std::string& w : words) text += (text.empty() ? "" : ", ") + w;
  return text;
}

/// A scalar's value for a message as the file wrote it, a plain number with its SI unit
/// (`-0.008 m`, `5 mm`), never a bare SI number the user did not write.
inline std::string AsWritten(const YAML::Node& node, std::string_view si_unit) {
  if (!node.IsScalar()) return "?";
  const QuantityResult q = ParseQuantity(node.Scalar());
  std::string text = Abbreviate(node.Scalar());
  if (q.quantity && !q.quantity->has_unit && !si_unit.empty()) text += " " + std::string(si_unit);
  return text;
}

inline const char* KindName(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Map:
      return "a map";
    case YAML::NodeType::Sequence:
      return "a sequence";
    case YAML::NodeType::Scalar:
      return "a scalar";
    case YAML::NodeType::Null:
      return "nothing";
    default:
      return "an undefined node";
  }
}

class Reader {
 public:
  Reader(const std::string& file, Diagnostics& diagnostics) : file_(file), diag_(diagnostics) {}

  void Error(const YAML::Mark& mark, const std::string& message, std::size_t column_offset = 0) {
    // yaml-cpp marks are 0-based; a null mark (-1) means "no position": report the file.
    if (mark.line < 0) {
      diag_.Error(file_, 0, 0, message);
    } else {
      diag_.Error(file_, mark.line + 1, mark.column + 1 + static_cast<int>(column_offset), message);
    }
  }
  void Error(const YAML::Node& node, const std::string& message, std::size_t column_offset = 0) {
    Error(node.Mark(), message, column_offset);
  }
  void Warning(const YAML::Node& node, const std::string& message) {
    const YAML::Mark mark = node.Mark();
    if (mark.line < 0)
      diag_.Warning(file_, 0, 0, message);
    else
      diag_.Warning(file_, mark.line + 1, mark.column + 1, message);
  }
  /// The diagnostics this reader adds to, for another file's problems (a scene's mesh file).
  Diagnostics& diagnostics() { return diag_; }
  std::size_t error_count() const {
    std::size_t n = 0;
    for (const Diagnostic& d : diag_.all()) n += d.severity == Severity::kError;
    return n;
  }

  /// Checks that `node` is a map whose keys are all in `allowed` (each once); reports unknown and
  /// duplicate keys. Returns false (after reporting) when the node is not a map.
  bool ExpectMap(const YAML::Node& node, const std::string& where,
                 const std::vector<std::string>& allowed) {
    if (!node.IsMap()) {
      Error(node, "'" + where + "' must be a map, found " + KindName(node) +
                      ", expected keys such as " + Join(allowed));
      return false;
    }
    std::set<std::string> seen;
    for (const auto& entry : node) {
      if (!entry.first.IsScalar()) {
        Error(entry.first,
              "a key in '" + where + "' is " + KindName(entry.first) + ", expected a plain name");
        continue;
      }
      const std::string key = entry.first.Scalar();
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
        Error(entry.first, "unknown key '" + Abbreviate(key) + "' in '" + where + "'" +
                               Suggestion(key, allowed) + " (expected one of: " + Join(allowed) +
                               ")");
      } else if (!seen.insert(key).second) {
        Error(entry.first,
              "duplicate key '" + Abbreviate(key) + "' in '" + where + "', expected each key once");
      }
    }
    return true;
  }

  /// The value of `key` in map `node`, or an undefined node (missing keys reported if required).
  YAML::Node Get(const YAML::Node& node, const std::string& key, const std::string& where,
                 bool required) {
    if (node.IsMap()) {
      for (const auto& entry : node) {
        if (entry.first.IsScalar() && entry.first.Scalar() == key) return entry.second;
      }
      if (required) Error(node, "missing key '" + key + "' in '" + where + "'");
    }
    return YAML::Node(YAML::NodeType::Undefined);
  }

  /// A quantity of `dimension`; reports and returns nullopt on any problem.
  std::optional<double> Quantity(const YAML::Node& node, const std::string& what,
                                 Dimension dimension) {
    if (!node.IsScalar()) {
      Error(node, what + " must be a quantity (a number or a string such as \"5 mm\"), found " +
                      KindName(node));
      return std::nullopt;
    }
    const QuantityResult parsed = ParseQuantityAs(node.Scalar(), dimension);
    if (!parsed.quantity) {
      // Quoted scalars start one column after their quote (yaml-cpp tags them "!").
      const std::size_t quote = node.Tag() == "!" ? 1 : 0;
      Error(node, what + ": " + parsed.error->message, quote + parsed.error->offset);
      return std::nullopt;
    }
    return parsed.quantity->value_si;
  }

  /// Reads map[key] as a quantity into `target` (kept when absent or bad).
  bool Field(const YAML::Node& map, const std::string& key, const std::string& where,
             Dimension dimension, bool required, double& target) {
    const YAML::Node node = Get(map, key, where, required);
    if (!node.IsDefined()) return !required;
    const auto value = Quantity(node, where + "." + key, dimension);
    if (value) target = *value;
    return value.has_value();
  }

  std::optional<Eigen::Vector3d> Vector(const YAML::Node& node, const std::string& what,
                                        Dimension dimension) {
    if (!node.IsSequence() || node.size() != 3) {
      Error(node, what + " must be a sequence of 3 quantities such as [0, 5 mm, 10 mm], found " +
                      (node.IsSequence() ? std::to_string(node.size()) + " items"
                                         : std::string(KindName(node))));
      return std::nullopt;
    }
    Eigen::Vector3d v;
    bool ok = true;
    for (std::size_t i = 0; i < 3; ++i) {
      const auto value = Quantity(node[i], what + "[" + std::to_string(i) + "]", dimension);
      if (value) v[static_cast<Eigen::Index>(i)] = *value;
      ok = ok && value.has_value();
    }
    return ok ? std::optional(v) : std::nullopt;
  }

  std::optional<std::string> String(const YAML::Node& node, const std::string& what) {
    if (!node.IsScalar()) {
      Error(node, what + " must be a string, found " + KindName(node));
      return std::nullopt;
    }
    return node.Scalar();
  }

  /// A contact formation in canonical or accepted text; with `elements`, each PC's part element
  /// must be one of them (else an error naming it, with a suggestion).
  std::optional<states::ContactFormation> Formation(
      const YAML::Node& node, const std::string& what,
      const std::vector<scene::PartElement>* elements) {
    const auto text = String(node, what);
    if (!text) return std::nullopt;
    const std::size_t quote = node.Tag() == "!" ? 1 : 0;
    const states::ParseResult parsed = states::ParseContactFormation(*text);
    if (!parsed.cf) {
      Error(node, what + ": " + parsed.error->message, quote + parsed.error->offset);
      return std::nullopt;
    }
    if (elements == nullptr) return parsed.cf;
    std::vector<std::string> names;
    for (const scene::PartElement& e : *elements) names.push_back(e.name);
    bool ok = true;
    for (const states::PrincipalContact& pc : parsed.cf->contacts) {
      if (scene::FindElement(*elements, pc.part_element) >= 0) continue;
      const std::size_t at = text->find(pc.part_element);
      Error(node,
            what + ": no element '" + pc.part_element + "' in this scene" +
                Suggestion(pc.part_element, names) +
                " (expected part.face, part.face_face or part.face_face_face)",
            quote + (at == std::string::npos ? 0 : at));
      ok = false;
    }
    return ok ? parsed.cf : std::nullopt;
  }

  template <typename Enum>
  std::optional<Enum> Choice(const YAML::Node& node, const std::string& what,
                             const std::vector<std::pair<std::string, Enum>>& choices) {
    const auto text = String(node, what);
    if (!text) return std::nullopt;
    std::vector<std::string> names;
    for (const auto& [name, value] : choices) {
      if (name == *text) return value;
      names.push_back(name);
    }
    Error(node, what + " '" + Abbreviate(*text) + "' is not known" + Suggestion(*text, names) +
                    " (expected one of: " + Join(names) + ")");
    return std::nullopt;
  }

 private:
  const std::string& file_;
  Diagnostics& diag_;
};

/// Scenes and plans nest four levels deep and hold a few hundred nodes. yaml-cpp shares an
/// aliased node instead of copying it, so loading a "billion laughs" (each anchor naming ten
/// aliases of the one before) is cheap, but anything that walks the document visits every alias
/// again: nine levels are a billion visits. These bounds refuse such documents before a reader
/// walks them, in time proportional to the bounds, not to the expansion.
inline constexpr int kMaxYamlDepth = 64;
inline constexpr std::size_t kMaxYamlNodes = 100000;

namespace detail {
// yaml-cpp's tags for nodes written without one: "?" (plain) and "!" (quoted).
inline bool Untagged(const YAML::Node& node) {
  return node.Tag().empty() || node.Tag() == "?" || node.Tag() == "!";
}

inline bool WalkYaml(Reader& r, const YAML::Node& node, int depth, std::size_t& visited,
                     const std::string& expected) {
  // A tag (`!custom`, `!!binary`) asks for a type the format does not have: said, not ignored.
  if (!Untagged(node))
    r.Error(node, "unknown tag '" + Abbreviate(node.Tag()) + "', expected " + expected +
                      " without tags (plain values such as 5 mm or \"5 mm\")");
  if (++visited > kMaxYamlNodes) {
    r.Error(node, "the document expands to more than " + std::to_string(kMaxYamlNodes) +
                      " nodes (aliases repeat what they name: a 'billion laughs'?), expected " +
                      expected + " of ordinary size");
    return false;
  }
  if (depth > kMaxYamlDepth) {
    r.Error(node, "nesting deeper than " + std::to_string(kMaxYamlDepth) + " levels, expected " +
                      expected + " (a few levels deep)");
    return false;
  }
  if (node.IsSequence()) {
    for (const YAML::Node& item : node)
      if (!WalkYaml(r, item, depth + 1, visited, expected)) return false;
  } else if (node.IsMap()) {
    for (const auto& entry : node) {
      if (!WalkYaml(r, entry.first, depth + 1, visited, expected)) return false;
      if (!WalkYaml(r, entry.second, depth + 1, visited, expected)) return false;
    }
  }
  return true;
}
}  // namespace detail

namespace detail {
// Where each document of a YAML stream starts; nothing else of it is kept.
class DocumentStarts : public YAML::EventHandler {
 public:
  std::vector<YAML::Mark> marks;
  void OnDocumentStart(const YAML::Mark& mark) override { marks.push_back(mark); }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t,
                const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}
};
}  // namespace detail

/// The one document of `text` (YAML::Load reads the first and ignores the rest, invalid or not).
/// A second document is an error at its start; a YAML error in it throws as in YAML::Load.
inline YAML::Node LoadOneDocument(Reader& r, const std::string& text, const std::string& expected) {
  YAML::Node root = YAML::Load(text);
  std::istringstream in(text);
  YAML::Parser parser(in);
  detail::DocumentStarts starts;
  if (parser.HandleNextDocument(starts) && parser.HandleNextDocument(starts) &&
      starts.marks.size() >= 2)
    r.Error(starts.marks[1], "a second YAML document starts here, expected " + expected +
                                 " as one document (no '---' after its start)");
  return root;
}

/// Checks the loaded document against kMaxYamlDepth and kMaxYamlNodes (counting a node once
/// for every alias that reaches it); reports the first bound exceeded and returns false.
inline bool CheckYamlShape(Reader& r, const YAML::Node& root, const std::string& expected) {
  std::size_t visited = 0;
  return detail::WalkYaml(r, root, 0, visited, expected);
}

}  // namespace tubeplan::io
