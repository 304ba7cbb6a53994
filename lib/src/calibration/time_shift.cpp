#include "alvio/calibration/time_shift.h"

#include <ceres/ceres.h>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <sstream>
#include <unordered_map>

#include "alvio/common/error.h"

namespace alvio {
namespace {

constexpr double kMaxPairGapS = 0.2;  // longer: the rotation vector no longer adds up linearly
constexpr std::size_t kMinPairs = 20;
// Beyond this apart, the essential matrix's rotation is the twisted pair, or the fit degenerate.
constexpr double kMaxDisagreementRad = 0.1;

Eigen::Vector3d bearing(const Eigen::Vector2d& xy) {
  return Eigen::Vector3d(xy.x(), xy.y(), 1.0).normalized();
}

// R minimising sum |a_i - R b_i|^2 (Kabsch), over the pairs marked in `use`.
Eigen::Matrix3d alignBearings(const std::vector<Eigen::Vector3d>& a,
                              const std::vector<Eigen::Vector3d>& b, const std::vector<bool>& use) {
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < a.size(); ++i)
    if (use[i]) M += a[i] * b[i].transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

// Sampson distance (normalised units) of a point pair to the epipolar geometry of the second
// camera's pose (R_c1_c0, t): E = [t]x R.
struct SampsonResidual {
  SampsonResidual(const Eigen::Vector2d& xy0, const Eigen::Vector2d& xy1)
      : x0(xy0.x(), xy0.y(), 1.0), x1(xy1.x(), xy1.y(), 1.0) {}
  template <typename T>
  bool operator()(const T* q_c1_c0, const T* t, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_c1_c0);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> tv(t);
    const Eigen::Matrix<T, 3, 1> Ex0 = tv.cross(q * x0.cast<T>());
    const Eigen::Matrix<T, 3, 1> Etx1 = -(q.conjugate() * tv.cross(x1.cast<T>()));
    const T norm = Ex0.x() * Ex0.x() + Ex0.y() * Ex0.y() + Etx1.x() * Etx1.x() +
                   Etx1.y() * Etx1.y() + T(1e-18);
    residual[0] = x1.cast<T>().dot(Ex0) / ceres::sqrt(norm);
    return true;
  }
  Eigen::Vector3d x0, x1;
};

// The pose refined on RANSAC's inliers (`use`) by least squares, with a Huber loss at the inlier
// threshold (the RANSAC model comes from five points and takes the threshold's slack); returns
// R_c1_c0 and marks the pairs then within the threshold.
Eigen::Matrix3d refinePose(const std::vector<cv::Point2d>& xy0, const std::vector<cv::Point2d>& xy1,
                           const Eigen::Matrix3d& R_c1_c0, const Eigen::Vector3d& t,
                           double threshold, std::vector<bool>* use) {
  Eigen::Quaterniond q(R_c1_c0);
  Eigen::Vector3d tv = t.normalized();
  ceres::Problem problem;
  for (std::size_t i = 0; i < xy0.size(); ++i)
    if ((*use)[i])
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<SampsonResidual, 1, 4, 3>(new SampsonResidual(
              Eigen::Vector2d(xy0[i].x, xy0[i].y), Eigen::Vector2d(xy1[i].x, xy1[i].y))),
          new ceres::HuberLoss(threshold), q.coeffs().data(), tv.data());
  problem.SetManifold(q.coeffs().data(), new ceres::EigenQuaternionManifold);
  problem.SetManifold(tv.data(), new ceres::SphereManifold<3>);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 20;
  options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  for (std::size_t i = 0; i < xy0.size(); ++i) {
    double r = 0;
    SampsonResidual(Eigen::Vector2d(xy0[i].x, xy0[i].y), Eigen::Vector2d(xy1[i].x, xy1[i].y))(
        q.coeffs().data(), tv.data(), &r);
    (*use)[i] = std::abs(r) <= threshold;
  }
  return q.normalized().toRotationMatrix();
}

