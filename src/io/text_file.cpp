#include "text_file.hpp"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <memory>
#include <sys/stat.h>
#include <unistd.h>

#include <tubeplan/io/interrupt.hpp>

namespace tubeplan::io {
namespace {

std::string MiB(std::uintmax_t bytes) { return std::to_string(bytes >> 20) + " MiB"; }

// Closes a file descriptor when it goes out of scope.
struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

// Opens `path` for reading if it is a regular file of at most `max_bytes`; else closes it and
// says why, in the words every "cannot read file (...)" message quotes.
std::string OpenRegularFile(const std::filesystem::path& path, std::uintmax_t max_bytes, Fd& in,
                            struct stat& info) {
  // O_NONBLOCK: opening a FIFO nobody writes to must not block; a regular file ignores it.
  in.fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (in.fd < 0) return errno == ENOENT ? "no such file" : std::strerror(errno);
  if (::fstat(in.fd, &info) != 0) return std::strerror(errno);
  if (S_ISDIR(info.st_mode)) return "it is a directory";
  if (!S_ISREG(info.st_mode)) return "it is not a regular file (a device, FIFO or socket)";
  const auto size = static_cast<std::uintmax_t>(info.st_size);
  if (size > max_bytes)
    return "it is " + MiB(size) + ", more than the " + MiB(max_bytes) + " allowed";
  return {};
}

// Reads up to `count` bytes, retrying on EINTR; -1 on an error (errno set).
ssize_t ReadSome(int fd, char* to, std::size_t count) {
  while (true) {
    const ssize_t n = ::read(fd, to, count);
    if (n < 0 && errno == EINTR) continue;
    return n;
  }
}

}  // namespace

ReadResult ReadInputFile(const std::filesystem::path& path, std::uintmax_t max_bytes) {
  ReadResult result;
  Fd in;
  struct stat info {};
  result.error = OpenRegularFile(path, max_bytes, in, info);
  if (!result.error.empty()) return result;
  std::string text(static_cast<std::size_t>(info.st_size), '\0');
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ReadSome(in.fd, text.data() + done, text.size() - done);
    if (n < 0) {
      result.error = std::strerror(errno);
      return result;
    }
    if (n == 0) break;  // the file shrank while we read it: what is there is what we have
    done += static_cast<std::size_t>(n);
  }
  text.resize(done);
  result.text = std::move(text);
  return result;
}

InputFileReader::~InputFileReader() {
  if (fd_ >= 0) ::close(fd_);
}

std::string InputFileReader::Open(const std::filesystem::path& path, std::uintmax_t max_bytes) {
  Fd in;
  struct stat info {};
  std::string error = OpenRegularFile(path, max_bytes, in, info);
  if (!error.empty()) return error;
  if (fd_ >= 0) ::close(fd_);
  fd_ = in.fd;
  in.fd = -1;
  size_ = left_ = static_cast<std::uintmax_t>(info.st_size);
  modified_ns_ = std::int64_t{info.st_mtim.tv_sec} * 1'000'000'000 + info.st_mtim.tv_nsec;
  buffer_.resize(kChunkBytes);
  error_.clear();
  return {};
}

std::string_view InputFileReader::Next() {
  if (fd_ < 0 || left_ == 0 || !error_.empty()) return {};
  const ssize_t n = ReadSome(
      fd_, buffer_.data(), static_cast<std::size_t>(std::min<std::uintmax_t>(left_, kChunkBytes)));
  if (n < 0) {
    error_ = std::strerror(errno);
    return {};
  }
  // n == 0: the file shrank while we read it; what was there is what we have (as ReadInputFile).
  left_ = n == 0 ? 0 : left_ - static_cast<std::uintmax_t>(n);
  return {buffer_.data(), static_cast<std::size_t>(n)};
}

