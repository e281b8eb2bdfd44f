// Mesh files: OBJ and STL in, a welded, checked mesh with its elements out, or every problem at
// once. The formats as read are documented for users in docs/meshes.md; keep the two in step.
#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <sstream>
#include <stdexcept>

#include <tubeplan/io/mesh_file.hpp>

#include "text_file.hpp"

namespace tubeplan::io {
namespace {

// Each kind of problem is listed this many times, then counted: a broken export repeats one
// mistake thousands of times.
constexpr int kMaxReportsPerKind = 20;

// A mesh as read, before welding: each triangle's place in the file.
struct RawMesh {
  scene::TriangleMesh mesh;
  std::vector<MeshPlace> places;
  bool binary = false;
};

// Reports of one kind, the first kMaxReportsPerKind in full, the rest counted at the end.
class Reporter {
 public:
  Reporter(std::string file, Diagnostics& diagnostics)
      : file_(std::move(file)), diagnostics_(diagnostics) {}
  void Error(const std::string& kind, int line, int column, const std::string& message) {
    if (++errors_[kind] <= kMaxReportsPerKind) diagnostics_.Error(file_, line, column, message);
  }
  void Warning(const std::string& kind, int line, int column, const std::string& message) {
    if (++warnings_[kind] <= kMaxReportsPerKind) diagnostics_.Warning(file_, line, column, message);
  }
  // "... and 37 more open edges" for each kind beyond the limit.
  void Finish() {
    for (const auto& [kind, count] : errors_)
      if (count > kMaxReportsPerKind)
        diagnostics_.ErrorAfterAll(file_, "and " + std::to_string(count - kMaxReportsPerKind) +
                                              " more " + kind + " (" + std::to_string(count) +
                                              " in all; the first " +
                                              std::to_string(kMaxReportsPerKind) + " are listed)");
    for (const auto& [kind, count] : warnings_)
      if (count > kMaxReportsPerKind)
        diagnostics_.Warning(file_, 0, 0,
                             "and " + std::to_string(count - kMaxReportsPerKind) + " more " + kind +
                                 " (" + std::to_string(count) + " in all)");
  }
  const std::string& file() const { return file_; }

 private:
  std::string file_;
  Diagnostics& diagnostics_;
  std::map<std::string, int> errors_, warnings_;
};

bool IsName(std::string_view text) {
  if (text.empty() || !std::isalpha(static_cast<unsigned char>(text[0]))) return false;
  return std::all_of(text.begin(), text.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
}

// A group's name as an element name: letters, digits and '_', starting with a letter.
std::string AsName(std::string_view text) {
  std::string name;
  for (char c : text) name += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  if (name.empty() || !std::isalpha(static_cast<unsigned char>(name[0]))) name = "g" + name;
  return name;
}

// The index of `name` in mesh.names, added if new.
int NameIndex(scene::TriangleMesh& mesh, const std::string& name) {
  const auto it = std::find(mesh.names.begin(), mesh.names.end(), name);
  if (it != mesh.names.end()) return static_cast<int>(it - mesh.names.begin());
  mesh.names.push_back(name);
  return static_cast<int>(mesh.names.size()) - 1;
}

// A group or solid name as written, checked: a name that is not one becomes one, with a warning.
int ReadName(std::string_view text, int line, int column, scene::TriangleMesh& mesh,
             Reporter& report) {
  if (text.empty()) return -1;
  const std::string name = AsName(text);
  if (!IsName(text))
    report.Warning("names changed", line, column,
                   "'" + std::string(text) +
                       "' is not a name (a letter, then letters, digits "
                       "and '_'), its faces are named '" +
                       name + "'");
  return NameIndex(mesh, name);
}

struct Token {
  std::string_view text;
  int line = 0;
  int column = 0;
};

// The whitespace-separated words of one line, with their columns; '#' starts a comment when
// `comments` is set.
std::vector<Token> Words(std::string_view line, int line_number, bool comments) {
  std::vector<Token> words;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i >= line.size() || (comments && line[i] == '#')) break;
    const std::size_t start = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    words.push_back({line.substr(start, i - start), line_number, static_cast<int>(start) + 1});
  }
  return words;
}

std::optional<double> Number(std::string_view text) {
  if (text.size() > 1 && text[0] == '+') text.remove_prefix(1);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(value))
    return std::nullopt;
  return value;
}

