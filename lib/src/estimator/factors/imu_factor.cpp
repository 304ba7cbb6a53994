#include "alvio/estimator/factors/imu_factor.h"

#include "alvio/common/rotation.h"
#include "alvio/estimator/pose_manifold.h"

namespace alvio {

namespace {

// Writes a whitened pose Jacobian whose first `Rows` rows are `top` (over the tangent space)
// and whose other rows are zero, as Ceres' 15 x 7 row-major block over the pose's ambient
// parameters. `R` is q's rotation matrix.
template <int Rows>
void writePoseJacobian(const Eigen::Matrix<double, Rows, 6>& top, const Eigen::Quaterniond& q,
                       const Eigen::Matrix3d& R, double* jacobian) {
  Eigen::Map<Eigen::Matrix<double, 15, 7, Eigen::RowMajor>> Ja(jacobian);
  Ja.topLeftCorner<Rows, 3>() = top.template leftCols<3>();
  Ja.topRightCorner<Rows, 4>() =
      rightRotationJacobianToQuaternion<Rows>(top.template rightCols<3>(), q, R);
  Ja.template bottomRows<15 - Rows>().setZero();
}

}  // namespace

ImuFactor::ImuFactor(const ImuPreintegration* preintegration, const Eigen::Vector3d& gravity)
    : pre_(preintegration), gravity_(gravity), sqrt_information_(pre_->sqrtInformation()) {}

bool ImuFactor::Evaluate(double const* const* parameters, double* residuals,
                         double** jacobians) const {
  const Eigen::Vector3d Pi = posePosition(parameters[0]);
  const Eigen::Quaterniond Qi = poseRotation(parameters[0]).normalized();
  const Eigen::Map<const Eigen::Matrix<double, 9, 1>> sbi(parameters[1]);
  const Eigen::Vector3d Pj = posePosition(parameters[2]);
  const Eigen::Quaterniond Qj = poseRotation(parameters[2]).normalized();
  const Eigen::Map<const Eigen::Matrix<double, 9, 1>> sbj(parameters[3]);
  const Eigen::Vector3d Vi = sbi.segment<3>(0), Bai = sbi.segment<3>(3), Bgi = sbi.segment<3>(6);
  const Eigen::Vector3d Vj = sbj.segment<3>(0), Baj = sbj.segment<3>(3), Bgj = sbj.segment<3>(6);

  Eigen::Map<Eigen::Matrix<double, 15, 1>> r(residuals);
  r = sqrt_information_ * pre_->residual(Pi, Qi, Vi, Bai, Bgi, Pj, Qj, Vj, Baj, Bgj, gravity_);
  if (!jacobians) return true;

  const double T = pre_->sumDt();
  const auto& J = pre_->jacobian();
  const Eigen::Matrix3d dp_dba = J.block<3, 3>(kIdxP, kIdxBa);
  const Eigen::Matrix3d dp_dbg = J.block<3, 3>(kIdxP, kIdxBg);
  const Eigen::Matrix3d dq_dbg = J.block<3, 3>(kIdxQ, kIdxBg);
  const Eigen::Matrix3d dv_dba = J.block<3, 3>(kIdxV, kIdxBa);
  const Eigen::Matrix3d dv_dbg = J.block<3, 3>(kIdxV, kIdxBg);
  const Eigen::Matrix3d RiT = Qi.toRotationMatrix().transpose();
  const Eigen::Quaterniond corrected_dq = pre_->correctedDeltaQ(Bgi);

  // sqrt_information_ is upper triangular (from a Cholesky factor), so a whitened Jacobian
  // whose raw rows below some index are zero keeps them zero, and only the rows above mix.
  const ImuPreintegration::Matrix15& S = sqrt_information_;
  if (jacobians[0]) {  // rows p, q, v
    Eigen::Matrix<double, 9, 6> Jl = Eigen::Matrix<double, 9, 6>::Zero();
    Jl.block<3, 3>(kIdxP, 0) = -RiT;
    Jl.block<3, 3>(kIdxP, 3) = skew(RiT * (Pj - Pi - Vi * T - 0.5 * gravity_ * T * T));
    Jl.block<3, 3>(kIdxQ, 3) = -(quaternionLeft(Qj.inverse() * Qi) * quaternionRight(corrected_dq))
                                    .bottomRightCorner<3, 3>();
    Jl.block<3, 3>(kIdxV, 3) = skew(RiT * (Vj - Vi - gravity_ * T));
    writePoseJacobian<9>(S.topLeftCorner<9, 9>() * Jl, Qi, RiT.transpose(), jacobians[0]);
  }
  if (jacobians[1]) {
    Eigen::Matrix<double, 15, 9> J = Eigen::Matrix<double, 15, 9>::Zero();
    J.block<3, 3>(kIdxP, 0) = -RiT * T;
    J.block<3, 3>(kIdxP, 3) = -dp_dba;
    J.block<3, 3>(kIdxP, 6) = -dp_dbg;
    J.block<3, 3>(kIdxQ, 6) =
        -quaternionLeft(Qj.inverse() * Qi * pre_->deltaQ()).bottomRightCorner<3, 3>() * dq_dbg;
    J.block<3, 3>(kIdxV, 0) = -RiT;
    J.block<3, 3>(kIdxV, 3) = -dv_dba;
    J.block<3, 3>(kIdxV, 6) = -dv_dbg;
    J.block<3, 3>(kIdxBa, 3) = -Eigen::Matrix3d::Identity();
    J.block<3, 3>(kIdxBg, 6) = -Eigen::Matrix3d::Identity();
    Eigen::Map<Eigen::Matrix<double, 15, 9, Eigen::RowMajor>>(jacobians[1]).noalias() = S * J;
  }
  if (jacobians[2]) {  // rows p, q
    Eigen::Matrix<double, 6, 6> Jl = Eigen::Matrix<double, 6, 6>::Zero();
    Jl.block<3, 3>(kIdxP, 0) = RiT;
    Jl.block<3, 3>(kIdxQ, 3) =
        quaternionLeft(corrected_dq.inverse() * Qi.inverse() * Qj).bottomRightCorner<3, 3>();
    writePoseJacobian<6>(S.topLeftCorner<6, 6>() * Jl, Qj, Qj.toRotationMatrix(), jacobians[2]);
  }
  if (jacobians[3]) {  // rows v, ba, bg: the raw Jacobian is diag(R_i^T, I, I) there
    Eigen::Map<Eigen::Matrix<double, 15, 9, Eigen::RowMajor>> Js(jacobians[3]);
    Js.leftCols<3>().noalias() = S.middleCols<3>(kIdxV) * RiT;
    Js.middleCols<3>(3) = S.middleCols<3>(kIdxBa);
    Js.rightCols<3>() = S.middleCols<3>(kIdxBg);
  }
  return true;
}

}  // namespace alvio
