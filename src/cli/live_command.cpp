// `tubeplan live PLAN --device KIND[:ARGS] [--record FILE] [--json] [--duration S]`: the plan
// verified live with a haptic device (docs/live.md). A servo thread runs the core at the scene's
// step against the device (device::ServoLoop); this thread judges every tick with the same judge
// as `evaluate`, writes the recording and draws the display, from the servo's lock-free
// hand-offs. At the end the verdicts in evaluate's format, plus the servo's timing.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <memory>
#include <sstream>
#include <thread>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <tubeplan/batch/report.hpp>
#include <tubeplan/device/clock.hpp>
#include <tubeplan/device/device_choice.hpp>
#include <tubeplan/device/emulator.hpp>
#include <tubeplan/device/host_check.hpp>
#include <tubeplan/device/openhaptics.hpp>
#include <tubeplan/device/openigtlink.hpp>
#include <tubeplan/device/servo.hpp>
#include <tubeplan/io/plan_file.hpp>
#include <tubeplan/io/trajectory_csv.hpp>
#include <tubeplan/plan/judge.hpp>
#include <tubeplan/report/text_report.hpp>

#include "app.hpp"
#include "commands.hpp"
#include "io/text_file.hpp"

namespace tubeplan::cli {
namespace {

struct LiveOptions {
  std::string plan;
  std::string device = "emulator";
  std::string record;
  bool json = false;
  double duration_s = 0.0;  // 0: the emulator's trajectory and a settling time
  bool no_realtime = false;
  bool check_host = false;
};

// The CF's canonical text from a tick's contacts, as core::Core::Formation makes it (the judge
// runs on this thread, away from the core).
std::string FormationText(const core::StepOutput& out,
                          const std::vector<scene::PartElement>& elements) {
  states::ContactFormation cf;
  for (const core::ContactState& pc : out.Contacts())
    cf.contacts.push_back({pc.tube, pc.marker, elements[std::size_t(pc.part_element)].name});
  states::Canonicalize(cf);
  return states::ToString(cf);
}

// The display: one block redrawn in place on a terminal, plain lines otherwise.
class Display {
 public:
  Display(std::ostream& out, bool terminal, double max_force_N)
      : out_(out), terminal_(terminal), max_force_N_(max_force_N) {}

  void Draw(const plan::Judging& judging, const device::ServoStatus& s, bool force_line) {
    const std::size_t n = judging.states().size() - 1;
    const std::size_t at = judging.at();
    long feasible = 0, infeasible = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const plan::TransitionVerdict& v = judging.transitions()[i];
      if (i < at && v.verdict != plan::Verdict::kInfeasible) ++feasible;
      if (v.verdict == plan::Verdict::kInfeasible && !v.reason.empty()) ++infeasible;
    }
    // After the goal: a limit exceeded or the goal left there is a verdict too.
    const plan::TransitionVerdict& after = judging.after_goal();
    const bool failed_after = after.started && after.verdict == plan::Verdict::kInfeasible;
    infeasible += failed_after;
    std::ostringstream line;
    line << std::fixed << std::setprecision(2);
    line << "t " << std::setw(6) << s.t_s << " s  CF " << judging.current() << "  next "
         << (at < n         ? judging.states()[at + 1]
             : failed_after ? std::string("(goal reached, then infeasible)")
                            : std::string("(goal reached)"))
         << "\n";
    line << "  progress " << at << "/" << n << "  force " << std::setw(5) << s.force_N << " N of "
         << max_force_N_ << " N  verdicts: " << feasible << " feasible, " << infeasible
         << " infeasible\n";
    line << "  servo " << std::setprecision(0) << s.rate_hz << " Hz, worst tick " << s.worst_us
         << " us, overruns " << s.overruns << "\n";
    const std::string text = line.str();
    if (terminal_) {
      // Cursor up over the last block, then redraw it (each line cleared to its end).
      if (drawn_) out_ << "\033[3F";
      std::istringstream lines(text);
      for (std::string l; std::getline(lines, l);) out_ << l << "\033[K\n";
      out_ << std::flush;
      drawn_ = true;
    } else if (force_line) {
      out_ << text << std::flush;
    }
  }

