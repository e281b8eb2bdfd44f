#pragma once
// The per-tick series of `simulate` (and of later replays) as CSV or JSON Lines, and its file
// written as it is made. The columns are documented in docs/simulate-output.md; keep the two in
// step.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include <tubeplan/core/core.hpp>

namespace tubeplan::io {
class AtomicFile;
}

namespace tubeplan::report {

enum class SeriesFormat { kNone, kCsv, kJsonLines };

/// The series' format by the extension of `path`: .csv or .jsonl, kNone for an empty path;
/// nullopt for any other, with `error` saying what was expected.
std::optional<SeriesFormat> SeriesFormatOf(const std::string& path, std::string& error);

/// Name of one StepFlag bit: "clamped", "penetration", "separated", "truncated",
/// "unconverged", "fault", "beyond_linear", "buckled".
std::string_view FlagName(std::uint32_t bit);

class SeriesWriter {
 public:
  SeriesWriter(SeriesFormat format, bool mesh);
  /// Appends one tick. `cf_text` is core.FormationText() for that tick.
  void Add(const core::Core& core, const core::StepOutput& out, const std::string& cf_text);
  const std::string& text() const { return text_; }
  /// Forgets the text written so far (after the caller saved it), keeping the buffer's memory.
  void Clear() { text_.clear(); }

  /// Points of the centreline written with --mesh.
  static constexpr int kMeshPoints = 21;

 private:
  SeriesFormat format_;
  bool mesh_;
  std::string text_;
};

/// The series written to its file as it is made (an hour at 1 kHz is about 2 GB of CSV), in
/// chunks of a megabyte into a temporary file next to it that Commit renames (io::AtomicFile):
/// the file is whole or absent.
class SeriesFile {
 public:
  /// Creates the temporary file (and missing directories); OpenError says whether it could not.
  SeriesFile(const std::filesystem::path& path, SeriesFormat format, bool mesh);
  ~SeriesFile();
  SeriesFile(const SeriesFile&) = delete;
  SeriesFile& operator=(const SeriesFile&) = delete;

  /// Empty when the temporary file was created, else why not, said before any tick.
  std::string OpenError();
  /// Appends one tick (SeriesWriter::Add).
  void Add(const core::Core& core, const core::StepOutput& out, const std::string& cf_text);
  /// Writes what is left and renames the file into place: empty on success, else the message.
  std::string Commit();

 private:
  SeriesWriter writer_;
  std::unique_ptr<io::AtomicFile> file_;
};

}  // namespace tubeplan::report