// --- OBJ ---------------------------------------------------------------------------------------

// One vertex reference of an `f`: the vertex index before the first '/', resolved against the
// vertices so far (negative: counted back from the last). 0-based, or -1 after an error.
int ObjVertexRef(const Token& word, int vertex_count, Reporter& report) {
  const std::string_view index_text = word.text.substr(0, word.text.find('/'));
  long long index = 0;
  const auto [end, ec] =
      std::from_chars(index_text.data(), index_text.data() + index_text.size(), index);
  if (index_text.empty() || ec != std::errc() || end != index_text.data() + index_text.size()) {
    report.Error("bad vertex references", word.line, word.column,
                 "'" + std::string(word.text) +
                     "' is not a vertex reference, expected i, i/t, "
                     "i//n or i/t/n with a vertex number i");
    return -1;
  }
  const long long resolved = index > 0 ? index - 1 : vertex_count + index;
  if (index == 0 || resolved < 0 || resolved >= vertex_count) {
    report.Error("bad vertex references", word.line, word.column,
                 "vertex " + std::to_string(index) + " does not exist, expected 1 to " +
                     std::to_string(vertex_count) + " or -1 to -" + std::to_string(vertex_count) +
                     " (the vertices written so far)");
    return -1;
  }
  return static_cast<int>(resolved);
}

RawMesh ReadObj(std::string_view text, Reporter& report) {
  RawMesh raw;
  scene::TriangleMesh& mesh = raw.mesh;
  int object = -1, group = -1;
  int line_number = 0;
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    const std::vector<Token> words = Words(text.substr(at, end - at), ++line_number, true);
    at = end + 1;
    if (words.empty()) continue;
    const std::string_view keyword = words[0].text;
    if (keyword == "v") {
      // x y z, then an optional w or colour, which do not matter here.
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      bool ok = words.size() >= 4;
      for (std::size_t i = 1; i < 4 && ok; ++i) {
        const std::optional<double> x = Number(words[i].text);
        if (!x)
          report.Error("bad numbers", words[i].line, words[i].column,
                       "'" + std::string(words[i].text) +
                           "' is not a number, expected a finite "
                           "coordinate");
        ok = ok && x;
        p[Eigen::Index(i - 1)] = x.value_or(0.0);
      }
      if (words.size() < 4)
        report.Error("bad vertices", words[0].line, words[0].column,
                     "a vertex with " + std::to_string(words.size() - 1) +
                         " coordinates, expected 3 (v x y z)");
      mesh.vertices_P_m.push_back(p);  // kept even when bad, so that later indices still count
    } else if (keyword == "f") {
      if (words.size() < 4) {
        report.Error("bad faces", words[0].line, words[0].column,
                     "a face of " + std::to_string(words.size() - 1) +
                         " vertices, expected 3 or more (f v1 v2 v3 ...)");
        continue;
      }
      std::vector<int> corners;
      const int vertex_count = static_cast<int>(mesh.vertices_P_m.size());
      for (std::size_t i = 1; i < words.size(); ++i)
        corners.push_back(ObjVertexRef(words[i], vertex_count, report));
      if (std::find(corners.begin(), corners.end(), -1) != corners.end()) continue;
      // A polygon as a fan from its first corner.
      const int name = group >= 0 ? group : object;
      for (std::size_t k = 1; k + 1 < corners.size(); ++k) {
        mesh.triangles.push_back({corners[0], corners[k], corners[k + 1]});
        mesh.triangle_names.push_back(name);
        raw.places.push_back({words[0].line, words[0].column});
      }
    } else if (keyword == "g" || keyword == "o") {
      if (words.size() > 2)
        report.Warning(
            "names changed", words[2].line, words[2].column,
            "faces in several groups take the first ('" + std::string(words[1].text) + "')");
      const int name = words.size() > 1
                           ? ReadName(words[1].text, words[1].line, words[1].column, mesh, report)
                           : -1;
      if (keyword == "o") {
        object = name;
        group = -1;
      } else {
        group = name;
      }
    }
    // Everything else (vt, vn, s, usemtl, mtllib, l, p, ...) says nothing about the solid.
  }
  return raw;
}

// --- STL ---------------------------------------------------------------------------------------

