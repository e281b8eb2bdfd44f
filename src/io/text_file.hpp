#pragma once
// Private to the libraries that read and write files (io, batch, live, report, cli) and their
// tests: text input (whole files, or chunks and lines for files too long to hold) and output
// for the loaders and writers, and the checks every text input passes before a parser sees it
// (docs/hardening.md lists the limits and why).

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

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
/// not UTF-16 or UTF-32 (a byte-order mark), valid UTF-8, no line longer than kMaxLineBytes, no
/// line ending in a carriage return alone (classic Mac OS; LF and CRLF are the line ends). Each
/// kind of problem is reported once, at its first place, as "what, and `expected`" (e.g. "a YAML
/// scene file"). Returns false when the text must not be parsed. A UTF-8 byte-order mark is fine.
bool CheckInputText(std::string_view text, const std::string& display_name,
                    std::string_view expected, Diagnostics& diagnostics);

/// CheckInputText's checks on a text that arrives in pieces (a file read in chunks): Feed the
/// pieces in order, then Finish reports exactly what CheckInputText reports for the whole text.
/// Holds at most a few bytes of it (a UTF-8 sequence cut by a piece's end) and the findings.
class InputTextCheck {
 public:
  void Feed(std::string_view piece);
  /// Reports and returns as CheckInputText does; call once, after the last piece.
  bool Finish(const std::string& display_name, std::string_view expected, Diagnostics& diagnostics);
  /// True once the text is known to fail (then a parser need not read on).
  bool failing() const { return wide_ != nullptr || !findings_.empty(); }

 private:
  enum class Kind { kNul, kUtf8, kLong, kLoneCr };
  struct Finding {
    Kind kind;
    int line = 0;
    int column = 0;
    unsigned char byte = 0;    // kUtf8: the lead byte
    std::uint64_t length = 0;  // kLong: the line's length, known at its end
  };
  void Scan(std::string_view data, bool last);
  void EndLongLine(std::uint64_t end);

  std::uint64_t size_ = 0;      // bytes fed
  std::uint64_t base_ = 0;      // the offset of the next byte Scan sees
  std::string carry_, joined_;  // a cut UTF-8 sequence (or the first bytes, for the BOM)
  bool blank_ = true;           // only " \t\r\n" so far
  bool bom_checked_ = false;
  const char* wide_ = nullptr;  // "UTF-16" or "UTF-32" when a byte-order mark says so
  bool nul_ = false, utf8_ = false, long_ = false, lone_cr_ = false;
  bool cr_pending_ = false;  // the last byte seen was a CR: a line feed may follow
  int cr_line_ = 0, cr_column_ = 0;
  std::size_t open_long_ = SIZE_MAX;  // index of the kLong finding whose line has not ended
  int line_ = 1;
  std::uint64_t line_start_ = 0;
  std::vector<Finding> findings_;
};

/// A regular file read in fixed-size chunks: ReadInputFile's refusals (same words), without
/// holding the file. Reads at most the size the file had when opened.
class InputFileReader {
 public:
  static constexpr std::size_t kChunkBytes = std::size_t{64} << 10;
  InputFileReader() = default;
  ~InputFileReader();
  InputFileReader(const InputFileReader&) = delete;
  InputFileReader& operator=(const InputFileReader&) = delete;

  /// Empty on success, else why not ("no such file", "it is a directory", ...).
  std::string Open(const std::filesystem::path& path, std::uintmax_t max_bytes = kMaxInputBytes);
  /// The next chunk (valid until the next call); empty at the end of the file or after a read
  /// error (then error() says which).
  std::string_view Next();
  const std::string& error() const { return error_; }
  /// What the file was when opened, to tell a second pass that it changed in between.
  std::uintmax_t size() const { return size_; }
  std::int64_t modified_ns() const { return modified_ns_; }

 private:
  int fd_ = -1;
  std::uintmax_t size_ = 0, left_ = 0;
  std::int64_t modified_ns_ = 0;
  std::string buffer_;
  std::string error_;
};

/// A text file line by line, read in chunks and checked as CheckInputText checks (FinishCheck).
/// Memory stays at a chunk and one line, whatever the file's length; a line longer than
/// kMaxLineBytes is handed out cut there (the check fails the file anyway).
class InputLineReader {
 public:
  std::string Open(const std::filesystem::path& path, std::uintmax_t max_bytes = kMaxInputBytes) {
    return file_.Open(path, max_bytes);
  }
  /// The next line without its '\n' (valid until the next call); false at the end of the file
  /// or on a read error (error()). A last line without '\n' is a line; nothing after a last
  /// '\n' is not.
  bool Next(std::string_view& line);
  const std::string& error() const { return file_.error(); }
  bool check_failing() const { return check_.failing(); }
  /// After the last line: CheckInputText's verdict on the whole file.
  bool FinishCheck(const std::string& display_name, std::string_view expected,
                   Diagnostics& diagnostics) {
    return check_.Finish(display_name, expected, diagnostics);
  }
  const InputFileReader& file() const { return file_; }

 private:
  InputFileReader file_;
  InputTextCheck check_;
  std::string_view chunk_;
  std::string line_;
  bool end_ = false;
};

/// `text` for a message: as is when short, else its first `max_bytes` bytes (never cutting a
/// UTF-8 sequence) and "...", so a 1 MB field does not become a 1 MB message.
std::string Abbreviate(std::string_view text, std::size_t max_bytes = 40);

/// A file a command reads or writes, with what it is to the user: "the scene", "--out".
struct RolePath {
  std::string role;
  std::filesystem::path path;
};

/// Refuses an output that is the very file of an input, or of another output: the same device
/// and inode when the output exists (a symlink or a hard link to the input included), else the
/// same canonical path. An empty string when every output is a file apart; else the message,
/// naming both paths ("--out T.csv is the same file as the trajectory T.csv, ..."), which the
/// command prints with exit code 2 before it writes anything. Empty roles and paths are skipped.
std::string CheckOutputsApart(const std::vector<RolePath>& outputs,
                              const std::vector<RolePath>& inputs);

/// A file written whole or not at all, for outputs too large to hold in memory: the text goes
/// to a temporary file next to `path` (`NAME.tmp.PID.N`) as it comes (Write), and Commit flushes
/// it to the disk and renames it over `path`. Destroyed without a successful Commit (an error,
/// an exception), it removes the temporary file and `path` stays as it was; so does SIGINT or
/// SIGTERM (io/interrupt.hpp). Missing parent directories of `path` are created.
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
  int slot_ = -1;  // the temporary's registration for the signal handler
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

/// A file written as it goes (a live recording): into a temporary file next to `path`
/// (`NAME.tmp.PID.N`), flushed to the operating system on every Flush(), and renamed over `path`
/// by Commit(). A crash or SIGKILL leaves `path` as it was (and the partial data in the
/// temporary file); destroying it uncommitted, SIGINT or SIGTERM remove the temporary file.
/// Missing parent directories of `path` are created.
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
  int slot_ = -1;
  bool failed_ = false;
};

/// Writes `files` ({path, text}) each to its temporary, then renames them one after the other:
/// a signal while they are written ends the process with none of them; one while they are
/// renamed comes too late to stop them (deferred, and then ignored), so there is never one
/// without the others. Empty on success, else "PATH: error: ..." of the first that failed.
std::string WriteFilesTogether(const std::vector<std::pair<std::string, std::string>>& files);

}  // namespace tubeplan::io
