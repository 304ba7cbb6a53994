#include "alvio/common/stop_signal.h"

#include <signal.h>

namespace alvio {
namespace {

std::atomic<bool> g_stop{false};
// Lock-free atomics are async-signal-safe; check rather than assume.
static_assert(std::atomic<bool>::is_always_lock_free);
static_assert(std::atomic<int>::is_always_lock_free);
std::atomic<int> g_signal{0};

void onStopSignal(int signo) {
  g_signal.store(signo);
  g_stop.store(true);
}

}  // namespace

const std::atomic<bool>& installStopSignalHandlers() {
  struct sigaction sa {};
  sa.sa_handler = onStopSignal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESETHAND | SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  return g_stop;
}

int stopSignalNumber() {
  return g_signal.load();
}

}  // namespace alvio
