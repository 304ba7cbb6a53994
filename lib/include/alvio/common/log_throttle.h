#pragma once
// Keeps a warning that a stream of bad input would repeat for every message (a NaN IMU
// burst, stamps going back) to one line per period of data time, with the number of
// occurrences folded into it. Data time, not wall time, so offline logs are deterministic.

#include <cstddef>
#include <limits>

namespace alvio {

class LogThrottle {
 public:
  explicit LogThrottle(double period_s = 2.0) : period_s_(period_s) {}

  /// Counts one occurrence at data time `t_s`; true when it should be logged now.
  /// `*since_last` receives how many occurrences this line stands for (itself included).
  bool shouldLog(double t_s, std::size_t* since_last) {
    ++total_;
    ++pending_;
    // Time going back (a new run) also logs at once.
    if (t_s >= last_s_ && t_s - last_s_ < period_s_) return false;
    last_s_ = t_s;
    *since_last = pending_;
    pending_ = 0;
    return true;
  }

  std::size_t total() const { return total_; }

 private:
  double period_s_;
  double last_s_ = -std::numeric_limits<double>::infinity();
  std::size_t total_ = 0, pending_ = 0;
};

}  // namespace alvio
