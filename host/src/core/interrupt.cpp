#include "fvp/host/core/interrupt.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <climits>
#include <cstring>

namespace fvp::host {
namespace {

std::atomic<int> g_signal{0};

// Slots the handler may read at any moment: a path is copied in before `used` is set and
// `used` is cleared before the slot is reused.
constexpr int kSlots = 64;
struct Slot {
  std::atomic<bool> used{false};
  std::atomic<bool> claimed{false};
  char path[PATH_MAX];
};
Slot g_slots[kSlots];

extern "C" void onInterrupt(int sig) {
  int expected = 0;
  if (g_signal.compare_exchange_strong(expected, sig)) return;  // first: stop at the next check
  // Second: remove the temporaries being written and leave now (async-signal-safe calls only).
  for (Slot& s : g_slots)
    if (s.used.load()) ::unlink(s.path);
  ::_exit(128 + g_signal.load());
}

}  // namespace

void installInterruptHandlers() {
  struct sigaction action {};
  action.sa_handler = onInterrupt;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // no SA_RESTART: a blocking read returns and the loop sees the flag
  ::sigaction(SIGINT, &action, nullptr);
  ::sigaction(SIGTERM, &action, nullptr);
}

int interruptSignal() {
  return g_signal.load();
}

void throwIfInterrupted() {
  const int sig = g_signal.load();
  if (sig != 0)
    throw Interrupted(std::string("interrupted by ") + (sig == SIGINT ? "SIGINT" : "SIGTERM"));
}

RegisteredTemporary::RegisteredTemporary(const std::string& path) {
  if (path.size() >= PATH_MAX) return;
  for (int i = 0; i < kSlots; ++i) {
    bool free = false;
    if (!g_slots[i].claimed.compare_exchange_strong(free, true)) continue;
    std::memcpy(g_slots[i].path, path.c_str(), path.size() + 1);
    g_slots[i].used.store(true);
    slot_ = i;
    return;
  }
}

RegisteredTemporary::~RegisteredTemporary() {
  if (slot_ < 0) return;
  g_slots[slot_].used.store(false);
  g_slots[slot_].claimed.store(false);
}

}  // namespace fvp::host
