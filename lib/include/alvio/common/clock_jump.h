#pragma once
// A stamp far behind the newest one means the source's clock jumped back (a clock reset, a
// bag played again), not a late message: what came before cannot be continued from it.

#include <cstdint>

namespace alvio {

/// Going back by more than this is a clock jump; a smaller step back is a late or reordered
/// message, which is dropped. IMU reordering and camera latency stay far below it.
constexpr int64_t kClockJumpBackNs = 200'000'000;

/// True when `t_ns` lies more than kClockJumpBackNs before `newest_ns` (0: nothing yet).
inline bool clockJumpedBack(int64_t t_ns, int64_t newest_ns) {
  return newest_ns != 0 && t_ns + kClockJumpBackNs < newest_ns;
}

/// True when `t_ns` is not after `newest_ns` (0: nothing yet): a repeated, late or reordered
/// stamp that cannot follow the newest one. Test clockJumpedBack() first.
inline bool staleStamp(int64_t t_ns, int64_t newest_ns) {
  return newest_ns != 0 && t_ns <= newest_ns;
}

}  // namespace alvio
