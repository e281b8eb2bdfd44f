// `tubeplan live PLAN --device KIND[:ARGS] [--record FILE] [--json] [--duration S]`: the plan
// verified live with a haptic device (docs/live.md). A servo thread runs the core at the scene's
// step against the device (device::ServoLoop); this thread judges every tick with the same judge
// as `evaluate`, writes the recording and draws the display, from the servo's lock-free
// hand-offs. At the end the verdicts in evaluate's format, plus the servo's timing.
#include <chrono>
#include <cstdio>
#include <iomanip>
#include <memory>
#include <sstream>
#include <thread>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <tubeplan/cli/app.hpp>
#include <tubeplan/device/clock.hpp>
#include <tubeplan/device/emulator.hpp>
#include <tubeplan/device/servo.hpp>
#include <tubeplan/io/plan_file.hpp>
#include <tubeplan/io/text_file.hpp>
#include <tubeplan/io/trajectory_csv.hpp>
#include <tubeplan/plan/judge.hpp>

#include "commands.hpp"
#include "report.hpp"

namespace tubeplan::cli {
namespace {

struct LiveOptions {
  std::string plan;
  std::string device = "emulator";
  std::string record;
  bool json = false;
  double duration_s = 0.0;  // 0: the emulator's trajectory and a settling time
  bool no_realtime = false;
};

// What `--device emulator[:ARG,...]` asks for.
struct EmulatorArgs {
  std::string trajectory;  // empty: the plan's
  bool stepped = false;    // `fast`: stepped clock, as fast as the core runs
  device::HandModel hand;
};

bool ParseDevice(const std::string& text, EmulatorArgs& args, std::string& error) {
  const std::string kind = text.substr(0, text.find(':'));
  if (kind != "emulator") {
    error = "--device \"" + text + "\": unknown device kind \"" + kind +
            "\", expected emulator[:ARGS] (openigtlink:// and openhaptics are not built in this "
            "version, see docs/live.md)";
    return false;
  }
  if (text.size() == kind.size()) return true;
  std::string rest = text.substr(kind.size() + 1);
  std::size_t start = 0;
  while (start <= rest.size()) {
    const std::size_t comma = rest.find(',', start);
    const std::string item =
        rest.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    start = comma == std::string::npos ? rest.size() + 1 : comma + 1;
    if (item.empty()) continue;
    const std::size_t eq = item.find('=');
    if (item == "fast") {
      args.stepped = true;
      continue;
    }
    if (eq == std::string::npos) {
      args.trajectory = item;
      continue;
    }
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    struct Param {
      const char* name;
      io::Dimension dimension;
      double* target;
    };
    const Param params[] = {{"mass", io::dim::kMass, &args.hand.mass_kg},
                            {"stiffness", io::dim::kStiffness, &args.hand.stiffness_N_per_m},
                            {"damping", io::dim::kDamping, &args.hand.damping_Ns_per_m}};
    bool known = key == "trajectory";
    if (known) args.trajectory = value;
    for (const Param& p : params) {
      if (key != p.name) continue;
      known = true;
      const io::QuantityResult q = io::ParseQuantityAs(value, p.dimension);
      if (!q.quantity || !(q.quantity->value_si > 0.0)) {
        error = "--device: " + key + "=\"" + value +
                "\": " + (q.quantity ? "must be greater than zero" : q.error->message);
        return false;
      }
      *p.target = q.quantity->value_si;
    }
    if (!known) {
      error = "--device: unknown emulator argument \"" + key +
              "\", expected FILE.csv, trajectory=FILE, fast, mass=, stiffness= or damping=";
      return false;
    }
  }
  return true;
}

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
    std::ostringstream line;
    line << std::fixed << std::setprecision(2);
    line << "t " << std::setw(6) << s.t_s << " s  CF " << judging.current() << "  next "
         << (at < n ? judging.states()[at + 1] : std::string("(goal reached)")) << "\n";
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

int RunLive(const LiveOptions& o, Streams io) {
  io::PlanLoadResult loaded = io::LoadPlanFile(o.plan);
  io.err << loaded.diagnostics.FormatAll();
  if (!loaded.plan) return kExitBadInput;
  EmulatorArgs args;
  std::string error;
  if (!ParseDevice(o.device, args, error)) {
    io.err << "tubeplan live: error: " << error << "\n";
    return kExitBadInput;
  }
  plan::Trajectory target = *loaded.trajectory;
  if (!args.trajectory.empty()) {
    io::TrajectoryLoadResult t = io::LoadTrajectoryFile(args.trajectory);
    io.err << t.diagnostics.FormatAll();
    if (!t.trajectory) return kExitBadInput;
    target = std::move(*t.trajectory);
  }
  const scene::Scene& scene = *loaded.scene;
  const plan::Plan& plan = *loaded.plan;
  const double T = scene.model.time_step_s;

  std::unique_ptr<device::Clock> clock;
  if (args.stepped)
    clock = std::make_unique<device::SteppedClock>();
  else
    clock = std::make_unique<device::MonotonicClock>();
  device::EmulatorDevice dev(*clock, target, args.hand);
  core::Core core(scene);
  // The coupling must be passive on this device (physics.md): refuse a stiffer one.
  if (core.coupling_stiffness_N_per_m() > dev.spec().max_stiffness_N_per_m) {
    io.err << o.plan << ": error: the scene's coupling stiffness "
           << core.coupling_stiffness_N_per_m() << " N/m is more than " << dev.spec().name
           << " renders stably (" << dev.spec().max_stiffness_N_per_m
           << " N/m), expected a softer device.coupling_stiffness\n";
    return kExitBadInput;
  }
  const double duration_s = o.duration_s > 0.0 ? o.duration_s
                                               // the trajectory, then 0.5 s for the last state
                                               // to settle and count (many dwells)
                                               : dev.target_duration_s() + 0.5;
  const long ticks = std::lround(duration_s / T) + 1;

  io::StreamingTextFile recording;
  if (!o.record.empty()) {
    if (const std::string e = recording.Open(o.record); !e.empty()) {
      io.err << o.record << ": error: " << e << "\n";
      return kExitBadInput;
    }
    recording.Append(
        io::TrajectoryCsvHeader(dev.spec().name + ", tubeplan live " + plan.name, 1.0 / T));
  }
  if (std::string e = dev.Open(); !e.empty()) {
    io.err << "tubeplan live: error: cannot open the device: " << e << "\n";
    return kExitBadInput;
  }
  if (std::string e = dev.Calibrate(); !e.empty()) {
    io.err << "tubeplan live: error: cannot calibrate the device: " << e << "\n";
    return kExitBadInput;
  }

  // A stepped run can outpace this thread: its ring holds the whole run. In real time 16 s of
  // ticks: far more than this thread ever lags.
  device::SpscRing<device::TickRecord> ring(args.stepped ? std::size_t(ticks) + 16 : 16384);
  device::Seqlock<device::ServoStatus> status;
  device::ServoConfig config;
  config.max_ticks = ticks;
  config.realtime = !o.no_realtime && !args.stepped;
  device::ServoLoop servo(core, dev, *clock, device::LimitsFor(dev.spec(), scene.device), config,
                          &ring, &status);
  plan::Judging judging(plan.states, plan.limits, T);
  const std::vector<scene::PartElement>& elements = core.elements();

  const bool stdout_terminal = isatty(STDOUT_FILENO) != 0;
  // With --json stdout carries the report alone: the display goes to stderr on a terminal.
  const bool show = o.json ? isatty(STDERR_FILENO) != 0 : true;
  Display display(o.json ? io.err : io.out, o.json ? true : stdout_terminal,
                  std::min(plan.limits.max_force_N, dev.spec().max_force_N));

  device::ScopedStopSignals signals;
  device::ServoStats stats;
  std::atomic<bool> done{false};
  std::thread servo_thread([&] {
    stats = servo.Run();
    done.store(true, std::memory_order_release);
  });

  std::string row, record_error;
  device::TickRecord record;
  long recorded = 0;
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
      if (!o.record.empty()) {
        row.clear();
        io::AppendTrajectoryCsvRow(row, record.hand);
        recording.Append(row);
        ++recorded;
      }
    }
    return any;
  };
  for (;;) {
    const bool finished = done.load(std::memory_order_acquire);
    const bool any = drain();
    const auto now = Clock::now();
    if (show && now >= next_draw) {
      if (const std::optional<device::ServoStatus> s = status.Load()) {
        // Plain output: a line a second and one whenever a new state counts.
        const bool line = now >= next_line || judging.counted() != last_counted;
        display.Draw(judging, *s, line);
        if (line) next_line = now + std::chrono::seconds(1);
        last_counted = judging.counted();
      }
      next_draw = now + std::chrono::milliseconds(33);  // ~30 Hz
    }
    if (!o.record.empty() && now >= next_flush) {
      if (std::string e = recording.Flush(); !e.empty() && record_error.empty()) record_error = e;
      next_flush = now + std::chrono::milliseconds(100);
    }
    if (finished && !any) break;
    if (!any) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  servo_thread.join();
  drain();
  dev.Close();

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
  if (!o.record.empty()) {
    if (recorded < 2) record_error = "fewer than two ticks recorded";
    if (record_error.empty()) record_error = recording.Commit();
    if (!record_error.empty()) io.err << o.record << ": error: " << record_error << "\n";
  }

  Evaluated e;
  e.file = o.plan;
  e.plan = plan;
  e.judgement = judging.Finish();
  e.replayed_s = e.judgement.replayed_s;
  nlohmann::json report = ToJson({e});
  report["servo"] = {{"ticks", stats.ticks},
                     {"overruns", stats.overruns},
                     {"median_us", stats.median_us},
                     {"p999_us", stats.p999_us},
                     {"max_us", stats.max_us},
                     {"rate_hz", stats.rate_hz},
                     {"max_latency_us", stats.max_latency_us},
                     {"max_jitter_us", stats.max_jitter_us},
                     {"dropped", stats.dropped},
                     {"stop", device::ToString(stats.stop)},
                     {"realtime", stats.realtime_note.empty()},
                     {"device", dev.spec().name},
                     {"clock", args.stepped ? "stepped" : "monotonic"}};
  if (o.json) {
    io.out << report.dump(2) << "\n";
  } else {
    std::ostringstream t;
    PrintVerdicts(t, e, stdout_terminal);
    t << std::fixed << std::setprecision(1) << "servo: " << stats.ticks << " ticks at "
      << stats.rate_hz << " Hz (" << (args.stepped ? "stepped clock" : "real time") << "), "
      << stats.overruns << " overruns; tick median " << stats.median_us << " us, p99.9 "
      << stats.p999_us << " us, worst " << stats.max_us
      << " us; ended: " << device::ToString(stats.stop) << "\n";
    if (!o.record.empty() && record_error.empty()) t << "recording written to " << o.record << "\n";
    io.out << t.str();
  }
  if (device::IsFault(stats.stop)) {
    io.err << "tubeplan live: error: the servo stopped on a fault (" << device::ToString(stats.stop)
           << "); the force was zeroed\n";
    return kExitInternal;
  }
  if (stats.dropped > 0 || !record_error.empty()) return kExitInternal;
  return e.judgement.feasible ? kExitOk : kExitNegative;
}

}  // namespace