bool LooksLikeAsciiStl(std::string_view bytes) {
  std::size_t i = 0;
  while (i < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[i]))) ++i;
  return bytes.substr(i, 5) == "solid";
}

// The tokens of an ASCII STL, with their lines and columns.
std::vector<Token> StlTokens(std::string_view text) {
  std::vector<Token> tokens;
  int line_number = 0;
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    const std::vector<Token> words = Words(text.substr(at, end - at), ++line_number, false);
    tokens.insert(tokens.end(), words.begin(), words.end());
    at = end + 1;
  }
  return tokens;
}

RawMesh ReadAsciiStl(std::string_view text, Reporter& report) {
  RawMesh raw;
  scene::TriangleMesh& mesh = raw.mesh;
  const std::vector<Token> tokens = StlTokens(text);
  std::size_t i = 0;
  const Token end_token{"end of file", tokens.empty() ? 1 : tokens.back().line,
                        tokens.empty() ? 1 : tokens.back().column};
  auto peek = [&]() -> const Token& { return i < tokens.size() ? tokens[i] : end_token; };
  auto fail = [&](const Token& found, const std::string& expected) {
    report.Error(
        "syntax errors", found.line, found.column,
        "'" + std::string(found.text) + "' where " + expected + " belongs, expected " + expected);
    // On to the next facet or solid.
    ++i;
    while (i < tokens.size() && tokens[i].text != "facet" && tokens[i].text != "endsolid" &&
           tokens[i].text != "solid")
      ++i;
  };
  auto expect = [&](std::string_view word) {
    if (peek().text == word && i < tokens.size()) {
      ++i;
      return true;
    }
    fail(peek(), "'" + std::string(word) + "'");
    return false;
  };
  auto vector = [&](Eigen::Vector3d& v) {
    for (int k = 0; k < 3; ++k) {
      const std::optional<double> x = i < tokens.size() ? Number(tokens[i].text) : std::nullopt;
      if (!x) {
        fail(peek(), "a finite number");
        return false;
      }
      v[k] = *x;
      ++i;
    }
    return true;
  };
  int name = -1;
  bool in_solid = false;
  while (i < tokens.size()) {
    const Token& t = tokens[i];
    if (t.text == "solid") {
      ++i;
      // The solid's name: the rest of its line, if anything.
      name = -1;
      if (i < tokens.size() && tokens[i].line == t.line) {
        name = ReadName(tokens[i].text, tokens[i].line, tokens[i].column, mesh, report);
        while (i < tokens.size() && tokens[i].line == t.line) ++i;
      }
      in_solid = true;
    } else if (t.text == "endsolid") {
      ++i;
      while (i < tokens.size() && tokens[i].line == t.line) ++i;
      in_solid = false;
    } else if (t.text == "facet" && in_solid) {
      ++i;
      Eigen::Vector3d normal;
      if (!expect("normal") || !vector(normal) || !expect("outer") || !expect("loop")) continue;
      std::vector<Eigen::Vector3d> corners;
      bool ok = true;
      while (ok && peek().text == "vertex" && i < tokens.size()) {
        ++i;
        Eigen::Vector3d v;
        ok = vector(v);
        corners.push_back(v);
      }
      if (!ok) continue;
      if (corners.size() < 3) {
        fail(peek(), corners.empty() ? "'vertex'" : "another 'vertex' (3 or more a facet)");
        continue;
      }
      if (!expect("endloop") || !expect("endfacet")) continue;
      // Unwelded: each corner its own vertex (welding joins them), a polygon as a fan.
      const int first = static_cast<int>(mesh.vertices_P_m.size());
      mesh.vertices_P_m.insert(mesh.vertices_P_m.end(), corners.begin(), corners.end());
      for (int k = 1; k + 1 < static_cast<int>(corners.size()); ++k) {
        mesh.triangles.push_back({first, first + k, first + k + 1});
        mesh.triangle_names.push_back(name);
        raw.places.push_back({t.line, t.column});
      }
    } else {
      fail(t, in_solid ? "'facet' or 'endsolid'" : "'solid'");
    }
  }
  if (in_solid)
    report.Error("syntax errors", end_token.line, end_token.column,
                 "the file ends inside a solid, expected 'endsolid'");
  return raw;
}

float FloatAt(std::string_view bytes, std::size_t offset) {
  // Binary STL is little-endian IEEE 754, as is every machine this builds on.
  float value = 0.0f;
  std::memcpy(&value, bytes.data() + offset, sizeof value);
  return value;
}

