#include "alvio/frontend/gyro_rotation.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <iterator>

#include "alvio/common/rotation.h"

namespace alvio {

void GyroRotation::add(const ImuSample& sample) {
  // A NaN rate would turn every predicted corner into NaN and end all tracks at once; the
  // estimator drops such samples too, and the rate between neighbours is interpolated.
  if (!sample.gyr.allFinite()) return;
  if (!samples_.empty() && sample.t_ns <= samples_.back().t_ns) return;
  samples_.push_back({sample.t_ns, sample.gyr});
}

std::optional<Eigen::Matrix3d> GyroRotation::cameraRotation(int64_t t0_ns, int64_t t1_ns) const {
  if (t1_ns < t0_ns || samples_.empty() || samples_.front().t_ns > t0_ns ||
      samples_.back().t_ns < t1_ns)
    return std::nullopt;
  auto rateAt = [](const Rate& a, const Rate& b, int64_t t) -> Eigen::Vector3d {
    const double s = static_cast<double>(t - a.t_ns) / static_cast<double>(b.t_ns - a.t_ns);
    return (1.0 - s) * a.w + s * b.w;
  };
  Eigen::Quaterniond q_b0_b1 = Eigen::Quaterniond::Identity();
  // From the last sample at or before t0 (a caller may keep a whole recording) to t1.
  const auto first = std::partition_point(samples_.begin(), samples_.end(),
                                          [&](const Rate& r) { return r.t_ns <= t0_ns; });
  for (auto it = std::prev(first); std::next(it) != samples_.end() && it->t_ns < t1_ns; ++it) {
    const Rate& a = *it;
    const Rate& b = *std::next(it);
    const int64_t from = std::max(a.t_ns, t0_ns), to = std::min(b.t_ns, t1_ns);
    if (to <= from) continue;
    const Eigen::Vector3d w = 0.5 * (rateAt(a, b, from) + rateAt(a, b, to));
    q_b0_b1 = q_b0_b1 * expQuaternion(w * ((to - from) * 1e-9));
  }
  const Eigen::Matrix3d R_c0_c1 = R_b_c_.transpose() * q_b0_b1.toRotationMatrix() * R_b_c_;
  return Eigen::Matrix3d(R_c0_c1.transpose());
}

void GyroRotation::dropBefore(int64_t t_ns) {
  while (samples_.size() >= 2 && samples_[1].t_ns <= t_ns) samples_.pop_front();
}

}  // namespace alvio
