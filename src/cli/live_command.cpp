// `tubeplan live PLAN --device KIND[:ARGS] [--record FILE] [--json] [--duration S]`: the plan
// verified live with a haptic device (docs/live.md): live::RunLive serves the device and judges
// every tick; at the end the verdicts in evaluate's format, plus the servo's timing.
#include <cstdlib>
#include <memory>
#include <unistd.h>

#include <tubeplan/device/clock.hpp>
#include <tubeplan/device/host_check.hpp>
#include <tubeplan/live/live_run.hpp>
#include <tubeplan/report/live_report.hpp>

#include "app.hpp"
#include "commands.hpp"

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
  if (o.json)
    io.out << report::HostCheckJson(l, v, limits, period_s).dump(2) << "\n";
  else
    report::PrintHostCheck(io.out, l, v, limits, period_s);
  return kExitOk;
}

int RunLive(const LiveOptions& o, Streams io) {
  const live::LiveRequest request{.plan = o.plan,
                                  .device = o.device,
                                  .record = o.record,
                                  .duration_s = o.duration_s,
                                  .realtime = !o.no_realtime};
  const bool stdout_terminal = isatty(STDOUT_FILENO) != 0;
  // With --json stdout carries the report alone: the display goes to stderr on a terminal.
  const bool show = o.json ? isatty(STDERR_FILENO) != 0 : true;
  report::LiveDisplay display(o.json ? io.err : io.out, o.json ? true : stdout_terminal);
  live::LiveProgress progress;
  if (show)
    progress = [&display](const plan::Judging& judging, const device::ServoStatus& status,
                          double max_force_N,
                          bool line) { display.Draw(judging, status, max_force_N, line); };
  const live::LiveRun run = live::RunLive(request, io.err, progress);
  if (run.end == live::LiveEnd::kBadInput) return kExitBadInput;
  if (run.end == live::LiveEnd::kNoTick) return kExitInternal;
  if (o.json)
    io.out << report::LiveJson(run).dump(2) << "\n";
  else
    report::PrintLive(io.out, run, stdout_terminal);
  // A signal or a fault ended the run: why, after the report.
  io.err << report::LiveStopMessage(run);
  const device::StopReason stop = run.stats.stop;
  if (stop == device::StopReason::kSignal) return kExitInterrupted;
  if (device::IsFault(stop))
    return stop == device::StopReason::kNonFinite ? kExitInternal : kExitDeviceFault;
  if (run.stats.dropped > 0 || !run.record_error.empty()) return kExitInternal;
  return run.evaluated.judgement.feasible ? kExitOk : kExitNegative;
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
