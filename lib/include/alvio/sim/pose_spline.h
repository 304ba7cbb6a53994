#pragma once
// Continuous-time body trajectory T_w_b(t): a uniform cubic B-spline on position
// and a cumulative cubic B-spline on SO(3) (Kim et al. 1995, Lovegrove et al.
// 2013) with the same knots. Both are C2, so velocity, acceleration and angular
// velocity (what an IMU measures) exist everywhere and are exact derivatives.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

namespace alvio::sim {

using Vector3dList = std::vector<Eigen::Vector3d, Eigen::aligned_allocator<Eigen::Vector3d>>;
using QuaternionList =
    std::vector<Eigen::Quaterniond, Eigen::aligned_allocator<Eigen::Quaterniond>>;

/// Everything about the body at one instant. Velocity and acceleration are in the
/// world frame, the angular velocity in the body frame.
struct BodyState {
  double t = 0.0;
  Eigen::Vector3d p_w = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_w_b = Eigen::Quaterniond::Identity();
  Eigen::Vector3d v_w = Eigen::Vector3d::Zero();
  Eigen::Vector3d a_w = Eigen::Vector3d::Zero();
  Eigen::Vector3d omega_b = Eigen::Vector3d::Zero();
  Eigen::Isometry3d T_w_b() const;
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

class PoseSpline {
 public:
  PoseSpline() = default;
  /// Control point j sits at time t0 + (j - 1) * dt; segment i spans
  /// [t0 + i dt, t0 + (i + 1) dt] and uses controls i..i+3. Needs >= 4 controls.
  PoseSpline(double t0, double dt, Vector3dList positions, QuaternionList rotations);

  double startTime() const { return t0_; }
  double endTime() const { return t0_ + dt_ * static_cast<double>(segments()); }
  double knotSpacing() const { return dt_; }
  int segments() const { return static_cast<int>(positions_.size()) - 3; }
  /// With 1 us of slack: absolute (epoch) times in double carry about 0.2 us of rounding.
  bool contains(double t) const { return t >= t0_ - 1e-6 && t <= endTime() + 1e-6; }

  const Vector3dList& positionControls() const { return positions_; }
  const QuaternionList& rotationControls() const { return rotations_; }

  Eigen::Vector3d position(double t) const;
  Eigen::Quaterniond orientation(double t) const;
  Eigen::Isometry3d pose(double t) const;
  /// Pose, velocity, acceleration and body angular velocity. Times outside the
  /// domain are clamped to it (the spline is not extrapolated).
  BodyState state(double t) const;

 private:
  /// Segment index and the fraction u in [0, 1] within it.
  void locate(double t, int* segment, double* u) const;

  double t0_ = 0.0;
  double dt_ = 1.0;
  Vector3dList positions_;
  QuaternionList rotations_;
  std::vector<Eigen::Vector3d, Eigen::aligned_allocator<Eigen::Vector3d>> log_deltas_;
};

/// The cubic B-spline blending weights (not cumulative) and their u-derivatives.
void cubicBSplineWeights(double u, double w[4], double dw[4], double ddw[4]);
/// Cumulative weights B~_1..B~_3 (B~_0 = 1) and their u-derivatives.
void cumulativeBSplineWeights(double u, double w[3], double dw[3]);

}  // namespace alvio::sim
