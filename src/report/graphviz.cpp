#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <spawn.h>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

#include <tubeplan/report/graphviz.hpp>

extern char** environ;

namespace tubeplan::report {
namespace {

// A temporary file that is removed when it goes out of scope.
class TempFile {
 public:
  explicit TempFile(const char* tag) {
    std::error_code ec;
    std::string pattern =
        (std::filesystem::temp_directory_path(ec) / "tubeplan-").string() + tag + "-XXXXXX";
    if (ec) pattern = std::string("/tmp/tubeplan-") + tag + "-XXXXXX";
    std::vector<char> name(pattern.begin(), pattern.end());
    name.push_back('\0');
    const int fd = mkstemp(name.data());
    if (fd >= 0) {
      close(fd);
      path_ = name.data();
    }
  }
  ~TempFile() {
    if (!path_.empty()) std::remove(path_.c_str());
  }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  const std::string& path() const { return path_; }  ///< empty: could not be made

 private:
  std::string path_;
};

std::string Slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The first lines of a program's stderr, for a message.
std::string Head(const std::string& text) {
  std::string out;
  int lines = 0;
  for (std::size_t at = 0; at < text.size() && lines < 5; ++lines) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    out += (out.empty() ? "" : "; ") + text.substr(at, end - at);
    at = end + 1;
  }
  return out;
}

}  // namespace

SvgFromDot RenderDot(const std::string& dot_text, const std::string& program) {
  SvgFromDot result;
  TempFile in("dot"), out("svg"), err("err");
  if (in.path().empty() || out.path().empty() || err.path().empty()) {
    result.error =
        std::string("cannot make a temporary file for Graphviz: ") + std::strerror(errno);
    return result;
  }
  {
    std::ofstream f(in.path(), std::ios::binary);
    f << dot_text;
    if (!f.flush()) {
      result.error = "cannot write the DOT to " + in.path();
      return result;
    }
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, in.path().c_str(), O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, out.path().c_str(), O_WRONLY | O_TRUNC,
                                   0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err.path().c_str(), O_WRONLY | O_TRUNC,
                                   0);
  std::string arg0 = program, arg1 = "-Tsvg";
  char* argv[] = {arg0.data(), arg1.data(), nullptr};
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, program.c_str(), &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) {
    result.error = spawned == ENOENT
                       ? "Graphviz's `" + program +
                             "` program was not found on PATH: install graphviz (tools/setup does, "
                             "or apt-get install graphviz)"
                       : "cannot run Graphviz's `" + program + "`: " + std::strerror(spawned);
    return result;
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      result.error = std::string("waiting for `") + program + "` failed: " + std::strerror(errno);
      return result;
    }
  }
  const std::string stderr_text = Slurp(err.path());
  if (WIFSIGNALED(status)) {
    result.error = "Graphviz's `" + program + "` was killed by signal " +
                   std::to_string(WTERMSIG(status)) +
                   (stderr_text.empty() ? "" : ": " + Head(stderr_text));
    return result;
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    result.error = "Graphviz's `" + program + "` failed (exit " +
                   std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")" +
                   (stderr_text.empty() ? "" : ": " + Head(stderr_text));
    return result;
  }
  result.svg = Slurp(out.path());
  result.warnings = stderr_text;
  if (result.svg.find("<svg") == std::string::npos) {
    result.error = "Graphviz's `" + program + "` exited 0 but wrote no SVG";
    result.svg.clear();
  }
  return result;
}

}  // namespace tubeplan::report
