#pragma once
// Reprojection factor of a 3D line landmark observed as a 2D segment.
//
// Parameter blocks:
//   [0] body pose T_w_b, 7 doubles [tx, ty, tz, qx, qy, qz, qw] (Eigen quaternion storage
//       order); manifold ProductManifold<EuclideanManifold<3>, EigenQuaternionManifold>.
//   [1] line in the WORLD frame, 4 doubles [theta, phi]; manifold OrthonormalLineManifold.
// The Jacobians written are the ambient ones (2x7 and 2x4), as Ceres expects; it applies
// the manifolds' PlusJacobians itself.
//
// Residual: the line is moved into the camera (T_c_w = (T_w_b T_b_c)^-1), projected to the
// normalised image line l = n_c, and the observed endpoints s, e (undistorted normalised
// coordinates, homogeneous [u, v, 1]) give
//   r = sqrt_info * [s.l, e.l] / sqrt(l1^2 + l2^2),
// their signed distances to l in normalised units, times sqrt_info. With
// sqrt_info = f / sigma_px (f the focal length in pixels, sigma_px the endpoint noise in
// pixels) the residual is in units of sigma (pixels / sigma_px). The robust loss is the
// caller's choice, given to Problem::AddResidualBlock.
//
// With estimateTimeShift() a third block, the camera's time shift td (1 double; see
// PointProjectionFactor): each endpoint is moved back by td times its image velocity.

#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace alvio {

class LineProjectionFactor final : public ceres::CostFunction {
 public:
  /// @param start_norm, end_norm observed endpoints, undistorted normalised coordinates.
  /// @param T_b_c camera pose in the body frame (constant extrinsic).
  /// @param sqrt_info scale of the residual (see the file comment).
  LineProjectionFactor(const Eigen::Vector2d& start_norm, const Eigen::Vector2d& end_norm,
                       const Eigen::Isometry3d& T_b_c, double sqrt_info = 1.0);
  /// Adds the time shift block: the endpoints' velocities, normalised units per second.
  void estimateTimeShift(const Eigen::Vector2d& start_velocity,
                         const Eigen::Vector2d& end_velocity);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

  /// The residual at a pose block and a line block (and the time shift, when estimated; no
  /// Jacobians); false if the line projects to a point (it passes through the camera centre).
  bool residual(const double* pose, const double* line, Eigen::Vector2d* r,
                double time_shift = 0.0) const;

  const Eigen::Vector2d& startNorm() const { return start_; }
  const Eigen::Vector2d& endNorm() const { return end_; }
  double sqrtInfo() const { return sqrt_info_; }

 private:
  Eigen::Vector2d start_, end_;
  Eigen::Vector2d start_velocity_ = Eigen::Vector2d::Zero(),
                  end_velocity_ = Eigen::Vector2d::Zero();
  Eigen::Matrix3d R_c_b_;
  Eigen::Vector3d t_b_c_;
  double sqrt_info_;
};

/// Pack a pose into the 7-double block [t, q(xyzw)].
void poseToParameters(const Eigen::Isometry3d& T, double* x);
Eigen::Isometry3d poseFromParameters(const double* x);

}  // namespace alvio