bool InputLineReader::Next(std::string_view& line) {
  line_.clear();
  bool partial = false;
  // A line cut by a chunk's end is copied into line_, up to just over the limit: the check
  // fails such a file, and its parser needs only to see that the line is long.
  const auto keep = [this](std::string_view piece) {
    if (line_.size() <= kMaxLineBytes)
      line_.append(piece.substr(0, kMaxLineBytes + 1 - line_.size()));
  };
  while (true) {
    if (chunk_.empty()) {
      if (!end_) {
        chunk_ = file_.Next();
        if (!chunk_.empty()) {
          check_.Feed(chunk_);
          continue;
        }
        end_ = true;
      }
      if (!partial) return false;
      line = line_;
      return true;
    }
    const std::size_t newline = chunk_.find('\n');
    if (newline == std::string_view::npos) {
      keep(chunk_);
      partial = true;
      chunk_ = {};
      continue;
    }
    if (partial) {
      keep(chunk_.substr(0, newline));
      line = line_;
    } else {
      line = chunk_.substr(0, newline);
    }
    chunk_.remove_prefix(newline + 1);
    return true;
  }
}

std::optional<std::string> ReadTextFile(const std::filesystem::path& path) {
  return ReadInputFile(path).text;
}

std::string Abbreviate(std::string_view text, std::size_t max_bytes) {
  if (text.size() <= max_bytes) return std::string(text);
  std::size_t cut = max_bytes;
  // Back up over UTF-8 continuation bytes (10xxxxxx) so a multi-byte character stays whole.
  while (cut > 0 && (static_cast<unsigned char>(text[cut]) & 0xC0) == 0x80) --cut;
  return std::string(text.substr(0, cut)) + "...";
}

namespace {

// What makes two paths one file: its device and inode when it exists, else its canonical path
// (an output not written yet, or an input that is missing).
struct FileIdentity {
  bool exists = false;
  dev_t device = 0;
  ino_t inode = 0;
  std::string canonical;
};

FileIdentity IdentityOf(const std::filesystem::path& path) {
  FileIdentity id;
  struct stat info {};
  if (::stat(path.c_str(), &info) == 0) {
    id.exists = true;
    id.device = info.st_dev;
    id.inode = info.st_ino;
  }
  std::error_code ec;
  const std::filesystem::path absolute = std::filesystem::absolute(path, ec);
  const std::filesystem::path canonical = std::filesystem::weakly_canonical(absolute, ec);
  id.canonical = (ec ? absolute.lexically_normal() : canonical).string();
  return id;
}

bool SameFile(const FileIdentity& a, const FileIdentity& b) {
  if (a.exists && b.exists) return a.device == b.device && a.inode == b.inode;
  return a.canonical == b.canonical;
}

// "--out T.csv" or "the trajectory T.csv".
std::string Named(const RolePath& p) { return p.role + " " + p.path.string(); }

// When the two spellings differ, how they can be one file.
std::string Through(const RolePath& a, const RolePath& b) {
  return a.path == b.path ? "" : " (through a link or another spelling of its path)";
}

}  // namespace

std::string CheckOutputsApart(const std::vector<RolePath>& outputs,
                              const std::vector<RolePath>& inputs) {
  std::vector<FileIdentity> input_ids;
  for (const RolePath& in : inputs) input_ids.push_back(IdentityOf(in.path));
  std::vector<FileIdentity> output_ids;
  for (const RolePath& out : outputs) {
    output_ids.push_back(out.path.empty() ? FileIdentity{} : IdentityOf(out.path));
    if (out.path.empty()) continue;
    for (std::size_t i = 0; i < inputs.size(); ++i) {
      if (inputs[i].path.empty() || !SameFile(output_ids.back(), input_ids[i])) continue;
      return Named(out) + " is the same file as " + Named(inputs[i]) + Through(out, inputs[i]) +
             ": writing it would replace the input, expected another file for the output";
    }
    for (std::size_t j = 0; j + 1 < output_ids.size(); ++j) {
      if (outputs[j].path.empty() || !SameFile(output_ids.back(), output_ids[j])) continue;
      return Named(out) + " is the same file as " + Named(outputs[j]) + Through(out, outputs[j]) +
             ": one would replace the other, expected a file of its own for each output";
    }
  }
  return {};
}

void InputTextCheck::Feed(std::string_view piece) {
  size_ += piece.size();
  if (blank_ && piece.find_first_not_of(" \t\r\n") != std::string_view::npos) blank_ = false;
  if (wide_ != nullptr) return;
  if (carry_.empty()) {
    Scan(piece, false);
  } else {
    joined_ = carry_;
    joined_.append(piece);
    carry_.clear();
    Scan(joined_, false);
  }
}