Command AddLiveCommand(CLI::App& app, Streams streams) {
  auto options = std::make_shared<LiveOptions>();
  CLI::App* sub = app.add_subcommand(
      "live",
      "Verify a plan live with a haptic device: the core at 1 kHz in a servo thread, a display, "
      "and at the end the verdicts as `evaluate` gives them plus the servo's timing.");
  sub->add_option("plan", options->plan, "plan file (.yaml)")->required();
  sub->add_option("--device", options->device,
                  "emulator[:FILE.csv][,fast][,mass=M][,stiffness=K][,damping=D]: a simulated "
                  "PHANToM Premium 1.5/6DOF held by a simulated hand following FILE (default: the "
                  "plan's trajectory); fast: a stepped clock, faster than real time")
      ->capture_default_str();
  sub->add_option("--record", options->record,
                  "write the hand trajectory to FILE (trajectory CSV), completed by rename");
  sub->add_flag("--json", options->json, "print the report as one JSON document");
  sub->add_option("--duration", options->duration_s,
                  "seconds to run (default: the emulator's trajectory and 0.5 s)")
      ->check(CLI::Range(0.001, 86400.0));
  sub->add_flag("--no-realtime", options->no_realtime,
                "do not ask for SCHED_FIFO for the servo thread");
  return {sub, [options, streams] { return RunLive(*options, streams); }};
}

}  // namespace tubeplan::cli
