// libFuzzer target: the EuRoC CSV readers (cam0, imu0, ground truth), with both time
// order policies. Any input must either parse or throw alvio::Error; what parses must
// be finite and in time order.
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "alvio/common/error.h"
#include "alvio/common/logging.h"
#include "alvio/io/euroc_dataset.h"
#include "fuzz_input_file.h"

using namespace alvio;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  static fuzz::InputFile file;
  static const bool quiet = [] {
    setLogSink([](LogLevel, const std::string&) {});  // sort/dedup warnings
    return true;
  }();
  (void)quiet;
  if (size == 0) return 0;
  // The first byte picks the reader and the policy; the rest is the file.
  const uint8_t selector = data[0];
  const std::string path = file.write(data + 1, size - 1);
  const TimeOrderPolicy policy =
      (selector & 4) ? TimeOrderPolicy::kSortAndDedup : TimeOrderPolicy::kStrict;
  try {
    switch (selector & 3) {
      case 0: {
        int64_t last = INT64_MIN;
        for (const auto& r : readEurocImageCsv(path, "/images", policy)) {
          if (r.t_ns <= last || r.path.empty()) std::abort();
          last = r.t_ns;
        }
        break;
      }
      case 1: {
        int64_t last = INT64_MIN;
        for (const auto& s : readEurocImuCsv(path, policy)) {
          if (s.t_ns <= last || !s.acc.allFinite() || !s.gyr.allFinite()) std::abort();
          last = s.t_ns;
        }
        break;
      }
      default: {
        int64_t last = INT64_MIN;
        for (const auto& s : readEurocGroundTruthCsv(path, policy)) {
          if (s.t_ns <= last || !s.p.allFinite() || std::abs(s.q.norm() - 1.0) > 1e-9) std::abort();
          last = s.t_ns;
        }
        break;
      }
    }
  } catch (const Error&) {
  }
  return 0;
}
