#include "alvio/estimator/factors/point_projection_factor.h"

#include "alvio/common/rotation.h"
#include "alvio/estimator/pose_manifold.h"

namespace alvio {

PointProjectionFactor::PointProjectionFactor(const Eigen::Vector2d& obs_i,
                                             const Eigen::Vector2d& obs_j,
                                             const Eigen::Isometry3d& T_b_c, double sqrt_info)
    : pts_i_(obs_i.x(), obs_i.y(), 1.0),
      pts_j_(obs_j.x(), obs_j.y(), 1.0),
      R_b_c_(T_b_c.linear()),
      t_b_c_(T_b_c.translation()),
      sqrt_info_(sqrt_info) {
  set_num_residuals(2);
  *mutable_parameter_block_sizes() = {7, 7, 1};
}

void PointProjectionFactor::estimateTimeShift(const Eigen::Vector2d& velocity_i,
                                              const Eigen::Vector2d& velocity_j) {
  velocity_i_ << velocity_i, 0.0;
  velocity_j_ << velocity_j, 0.0;
  if (parameter_block_sizes().size() == 3) mutable_parameter_block_sizes()->push_back(1);
}

bool PointProjectionFactor::Evaluate(double const* const* parameters, double* residuals,
                                     double** jacobians) const {
  const Eigen::Vector3d Pi = posePosition(parameters[0]);
  const Eigen::Quaterniond Qi = poseRotation(parameters[0]).normalized();
  const Eigen::Vector3d Pj = posePosition(parameters[1]);
  const Eigen::Quaterniond Qj = poseRotation(parameters[1]).normalized();
  const double inv_depth = parameters[2][0];
  const bool with_time_shift = parameter_block_sizes().size() == 4;
  const double td = with_time_shift ? parameters[3][0] : 0.0;
  const Eigen::Vector3d pts_i =
      with_time_shift ? Eigen::Vector3d(pts_i_ - td * velocity_i_) : pts_i_;
  const Eigen::Vector3d pts_j =
      with_time_shift ? Eigen::Vector3d(pts_j_ - td * velocity_j_) : pts_j_;

  // Camera i -> body i -> world -> body j -> camera j.
  const Eigen::Vector3d p_ci = pts_i / inv_depth;
  const Eigen::Vector3d p_bi = R_b_c_ * p_ci + t_b_c_;
  const Eigen::Vector3d p_w = Qi * p_bi + Pi;
  const Eigen::Vector3d p_bj = Qj.inverse() * (p_w - Pj);
  const Eigen::Vector3d p_cj = R_b_c_.transpose() * (p_bj - t_b_c_);
  const double z = p_cj.z();

  Eigen::Map<Eigen::Vector2d> r(residuals);
  r = sqrt_info_ * (p_cj.head<2>() / z - pts_j.head<2>());
  if (!jacobians) return true;

  const Eigen::Matrix3d Ri = Qi.toRotationMatrix(), Rj = Qj.toRotationMatrix();
  Eigen::Matrix<double, 2, 3> reduce;
  reduce << 1.0 / z, 0, -p_cj.x() / (z * z), 0, 1.0 / z, -p_cj.y() / (z * z);
  reduce *= sqrt_info_;
  // d r / d p_w and d r / d p_bi, shared by the blocks.
  const Eigen::Matrix<double, 2, 3> reduce_c_b = reduce * R_b_c_.transpose();
  const Eigen::Matrix<double, 2, 3> d_p_w = reduce_c_b * Rj.transpose();
  const Eigen::Matrix<double, 2, 3> d_p_bi = d_p_w * Ri;

  if (jacobians[0]) {
    Eigen::Map<Eigen::Matrix<double, 2, 7, Eigen::RowMajor>> J(jacobians[0]);
    J.leftCols<3>() = d_p_w;
    const Eigen::Matrix<double, 2, 3> J_theta = d_p_bi * -skew(p_bi);
    J.rightCols<4>() = rightRotationJacobianToQuaternion<2>(J_theta, Qi, Ri);
  }
  if (jacobians[1]) {
    Eigen::Map<Eigen::Matrix<double, 2, 7, Eigen::RowMajor>> J(jacobians[1]);
    J.leftCols<3>() = -d_p_w;
    const Eigen::Matrix<double, 2, 3> J_theta = reduce_c_b * skew(p_bj);
    J.rightCols<4>() = rightRotationJacobianToQuaternion<2>(J_theta, Qj, Rj);
  }
  if (jacobians[2]) {
    Eigen::Map<Eigen::Vector2d> J(jacobians[2]);
    J = d_p_bi * R_b_c_ * pts_i * (-1.0 / (inv_depth * inv_depth));
  }
  if (with_time_shift && jacobians[3]) {
    Eigen::Map<Eigen::Vector2d> J(jacobians[3]);
    J = d_p_bi * R_b_c_ * velocity_i_ * (-1.0 / inv_depth) + sqrt_info_ * velocity_j_.head<2>();
  }
  return true;
}

}  // namespace alvio
