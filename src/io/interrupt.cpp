#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <pthread.h>
#include <unistd.h>

#include <tubeplan/io/interrupt.hpp>

namespace tubeplan::io {
namespace {

// The handler reads only these: fixed buffers and atomics, never freed, so that it needs no
// lock and no allocation (both unsafe in a signal handler).
constexpr std::size_t kSlots = 32;
constexpr std::size_t kPathBytes = 4096;
std::array<std::array<char, kPathBytes>, kSlots> g_paths{};
std::array<std::atomic<bool>, kSlots> g_in_use{};

// Bit 31: a handler is removing the temporaries and ending the process. The bits below count
// threads between creating a temporary and registering it: the handler leaves the sweep to the
// last of them, so no temporary is created after the sweep.
constexpr unsigned kDying = 1u << 31;
std::atomic<unsigned> g_state{0};

std::atomic<bool> g_interrupted{false};
std::atomic<int> g_defer_depth{0};
std::atomic<bool> g_installed{false};

std::array<char, 512> g_message{};
std::atomic<std::size_t> g_message_bytes{0};

[[noreturn]] void RemoveTemporariesAndExit() {
  for (std::size_t i = 0; i < kSlots; ++i)
    if (g_in_use[i].load()) ::unlink(g_paths[i].data());
  const std::size_t bytes = g_message_bytes.load();
  if (bytes > 0) {
    [[maybe_unused]] const ssize_t written = ::write(STDERR_FILENO, g_message.data(), bytes);
  }
  ::_exit(130);
}

extern "C" void OnInterrupt(int) {
  const int saved_errno = errno;
  // Deferred: the first signal is the command's to act on.
  if (g_defer_depth.load() > 0 && !g_interrupted.exchange(true)) {
    errno = saved_errno;
    return;
  }
  const unsigned before = g_state.fetch_or(kDying);
  if (before & kDying) {
    for (;;) ::pause();  // another thread's handler is ending the process
  }
  if (before != 0) {
    errno = saved_errno;
    return;  // a thread is creating a temporary: it ends the process when it has registered it
  }
  RemoveTemporariesAndExit();
}

// Between creating a temporary and registering it.
class Busy {
 public:
  Busy() {
    if (g_state.fetch_add(1) & kDying) {
      for (;;) ::pause();  // the handler is ending the process
    }
  }
  ~Busy() {
    const unsigned before = g_state.fetch_sub(1);
    if ((before & kDying) && (before & ~kDying) == 1) RemoveTemporariesAndExit();
  }
  Busy(const Busy&) = delete;
  Busy& operator=(const Busy&) = delete;
};

void SetMask(int how, const sigset_t* set, sigset_t* old) { ::pthread_sigmask(how, set, old); }

sigset_t InterruptSignals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  return set;
}

thread_local sigset_t t_deferred_mask;

}  // namespace

void HandleInterrupts() {
  if (g_installed.exchange(true)) return;
  if (g_message_bytes.load() == 0) SetInterruptMessage("tubeplan: interrupted");
  struct sigaction action {};
  action.sa_handler = OnInterrupt;
  action.sa_flags = SA_RESTART;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

void SetInterruptMessage(std::string_view message) {
  // Emptied first: a handler running meanwhile prints nothing rather than half a message.
  g_message_bytes.store(0);
  const std::size_t bytes = std::min(message.size(), g_message.size() - 2);
  std::memcpy(g_message.data(), message.data(), bytes);
  g_message[bytes] = '\n';
  g_message_bytes.store(bytes + 1);
}

bool Interrupted() { return g_interrupted.load(); }

DeferInterrupts::DeferInterrupts() {
  g_interrupted.store(false);
  ++g_defer_depth;
  HandleInterrupts();
  const sigset_t set = InterruptSignals();
  SetMask(SIG_UNBLOCK, &set, &t_deferred_mask);
}

DeferInterrupts::~DeferInterrupts() {
  SetMask(SIG_SETMASK, &t_deferred_mask, nullptr);
  --g_defer_depth;
}

int CreateRegistered(const char* path, int flags, unsigned mode, int& slot) {
  slot = -1;
  const std::size_t length = std::strlen(path);
  const Busy busy;
  const int fd = ::open(path, flags, static_cast<mode_t>(mode));
  if (fd < 0 || length >= kPathBytes) return fd;
  for (std::size_t i = 0; i < kSlots; ++i) {
    bool expected = false;
    if (g_in_use[i].load() || !g_in_use[i].compare_exchange_strong(expected, true)) continue;
    // Marked in use before the path is written: the handler cannot run here (Busy), and a
    // sweep that started earlier is ending the process before this thread got the slot.
    std::memcpy(g_paths[i].data(), path, length + 1);
    slot = static_cast<int>(i);
    break;
  }
  return fd;
}

void ForgetTemporary(int slot) {
  if (slot >= 0 && static_cast<std::size_t>(slot) < kSlots)
    g_in_use[static_cast<std::size_t>(slot)].store(false);
}

}  // namespace tubeplan::io