std::uint32_t CountAt(std::string_view bytes, std::size_t offset) {
  const auto* b = reinterpret_cast<const unsigned char*>(bytes.data() + offset);
  return std::uint32_t(b[0]) | std::uint32_t(b[1]) << 8 | std::uint32_t(b[2]) << 16 |
         std::uint32_t(b[3]) << 24;
}

RawMesh ReadBinaryStl(std::string_view bytes, Reporter& report) {
  RawMesh raw;
  raw.binary = true;
  scene::TriangleMesh& mesh = raw.mesh;
  const std::uint32_t count = CountAt(bytes, 80);
  // Refused by its header's count, before a quarter gigabyte of records is parsed.
  if (count > scene::kMaxTriangles) {
    report.Error("format errors", 1, 81,
                 "the header counts " + std::to_string(count) + " triangles, expected at most " +
                     std::to_string(scene::kMaxTriangles) + " (simplify the mesh in its export)");
    return raw;
  }
  static constexpr std::array<char, 3> kAxis = {'x', 'y', 'z'};
  for (std::uint32_t t = 0; t < count; ++t) {
    const std::size_t record = 84 + 50 * std::size_t(t);
    bool ok = true;
    std::array<Eigen::Vector3d, 3> corners;
    for (std::size_t c = 0; c < 3; ++c)
      for (std::size_t k = 0; k < 3; ++k) {
        const std::size_t offset = record + 12 + 12 * c + 4 * k;
        const float x = FloatAt(bytes, offset);
        corners[c][Eigen::Index(k)] = double(x);
        if (std::isfinite(x)) continue;
        ok = false;
        report.Error("bad numbers", 1, static_cast<int>(offset) + 1,
                     "triangle " + std::to_string(t + 1) + ": corner " + std::to_string(c + 1) +
                         "'s " + kAxis[k] + " is not a finite number, expected a coordinate");
      }
    if (!ok) continue;
    const int first = static_cast<int>(mesh.vertices_P_m.size());
    mesh.vertices_P_m.insert(mesh.vertices_P_m.end(), corners.begin(), corners.end());
    mesh.triangles.push_back({first, first + 1, first + 2});
    mesh.triangle_names.push_back(-1);
    raw.places.push_back({1, static_cast<int>(record) + 1});
  }
  return raw;
}

// Binary when the size is exactly what the header's count says: an ASCII file starting "solid"
// has that size only by a one-in-fifty chance *and* a count that matches, while binary files
// from some exporters start with "solid" too.
std::optional<RawMesh> ReadStl(std::string_view bytes, Reporter& report) {
  if (bytes.size() >= 84 && bytes.size() == 84 + 50 * std::uint64_t(CountAt(bytes, 80)))
    return ReadBinaryStl(bytes, report);
  if (LooksLikeAsciiStl(bytes)) return ReadAsciiStl(bytes, report);
  if (bytes.size() < 84) {
    report.Error("format errors", 1, 1,
                 "the file has " + std::to_string(bytes.size()) +
                     " bytes and does not start with 'solid', expected an ASCII STL (starting "
                     "'solid') or a binary STL (84 bytes or more)");
  } else {
    const std::uint64_t count = CountAt(bytes, 80);
    report.Error("format errors", 1, 81,
                 "the header gives " + std::to_string(count) +
                     " triangles, so a binary STL of 84 + 50 x " + std::to_string(count) + " = " +
                     std::to_string(84 + 50 * count) + " bytes, but the file has " +
                     std::to_string(bytes.size()) +
                     " bytes and does not start with 'solid' either, expected an ASCII or a "
                     "binary STL");
  }
  return std::nullopt;
}