void InputTextCheck::EndLongLine(std::uint64_t end) {
  findings_[open_long_].length = end - line_start_;
  open_long_ = SIZE_MAX;
}

// `data` starts at offset base_ of the whole text; `last`: nothing follows it. A UTF-8 sequence
// (or, at the start, a byte-order mark) cut by data's end is kept in carry_ for the next piece,
// so every decision sees the same bytes as a scan of the whole text would.
void InputTextCheck::Scan(std::string_view data, bool last) {
  const std::size_t n = data.size();
  if (!bom_checked_) {
    if (n < 4 && !last) {
      carry_.assign(data);
      return;
    }
    // Byte-order marks of the encodings a Windows editor may save in.
    auto starts = [&](std::string_view bom) { return data.substr(0, bom.size()) == bom; };
    bom_checked_ = true;
    if (starts(std::string_view("\xFF\xFE\x00\x00", 4)) ||
        starts(std::string_view("\x00\x00\xFE\xFF", 4))) {
      wide_ = "UTF-32";
    } else if (starts("\xFF\xFE") || starts("\xFE\xFF")) {
      wide_ = "UTF-16";
    }
    if (wide_ != nullptr) return;
  }
  const auto column = [&](std::size_t at) {
    return static_cast<int>(base_ + at - line_start_) + 1;
  };
  for (std::size_t i = 0; i < n;) {
    const auto c = static_cast<unsigned char>(data[i]);
    // A CR ends a line only with a LF after it: one alone means the file's lines end in CR.
    if (cr_pending_) {
      cr_pending_ = false;
      if (c != '\n' && !lone_cr_) {
        findings_.push_back({Kind::kLoneCr, cr_line_, cr_column_});
        lone_cr_ = true;
      }
    }
    if (c == '\r') {
      cr_pending_ = true;
      cr_line_ = line_;
      cr_column_ = column(i);
      ++i;
      continue;
    }
    if (c == '\n') {
      if (open_long_ != SIZE_MAX) EndLongLine(base_ + i);
      ++line_;
      line_start_ = base_ + ++i;
      continue;
    }
    if (!long_ && base_ + i - line_start_ >= kMaxLineBytes) {
      open_long_ = findings_.size();
      findings_.push_back({Kind::kLong, line_, 1});
      long_ = true;
    }
    if (c == 0) {
      if (!nul_) findings_.push_back({Kind::kNul, line_, column(i)});
      nul_ = true;
      ++i;
      continue;
    }
    if (c < 0x80) {
      ++i;
      continue;
    }
    // A multi-byte UTF-8 sequence: its length from the lead byte, then the shortest-form and
    // range rules (no overlong forms, no surrogates, nothing above U+10FFFF).
    std::size_t length = 0;
    unsigned lo = 0x80, hi = 0xBF;  // the allowed range of the second byte
    if (c >= 0xC2 && c <= 0xDF) {
      length = 2;
    } else if (c >= 0xE0 && c <= 0xEF) {
      length = 3;
      if (c == 0xE0) lo = 0xA0;
      if (c == 0xED) hi = 0x9F;
    } else if (c >= 0xF0 && c <= 0xF4) {
      length = 4;
      if (c == 0xF0) lo = 0x90;
      if (c == 0xF4) hi = 0x8F;
    }
    if (length > 0 && i + length > n && !last) {
      carry_.assign(data.substr(i));
      base_ += i;
      return;
    }
    bool valid = length > 0 && i + length <= n;
    for (std::size_t k = 1; valid && k < length; ++k) {
      const auto b = static_cast<unsigned char>(data[i + k]);
      valid = k == 1 ? (b >= lo && b <= hi) : (b >= 0x80 && b <= 0xBF);
    }
    if (!valid) {
      if (!utf8_) findings_.push_back({Kind::kUtf8, line_, column(i), c});
      utf8_ = true;
      ++i;
      continue;
    }
    i += length;
  }
  base_ += n;
}

