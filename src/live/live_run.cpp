// The live run (docs/live.md): the servo on its thread, the judge, the recording and the display
// on the calling one.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <thread>

#include <tubeplan/device/clock.hpp>
#include <tubeplan/device/device_choice.hpp>
#include <tubeplan/device/emulator.hpp>
#include <tubeplan/device/handoff.hpp>
#include <tubeplan/device/openigtlink.hpp>
#include <tubeplan/io/plan_file.hpp>
#include <tubeplan/io/trajectory_csv.hpp>
#include <tubeplan/live/live_run.hpp>

#include "io/text_file.hpp"

namespace tubeplan::live {
namespace {

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
// and feeds the display, until the servo stops.
Served Serve(device::ServoLoop& servo, device::SpscRing<device::TickRecord>& ring,
             device::Seqlock<device::ServoStatus>& status, plan::Judging& judging,
             const std::vector<scene::PartElement>& elements, io::StreamingTextFile* recording,
             const LiveProgress& progress, double max_force_N) {
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
    if (progress && now >= next_draw) {
      if (const std::optional<device::ServoStatus> st = status.Load()) {
        // Plain output: a line a second and one whenever a new state counts.
        const bool line = now >= next_line || judging.counted() != last_counted;
        progress(judging, *st, max_force_N, line);
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

}  // namespace

LiveRun RunLive(const LiveRequest& o, std::ostream& err, const LiveProgress& progress) {
  LiveRun run;
  io::PlanLoadResult loaded = io::LoadPlanFile(o.plan);
  err << loaded.diagnostics.FormatAll();
  if (!loaded.plan) return run;
  device::DeviceChoice choice;
  std::string error;
  if (!device::ParseDeviceChoice(o.device, choice, error)) {
    err << "tubeplan live: error: " << error << "\n";
    return run;
  }
  const device::EmulatorArgs& args = choice.emulator;
  const bool emulated = choice.kind == device::DeviceChoice::Kind::kEmulator;
  const bool stepped = emulated && args.stepped;
  const std::filesystem::path plan_directory = std::filesystem::path(o.plan).parent_path();
  if (const std::string problem = io::CheckOutputsApart(
          {{"--record", o.record}},
          {{"the plan", o.plan},
           {"the plan's scene", plan_directory / loaded.plan->scene},
           {"the plan's trajectory", plan_directory / loaded.plan->trajectory},
           {"the emulator's trajectory", emulated ? args.trajectory : std::string()}});
      !problem.empty()) {
    err << "tubeplan live: error: " << problem << "\n";
    return run;
  }
  trajectories::Trajectory target = *loaded.trajectory;
  if (emulated && !args.trajectory.empty()) {
    io::TrajectoryLoadResult t = io::LoadTrajectoryFile(args.trajectory);
    err << t.diagnostics.FormatAll();
    if (!t.trajectory) return run;
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
    err << "tubeplan live: error: --device \"" << o.device << "\": " << error << "\n";
    return run;
  }
  auto* emulator = emulated ? static_cast<device::EmulatorDevice*>(dev.get()) : nullptr;
  auto* igtl = choice.kind == device::DeviceChoice::Kind::kOpenIGTLink
                   ? static_cast<device::OpenIGTLinkDevice*>(dev.get())
                   : nullptr;
  core::Core core(scene);
  // A device that reports its limits at Open (openhaptics) is checked after it.
  const bool limits_at_open = choice.kind == device::DeviceChoice::Kind::kOpenHaptics;
  if (!limits_at_open && !CouplingFits(core, *dev, o.plan, err)) return run;
  // The emulator's trajectory, then 0.5 s for the last state to settle and count (many
  // dwells); a real device runs until --duration or Ctrl-C.
  const double duration_s = o.duration_s > 0.0 ? o.duration_s
                            : emulator         ? emulator->target_duration_s() + 0.5
                                               : 0.0;
  const long ticks = duration_s > 0.0 ? std::lround(duration_s / T) + 1 : 0;
  if (std::string e = dev->Open(); !e.empty()) {
    err << "tubeplan live: error: cannot open the device: " << e << "\n";
    return run;
  }
  if (std::string e = dev->Calibrate(); !e.empty()) {
    err << "tubeplan live: error: cannot calibrate the device: " << e << "\n";
    return run;
  }
  if (limits_at_open && !CouplingFits(core, *dev, o.plan, err)) return run;
  io::StreamingTextFile recording;
  if (!o.record.empty()) {
    if (const std::string e = recording.Open(o.record); !e.empty()) {
      err << o.record << ": error: " << e << "\n";
      return run;
    }
    recording.Append(io::TrajectoryCsvHeader(dev->spec().name + ", tubeplan live " + plan.name,
                                             1.0 / T, {"stall_ms"}));
  }

  // A stepped run can outpace this thread: its ring holds the whole run. In real time 16 s of
  // ticks: far more than this thread ever lags.
  device::SpscRing<device::TickRecord> ring(stepped ? std::size_t(ticks) + 16 : 16384);
  device::Seqlock<device::ServoStatus> status;
  device::ServoConfig& config = run.config;
  config.max_ticks = ticks;
  config.realtime = o.realtime && !stepped;
  // A bridge's poses come over a network, at about the servo's rate but with jitter: stale
  // after its window (docs/live.md), not after one tick.
  if (igtl)
    config.max_stale_ticks = std::max(1, int(std::lround(igtl->options().stale_after_s / T)));
  device::ServoLoop servo(core, *dev, *clock, device::LimitsFor(dev->spec(), scene.device), config,
                          &ring, &status);
  plan::Judging judging(plan.states, plan.limits, T, scene.tube);
  device::ScopedStopSignals signals;
  Served served =
      Serve(servo, ring, status, judging, core.elements(), o.record.empty() ? nullptr : &recording,
            progress, std::min(plan.limits.max_force_N, dev->spec().max_force_N));
  const device::ServoStats& stats = served.stats;
  dev->Close();
  if (igtl) {
    const device::OpenIGTLinkCounters c = igtl->counters();
    err << "tubeplan live: openigtlink: " << c.poses << " poses received, " << c.wrenches_sent
        << " wrenches sent, " << c.wrenches_skipped << " skipped (socket full)";
    if (const std::string e = igtl->link_error(); !e.empty()) err << "; the link failed: " << e;
    err << "\n";
  }
  if (!stats.realtime_note.empty()) err << "tubeplan live: note: " << stats.realtime_note << "\n";
  if (stats.dropped > 0)
    err << "tubeplan live: error: " << stats.dropped
        << " ticks were not judged or recorded (this thread fell behind the servo)\n";
  run.stats = stats;
  run.device_name = dev->spec().name;
  run.stepped = stepped;
  if (judging.ticks() == 0) {
    err << "tubeplan live: error: the servo stopped before its first tick ("
        << device::ToString(stats.stop) << ")\n";
    run.end = LiveEnd::kNoTick;
    return run;
  }
  // A fault or a signal ends the run before the trajectory does: what it cut short is not judged,
  // in this report and in evaluate's of the recording.
  run.stopped_early = StoppedEarly(stats, served.t_last_s);
  if (!o.record.empty()) {
    std::string& record_error = served.record_error;
    if (served.recorded < 2) record_error = "fewer than two ticks recorded";
    if (!run.stopped_early.empty()) recording.Append(io::TrajectoryCsvStopped(run.stopped_early));
    if (record_error.empty()) record_error = recording.Commit();
    if (!record_error.empty()) err << o.record << ": error: " << record_error << "\n";
  }
  run.record_error = served.record_error;
  if (!o.record.empty() && run.record_error.empty()) run.recording = o.record;

  batch::Evaluated& e = run.evaluated;
  e.file = o.plan;
  e.plan = plan;
  e.judgement = judging.Finish(run.stopped_early);
  e.replayed_s = e.judgement.replayed_s;
  run.end = LiveEnd::kRan;
  return run;
}

}  // namespace tubeplan::live
