// libFuzzer target: the trajectory reader (TUM, with format detection, which also
// reaches the EuRoC/VINS-Mono CSV branch). Any input must either parse or throw
// alvio::Error; parsed poses must be finite, unit-quaternion and in time order.
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "alvio/common/error.h"
#include "alvio/common/logging.h"
#include "alvio/io/trajectory_io.h"
#include "fuzz_input_file.h"

using namespace alvio;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  static fuzz::InputFile file;
  static const bool quiet = [] {
    setLogSink([](LogLevel, const std::string&) {});
    return true;
  }();
  (void)quiet;
  if (size == 0) return 0;
  const uint8_t selector = data[0];
  const std::string path = file.write(data + 1, size - 1);
  const TrajectoryFormat format = (selector & 1) ? TrajectoryFormat::kTum : TrajectoryFormat::kAuto;
  const TimeOrderPolicy policy =
      (selector & 2) ? TimeOrderPolicy::kSortAndDedup : TimeOrderPolicy::kStrict;
  try {
    const Trajectory t = readTrajectory(path, format, policy);
    double last = -INFINITY;
    for (const auto& p : t) {
      if (!(p.t > last) || !p.p.allFinite() || std::abs(p.q.norm() - 1.0) > 1e-9) std::abort();
      last = p.t;
    }
  } catch (const Error&) {
  }
  return 0;
}
