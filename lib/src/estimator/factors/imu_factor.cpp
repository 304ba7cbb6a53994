#include "alvio/estimator/factors/imu_factor.h"

#include <Eigen/Cholesky>

#include "alvio/common/rotation.h"
#include "alvio/estimator/pose_manifold.h"

namespace alvio {

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

  if (jacobians[0]) {
    Eigen::Matrix<double, 15, 6> Jl = Eigen::Matrix<double, 15, 6>::Zero();
    Jl.block<3, 3>(kIdxP, 0) = -RiT;
    Jl.block<3, 3>(kIdxP, 3) = skew(RiT * (Pj - Pi - Vi * T - 0.5 * gravity_ * T * T));
    Jl.block<3, 3>(kIdxQ, 3) = -(quaternionLeft(Qj.inverse() * Qi) * quaternionRight(corrected_dq))
                                    .bottomRightCorner<3, 3>();
    Jl.block<3, 3>(kIdxV, 3) = skew(RiT * (Vj - Vi - gravity_ * T));
    Jl = sqrt_information_ * Jl;
    Eigen::Map<Eigen::Matrix<double, 15, 7, Eigen::RowMajor>> Ja(jacobians[0]);
    Ja.leftCols<3>() = Jl.leftCols<3>();
    Ja.rightCols<4>() = rightRotationJacobianToQuaternion<15>(Jl.rightCols<3>(), Qi);
  }
  if (jacobians[1]) {
    Eigen::Map<Eigen::Matrix<double, 15, 9, Eigen::RowMajor>> Js(jacobians[1]);
    Js.setZero();
    Js.block<3, 3>(kIdxP, 0) = -RiT * T;
    Js.block<3, 3>(kIdxP, 3) = -dp_dba;
    Js.block<3, 3>(kIdxP, 6) = -dp_dbg;
    Js.block<3, 3>(kIdxQ, 6) =
        -quaternionLeft(Qj.inverse() * Qi * pre_->deltaQ()).bottomRightCorner<3, 3>() * dq_dbg;
    Js.block<3, 3>(kIdxV, 0) = -RiT;
    Js.block<3, 3>(kIdxV, 3) = -dv_dba;
    Js.block<3, 3>(kIdxV, 6) = -dv_dbg;
    Js.block<3, 3>(kIdxBa, 3) = -Eigen::Matrix3d::Identity();
    Js.block<3, 3>(kIdxBg, 6) = -Eigen::Matrix3d::Identity();
    Js = sqrt_information_ * Js;
  }
  if (jacobians[2]) {
    Eigen::Matrix<double, 15, 6> Jl = Eigen::Matrix<double, 15, 6>::Zero();
    Jl.block<3, 3>(kIdxP, 0) = RiT;
    Jl.block<3, 3>(kIdxQ, 3) =
        quaternionLeft(corrected_dq.inverse() * Qi.inverse() * Qj).bottomRightCorner<3, 3>();
    Jl = sqrt_information_ * Jl;
    Eigen::Map<Eigen::Matrix<double, 15, 7, Eigen::RowMajor>> Ja(jacobians[2]);
    Ja.leftCols<3>() = Jl.leftCols<3>();
    Ja.rightCols<4>() = rightRotationJacobianToQuaternion<15>(Jl.rightCols<3>(), Qj);
  }
  if (jacobians[3]) {
    Eigen::Map<Eigen::Matrix<double, 15, 9, Eigen::RowMajor>> Js(jacobians[3]);
    Js.setZero();
    Js.block<3, 3>(kIdxV, 0) = RiT;
    Js.block<3, 3>(kIdxBa, 3) = Eigen::Matrix3d::Identity();
    Js.block<3, 3>(kIdxBg, 6) = Eigen::Matrix3d::Identity();
    Js = sqrt_information_ * Js;
  }
  return true;
}

}  // namespace alvio
