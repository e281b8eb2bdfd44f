// Outputs under trouble (docs/hardening.md): a full disk, a file-size limit, a read-only
// directory and an interrupted batch each give a clear message and leave no partial file. The
// troubles are made real in a child process (a file-size limit, a user without write
// permission, a pending SIGINT), so the parent test process stays unaffected.
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "../device/live_replay.hpp"
#include "cli/app.hpp"

namespace {

struct Outcome {
  int exit_code = -1;
  std::string err;
};

std::string SourcePath(const std::string& relative) {
  return std::string(TUBEPLAN_SOURCE_DIR) + "/" + relative;
}

std::filesystem::path Scratch() {
  const auto dir =
      std::filesystem::temp_directory_path() / ("tubeplan-outputs-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

std::string ReadAll(int fd) {
  std::string text;
  char buffer[4096];
  for (ssize_t n; (n = ::read(fd, buffer, sizeof buffer)) != 0;) {
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) break;
    text.append(buffer, static_cast<std::size_t>(n));
  }
  return text;
}

// Runs the command in a forked child after `setup` (which limits the child); its stderr comes
// back through a pipe.
Outcome RunInChild(const std::function<void()>& setup, std::vector<std::string> args) {
  int pipe_fds[2];
  REQUIRE(::pipe(pipe_fds) == 0);
  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    ::close(pipe_fds[0]);
    setup();
    std::ostringstream out, err;
    const int code = tubeplan::cli::Run(args, out, err);
    const std::string text = err.str();
    [[maybe_unused]] const ssize_t written = ::write(pipe_fds[1], text.data(), text.size());
    ::_exit(code);
  }
  ::close(pipe_fds[1]);
  Outcome outcome;
  outcome.err = ReadAll(pipe_fds[0]);
  ::close(pipe_fds[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  outcome.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return outcome;
}

std::vector<std::string> Entries(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    names.push_back(entry.path().filename().string());
  return names;
}

std::string ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

TEST_CASE("A full disk (a file-size limit) is an error that leaves the old file whole",
          "[cli][outputs]") {
  const auto dir = Scratch() / "full";
  std::filesystem::create_directories(dir);
  const std::string report = (dir / "report.json").string();
  std::ofstream(report) << "the old report\n";
  // 1 KiB: the evaluation report of one plan is several kilobytes. SIGXFSZ is ignored by the
  // writer, so the write fails with EFBIG as it would with ENOSPC on a full disk.
  const Outcome r = RunInChild(
      [] {
        const rlimit limit{1024, 1024};
        ::setrlimit(RLIMIT_FSIZE, &limit);
      },
      {"evaluate", SourcePath("plans/groove-insert-coarse.yaml"), "--jobs", "1", "--report",
       report});
  CHECK(r.exit_code == 2);
  CHECK_THAT(r.err, Catch::StartsWith(report + ": error: cannot write " + report + ".tmp."));
  CHECK_THAT(r.err, Catch::Contains(": File too large; nothing was written (" + report +
                                    " is as it was), expected a writable directory with room for"));
  CHECK(ReadFile(report) == "the old report\n");
  CHECK(Entries(dir) == std::vector<std::string>{"report.json"});
  std::filesystem::remove_all(Scratch());
}

TEST_CASE("A read-only directory is an error and no file appears in it", "[cli][outputs]") {
  const auto dir = Scratch() / "read-only";
  std::filesystem::create_directories(dir);
  // Readable and searchable by all, writable by nobody: as root (who writes anywhere) the child
  // becomes user nobody first.
  std::filesystem::permissions(Scratch(), std::filesystem::perms::all);
  std::filesystem::permissions(
      dir, std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec |
               std::filesystem::perms::group_read | std::filesystem::perms::group_exec |
               std::filesystem::perms::others_read | std::filesystem::perms::others_exec);
  const std::string series = (dir / "series.csv").string();
  const Outcome r = RunInChild(
      [] {
        if (::geteuid() == 0 && (::setgid(65534) != 0 || ::setuid(65534) != 0)) ::_exit(99);
      },
      {"simulate", SourcePath("scenes/groove.yaml"), SourcePath("plans/groove-insert.csv"), "--out",
       series});
  CHECK(r.exit_code == 2);
  CHECK_THAT(r.err, Catch::StartsWith(series + ": error: cannot create " + series + ".tmp."));
  CHECK_THAT(r.err, Catch::Contains(": Permission denied; nothing was written (" + series +
                                    " is as it was), expected a writable directory"));
  CHECK(Entries(dir).empty());
  std::filesystem::permissions(dir, std::filesystem::perms::owner_all);
  std::filesystem::remove_all(Scratch());
}

TEST_CASE("SIGINT during a batch evaluation stops it and writes no report", "[cli][outputs]") {
  const auto dir = Scratch() / "interrupted";
  std::filesystem::create_directories(dir);
  const std::string report = (dir / "report.json").string();
  std::ofstream(report) << "the old report\n";
  int pipe_fds[2];
  REQUIRE(::pipe(pipe_fds) == 0);
  // SIGINT blocked across fork and exec stays pending until evaluate installs its handler and
  // unblocks it: the interruption arrives at a known point, whatever the machine's load. It is
  // blocked before the fork, so the child never runs a moment without the block.
  sigset_t set, old_set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  REQUIRE(::pthread_sigmask(SIG_BLOCK, &set, &old_set) == 0);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::dup2(pipe_fds[1], STDERR_FILENO);
    ::close(pipe_fds[0]);
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, STDOUT_FILENO);
    ::execl(TUBEPLAN_BINARY, TUBEPLAN_BINARY, "evaluate", SourcePath("plans").c_str(), "--jobs",
            "1", "--report", report.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::pthread_sigmask(SIG_SETMASK, &old_set, nullptr);
  REQUIRE(pid > 0);
  ::close(pipe_fds[1]);
  REQUIRE(::kill(pid, SIGINT) == 0);
  const std::string err = ReadAll(pipe_fds[0]);
  ::close(pipe_fds[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 130);
  CHECK(err == "tubeplan evaluate: interrupted after 0 of 5 plans; no report written (" + report +
                   " is left as it was)\n");
  CHECK(ReadFile(report) == "the old report\n");
  CHECK(Entries(dir) == std::vector<std::string>{"report.json"});
  std::filesystem::remove_all(Scratch());
}

namespace {

struct Signalled {
  bool exited = false;  // ended by exit(), not killed by the signal
  int exit_code = -1;
  std::string err;
};

// Runs the real binary with `args`, stdout to `out_path`; once `ready` holds (polled every 5 ms,
// for at most 20 s) sends it `signal` after `delay_ms`, and waits for it.
Signalled RunAndSignal(std::vector<std::string> args, const std::function<bool()>& ready,
                       int signal, int delay_ms = 0, const std::string& out_path = "/dev/null") {
  int pipe_fds[2];
  REQUIRE(::pipe(pipe_fds) == 0);
  std::vector<char*> argv{const_cast<char*>(TUBEPLAN_BINARY)};
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::dup2(pipe_fds[1], STDERR_FILENO);
    ::close(pipe_fds[0]);
    const int out = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(out, STDOUT_FILENO);
    ::execv(TUBEPLAN_BINARY, argv.data());
    ::_exit(127);
  }
  REQUIRE(pid > 0);
  ::close(pipe_fds[1]);
  for (int waited = 0; waited < 4000 && !ready(); ++waited) ::usleep(5000);
  ::usleep(static_cast<useconds_t>(delay_ms) * 1000);
  ::kill(pid, signal);
  Signalled s;
  s.err = ReadAll(pipe_fds[0]);
  ::close(pipe_fds[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  s.exited = WIFEXITED(status);
  s.exit_code = s.exited ? WEXITSTATUS(status) : -WTERMSIG(status);
  return s;
}

// A trajectory of `seconds` at 20 Hz holding groove.yaml's start pose (the core resamples it
// to 1 kHz: a long replay from a small file).
std::string LongHold(const std::filesystem::path& dir, int seconds) {
  const std::string path = (dir / "hold.csv").string();
  std::ofstream csv(path);
  csv << "t,px,py,pz,qw,qx,qy,qz\n";
  for (int k = 0; k <= 20 * seconds; ++k)
    csv << k * 0.05 << ",0,-0.09,0.04,0.7071068,-0.7071068,0,0\n";
  return path;
}

}  // namespace

TEST_CASE("SIGINT or SIGTERM during simulate --out removes the temporary and exits 130",
          "[cli][outputs]") {
  for (const int signal : {SIGINT, SIGTERM}) {
    CAPTURE(signal);
    const auto dir = Scratch() / "signalled";
    std::filesystem::create_directories(dir);
    const std::string trajectory = LongHold(dir, 600);
    const std::string series = (dir / "series.csv").string();
    // Signalled once the series' temporary exists: the replay is then under way (600 s of
    // ticks, far longer than the wait).
    const auto temporary_exists = [&] {
      for (const std::string& name : Entries(dir))
        if (name.rfind("series.csv.tmp.", 0) == 0) return true;
      return false;
    };
    const Signalled s =
        RunAndSignal({"simulate", SourcePath("scenes/groove.yaml"), trajectory, "--out", series},
                     temporary_exists, signal);
    CHECK(s.exited);
    CHECK(s.exit_code == 130);
    CHECK(s.err ==
          "tubeplan simulate: interrupted; outputs not finished were not written (their "
          "temporary files are removed)\n");
    CHECK(Entries(dir) == std::vector<std::string>{"hold.csv"});
    std::filesystem::remove_all(Scratch());
  }
}

#if TUBEPLAN_HTML_REPORT
TEST_CASE("Ctrl-C while evaluate makes its HTML page exits 130 and writes no report",
          "[cli][outputs]") {
  const auto dir = Scratch() / "html";
  std::filesystem::create_directories(dir);
  const std::string report = (dir / "report.json").string();
  const std::string html = (dir / "report.html").string();
  std::ofstream(report) << "the old report\n";
  // The coarse plan is judged in a fraction of a second; --html-graph then explores the scene
  // for seconds: the signal comes during the exploration (or, on a slow machine, still in the
  // batch; either way nothing may be written).
  const Signalled s = RunAndSignal(
      {"evaluate", SourcePath("plans/groove-insert-coarse.yaml"), "--jobs", "1", "--report", report,
       "--html", html, "--html-graph"},
      [] { return true; }, SIGINT, 1500);
  CHECK(s.exited);
  CHECK(s.exit_code == 130);
  CHECK_THAT(s.err, Catch::StartsWith("tubeplan evaluate: interrupted"));
  CHECK_THAT(s.err, Catch::EndsWith("no report written (" + report + " and " + html +
                                    " are left as they were)\n") ||
                        Catch::EndsWith("no report written (" + report + " is left as it was)\n"));
  CHECK(ReadFile(report) == "the old report\n");
  CHECK(Entries(dir) == std::vector<std::string>{"report.json"});
  std::filesystem::remove_all(Scratch());
}
#else
TEST_CASE("evaluate --html in a build without the HTML report says why, before any replay",
          "[cli][outputs]") {
  const auto dir = Scratch() / "no-html";
  std::filesystem::create_directories(dir);
  const std::string html = (dir / "report.html").string();
  const tubeplan::testing::Outcome r = tubeplan::testing::RunTool(
      {"evaluate", SourcePath("plans/groove-insert-coarse.yaml"), "--html", html});
  CHECK(r.exit_code == 2);
  CHECK_THAT(r.err, Catch::Contains("--html: this tubeplan was built without the HTML report"));
  CHECK(r.out.empty());
  CHECK(Entries(dir).empty());
  std::filesystem::remove_all(Scratch());
}
#endif

TEST_CASE("Every command refuses an output that is one of its inputs, and writes nothing",
          "[cli][outputs]") {
  namespace fs = std::filesystem;
  const auto dir = Scratch() / "same";
  fs::create_directories(dir / "plans");
  fs::create_directories(dir / "scenes");
  // A copy of a shipped plan with its scene and trajectory, so that overwriting would be seen.
  fs::copy_file(SourcePath("scenes/groove.yaml"), dir / "scenes" / "groove.yaml");
  fs::copy_file(SourcePath("plans/groove-insert.csv"), dir / "plans" / "groove-insert.csv");
  fs::copy_file(SourcePath("plans/groove-insert-coarse.yaml"), dir / "plans" / "coarse.yaml");
  const std::string scene = (dir / "scenes" / "groove.yaml").string();
  const std::string trajectory = (dir / "plans" / "groove-insert.csv").string();
  const std::string plan = (dir / "plans" / "coarse.yaml").string();
  fs::create_symlink(trajectory, dir / "link.csv");
  const std::string link = (dir / "link.csv").string();
  std::ofstream(dir / "report.json") << "{}\n";
  const std::string report = (dir / "report.json").string();
  const std::vector<std::string> before = {ReadFile(scene), ReadFile(trajectory), ReadFile(plan)};
  const auto run = [](std::vector<std::string> args) {
    std::ostringstream out, err;
    const int code = tubeplan::cli::Run(args, out, err);
    return Outcome{code, err.str()};
  };
  const auto same = [](const std::string& command, const std::string& option,
                       const std::string& output, const std::string& role,
                       const std::string& input) {
    return "tubeplan " + command + ": error: " + option + " " + output + " is the same file as " +
           role + " " + input +
           (output == input ? "" : " (through a link or another spelling of its path)") +
           ": writing it would replace the input, expected another file for the output\n";
  };
  struct Case {
    std::vector<std::string> args;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {{"simulate", scene, trajectory, "--out", trajectory},
       same("simulate", "--out", trajectory, "the trajectory", trajectory)},
      {{"simulate", scene, trajectory, "--out", link},
       same("simulate", "--out", link, "the trajectory", trajectory)},
      {{"evaluate", plan, "--report", plan}, same("evaluate", "--report", plan, "the plan", plan)},
      {{"evaluate", plan, "--html", scene},
       same("evaluate", "--html", scene, "the scene of " + plan,
            (dir / "plans" / "../scenes/groove.yaml").string())},
      {{"evaluate", plan, "--report", link},
       same("evaluate", "--report", link, "the trajectory of " + plan,
            (dir / "plans" / "groove-insert.csv").string())},
      {{"graph", scene, "--json", scene}, same("graph", "--json", scene, "the scene", scene)},
      {{"graph", scene, "--dot", report, "--verdicts", report},
       same("graph", "--dot", report, "--verdicts", report)},
      {{"graph", scene, "--dot", report, "--json", report},
       "tubeplan graph: error: --json " + report + " is the same file as --dot " + report +
           ": one would replace the other, expected a file of its own for each output\n"},
      {{"live", plan, "--device", "emulator:fast", "--record", trajectory},
       same("live", "--record", trajectory, "the plan's trajectory",
            (dir / "plans" / "groove-insert.csv").string())},
      {{"live", plan, "--device", "emulator:" + link + ",fast", "--record", link},
       same("live", "--record", link, "the plan's trajectory",
            (dir / "plans" / "groove-insert.csv").string())},
      {{"accuracy", scene, "--svg", scene}, same("accuracy", "--svg", scene, "the scene", scene)},
  };
  for (const Case& c : cases) {
    CAPTURE(c.args);
    const Outcome r = run(c.args);
    CHECK(r.exit_code == 2);
    CHECK(r.err == c.expected);
  }
  // plans: its candidate's name is the scene's own file.
  fs::copy_file(scene, dir / "scenes" / "groove-candidate-1.yaml");
  const std::string candidate = (dir / "scenes" / "groove-candidate-1.yaml").string();
  const Outcome plans = run({"plans", candidate, "--out-dir", (dir / "scenes").string()});
  CHECK(plans.exit_code == 2);
  CHECK(plans.err == same("plans", "the plan file", candidate, "the scene", candidate));
  // merge: a report merged into itself (a valid one, so the check is what refuses it).
  const Outcome evaluated = run({"evaluate", plan, "--jobs", "1", "--report", report});
  REQUIRE(evaluated.exit_code == 0);
  const std::string merged_before = ReadFile(report);
  const Outcome merged = run({"merge", report, "--report", report});
  CHECK(merged.exit_code == 2);
  CHECK(merged.err == same("merge", "--report", report, "the report", report));
  CHECK(ReadFile(report) == merged_before);
  // One report is "1 report".
  std::ostringstream merged_out, merged_err;
  CHECK(tubeplan::cli::Run(std::vector<std::string>{"merge", report}, merged_out, merged_err) == 0);
  CHECK_THAT(merged_out.str(), Catch::EndsWith("(merged from 1 report)\n"));
  // simulate's output format: no stray "and" before "expected".
  const Outcome format = run({"simulate", scene, trajectory, "--out", (dir / "x.yaml").string()});
  CHECK(format.exit_code == 2);
  CHECK(format.err == (dir / "x.yaml").string() +
                          ": error: unknown output format \".yaml\", expected a file name ending "
                          "in .csv or .jsonl\n");
  // Nothing was touched, and no temporary is left anywhere.
  CHECK(std::vector<std::string>{ReadFile(scene), ReadFile(trajectory), ReadFile(plan)} == before);
  for (const auto& entry : fs::recursive_directory_iterator(dir))
    CHECK(entry.path().filename().string().find(".tmp.") == std::string::npos);
  fs::remove_all(Scratch());
}

TEST_CASE("SIGINT during live exits 130 and leaves what the run cut short not judged",
          "[cli][outputs][live]") {
  const auto dir = Scratch() / "live";
  std::filesystem::create_directories(dir);
  const std::string recording = (dir / "live.csv").string(), report = (dir / "live.json").string();
  // Signalled once the recording holds most of a second of ticks (about 95 bytes a row): the
  // insertion, 5.5 s long, is then under way.
  const auto recorded = [&] {
    for (const std::string& name : Entries(dir))
      if (name.rfind("live.csv.tmp.", 0) == 0 && std::filesystem::file_size(dir / name) > 80'000)
        return true;
    return false;
  };
  const Signalled s = RunAndSignal({"live", SourcePath("plans/groove-insert.yaml"), "--device",
                                    "emulator", "--record", recording, "--json"},
                                   recorded, SIGINT, 0, report);
  INFO(s.err);
  CHECK(s.exited);
  const nlohmann::json live = nlohmann::json::parse(ReadFile(report));
  // A loaded host may stall the servo beyond what a run survives before the signal: a device
  // fault, which cuts the run short the same way.
  const bool fault = live["servo"]["stop"] == "missed deadlines";
  if (!fault) {
    CHECK(live["servo"]["stop"] == "signal");
    CHECK(s.exit_code == 130);
    CHECK_THAT(s.err, Catch::Contains("tubeplan live: interrupted at t = "));
  } else {
    CHECK(s.exit_code == tubeplan::cli::kExitDeviceFault);
  }
  const nlohmann::json& plan = live["plans"][0];
  const std::string stopped = plan["stopped_early"];
  CHECK_THAT(stopped,
             Catch::StartsWith(fault ? "missed deadlines at t = " : "interrupted at t = "));
  CHECK(plan["outcome"] == "not judged");
  CHECK(live["summary"]["not_judged"] == 1);
  int not_judged = 0;
  for (const nlohmann::json& v : plan["transitions"]) {
    CHECK(v["verdict"] != "infeasible");
    if (v["verdict"] == "not judged") {
      ++not_judged;
      CHECK(v["reason"] == "the run stopped: " + stopped);
    }
  }
  CHECK(not_judged >= 1);
  // The recording is whole and says where the run stopped: evaluate judges it as live did.
  CHECK_THAT(ReadFile(recording), Catch::EndsWith("\n# stopped: " + stopped + "\n"));
  const tubeplan::testing::Evaluated batch =
      tubeplan::testing::EvaluateRecording(recording, dir / "live.yaml");
  CHECK(batch.exit_code == 1);
  tubeplan::testing::CheckSameVerdicts(live, batch.report);
  const tubeplan::testing::Outcome text =
      tubeplan::testing::RunTool({"evaluate", (dir / "live.yaml").string()});
  CHECK_THAT(text.out, Catch::Contains("NOT JUDGED"));
  CHECK_THAT(text.out,
             Catch::Contains("summary: 1 plan, 0 feasible, 0 infeasible, 1 not judged; "));
  std::filesystem::remove_all(Scratch());
}