 private:
  std::ostream& out_;
  bool terminal_;
  double max_force_N_;
  bool drawn_ = false;
};

// `live --check-host`: this host's wake-ups at the servo's rate, and what they mean for a run.
int RunHostCheck(const LiveOptions& o, Streams io) {
  // Every wake-up's lateness is kept (8 bytes a millisecond): an hour at most.
  constexpr double kMaxCheck_s = 3600.0;
  if (o.duration_s > kMaxCheck_s) {
    io.err << "tubeplan live: error: --check-host --duration " << o.duration_s
           << ": expected at most " << kMaxCheck_s << " s\n";
    return kExitBadInput;
  }
  // The servo's period: the scene format's step (1 kHz).
  const double period_s = scene::ModelOptions{}.time_step_s;
  device::MonotonicClock clock;
  const device::HostLatency l = device::MeasureHostLatency(
      clock, o.duration_s > 0.0 ? o.duration_s : 10.0, period_s, !o.no_realtime);
  const device::ServoConfig limits;
  const device::HostVerdict v = device::JudgeHost(l, device::ReadHostFacts(), limits);
  if (!l.realtime_note.empty()) io.err << "tubeplan live: note: " << l.realtime_note << "\n";
  if (o.json) {
    const nlohmann::json report = {{"tubeplan_host_check", 1},
                                   {"period_us", period_s * 1e6},
                                   {"duration_s", l.duration_s},
                                   {"wakes", l.wakes},
                                   {"median_us", l.median_us},
                                   {"p99_us", l.p99_us},
                                   {"p999_us", l.p999_us},
                                   {"max_us", l.max_us},
                                   {"stalls", l.stalls},
                                   {"periods_lost", l.periods_lost},
                                   {"worst_stalls_per_s", l.worst_stalls_per_s},
                                   {"realtime", l.realtime_asked && l.realtime_note.empty()},
                                   {"max_stall_ms", limits.max_stall_s * 1e3},
                                   {"max_stalls_per_s", limits.max_stalls_per_s},
                                   {"verdict", device::ToString(v.fitness)},
                                   {"summary", v.summary},
                                   {"advice", v.advice}};
    io.out << report.dump(2) << "\n";
    return kExitOk;
  }
  std::ostringstream t;
  t << std::fixed << std::setprecision(1) << "host check: " << l.wakes << " wake-ups every "
    << period_s * 1e3 << " ms over " << l.duration_s << " s, "
    << (!l.realtime_asked         ? "normal priority (--no-realtime)"
        : l.realtime_note.empty() ? "SCHED_FIFO (as the servo thread)"
                                  : "normal priority (SCHED_FIFO not permitted)")
    << "\n";
  t << "lateness: median " << l.median_us << " us, p99 " << l.p99_us << " us, p99.9 " << l.p999_us
    << " us, max " << l.max_us << " us\n";
  t << "stalls (more than a period late): ";
  if (l.stalls == 0)
    t << "none";
  else
    t << l.stalls << ", " << l.periods_lost << " periods lost, at most " << l.worst_stalls_per_s
      << " in one second";
  t << " (a live run stops on one longer than " << std::lround(limits.max_stall_s * 1e3)
    << " ms or more than " << limits.max_stalls_per_s << " in a second)\n";
  t << "verdict: " << v.summary << "\n";
  if (!v.advice.empty()) t << "what would help:\n";
  for (const std::string& a : v.advice) t << "  - " << a << "\n";
  io.out << t.str();
  return kExitOk;
}

// Refuses a coupling stiffer than the device renders stably (docs/scene-format.md, "Device").
bool CouplingFits(const core::Core& core, const device::HapticDevice& dev,
                  const std::string& plan_path, std::ostream& err) {
  if (core.coupling_stiffness_N_per_m() <= dev.spec().max_stiffness_N_per_m) return true;
  err << plan_path << ": error: the scene's coupling stiffness "
      << core.coupling_stiffness_N_per_m() << " N/m is more than " << dev.spec().name
      << " renders stably (" << dev.spec().max_stiffness_N_per_m
      << " N/m), expected a softer device.coupling_stiffness\n";
  return false;
}

// What the servo and the judge did over a run.
struct Served {
  device::ServoStats stats;
  double t_last_s = 0.0;  ///< the last judged tick's trajectory time
  long recorded = 0;      ///< rows written to the recording
  std::string record_error;
};

// Runs the servo on its thread and, on this one, judges and records every tick it hands over
// and redraws the display, until the servo stops.
Served Serve(device::ServoLoop& servo, device::SpscRing<device::TickRecord>& ring,
             device::Seqlock<device::ServoStatus>& status, plan::Judging& judging,
             const std::vector<scene::PartElement>& elements, io::StreamingTextFile* recording,
             Display* display) {
  Served served;
  std::atomic<bool> done{false};
  std::thread servo_thread([&] {
    served.stats = servo.Run();
    done.store(true, std::memory_order_release);
  });
  std::string row;
  device::TickRecord record;
  using Clock = std::chrono::steady_clock;
  auto next_draw = Clock::now(), next_flush = Clock::now(), next_line = Clock::now();
  std::string last_counted;
  auto drain = [&] {
    bool any = false;
    while (ring.TryPop(record)) {
      any = true;
      if (!record.stepped) continue;
      judging.Tick(record.hand.t_s, record.out,
                   [&] { return FormationText(record.out, elements); });
      served.t_last_s = record.hand.t_s;
      if (recording == nullptr) continue;
      row.clear();
      // The stall's lateness to 0.01 ms, "0" on a tick that woke in time.
      char stall[24] = "0";
      if (record.stalled) std::snprintf(stall, sizeof stall, "%.2f", double(record.stall_ms));
      io::AppendTrajectoryCsvRow(row, record.hand, stall);
      recording->Append(row);
      ++served.recorded;
    }
    return any;
  };
  for (;;) {
    const bool finished = done.load(std::memory_order_acquire);
    const bool any = drain();
    const auto now = Clock::now();
    if (display != nullptr && now >= next_draw) {
      if (const std::optional<device::ServoStatus> st = status.Load()) {
        // Plain output: a line a second and one whenever a new state counts.
        const bool line = now >= next_line || judging.counted() != last_counted;
        display->Draw(judging, *st, line);
        if (line) next_line = now + std::chrono::seconds(1);
        last_counted = judging.counted();
      }
      next_draw = now + std::chrono::milliseconds(33);  // ~30 Hz
    }
    if (recording != nullptr && now >= next_flush) {
      if (std::string e = recording->Flush(); !e.empty() && served.record_error.empty())
        served.record_error = e;
      next_flush = now + std::chrono::milliseconds(100);
    }
    if (finished && !any) break;
    if (!any) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  servo_thread.join();
  drain();
  return served;
}

// "interrupted at t = 2.310 s" or "<fault> at t = ...", when a signal or a fault ended the run
// before its trajectory did; empty otherwise.
std::string StoppedEarly(const device::ServoStats& stats, double t_last_s) {
  if (stats.stop != device::StopReason::kSignal && !device::IsFault(stats.stop)) return {};
  char when[48];
  std::snprintf(when, sizeof when, " at t = %.3f s", t_last_s);
  return (stats.stop == device::StopReason::kSignal ? std::string("interrupted")
                                                    : device::ToString(stats.stop)) +
         when;
}

// evaluate's report of the run's one plan, with the servo's figures.
nlohmann::json LiveReport(const batch::Evaluated& e, const device::ServoStats& stats,
                          const std::string& device_name, bool stepped) {
  // A live run's report covers its one plan: the plan set of that file, shard 1 of 1.
  batch::ReportScope scope;
  scope.plan_set_id = batch::PlanSetId({batch::CanonicalPlanPath(e.file)});
  scope.plan_set_plans = 1;
  nlohmann::json report = batch::ToJson({e}, scope);
  report["servo"] = {{"ticks", stats.ticks},
                     {"overruns", stats.overruns},
                     {"median_us", stats.median_us},
                     {"p999_us", stats.p999_us},
                     {"max_us", stats.max_us},
                     {"rate_hz", stats.rate_hz},
                     {"max_latency_us", stats.max_latency_us},
                     {"max_jitter_us", stats.max_jitter_us},
                     {"dropped", stats.dropped},
                     {"stalls", stats.stalls},
                     {"ticks_lost", stats.ticks_lost},
                     {"longest_stall_ms", stats.longest_stall_ms},
                     {"stop", device::ToString(stats.stop)},
                     {"realtime", stats.realtime_note.empty()},
                     {"device", device_name},
                     {"clock", stepped ? "stepped" : "monotonic"}};
  return report;
}

// The run's verdicts and the servo's figures as text.
void PrintLiveText(std::ostream& out, const batch::Evaluated& e, const device::ServoStats& stats,
                   bool stepped, bool colour, const std::string& recording_written) {
  std::ostringstream t;
  report::PrintVerdicts(t, e, colour);
  t << std::fixed << std::setprecision(1) << "servo: " << stats.ticks << " ticks at "
    << stats.rate_hz << " Hz (" << (stepped ? "stepped clock" : "real time") << "), "
    << stats.overruns << " overruns; tick median " << stats.median_us << " us, p99.9 "
    << stats.p999_us << " us, worst " << stats.max_us
    << " us; ended: " << device::ToString(stats.stop) << "\n";
  if (stats.stalls > 0)
    t << "servo: " << stats.stalls << (stats.stalls == 1 ? " stall" : " stalls")
      << " (the loop woke more than a tick late; first at t = " << stats.first_stall_s
      << " s, longest " << stats.longest_stall_ms << " ms, " << stats.ticks_lost
      << " periods lost): the force went to zero and ramped back in over 10 ms each time\n";
  if (!recording_written.empty()) t << "recording written to " << recording_written << "\n";
  out << t.str();
}

// The exit code of a run, saying on `err` why a signal or a fault ended it.
int LiveExitCode(const Served& served, const device::ServoConfig& config,
                 const std::string& stopped_early, bool feasible, std::ostream& err) {
  const device::ServoStats& stats = served.stats;
  if (stats.stop == device::StopReason::kSignal) {
    err << "tubeplan live: " << stopped_early
        << "; the force was zeroed; the transitions the run did not finish are not judged\n";
    return kExitInterrupted;
  }
  if (device::IsFault(stats.stop)) {
    err << "tubeplan live: error: the servo stopped on a fault (" << device::ToString(stats.stop)
        << (stats.stop == device::StopReason::kMissedDeadlines
                ? ": a stall longer than " + std::to_string(std::lround(config.max_stall_s * 1e3)) +
                      " ms or more than " + std::to_string(config.max_stalls_per_s) +
                      " in a second; docs/live.md says what helps"
                : std::string())
        << ") " << stopped_early.substr(stopped_early.find(" at t"))
        << "; the force was zeroed; the transitions the run did not finish are not judged\n";
    return stats.stop == device::StopReason::kNonFinite ? kExitInternal : kExitDeviceFault;
  }
  if (stats.dropped > 0 || !served.record_error.empty()) return kExitInternal;
  return feasible ? kExitOk : kExitNegative;
}

int RunLive(const LiveOptions& o, Streams io) {
  io::PlanLoadResult loaded = io::LoadPlanFile(o.plan);
  io.err << loaded.diagnostics.FormatAll();
  if (!loaded.plan) return kExitBadInput;
  device::DeviceChoice choice;
  std::string error;
  if (!device::ParseDeviceChoice(o.device, choice, error)) {
    io.err << "tubeplan live: error: " << error << "\n";
    return kExitBadInput;
  }
  const device::EmulatorArgs& args = choice.emulator;
  const bool emulated = choice.kind == device::DeviceChoice::Kind::kEmulator;
  const bool stepped = emulated && args.stepped;
  const std::filesystem::path plan_directory = std::filesystem::path(o.plan).parent_path();
  if (!OutputsApart("live", {{"--record", o.record}},
                    {{"the plan", o.plan},
                     {"the plan's scene", plan_directory / loaded.plan->scene},
                     {"the plan's trajectory", plan_directory / loaded.plan->trajectory},
                     {"the emulator's trajectory", emulated ? args.trajectory : std::string()}},
                    io.err))
    return kExitBadInput;
  plan::Trajectory target = *loaded.trajectory;
  if (emulated && !args.trajectory.empty()) {
    io::TrajectoryLoadResult t = io::LoadTrajectoryFile(args.trajectory);
    io.err << t.diagnostics.FormatAll();
    if (!t.trajectory) return kExitBadInput;
    target = std::move(*t.trajectory);
  }
  const scene::Scene& scene = *loaded.scene;
  const plan::Plan& plan = *loaded.plan;
  const double T = scene.model.time_step_s;

  std::unique_ptr<device::Clock> clock;
  if (stepped)
    clock = std::make_unique<device::SteppedClock>();
  else
    clock = std::make_unique<device::MonotonicClock>();
  const std::unique_ptr<device::HapticDevice> dev =
      device::MakeDevice(choice, *clock, target, error);
  if (!dev) {
    io.err << "tubeplan live: error: --device \"" << o.device << "\": " << error << "\n";
    return kExitBadInput;
  }
  auto* emulator = emulated ? static_cast<device::EmulatorDevice*>(dev.get()) : nullptr;
  auto* igtl = choice.kind == device::DeviceChoice::Kind::kOpenIGTLink
                   ? static_cast<device::OpenIGTLinkDevice*>(dev.get())
                   : nullptr;
  core::Core core(scene);
  // A device that reports its limits at Open (openhaptics) is checked after it.
  const bool limits_at_open = choice.kind == device::DeviceChoice::Kind::kOpenHaptics;
  if (!limits_at_open && !CouplingFits(core, *dev, o.plan, io.err)) return kExitBadInput;
  // The emulator's trajectory, then 0.5 s for the last state to settle and count (many
  // dwells); a real device runs until --duration or Ctrl-C.
  const double duration_s = o.duration_s > 0.0 ? o.duration_s
                            : emulator         ? emulator->target_duration_s() + 0.5
                                               : 0.0;
  const long ticks = duration_s > 0.0 ? std::lround(duration_s / T) + 1 : 0;
  if (std::string e = dev->Open(); !e.empty()) {
    io.err << "tubeplan live: error: cannot open the device: " << e << "\n";
    return kExitBadInput;
  }
  if (std::string e = dev->Calibrate(); !e.empty()) {
    io.err << "tubeplan live: error: cannot calibrate the device: " << e << "\n";
    return kExitBadInput;
  }
  if (limits_at_open && !CouplingFits(core, *dev, o.plan, io.err)) return kExitBadInput;
  io::StreamingTextFile recording;
  if (!o.record.empty()) {
    if (const std::string e = recording.Open(o.record); !e.empty()) {
      io.err << o.record << ": error: " << e << "\n";
      return kExitBadInput;
    }
    recording.Append(io::TrajectoryCsvHeader(dev->spec().name + ", tubeplan live " + plan.name,
                                             1.0 / T, {"stall_ms"}));
  }

  // A stepped run can outpace this thread: its ring holds the whole run. In real time 16 s of
  // ticks: far more than this thread ever lags.
  device::SpscRing<device::TickRecord> ring(stepped ? std::size_t(ticks) + 16 : 16384);
  device::Seqlock<device::ServoStatus> status;
  device::ServoConfig config;
  config.max_ticks = ticks;
  config.realtime = !o.no_realtime && !stepped;
  // A bridge's poses come over a network, at about the servo's rate but with jitter: stale
  // after its window (docs/live.md), not after one tick.
  if (igtl)
    config.max_stale_ticks = std::max(1, int(std::lround(igtl->options().stale_after_s / T)));
  device::ServoLoop servo(core, *dev, *clock, device::LimitsFor(dev->spec(), scene.device), config,
                          &ring, &status);
  plan::Judging judging(plan.states, plan.limits, T, scene.tube);
  const bool stdout_terminal = isatty(STDOUT_FILENO) != 0;
  // With --json stdout carries the report alone: the display goes to stderr on a terminal.
  const bool show = o.json ? isatty(STDERR_FILENO) != 0 : true;
  Display display(o.json ? io.err : io.out, o.json ? true : stdout_terminal,
                  std::min(plan.limits.max_force_N, dev->spec().max_force_N));
  device::ScopedStopSignals signals;
  Served served = Serve(servo, ring, status, judging, core.elements(),
                        o.record.empty() ? nullptr : &recording, show ? &display : nullptr);
  const device::ServoStats& stats = served.stats;
  dev->Close();
  if (igtl) {
    const device::OpenIGTLinkCounters c = igtl->counters();
    io.err << "tubeplan live: openigtlink: " << c.poses << " poses received, " << c.wrenches_sent
           << " wrenches sent, " << c.wrenches_skipped << " skipped (socket full)";
    if (const std::string e = igtl->link_error(); !e.empty()) io.err << "; the link failed: " << e;
    io.err << "\n";
  }
  if (!stats.realtime_note.empty())
    io.err << "tubeplan live: note: " << stats.realtime_note << "\n";
  if (stats.dropped > 0)
    io.err << "tubeplan live: error: " << stats.dropped
           << " ticks were not judged or recorded (this thread fell behind the servo)\n";
  if (judging.ticks() == 0) {
    io.err << "tubeplan live: error: the servo stopped before its first tick ("
           << device::ToString(stats.stop) << ")\n";
    return kExitInternal;
  }
  // A fault or a signal ends the run before the trajectory does: what it cut short is not judged,
  // in this report and in evaluate's of the recording.
  const std::string stopped_early = StoppedEarly(stats, served.t_last_s);
  if (!o.record.empty()) {
    std::string& record_error = served.record_error;
    if (served.recorded < 2) record_error = "fewer than two ticks recorded";
    if (!stopped_early.empty()) recording.Append(io::TrajectoryCsvStopped(stopped_early));
    if (record_error.empty()) record_error = recording.Commit();
    if (!record_error.empty()) io.err << o.record << ": error: " << record_error << "\n";
  }

  batch::Evaluated e;
  e.file = o.plan;
  e.plan = plan;
  e.judgement = judging.Finish(stopped_early);
  e.replayed_s = e.judgement.replayed_s;
  if (o.json)
    io.out << LiveReport(e, stats, dev->spec().name, stepped).dump(2) << "\n";
  else
    PrintLiveText(io.out, e, stats, stepped, stdout_terminal,
                  !o.record.empty() && served.record_error.empty() ? o.record : std::string());
  return LiveExitCode(served, config, stopped_early, e.judgement.feasible, io.err);
}

}  // namespace

Command AddLiveCommand(CLI::App& app, Streams streams) {
  auto options = std::make_shared<LiveOptions>();
  CLI::App* sub = app.add_subcommand(
      "live",
      "Verify a plan live with a haptic device: the core at 1 kHz in a servo thread, a display, "
      "and at the end the verdicts as `evaluate` gives them plus the servo's timing.");
  CLI::Option* plan_option = sub->add_option("plan", options->plan, "plan file (.yaml)");
  sub->add_option("--device", options->device,
                  "emulator[:FILE.csv][,fast][,mass=M][,stiffness=K][,damping=D]: a simulated "
                  "PHANToM Premium 1.5/6DOF held by a simulated hand following FILE (default: the "
                  "plan's trajectory); fast: a stepped clock, faster than real time. "
                  "openigtlink://HOST:PORT[,timeout=T][,stale=T][,max_force=F][,max_torque=M]"
                  "[,max_stiffness=K][,damping=D]: a device behind an OpenIGTLink bridge (pose in "
                  "as TRANSFORM, wrench out as SENSOR; limits default to the PHANToM Premium's). "
                  "openhaptics[:NAME]: a PHANToM through the OpenHaptics SDK (only in a build "
                  "with -DTUBEPLAN_OPENHAPTICS=ON)")
      ->capture_default_str();
  CLI::Option* record_option =
      sub->add_option("--record", options->record,
                      "write the hand trajectory to FILE (trajectory CSV), completed by rename");
  sub->add_flag("--json", options->json, "print the report as one JSON document");
  sub->add_option("--duration", options->duration_s,
                  "seconds to run (default: the emulator's trajectory and 0.5 s; other devices "
                  "until Ctrl-C)")
      ->check(CLI::Range(0.001, 86400.0));
  sub->add_flag("--no-realtime", options->no_realtime,
                "do not ask for SCHED_FIFO for the servo thread");
  sub->add_flag("--check-host", options->check_host,
                "no plan, no device: wake at the servo's 1 kHz for --duration (default 10 s) and "
                "report how late this host wakes the thread and what to expect of a live run")
      ->excludes(plan_option)
      ->excludes(record_option)
      ->excludes("--device");
  return {sub, [options, streams] {
            if (options->check_host) return RunHostCheck(*options, streams);
            if (options->plan.empty()) {
              streams.err << "tubeplan live: error: a plan file is needed (or --check-host to "
                             "check this host alone)\n";
              return kExitBadInput;
            }
            return RunLive(*options, streams);
          }};
}

}  // namespace tubeplan::cli
