#pragma once
// SIGINT and SIGTERM while a command writes its outputs (docs/hardening.md): every output goes to
// a temporary file next to it (AtomicFile, StreamingTextFile), registered here while it exists.
// On a signal the handler removes the registered temporaries, says so on stderr and ends the
// process with exit code 130, so an interrupted command leaves its outputs as they were and no
// `NAME.tmp.PID.N` behind. A command that wants to stop on its own (a batch that finishes the
// plans under way) defers the first signal with a DeferInterrupts scope and polls Interrupted().
// Only SIGKILL (which no process can catch) or a power cut leaves temporaries.

#include <string_view>

namespace tubeplan::io {

/// Installs the handler for SIGINT and SIGTERM; later calls do nothing. The tubeplan executable
/// calls it first thing; signals a parent left blocked stay blocked (DeferInterrupts unblocks).
void HandleInterrupts();

/// What the handler prints, with a newline, when it ends the process (at most 511 bytes kept),
/// e.g. "tubeplan simulate: interrupted; ...".
void SetInterruptMessage(std::string_view message);

/// True once a signal arrived inside a DeferInterrupts scope.
bool Interrupted();

/// Within its lifetime the first SIGINT or SIGTERM only sets Interrupted(): the command stops at
/// a point of its choosing and says what it did. A second signal ends the process as outside
/// the scope. Unblocks both signals for the calling thread (a signal sent while a parent kept it
/// blocked is delivered now) and puts the mask back when it ends. Not nested.
class DeferInterrupts {
 public:
  DeferInterrupts();
  ~DeferInterrupts();
  DeferInterrupts(const DeferInterrupts&) = delete;
  DeferInterrupts& operator=(const DeferInterrupts&) = delete;
};

/// The temporaries the handler removes: an index to hand back to ForgetTemporary, or -1 when
/// the path could not be kept (over 4095 bytes, or 32 temporaries at once: then it is not
/// removed on a signal). CreateRegistered opens `path` with open(2)'s `flags` and registers it
/// as one step that a signal cannot split (a temporary created after the handler's sweep would
/// be left behind); returns the descriptor or -1 with errno set.
int CreateRegistered(const char* path, int flags, unsigned mode, int& slot);
void ForgetTemporary(int slot);

}  // namespace tubeplan::io
