#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <system_error>
#include <unistd.h>

#include <tubeplan/io/text_file.hpp>

namespace tubeplan::io {

std::optional<std::string> ReadTextFile(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return std::nullopt;
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream text;
  text << in.rdbuf();  // an empty file sets failbit on `text`, which is fine: it is ""
  if (in.bad()) return std::nullopt;
  return text.str();
}

std::string WriteTextFileAtomically(const std::filesystem::path& path, std::string_view text) {
  // Same directory, so the rename is atomic (same file system); the pid keeps two concurrent
  // writers of one path from sharing a temporary file.
  std::filesystem::path temporary = path;
  temporary += ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) return "cannot create " + temporary.string() + ": " + std::strerror(errno);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.flush();
    if (!out) {
      std::error_code ignored;
      std::filesystem::remove(temporary, ignored);
      return "cannot write " + temporary.string() + ": " + std::strerror(errno);
    }
  }
  std::error_code ec;
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    return "cannot rename " + temporary.string() + " to " + path.string() + ": " + ec.message();
  }
  return {};
}

StreamingTextFile::~StreamingTextFile() {
  if (file_ == nullptr) return;
  std::fclose(file_);
  std::error_code ignored;
  std::filesystem::remove(temporary_, ignored);
}

std::string StreamingTextFile::Open(const std::filesystem::path& path) {
  path_ = path;
  temporary_ = path;
  temporary_ += ".tmp." + std::to_string(::getpid());
  file_ = std::fopen(temporary_.c_str(), "wb");
  if (file_ == nullptr) return "cannot create " + temporary_.string() + ": " + std::strerror(errno);
  return {};
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
  return error;
}

}  // namespace tubeplan::io
