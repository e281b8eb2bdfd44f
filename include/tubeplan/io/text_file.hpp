#pragma once
// Whole-file text input and output for the loaders and writers.

#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace tubeplan::io {

/// The file's bytes, or nullopt when it cannot be read (missing, a directory, no permission).
std::optional<std::string> ReadTextFile(const std::filesystem::path& path);

/// Writes `text` to a temporary file next to `path` and renames it over `path`, so a reader never
/// sees a half-written file and a failed write leaves the old one in place. Returns an empty
/// string on success, else what went wrong (the temporary file is removed).
std::string WriteTextFileAtomically(const std::filesystem::path& path, std::string_view text);

/// A file written as it goes (a live recording): into a temporary file next to `path`, flushed
/// to the operating system on every Flush(), and renamed over `path` by Commit(). A crash leaves
/// `path` as it was (and the partial data in the temporary file); destroying it uncommitted
/// removes the temporary file.
class StreamingTextFile {
 public:
  StreamingTextFile() = default;
  ~StreamingTextFile();
  StreamingTextFile(const StreamingTextFile&) = delete;
  StreamingTextFile& operator=(const StreamingTextFile&) = delete;

  /// Empty on success, else what went wrong.
  std::string Open(const std::filesystem::path& path);
  /// Buffered; a write error is reported by Flush or Commit.
  void Append(std::string_view text);
  std::string Flush();
  std::string Commit();
  const std::filesystem::path& temporary() const { return temporary_; }

 private:
  std::filesystem::path path_, temporary_;
  std::FILE* file_ = nullptr;
  bool failed_ = false;
};

}  // namespace tubeplan::io