bool InputTextCheck::Finish(const std::string& display_name, std::string_view expected,
                            Diagnostics& diagnostics) {
  if (!carry_.empty() || !bom_checked_) {
    const std::string rest = std::move(carry_);
    carry_.clear();
    if (wide_ == nullptr) Scan(rest, true);
  }
  if (open_long_ != SIZE_MAX) EndLongLine(size_);
  const std::string expect(expected);
  if (blank_) {
    diagnostics.Error(display_name, 0, 0,
                      std::string(size_ == 0 ? "the file is empty" : "the file is blank") +
                          ", expected " + expect);
    return false;
  }
  if (wide_ != nullptr) {
    diagnostics.Error(display_name, 1, 1,
                      std::string("the file is ") + wide_ +
                          " (it starts with a byte-order mark), expected UTF-8 text: " + expect);
    return false;
  }
  for (const Finding& f : findings_) {
    switch (f.kind) {
      case Kind::kNul:
        diagnostics.Error(display_name, f.line, f.column,
                          "a NUL byte: this is a binary file, expected UTF-8 text: " + expect);
        break;
      case Kind::kUtf8: {
        char hex[8];
        std::snprintf(hex, sizeof hex, "0x%02X", f.byte);
        diagnostics.Error(
            display_name, f.line, f.column,
            std::string("invalid UTF-8 (byte ") + hex + "), expected UTF-8 text: " + expect);
        break;
      }
      case Kind::kLoneCr:
        diagnostics.Error(display_name, f.line, f.column,
                          "a carriage return (CR) with no line feed after it: the lines end in "
                          "CR alone (as classic Mac OS saved text), expected LF or CRLF line "
                          "endings in " +
                              expect);
        break;
      case Kind::kLong:
        // The lines of a file that ends them in CR alone are one line here: said above.
        if (lone_cr_) break;
        diagnostics.Error(display_name, f.line, 1,
                          "line " + std::to_string(f.line) + " is " + std::to_string(f.length) +
                              " bytes long, expected at most " + std::to_string(kMaxLineBytes) +
                              " bytes per line in " + expect);
        break;
    }
  }
  return findings_.empty();
}

bool CheckInputText(std::string_view text, const std::string& display_name,
                    std::string_view expected, Diagnostics& diagnostics) {
  // One implementation for whole texts and streamed files: the same text, the same messages.
  InputTextCheck check;
  check.Feed(text);
  return check.Finish(display_name, expected, diagnostics);
}

namespace {

// `path` + ".tmp.PID.N": in the same directory, so the rename is atomic (same file system); the
// pid and a counter keep two writers of one path (processes or threads) from sharing one.
std::filesystem::path TemporaryFor(const std::filesystem::path& path) {
  static std::atomic<unsigned> counter{0};
  std::filesystem::path temporary = path;
  temporary += ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter++);
  return temporary;
}

// Creates the temporary file for `path`, and the directories above it when they are missing (a
// fresh checkout has no build/); -1 and `error` set when it cannot.
int CreateTemporary(const std::filesystem::path& path, const std::filesystem::path& temporary,
                    int& slot, std::string& error) {
  constexpr int kFlags = O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC;
  int fd = CreateRegistered(temporary.c_str(), kFlags, 0666, slot);
  if (fd < 0 && errno == ENOENT && path.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(path.parent_path(), ec);
    if (ec) {
      error = "cannot create the directory " + path.parent_path().string() + ": " + ec.message();
      return -1;
    }
    fd = CreateRegistered(temporary.c_str(), kFlags, 0666, slot);
  }
  if (fd < 0) error = "cannot create " + temporary.string() + ": " + std::strerror(errno);
  return fd;
}

}  // namespace

AtomicFile::AtomicFile(std::filesystem::path path)
    : path_(std::move(path)), temporary_(TemporaryFor(path_)) {
  // A write past RLIMIT_FSIZE raises SIGXFSZ, whose default action kills the process and leaves
  // the temporary behind; ignored, the write fails with EFBIG and is reported like a full disk.
  std::signal(SIGXFSZ, SIG_IGN);
  fd_ = CreateTemporary(path_, temporary_, slot_, error_);
}

AtomicFile::~AtomicFile() {
  if (fd_ >= 0) ::close(fd_);
  if (!committed_ && fd_ >= 0) ::unlink(temporary_.c_str());
  ForgetTemporary(slot_);
}

void AtomicFile::Fail(const char* what, int error) {
  if (!error_.empty()) return;
  error_ = std::string(what) + " " + temporary_.string() + ": " + std::strerror(error);
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  ::unlink(temporary_.c_str());
  ForgetTemporary(slot_);
  slot_ = -1;
}