std::string Lowercase(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

std::string PlaceText(const RawMesh& raw, int triangle) {
  const MeshPlace& p = raw.places[std::size_t(triangle)];
  if (raw.binary) return "triangle " + std::to_string((p.column - 1 - 84) / 50 + 1);
  return "the face at line " + std::to_string(p.line);
}

// The checks' findings as diagnostics at the triangles' places.
void ReportProblems(const std::vector<scene::MeshProblem>& problems, const RawMesh& raw,
                    const std::vector<int>& source, Reporter& report) {
  for (const scene::MeshProblem& problem : problems) {
    // Indexed by scene::MeshProblemKind.
    static constexpr std::array<const char*, 8> kKinds = {
        "too many triangles", "degenerate triangles", "open edges",  "non-manifold edges",
        "winding errors",     "inverted bodies",      "flat bodies", "self-intersections"};
    const char* kind = kKinds[std::size_t(problem.kind)];
    if (problem.triangle < 0) {
      report.Error(kind, 0, 0, problem.message);
      continue;
    }
    const int t = source[std::size_t(problem.triangle)];
    std::string message = problem.message;
    if (problem.other_triangle >= 0)
      message +=
          " (the other triangle: " + PlaceText(raw, source[std::size_t(problem.other_triangle)]) +
          ")";
    if (raw.binary) message = PlaceText(raw, t) + ": " + message;
    const MeshPlace& p = raw.places[std::size_t(t)];
    report.Error(kind, p.line, p.column, message);
  }
}

}  // namespace

MeshLoadResult LoadMeshBytes(std::string_view bytes, const std::string& display_name,
                             double scale) {
  if (!(scale > 0.0) || !std::isfinite(scale)) {
    std::ostringstream m;
    m << "LoadMeshBytes: scale " << scale << " must be a finite number greater than zero";
    throw std::invalid_argument(m.str());
  }
  MeshLoadResult result;
  Reporter report(display_name, result.diagnostics);
  const std::string extension = Lowercase(std::filesystem::path(display_name).extension().string());
  std::optional<RawMesh> raw;
  if (extension == ".obj") {
    raw = ReadObj(bytes, report);
  } else if (extension == ".stl") {
    raw = ReadStl(bytes, report);
  } else {
    result.diagnostics.Error(
        display_name, 0, 0,
        "the extension '" + extension + "' names no mesh format, expected .obj or .stl");
  }
  if (raw && raw->mesh.triangles.empty() && !result.diagnostics.HasErrors())
    result.diagnostics.Error(display_name, 0, 0,
                             "the file holds no triangles, expected a closed triangle mesh");
  if (!raw || result.diagnostics.HasErrors()) {
    report.Finish();
    return result;
  }
  // Refused before the work of welding and checking.
  if (raw->mesh.triangles.size() > scene::kMaxTriangles) {
    const MeshPlace& p = raw->places[scene::kMaxTriangles];
    result.diagnostics.Error(
        display_name, p.line, p.column,
        "triangle " + std::to_string(scene::kMaxTriangles + 1) + " is one too many: the file has " +
            std::to_string(raw->mesh.triangles.size()) + " triangles, expected at most " +
            std::to_string(scene::kMaxTriangles) + " (simplify the mesh in its export)");
    return result;
  }
  for (Eigen::Vector3d& v : raw->mesh.vertices_P_m) v *= scale;
  std::vector<int> source;
  scene::TriangleMesh mesh =
      scene::WeldVertices(raw->mesh, scene::WeldTolerance_m(raw->mesh), &source);
  // Triangles whose corners welded together: slivers an exporter left, harmless once dropped.
  for (std::size_t t = 0, kept = 0; t < raw->mesh.triangles.size(); ++t) {
    if (kept < source.size() && source[kept] == static_cast<int>(t)) {
      ++kept;
      continue;
    }
    const MeshPlace& p = raw->places[t];
    report.Warning("collapsed triangles", p.line, p.column,
                   (raw->binary ? PlaceText(*raw, static_cast<int>(t)) + ": " : std::string()) +
                       "two corners of this triangle are one point (within the weld tolerance), "
                       "so it is left out, expected three distinct corners");
  }
  ReportProblems(scene::CheckMesh(mesh), *raw, source, report);
  report.Finish();
  if (result.diagnostics.HasErrors()) return result;
  result.elements = scene::FindElements(mesh);
  result.mesh = std::move(mesh);
  return result;
}

MeshLoadResult LoadMeshFile(const std::filesystem::path& path, double scale) {
  const ReadResult read = ReadInputFile(path, kMaxMeshBytes);
  if (!read.text) {
    MeshLoadResult result;
    result.diagnostics.Error(
        path.string(), 0, 0,
        "cannot read file (" + read.error + "), expected a readable OBJ or STL mesh file");
    return result;
  }
  return LoadMeshBytes(*read.text, path.string(), scale);
}

}  // namespace tubeplan::io
