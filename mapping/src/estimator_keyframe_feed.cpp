#include "alvio/mapping/estimator_keyframe_feed.h"
#include "alvio/common/angles.h"

#include <algorithm>
#include <cmath>

namespace alvio {

namespace {
// Largest angle at p between the ray from centres[first] and the rays from centres[k],
// k in (first, last].
double parallaxDeg(const Eigen::Vector3d& p, const std::vector<Eigen::Vector3d>& centres, int first,
                   int last) {
  const Eigen::Vector3d a = (centres.at(first) - p).normalized();
  double max_angle = 0;
  for (int k = first + 1; k <= last && k < static_cast<int>(centres.size()); ++k) {
    const Eigen::Vector3d b = (centres[k] - p).normalized();
    max_angle = std::max(max_angle, std::atan2(a.cross(b).norm(), a.dot(b)));
  }
  return max_angle * kRadToDeg;
}
}  // namespace

KeyframeLandmarks EstimatorKeyframeFeed::keyframe(const Estimator& estimator, int index) const {
  const auto window = estimator.windowStates();
  KeyframeLandmarks kf;
  const BodyState& s = window.at(index);
  kf.t = s.t;
  kf.T_w_c = s.T_w_b() * T_b_c_;
  std::vector<Eigen::Vector3d> centres;
  for (const BodyState& b : window) centres.push_back(b.p + b.q * T_b_c_.translation());
  const auto& landmarks = estimator.points().landmarks();
  for (const auto& [id, p_w] : estimator.landmarkPositions()) {
    auto it = landmarks.find(id);
    if (it == landmarks.end() || it->second.start_frame != index) continue;
    kf.points.push_back({id, p_w, parallaxDeg(p_w, centres, index, it->second.endFrame())});
  }
  return kf;
}

KeyframeLandmarks retiredLinesKeyframe(const BodyState& state, const Eigen::Isometry3d& T_b_c,
                                       const LineSegments3& retired) {
  KeyframeLandmarks kf;
  kf.t = state.t;
  kf.T_w_c = Eigen::Translation3d(state.p) * state.q * T_b_c;
  for (const LineSegment3& l : retired)
    kf.lines.push_back(
        {l.id, l.start, l.end, l.observations, l.direction_std_deg, l.midpoint_std_m});
  return kf;
}

std::optional<KeyframeLandmarks> EstimatorKeyframeFeed::poll(const Estimator& estimator) {
  if (estimator.status() != EstimatorStatus::kTracking) return std::nullopt;
  const auto window = estimator.windowStates();
  if (window.empty() || window.front().t == last_oldest_t_) return std::nullopt;
  last_oldest_t_ = window.front().t;
  return keyframe(estimator, 0);
}

std::vector<KeyframeLandmarks> EstimatorKeyframeFeed::flush(const Estimator& estimator) const {
  std::vector<KeyframeLandmarks> out;
  if (estimator.status() != EstimatorStatus::kTracking) return out;
  const int n = static_cast<int>(estimator.windowStates().size());
  for (int i = 0; i < n; ++i) {
    KeyframeLandmarks kf = keyframe(estimator, i);
    if (!kf.points.empty() || !kf.lines.empty()) out.push_back(std::move(kf));
  }
  return out;
}

}  // namespace alvio
