#pragma once
// A stamp far behind the newest one means the source's clock jumped back (a clock reset, a
// bag played again), not a late message: what came before cannot be continued from it.

#include <algorithm>
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

/// Follows one source's newest stamp (the IMU, the odometry) and tells when its clock jumps back:
/// the nodelets start a new run on it.
class ClockWatch {
 public:
  /// Takes the next stamp. Returns how far the clock jumped back (ns) when it did, else 0. After
  /// a jump the stamp is the newest one: the new clock is followed from there.
  int64_t follow(int64_t t_ns) {
    const int64_t back = clockJumpedBack(t_ns, newest_ns_) ? newest_ns_ - t_ns : 0;
    newest_ns_ = back ? t_ns : std::max(newest_ns_, t_ns);
    if (back) lagging_on_old_clock_ = true;
    return back;
  }

  /// For one stream that lags this source (images and tracked frames behind the IMU): true for
  /// its messages still stamped on the clock before the last jump, which must be dropped. Left
  /// waiting for the new clock's IMU, one would hold back every later message until the new
  /// clock caught up with it. The stream's first message on the new clock ends this.
  bool laggingOnOldClock(int64_t t_ns) {
    if (lagging_on_old_clock_ && aheadByAJump(t_ns)) return true;
    lagging_on_old_clock_ = false;
    return false;
  }

  /// True when `t_ns` lies more than a jump ahead of the newest stamp: a message stamped on the
  /// clock before the last jump, still on its way through a queue. False before any stamp.
  bool aheadByAJump(int64_t t_ns) const {
    return newest_ns_ != 0 && clockJumpedBack(newest_ns_, t_ns);
  }

  /// The newest stamp since the last jump (0: none yet).
  int64_t newest() const { return newest_ns_; }

 private:
  int64_t newest_ns_ = 0;
  bool lagging_on_old_clock_ = false;  // since the last jump, until the lagging stream caught up
};

}  // namespace alvio
