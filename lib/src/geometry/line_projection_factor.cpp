#include "alvio/geometry/line_projection_factor.h"

#include <cmath>

#include "alvio/geometry/orthonormal_line.h"
#include "alvio/geometry/so3_utils.h"

namespace alvio {
namespace {
// Below this |(l1, l2)| the line projects to (almost) a point and has no direction.
constexpr double kMinImageLineNorm = 1e-12;
}  // namespace

void poseToParameters(const Eigen::Isometry3d& T, double* x) {
  Eigen::Map<Eigen::Vector3d> t(x);
  Eigen::Map<Eigen::Quaterniond> q(x + 3);
  t = T.translation();
  q = Eigen::Quaterniond(T.linear()).normalized();
}

Eigen::Isometry3d poseFromParameters(const double* x) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Map<const Eigen::Quaterniond>(x + 3).normalized().toRotationMatrix();
  T.translation() = Eigen::Map<const Eigen::Vector3d>(x);
  return T;
}

LineProjectionFactor::LineProjectionFactor(const Eigen::Vector2d& start_norm,
                                           const Eigen::Vector2d& end_norm,
                                           const Eigen::Isometry3d& T_b_c, double sqrt_info)
    : start_(start_norm),
      end_(end_norm),
      R_c_b_(T_b_c.linear().transpose()),
      t_b_c_(T_b_c.translation()),
      sqrt_info_(sqrt_info) {
  set_num_residuals(2);
  *mutable_parameter_block_sizes() = {7, 4};
}

void LineProjectionFactor::estimateTimeShift(const Eigen::Vector2d& start_velocity,
                                             const Eigen::Vector2d& end_velocity) {
  start_velocity_ = start_velocity;
  end_velocity_ = end_velocity;
  if (parameter_block_sizes().size() == 2) mutable_parameter_block_sizes()->push_back(1);
}

bool LineProjectionFactor::residual(const double* pose, const double* line, Eigen::Vector2d* r,
                                    double time_shift) const {
  double residuals[2];
  const double* params[3] = {pose, line, &time_shift};
  if (!Evaluate(params, residuals, nullptr)) return false;
  *r = Eigen::Vector2d(residuals[0], residuals[1]);
  return true;
}

bool LineProjectionFactor::Evaluate(double const* const* parameters, double* residuals,
                                    double** jacobians) const {
  const Eigen::Map<const Eigen::Vector3d> t_w_b(parameters[0]);
  const Eigen::Map<const Eigen::Quaterniond> q_w_b(parameters[0] + 3);
  const double* x_line = parameters[1];
  // Not normalised: the ambient Jacobian below is of exactly this formula.
  const Eigen::Matrix3d R_w_b = q_w_b.toRotationMatrix();

  const OrthonormalLine ortho_w = OrthonormalLine::fromParameters(x_line);
  const PluckerLine L_w = ortho_w.toPlucker();
  // World -> body: moment about the body origin, then rotate. Body -> camera likewise.
  const Eigen::Vector3d m_w = L_w.n - t_w_b.cross(L_w.d);
  const Eigen::Vector3d n_b = R_w_b.transpose() * m_w;
  const Eigen::Vector3d d_b = R_w_b.transpose() * L_w.d;
  // l = n_c = A n_b + B d_b
  const Eigen::Matrix3d& A = R_c_b_;
  const Eigen::Matrix3d B = -R_c_b_ * skew(t_b_c_);
  const Eigen::Vector3d l = A * n_b + B * d_b;

  const double norm2 = l.x() * l.x() + l.y() * l.y();
  const double norm = std::sqrt(norm2);
  if (!(norm > kMinImageLineNorm)) return false;
  const bool with_time_shift = parameter_block_sizes().size() == 3;
  const double td = with_time_shift ? parameters[2][0] : 0.0;
  const Eigen::Vector2d start =
      with_time_shift ? Eigen::Vector2d(start_ - td * start_velocity_) : start_;
  const Eigen::Vector2d end = with_time_shift ? Eigen::Vector2d(end_ - td * end_velocity_) : end_;
  const Eigen::Vector3d s(start.x(), start.y(), 1.0);
  const Eigen::Vector3d e(end.x(), end.y(), 1.0);
  const double s_l = s.dot(l), e_l = e.dot(l);
  residuals[0] = sqrt_info_ * s_l / norm;
  residuals[1] = sqrt_info_ * e_l / norm;
  if (!jacobians) return true;

  // dr/dl: d(p.l / |l_12|)/dl = p^T / |l_12| - (p.l) / |l_12|^3 [l1, l2, 0].
  Eigen::Matrix<double, 2, 3> dr_dl;
  const Eigen::RowVector3d l12(l.x(), l.y(), 0.0);
  dr_dl.row(0) = s.transpose() / norm - s_l / (norm2 * norm) * l12;
  dr_dl.row(1) = e.transpose() / norm - e_l / (norm2 * norm) * l12;
  dr_dl *= sqrt_info_;

  if (jacobians[0]) {
    Eigen::Map<Eigen::Matrix<double, 2, 7, Eigen::RowMajor>> J(jacobians[0]);
    Eigen::Matrix<double, 3, 7> dl_dpose;
    // m_w = n_w - t x d_w = n_w + [d_w]x t.
    dl_dpose.leftCols<3>() = A * R_w_b.transpose() * skew(L_w.d);
    dl_dpose.rightCols<4>() = A * inverseRotationJacobianWrtQuaternion(q_w_b, m_w) +
                              B * inverseRotationJacobianWrtQuaternion(q_w_b, L_w.d);
    J = dr_dl * dl_dpose;
  }
  if (jacobians[1]) {
    Eigen::Map<Eigen::Matrix<double, 2, 4, Eigen::RowMajor>> J(jacobians[1]);
    Eigen::Matrix<double, 3, 6> dl_dnd;
    dl_dnd.leftCols<3>() = A * R_w_b.transpose();
    dl_dnd.rightCols<3>() = -A * R_w_b.transpose() * skew(t_w_b) + B * R_w_b.transpose();
    // Tangent Jacobian, then to the ambient [theta, phi]: d(tangent)/d(theta) = Jr(theta).
    const Eigen::Matrix<double, 2, 4> J_tangent =
        dr_dl * dl_dnd * pluckerJacobianWrtTangent(ortho_w);
    J.leftCols<3>() = J_tangent.leftCols<3>() *
                      rightJacobianSO3(Eigen::Vector3d(x_line[0], x_line[1], x_line[2]));
    J.col(3) = J_tangent.col(3);
  }
  if (with_time_shift && jacobians[2]) {
    // d(p.l)/dp = (l1, l2) for each endpoint p, moved by -td * velocity.
    const Eigen::Vector2d l12_over_norm = sqrt_info_ * Eigen::Vector2d(l.x(), l.y()) / norm;
    jacobians[2][0] = -l12_over_norm.dot(start_velocity_);
    jacobians[2][1] = -l12_over_norm.dot(end_velocity_);
  }
  return true;
}

}  // namespace alvio