Eigen::Vector3d rotationVector(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

// The gyroscope's integral from its first sample, at any time inside its span: the rate
// linear between samples.
class GyroIntegral {
 public:
  explicit GyroIntegral(const std::vector<ImuSample>& imu) : imu_(imu) {
    cumulative_.assign(imu.size(), Eigen::Vector3d::Zero());
    for (std::size_t i = 1; i < imu.size(); ++i)
      cumulative_[i] = cumulative_[i - 1] + 0.5 * (imu[i - 1].gyr + imu[i].gyr) * seconds(i - 1, i);
  }
  double first() const { return relative(imu_.front().t_ns); }
  double last() const { return relative(imu_.back().t_ns); }
  /// Seconds since the first sample.
  double relative(int64_t t_ns) const {
    return static_cast<double>(t_ns - imu_.front().t_ns) * 1e-9;
  }
  Eigen::Vector3d at(double t) const {
    std::size_t i = static_cast<std::size_t>(
        std::upper_bound(imu_.begin(), imu_.end(), t,
                         [&](double v, const ImuSample& s) { return v < relative(s.t_ns); }) -
        imu_.begin());
    i = std::clamp<std::size_t>(i, 1, imu_.size() - 1) - 1;
    const double h = seconds(i, i + 1), tau = t - relative(imu_[i].t_ns);
    const Eigen::Vector3d slope = (imu_[i + 1].gyr - imu_[i].gyr) / h;
    return cumulative_[i] + imu_[i].gyr * tau + 0.5 * slope * tau * tau;
  }

 private:
  double seconds(std::size_t i, std::size_t j) const {
    return static_cast<double>(imu_[j].t_ns - imu_[i].t_ns) * 1e-9;
  }
  const std::vector<ImuSample>& imu_;
  std::vector<Eigen::Vector3d> cumulative_;
};

}  // namespace

std::optional<FrameRotation> rotationBetween(const FeatureFrame& first, const FeatureFrame& second,
                                             int min_points, double inlier_threshold) {
  std::unordered_map<int, const PointObservation*> by_id;
  for (const PointObservation& p : first.points) by_id[p.id] = &p;
  std::vector<cv::Point2d> xy0, xy1;
  std::vector<Eigen::Vector3d> a, b;
  for (const PointObservation& p : second.points) {
    const auto it = by_id.find(p.id);
    if (it == by_id.end()) continue;
    xy0.emplace_back(it->second->xy.x(), it->second->xy.y());
    xy1.emplace_back(p.xy.x(), p.xy.y());
    a.push_back(bearing(it->second->xy));
    b.push_back(bearing(p.xy));
  }
  const std::size_t needed = static_cast<std::size_t>(std::max(min_points, 5));
  if (a.size() < needed) return std::nullopt;
  // The essential matrix, so that the translation's parallax does not pass for rotation; with
  // little translation its rotation stays determined (any translation fits a pure rotation).
  cv::Mat inliers;
  const cv::Mat E = cv::findEssentialMat(xy0, xy1, cv::Mat::eye(3, 3, CV_64F), cv::RANSAC, 0.999,
                                         inlier_threshold, inliers);
  if (E.rows != 3 || E.cols != 3) return std::nullopt;  // several solutions stacked: ambiguous
  std::vector<bool> use(a.size(), false);
  for (std::size_t i = 0; i < a.size(); ++i) use[i] = inliers.at<uchar>(static_cast<int>(i)) != 0;
  // Of its two rotations (the other is twisted by half a turn about the translation), the one
  // nearest the rotation that explains the same points without translation. Not by cheirality:
  // at 20 Hz most points are too far for the baseline to put in front of either camera.
  const Eigen::Matrix3d rotation_only = alignBearings(a, b, use);
  cv::Mat R1, R2, t_cv;
  cv::decomposeEssentialMat(E, R1, R2, t_cv);
  Eigen::Matrix3d R1_c1_c0, R2_c1_c0;
  cv::cv2eigen(R1, R1_c1_c0);
  cv::cv2eigen(R2, R2_c1_c0);
  // OpenCV's R takes the first camera's points into the second's: R_c1_c0.
  const auto offBy = [&](const Eigen::Matrix3d& R_c1_c0) {
    return Eigen::AngleAxisd(rotation_only.transpose() * R_c1_c0.transpose()).angle();
  };
  Eigen::Matrix3d R_c1_c0 = offBy(R2_c1_c0) < offBy(R1_c1_c0) ? R2_c1_c0 : R1_c1_c0;
  const Eigen::Vector3d t(t_cv.at<double>(0), t_cv.at<double>(1), t_cv.at<double>(2));
  R_c1_c0 = refinePose(xy0, xy1, R_c1_c0, t, inlier_threshold, &use);
  const int kept = static_cast<int>(std::count(use.begin(), use.end(), true));
  if (kept < static_cast<int>(needed) || offBy(R_c1_c0) > kMaxDisagreementRad) return std::nullopt;
  const Eigen::Matrix3d R_c0_c1 = R_c1_c0.transpose();
  FrameRotation r;
  r.t0_ns = first.t_ns;
  r.t1_ns = second.t_ns;
  r.rotation = rotationVector(R_c0_c1);
  r.points = kept;
  return r;
}

