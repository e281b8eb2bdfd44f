#pragma once
// Whole-file text input and output for the loaders and writers, and the checks every text input
// passes before a parser sees it (docs/hardening.md lists the limits and why).

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include <tubeplan/io/diagnostics.hpp>

namespace tubeplan::io {

/// The largest file any loader reads: 2 GiB, a trajectory of about 28 million rows (almost eight
/// hours at 1 kHz). Anything larger is refused before it is read, not after it filled the memory.
inline constexpr std::uintmax_t kMaxInputBytes = std::uintmax_t{2} << 30;
/// Scene and plan files are a few kilobytes; 16 MiB of YAML is a mistake (or an attack), and
/// yaml-cpp keeps about fifty times the text's size in nodes.
inline constexpr std::uintmax_t kMaxYamlBytes = std::uintmax_t{16} << 20;
/// A line of a scene, plan or trajectory is under 200 bytes; 64 KiB allows a CSV with a few
/// thousand extra columns and stops a binary or minified file from reaching the parsers.
inline constexpr std::size_t kMaxLineBytes = std::size_t{64} << 10;

struct ReadResult {
  std::optional<std::string> text;  ///< the file's bytes, when it could be read
  std::string error;                ///< else why not: "no such file", "it is a directory", ...
};

/// Reads a regular file of at most `max_bytes`. Directories, devices, FIFOs and sockets are
/// refused without reading (a plan naming /dev/zero must not hang the tool).
ReadResult ReadInputFile(const std::filesystem::path& path,
                         std::uintmax_t max_bytes = kMaxInputBytes);

/// The file's bytes, or nullopt when it cannot be read (missing, a directory, no permission, not
/// a regular file, larger than kMaxInputBytes).
std::optional<std::string> ReadTextFile(const std::filesystem::path& path);

/// Checks that `text` is text a person or a recorder wrote: not empty, not binary (a NUL byte),
/// not UTF-16 or UTF-32 (a byte-order mark), valid UTF-8, no line longer than kMaxLineBytes. Each
/// kind of problem is reported once, at its first place, as "what, and `expected`" (e.g. "a YAML
/// scene file"). Returns false when the text must not be parsed. A UTF-8 byte-order mark is fine.
bool CheckInputText(std::string_view text, const std::string& display_name,
                    std::string_view expected, Diagnostics& diagnostics);

/// `text` for a message: as is when short, else its first `max_bytes` bytes (never cutting a
/// UTF-8 sequence) and "...", so a 1 MB field does not become a 1 MB message.
std::string Abbreviate(std::string_view text, std::size_t max_bytes = 40);

/// A file written whole or not at all, for outputs too large to hold in memory: the text goes
/// to a temporary file next to `path` as it comes (Write), and Commit flushes it to the disk and
/// renames it over `path`. Destroyed without a successful Commit (an error, an exception, an
/// interruption), it removes the temporary file and `path` stays as it was.
class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// Appends; false once anything failed (then every later call is a no-op).
  bool Write(std::string_view text);
  /// Empty on success, else the message (as WriteTextFileAtomically's).
  std::string Commit();
  /// The first failure ("cannot write X.tmp.1.0: No space left on device"), or empty.
  const std::string& error() const { return error_; }

 private:
  void Fail(const char* what, int error);
  std::filesystem::path path_, temporary_;
  int fd_ = -1;
  std::uintmax_t bytes_ = 0;
  bool committed_ = false;
  std::string error_;
};

/// Writes `text` to a temporary file next to `path` and renames it over `path`, so a reader never
/// sees a half-written file and a failed write leaves the old one in place. The data is flushed
/// to the disk (fsync) before the rename. Returns an empty string on success, else what went
/// wrong (the temporary file is removed). A full disk, a file-size limit, a read-only file system
/// or a missing directory all come back here as a message, never as a partial file.
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
