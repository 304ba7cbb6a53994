#include "alvio/estimator/point_landmarks.h"

#include <Eigen/SVD>

namespace alvio {

namespace {
constexpr double kDefaultDepth = 5.0;  // metres; for landmarks re-anchored behind the camera
// A DLT depth below this (metres) is degenerate or behind the camera, not a real point.
constexpr double kMinTriangulatedDepth = 0.1;
}  // namespace

bool PointLandmarks::addFrameAndCheckParallax(int frame_index, const FeatureFrame& frame) {
  last_track_num_ = 0;
  for (const auto& o : frame.points) {
    PointSighting s;
    s.xy1 = Eigen::Vector3d(o.xy.x(), o.xy.y(), 1.0);
    s.px = o.px;
    s.velocity = o.velocity;
    auto it = landmarks_.find(o.id);
    // Tracks are continuous; an ID that reappears after a gap starts a new landmark.
    if (it != landmarks_.end() && it->second.endFrame() != frame_index - 1) {
      landmarks_.erase(it);
      it = landmarks_.end();
    }
    if (it == landmarks_.end()) {
      PointLandmark l;
      l.id = o.id;
      l.start_frame = frame_index;
      l.sightings.push_back(s);
      landmarks_.emplace(o.id, std::move(l));
    } else {
      // A new track has no velocity in its first frame: take its second's (the time shift's
      // estimate would otherwise read each anchor as still, and pull toward no shift).
      PointSighting& first = it->second.sightings.front();
      if (it->second.sightings.size() == 1 && first.velocity.isZero()) first.velocity = s.velocity;
      it->second.sightings.push_back(s);
      ++last_track_num_;
    }
  }
  if (frame_index < 2 || last_track_num_ < 20) return true;
  // Mean parallax between the two previous frames of points seen in both.
  double sum = 0;
  int count = 0;
  for (const auto& [id, l] : landmarks_) {
    if (l.start_frame <= frame_index - 2 && l.endFrame() >= frame_index - 1) {
      const Eigen::Vector3d& a = l.sightings[frame_index - 2 - l.start_frame].xy1;
      const Eigen::Vector3d& b = l.sightings[frame_index - 1 - l.start_frame].xy1;
      sum += (a.head<2>() - b.head<2>()).norm();
      ++count;
    }
  }
  return count == 0 || sum / count >= min_parallax_;
}

std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> PointLandmarks::correspondences(
    int a, int b) const {
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> out;
  for (const auto& [id, l] : landmarks_)
    if (l.start_frame <= a && l.endFrame() >= b)
      out.emplace_back(l.sightings[a - l.start_frame].xy1, l.sightings[b - l.start_frame].xy1);
  return out;
}

namespace {

// Projection matrices [R^T | -R^T t] of camera i relative to an anchor camera i0, for every
// pair of window frames a landmark needs: many landmarks share an anchor, so each pair is
// computed once per triangulation pass instead of once per sighting.
class RelativeProjections {
 public:
  RelativeProjections(const std::vector<Eigen::Vector3d>& P, const std::vector<Eigen::Matrix3d>& R,
                      const Eigen::Isometry3d& T_b_c)
      : P_(P),
        R_(R),
        R_b_c_(T_b_c.linear()),
        t_b_c_(T_b_c.translation()),
        n_(P.size()),
        projection_(n_ * n_),
        known_(n_ * n_, false) {}

  const Eigen::Matrix<double, 3, 4>& operator()(int i0, int i) {
    const std::size_t k = static_cast<std::size_t>(i0) * n_ + static_cast<std::size_t>(i);
    if (!known_[k]) {
      const Eigen::Vector3d t0 = P_[i0] + R_[i0] * t_b_c_;
      const Eigen::Matrix3d R0 = R_[i0] * R_b_c_;
      const Eigen::Vector3d t1 = P_[i] + R_[i] * t_b_c_;
      const Eigen::Matrix3d R1 = R_[i] * R_b_c_;
      // Pose of anchor-frame points in camera i: x_i = R^T (x_0 - t).
      const Eigen::Vector3d t = R0.transpose() * (t1 - t0);
      const Eigen::Matrix3d Rr = R0.transpose() * R1;
      projection_[k].leftCols<3>() = Rr.transpose();
      projection_[k].rightCols<1>() = -Rr.transpose() * t;
      known_[k] = true;
    }
    return projection_[k];
  }

