#include "alvio/mapping/estimator_keyframe_feed.h"

namespace alvio {

KeyframeLandmarks EstimatorKeyframeFeed::keyframe(const Estimator& estimator, int index) const {
  const auto window = estimator.windowStates();
  KeyframeLandmarks kf;
  const BodyState& s = window.at(index);
  kf.t = s.t;
  Eigen::Isometry3d T_w_b = Eigen::Isometry3d::Identity();
  T_w_b.linear() = s.q.toRotationMatrix();
  T_w_b.translation() = s.p;
  kf.T_w_c = T_w_b * T_b_c_;
  const auto& landmarks = estimator.points().landmarks();
  for (const auto& [id, p_w] : estimator.landmarkPositions()) {
    auto it = landmarks.find(id);
    if (it != landmarks.end() && it->second.start_frame == index) kf.points.push_back({id, p_w});
  }
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
