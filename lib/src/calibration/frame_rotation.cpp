#include "alvio/calibration/frame_rotation.h"

#include <ceres/ceres.h>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <unordered_map>

#include "alvio/common/rotation.h"

namespace alvio {
namespace {

// Beyond this apart, the essential matrix's rotation is the twisted pair, or the fit degenerate.
constexpr double kMaxDisagreementRad = 0.1;

Eigen::Vector3d bearing(const cv::Point2d& xy) {
  return Eigen::Vector3d(xy.x, xy.y, 1.0).normalized();
}

// R minimising sum |a_i - R b_i|^2 over the bearings a_i of xy0 and b_i of xy1 (Kabsch), over
// the pairs marked in `use`.
Eigen::Matrix3d alignBearings(const std::vector<cv::Point2d>& xy0,
                              const std::vector<cv::Point2d>& xy1, const std::vector<bool>& use) {
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < xy0.size(); ++i)
    if (use[i]) M += bearing(xy0[i]) * bearing(xy1[i]).transpose();
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

}  // namespace

std::optional<FrameRotation> rotationBetween(const FeatureFrame& first, const FeatureFrame& second,
                                             int min_points, double inlier_threshold) {
  std::unordered_map<int, const PointObservation*> by_id;
  for (const PointObservation& p : first.points) by_id[p.id] = &p;
  std::vector<cv::Point2d> xy0, xy1;
  for (const PointObservation& p : second.points) {
    const auto it = by_id.find(p.id);
    if (it == by_id.end()) continue;
    xy0.emplace_back(it->second->xy.x(), it->second->xy.y());
    xy1.emplace_back(p.xy.x(), p.xy.y());
  }
  const std::size_t needed = static_cast<std::size_t>(std::max(min_points, 5));
  if (xy0.size() < needed) return std::nullopt;
  // The essential matrix, so that the translation's parallax does not pass for rotation; with
  // little translation its rotation stays determined (any translation fits a pure rotation).
  cv::Mat inliers;
  const cv::Mat E = cv::findEssentialMat(xy0, xy1, cv::Mat::eye(3, 3, CV_64F), cv::RANSAC, 0.999,
                                         inlier_threshold, inliers);
  if (E.rows != 3 || E.cols != 3) return std::nullopt;  // several solutions stacked: ambiguous
  std::vector<bool> use(xy0.size(), false);
  for (std::size_t i = 0; i < xy0.size(); ++i) use[i] = inliers.at<uchar>(static_cast<int>(i)) != 0;
  // Of its two rotations (the other is twisted by half a turn about the translation), the one
  // nearest the rotation that explains the same points without translation. Not by cheirality:
  // at 20 Hz most points are too far for the baseline to put in front of either camera.
  const Eigen::Matrix3d rotation_only = alignBearings(xy0, xy1, use);
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
  FrameRotation r;
  r.t0_ns = first.t_ns;
  r.t1_ns = second.t_ns;
  r.rotation = logQuaternion(Eigen::Quaterniond(R_c1_c0.transpose()));  // R_c0_c1
  r.points = kept;
  return r;
}

}  // namespace alvio