 private:
  const std::vector<Eigen::Vector3d>& P_;
  const std::vector<Eigen::Matrix3d>& R_;
  const Eigen::Matrix3d R_b_c_;
  const Eigen::Vector3d t_b_c_;
  const std::size_t n_;
  std::vector<Eigen::Matrix<double, 3, 4>> projection_;
  std::vector<bool> known_;
};

// The two DLT rows of each sighting (a_k^T X = 0 for the point X in the anchor camera):
// row(k, r0, r1) for k over the sightings.
template <class RowPair>
void forEachDltRowPair(const PointLandmark& l, RelativeProjections& projection, RowPair&& row) {
  const int i0 = l.start_frame;
  for (std::size_t k = 0; k < l.sightings.size(); ++k) {
    const Eigen::Matrix<double, 3, 4>& Pm = projection(i0, i0 + static_cast<int>(k));
    const Eigen::Vector3d f = l.sightings[k].xy1.normalized();
    row(k, Eigen::RowVector4d(f[0] * Pm.row(2) - f[2] * Pm.row(0)),
        Eigen::RowVector4d(f[1] * Pm.row(2) - f[2] * Pm.row(1)));
  }
}

// Depth in the anchor camera by linear triangulation (DLT) over all sightings.
double dltDepth(const PointLandmark& l, RelativeProjections& projection) {
  Eigen::MatrixXd A(2 * l.sightings.size(), 4);
  forEachDltRowPair(l, projection,
                    [&](std::size_t k, const Eigen::RowVector4d& r0, const Eigen::RowVector4d& r1) {
                      A.row(2 * k) = r0;
                      A.row(2 * k + 1) = r1;
                    });
  const Eigen::Vector4d X =
      Eigen::JacobiSVD<Eigen::MatrixXd>(A, Eigen::ComputeThinV).matrixV().col(3);
  return X[2] / X[3];
}

// Inverse depth along the anchor ray: with X = (xy1_0, rho) each DLT row r gives
// r.head(3) . xy1_0 + r(3) rho = 0, solved for rho by least squares. The estimator keeps a
// point on that ray anyway, and a 1-D solve is much cheaper than the 4x4 eigenproblem of the
// free DLT; this runs for every left-out point on every frame. The anchor's own rows drop out
// (their r(3) is zero). Returns 0 when the sightings have no baseline.
double inverseDepthOnAnchorRay(const PointLandmark& l, RelativeProjections& projection) {
  const Eigen::Vector3d& xy1 = l.sightings.front().xy1;
  double ab = 0, bb = 0;
  forEachDltRowPair(l, projection,
                    [&](std::size_t, const Eigen::RowVector4d& r0, const Eigen::RowVector4d& r1) {
                      ab += r0.head<3>().dot(xy1) * r0[3] + r1.head<3>().dot(xy1) * r1[3];
                      bb += r0[3] * r0[3] + r1[3] * r1[3];
                    });
  return bb > 0 ? -ab / bb : 0.0;
}

}  // namespace

void PointLandmarks::triangulate(const std::vector<Eigen::Vector3d>& P,
                                 const std::vector<Eigen::Matrix3d>& R,
                                 const Eigen::Isometry3d& T_b_c) {
  RelativeProjections projection(P, R, T_b_c);
  for (auto& [id, l] : landmarks_) {
    if (!l.usable(window_size_) || l.depth > 0) continue;
    const double depth = dltDepth(l, projection);
    l.depth = depth < kMinTriangulatedDepth ? kDefaultDepth : depth;
    l.state = PointLandmark::State::kTriangulated;
  }
}

void PointLandmarks::retriangulate(const std::vector<Eigen::Vector3d>& P,
                                   const std::vector<Eigen::Matrix3d>& R,
                                   const Eigen::Isometry3d& T_b_c,
                                   const std::function<bool(const PointLandmark&)>& which) {
  RelativeProjections projection(P, R, T_b_c);
  for (auto& [id, l] : landmarks_) {
    if (!l.usable(window_size_) || l.depth <= 0 || !which(l)) continue;
    const double inverse_depth = inverseDepthOnAnchorRay(l, projection);
    if (inverse_depth > 0 && 1.0 / inverse_depth >= kMinTriangulatedDepth)
      l.depth = 1.0 / inverse_depth;  // a degenerate solution keeps the last depth
  }
}

int PointLandmarks::usableCount() const {
  int n = 0;
  for (const auto& [id, l] : landmarks_) n += l.usable(window_size_);
  return n;
}

bool PointLandmarks::seenIn(int frame_index) const {
  for (const auto& [id, l] : landmarks_)
    if (l.start_frame <= frame_index && frame_index <= l.endFrame()) return true;
  return false;
}

Eigen::VectorXd PointLandmarks::inverseDepths() const {
  Eigen::VectorXd v(usableCount());
  int k = 0;
  for (const auto& [id, l] : landmarks_)
    if (l.usable(window_size_)) v[k++] = 1.0 / l.depth;
  return v;
}

void PointLandmarks::setInverseDepths(const Eigen::VectorXd& inv) {
  int k = 0;
  for (auto& [id, l] : landmarks_) {
    if (!l.usable(window_size_)) continue;
    l.depth = 1.0 / inv[k++];
    l.state = l.depth < 0 ? PointLandmark::State::kFailed : PointLandmark::State::kTriangulated;
  }
}

void PointLandmarks::clearDepths() {
  for (auto& [id, l] : landmarks_) {
    l.depth = -1;
    l.state = PointLandmark::State::kNew;
  }
}

void PointLandmarks::removeOldestShiftDepth(const Eigen::Matrix3d& R_old,
                                            const Eigen::Vector3d& p_old,
                                            const Eigen::Matrix3d& R_new,
                                            const Eigen::Vector3d& p_new) {
  for (auto it = landmarks_.begin(); it != landmarks_.end();) {
    PointLandmark& l = it->second;
    if (l.start_frame != 0) {
      --l.start_frame;
      ++it;
      continue;
    }
    const Eigen::Vector3d xy1 = l.sightings.front().xy1;
    l.sightings.erase(l.sightings.begin());
    if (l.sightings.size() < 2) {
      it = landmarks_.erase(it);
      continue;
    }
    if (l.depth > 0) {
      const Eigen::Vector3d p_w = R_old * (xy1 * l.depth) + p_old;
      const Eigen::Vector3d p_c = R_new.transpose() * (p_w - p_new);
      l.depth = p_c.z() > 0 ? p_c.z() : kDefaultDepth;
    }
    ++it;
  }
}

void PointLandmarks::removeOldest() {
  for (auto it = landmarks_.begin(); it != landmarks_.end();) {
    PointLandmark& l = it->second;
    if (l.start_frame != 0) {
      --l.start_frame;
    } else {
      l.sightings.erase(l.sightings.begin());
      if (l.sightings.empty()) {
        it = landmarks_.erase(it);
        continue;
      }
    }
    ++it;
  }
}

void PointLandmarks::removeSecondNewest(int frame_index) {
  for (auto it = landmarks_.begin(); it != landmarks_.end();) {
    PointLandmark& l = it->second;
    if (l.start_frame == frame_index) {
      --l.start_frame;  // only seen in the newest frame, which takes the dropped slot
    } else if (l.endFrame() >= frame_index - 1) {
      l.sightings.erase(l.sightings.begin() + (frame_index - 1 - l.start_frame));
      if (l.sightings.empty()) {
        it = landmarks_.erase(it);
        continue;
      }
    }
    ++it;
  }
}

void PointLandmarks::removeFailures() {
  for (auto it = landmarks_.begin(); it != landmarks_.end();)
    it = it->second.state == PointLandmark::State::kFailed ? landmarks_.erase(it) : std::next(it);
}

void PointLandmarks::removeIds(const std::vector<int>& ids) {
  for (int id : ids) landmarks_.erase(id);
}

}  // namespace alvio
