#include "alvio/eval/trajectory_interpolation.h"

#include <algorithm>

namespace alvio {

std::optional<StampedPose> interpolatePose(const Trajectory& trajectory, double t,
                                           double max_gap_s) {
  if (trajectory.empty()) return std::nullopt;
  const auto after = std::lower_bound(trajectory.begin(), trajectory.end(), t,
                                      [](const StampedPose& p, double time) { return p.t < time; });
  if (after == trajectory.end()) return std::nullopt;
  if (after->t == t) return *after;
  if (after == trajectory.begin()) return std::nullopt;
  const StampedPose& a = *(after - 1);
  const StampedPose& b = *after;
  if (b.t - a.t > max_gap_s) return std::nullopt;
  const double s = (t - a.t) / (b.t - a.t);
  StampedPose p;
  p.t = t;
  p.p = (1 - s) * a.p + s * b.p;
  p.q = a.q.slerp(s, b.q).normalized();
  return p;
}

}  // namespace alvio