bool AtomicFile::Write(std::string_view text) {
  bytes_ += text.size();  // what was asked: the room a retry needs
  if (!error_.empty()) return false;
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd_, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      Fail("cannot write", errno);
      return false;
    }
    done += static_cast<std::size_t>(n);
  }
  return true;
}

std::string AtomicFile::Commit() {
  if (error_.empty()) {
    // fsync before the rename: after a power cut the file is either the old one or the new one
    // whole, never a new name for blocks that never reached the disk.
    if (::fsync(fd_) != 0 && errno != EINVAL) {
      Fail("cannot write", errno);
    } else {
      const int fd = fd_;
      fd_ = -1;
      if (::close(fd) != 0) {
        Fail("cannot write", errno);
      } else if (::rename(temporary_.c_str(), path_.c_str()) != 0) {
        const int error = errno;
        ::unlink(temporary_.c_str());
        error_ = "cannot rename " + temporary_.string() + " to " + path_.string() + ": " +
                 std::strerror(error);
      } else {
        committed_ = true;
        return {};
      }
    }
  }
  // Nothing asked to be written yet (the temporary could not be created): no room to name.
  return error_ + "; nothing was written (" + path_.string() +
         " is as it was), expected a writable directory" +
         (bytes_ > 0 ? " with room for " + std::to_string(bytes_) + " bytes" : std::string());
}

std::string WriteTextFileAtomically(const std::filesystem::path& path, std::string_view text) {
  AtomicFile file(path);
  file.Write(text);
  return file.Commit();
}

StreamingTextFile::~StreamingTextFile() {
  if (file_ != nullptr) {
    std::fclose(file_);
    std::error_code ignored;
    std::filesystem::remove(temporary_, ignored);
  }
  ForgetTemporary(slot_);
}

std::string StreamingTextFile::Open(const std::filesystem::path& path) {
  path_ = path;
  temporary_ = TemporaryFor(path);
  std::string error;
  const int fd = CreateTemporary(path_, temporary_, slot_, error);
  if (fd < 0) return error;
  file_ = ::fdopen(fd, "wb");
  if (file_ == nullptr) {
    error = "cannot create " + temporary_.string() + ": " + std::strerror(errno);
    ::close(fd);
    ::unlink(temporary_.c_str());
  }
  return error;
}

void StreamingTextFile::Append(std::string_view text) {
  if (file_ == nullptr || failed_) return;
  if (std::fwrite(text.data(), 1, text.size(), file_) != text.size()) failed_ = true;
}

std::string StreamingTextFile::Flush() {
  if (file_ == nullptr) return "not open";
  if (failed_ || std::fflush(file_) != 0)
    return "cannot write " + temporary_.string() + ": " + std::strerror(errno);
  return {};
}

std::string StreamingTextFile::Commit() {
  std::string error = Flush();
  if (file_ != nullptr && ::fsync(::fileno(file_)) != 0 && error.empty())
    error = "cannot sync " + temporary_.string() + ": " + std::strerror(errno);
  if (file_ != nullptr && std::fclose(file_) != 0 && error.empty())
    error = "cannot close " + temporary_.string() + ": " + std::strerror(errno);
  file_ = nullptr;
  std::error_code ec;
  if (error.empty()) {
    std::filesystem::rename(temporary_, path_, ec);
    if (ec)
      error =
          "cannot rename " + temporary_.string() + " to " + path_.string() + ": " + ec.message();
  }
  if (!error.empty()) std::filesystem::remove(temporary_, ec);
  ForgetTemporary(slot_);
  slot_ = -1;
  return error;
}

std::string WriteFilesTogether(const std::vector<std::pair<std::string, std::string>>& files) {
  std::vector<std::pair<std::string, std::unique_ptr<AtomicFile>>> outputs;
  for (const auto& [path, text] : files) {
    outputs.emplace_back(path, std::make_unique<AtomicFile>(path));
    outputs.back().second->Write(text);
  }
  for (const auto& [path, file] : outputs) {
    if (file->error().empty()) continue;
    return path + ": error: " + file->Commit();
  }
  const DeferInterrupts too_late;
  for (const auto& [path, file] : outputs)
    if (const std::string e = file->Commit(); !e.empty()) return path + ": error: " + e;
  return std::string();
}

}  // namespace tubeplan::io
