#include "alvio/eval/alignment.h"

#include <Eigen/SVD>
#include <cmath>

#include "alvio/common/error.h"

namespace alvio {

AlignmentMode parseAlignmentMode(const std::string& name) {
  if (name == "se3") return AlignmentMode::kSE3;
  if (name == "sim3") return AlignmentMode::kSim3;
  if (name == "posyaw") return AlignmentMode::kPosYaw;
  if (name == "none") return AlignmentMode::kNone;
  throw Error("unknown alignment '" + name + "' (expected se3, sim3, posyaw or none)");
}

const char* alignmentModeName(AlignmentMode mode) {
  switch (mode) {
    case AlignmentMode::kSE3:
      return "se3";
    case AlignmentMode::kSim3:
      return "sim3";
    case AlignmentMode::kPosYaw:
      return "posyaw";
    case AlignmentMode::kNone:
      return "none";
  }
  return "?";
}

Similarity3 alignPoints(const Points3& est, const Points3& gt, AlignmentMode mode) {
  if (est.size() != gt.size()) throw Error("alignPoints: point sets differ in size");
  Similarity3 T;
  if (mode == AlignmentMode::kNone) return T;
  const std::size_t n = est.size();
  const std::size_t min_pairs = mode == AlignmentMode::kPosYaw ? 2 : 3;
  if (n < min_pairs)
    throw Error("alignment needs at least " + std::to_string(min_pairs) + " matched poses, got " +
                std::to_string(n));

  Eigen::Vector3d mu_e = Eigen::Vector3d::Zero(), mu_g = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    mu_e += est[i];
    mu_g += gt[i];
  }
  mu_e /= n;
  mu_g /= n;

  if (mode == AlignmentMode::kPosYaw) {
    // Rotation about z only: yaw = atan2(sum of cross_z, sum of dot_xy) of centred points.
    double a = 0, b = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d e = est[i] - mu_e, g = gt[i] - mu_g;
      a += e.x() * g.x() + e.y() * g.y();
      b += e.x() * g.y() - e.y() * g.x();
    }
    T.R = Eigen::AngleAxisd(std::atan2(b, a), Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.t = mu_g - T.R * mu_e;
    return T;
  }

  // Umeyama (1991): cross-covariance, SVD, reflection guard, optional scale.
  Eigen::Matrix3d sigma = Eigen::Matrix3d::Zero();
  double var_e = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d e = est[i] - mu_e, g = gt[i] - mu_g;
    sigma += g * e.transpose();
    var_e += e.squaredNorm();
  }
  sigma /= n;
  var_e /= n;
  if (var_e < 1e-18) throw Error("alignment is degenerate: the estimated positions do not move");
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(sigma, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0) S(2, 2) = -1;
  T.R = svd.matrixU() * S * svd.matrixV().transpose();
  if (mode == AlignmentMode::kSim3) T.s = (svd.singularValues().asDiagonal() * S).trace() / var_e;
  T.t = mu_g - T.s * T.R * mu_e;
  return T;
}

}  // namespace alvio
