#pragma once
// A live run as people and programs read it (docs/live.md): the display drawn while it runs, the
// report at its end (evaluate's, with the servo's figures), and the host check's.
#include <ostream>
#include <string>

#include <nlohmann/json.hpp>

#include <tubeplan/device/host_check.hpp>
#include <tubeplan/device/servo.hpp>
#include <tubeplan/live/live_run.hpp>
#include <tubeplan/plan/judge.hpp>

namespace tubeplan::report {

/// The display: one block redrawn in place on a terminal, plain lines otherwise.
class LiveDisplay {
 public:
  LiveDisplay(std::ostream& out, bool terminal) : out_(out), terminal_(terminal) {}
  /// Draws the block (on a terminal), or prints it when `force_line` (otherwise).
  void Draw(const plan::Judging& judging, const device::ServoStatus& s, double max_force_N,
            bool force_line);

 private:
  std::ostream& out_;
  bool terminal_;
  bool drawn_ = false;
};

/// evaluate's report of the run's one plan, with the servo's figures.
nlohmann::json LiveJson(const live::LiveRun& run);

/// The run's verdicts and the servo's figures as text (`colour`: ANSI colours).
void PrintLive(std::ostream& out, const live::LiveRun& run, bool colour);

/// Why a signal or a fault ended the run ("interrupted at t = ...; the force was zeroed; ..."),
/// empty when neither did.
std::string LiveStopMessage(const live::LiveRun& run);

/// The host check's report (`period_s`: the servo's period).
nlohmann::json HostCheckJson(const device::HostLatency& latency, const device::HostVerdict& verdict,
                             const device::ServoConfig& limits, double period_s);
void PrintHostCheck(std::ostream& out, const device::HostLatency& latency,
                    const device::HostVerdict& verdict, const device::ServoConfig& limits,
                    double period_s);

}  // namespace tubeplan::report