TimeShiftEstimate estimateTimeShift(const std::vector<FrameRotation>& rotations,
                                    const std::vector<ImuSample>& imu, const Eigen::Matrix3d& R_b_c,
                                    const TimeShiftOptions& options) {
  if (!(options.max_shift_s > 0 && options.max_shift_s <= 1.0))
    throw Error("time shift: the search must reach a shift in (0, 1] s, got " +
                std::to_string(options.max_shift_s));
  if (!(options.step_s > 0 && options.step_s <= options.max_shift_s / 2))
    throw Error("time shift: the step must be in (0, max shift / 2], got " +
                std::to_string(options.step_s));
  if (imu.size() < 2) throw Error("time shift: fewer than 2 IMU samples");
  const GyroIntegral gyro(imu);
  const Eigen::Matrix3d R_c_b = R_b_c.transpose();

  // Only the pairs inside the IMU's span at every trial: each trial is scored on the same data.
  std::vector<const FrameRotation*> pairs;
  double sum_sq_rate = 0;
  for (const FrameRotation& r : rotations) {
    const double t0 = gyro.relative(r.t0_ns), t1 = gyro.relative(r.t1_ns);
    if (!(t1 > t0) || t1 - t0 > kMaxPairGapS) continue;
    if (t0 - options.max_shift_s < gyro.first() || t1 + options.max_shift_s > gyro.last()) continue;
    pairs.push_back(&r);
    sum_sq_rate += r.rotation.squaredNorm() / ((t1 - t0) * (t1 - t0));
  }
  if (pairs.size() < kMinPairs) {
    std::ostringstream os;
    os << "time shift: " << pairs.size() << " image pairs lie inside the IMU's span at every "
       << "shift up to " << options.max_shift_s << " s, " << kMinPairs << " needed";
    throw Error(os.str());
  }

  TimeShiftEstimate e;
  e.pairs = pairs.size();
  e.rms_rate_rps = std::sqrt(sum_sq_rate / static_cast<double>(pairs.size()));
  const int steps = static_cast<int>(std::floor(options.max_shift_s / options.step_s));
  std::vector<Eigen::Vector3d> mean_residual;
  for (int k = -steps; k <= steps; ++k) {
    const double shift = k * options.step_s;
    std::vector<Eigen::Vector3d> residuals;
    residuals.reserve(pairs.size());
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const FrameRotation* r : pairs) {
      const double t0 = gyro.relative(r->t0_ns) + shift, t1 = gyro.relative(r->t1_ns) + shift;
      const Eigen::Vector3d gyro_rotation = R_c_b * (gyro.at(t1) - gyro.at(t0));
      residuals.push_back((gyro_rotation - r->rotation) / (t1 - t0));
      mean += residuals.back();
    }
    mean /= static_cast<double>(pairs.size());
    double cost = 0;
    for (const Eigen::Vector3d& v : residuals) cost += (v - mean).squaredNorm();
    e.trial_shift_s.push_back(shift);
    e.cost.push_back(cost / static_cast<double>(pairs.size()));
    mean_residual.push_back(mean);
  }
  const std::size_t best =
      static_cast<std::size_t>(std::min_element(e.cost.begin(), e.cost.end()) - e.cost.begin());
  e.shift_s = e.trial_shift_s[best];
  e.gyro_bias_rps = mean_residual[best];
  e.at_search_edge = best == 0 || best + 1 == e.cost.size();
  if (!e.at_search_edge) {
    // The parabola through the best trial and its neighbours.
    const double c0 = e.cost[best - 1], c1 = e.cost[best], c2 = e.cost[best + 1];
    const double curvature = c0 - 2 * c1 + c2;
    if (curvature > 0) e.shift_s += 0.5 * (c0 - c2) / curvature * options.step_s;
  }
  return e;
}

}  // namespace alvio
