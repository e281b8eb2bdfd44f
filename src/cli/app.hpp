#pragma once
// Private to the cli library (main.cpp and the tests): the tubeplan command line. Exit codes
// (documented in README): 0 success, 1 the job ran and found a negative answer (e.g. an infeasible
// plan), 2 bad input or bad usage, 3 internal error, 130 interrupted (SIGINT or SIGTERM; 128 +
// SIGINT as shells report it) with nothing written.

#include <ostream>
#include <span>
#include <string>

namespace tubeplan::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitNegative = 1;
inline constexpr int kExitBadInput = 2;
inline constexpr int kExitInternal = 3;
/// A live run ended on a persistent fault of the device or the host (stalls too long or too
/// frequent, stale device data, a device error); the message names it.
inline constexpr int kExitDeviceFault = 4;
inline constexpr int kExitInterrupted = 130;

/// Runs the command with `args` (without the program name); output to `out`, logs to `err`.
int Run(std::span<const std::string> args, std::ostream& out, std::ostream& err);

}  // namespace tubeplan::cli
