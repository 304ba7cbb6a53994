#include "alvio/imu/imu_preintegration.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "alvio/common/rotation.h"

namespace alvio {

ImuPreintegration::ImuPreintegration(const Eigen::Vector3d& acc0, const Eigen::Vector3d& gyr0,
                                     const Eigen::Vector3d& ba, const Eigen::Vector3d& bg,
                                     const ImuNoise& noise)
    : noise_(noise),
      acc0_(acc0),
      gyr0_(gyr0),
      last_acc_(acc0),
      last_gyr_(gyr0),
      linearized_ba_(ba),
      linearized_bg_(bg) {}

void ImuPreintegration::push(double dt, const Eigen::Vector3d& acc, const Eigen::Vector3d& gyr) {
  dts_.push_back(dt);
  accs_.push_back(acc);
  gyrs_.push_back(gyr);
  integrate(dt, acc, gyr);
}

void ImuPreintegration::repropagate(const Eigen::Vector3d& ba, const Eigen::Vector3d& bg) {
  sum_dt_ = 0;
  last_acc_ = acc0_;
  last_gyr_ = gyr0_;
  delta_p_.setZero();
  delta_q_.setIdentity();
  delta_v_.setZero();
  linearized_ba_ = ba;
  linearized_bg_ = bg;
  jacobian_.setIdentity();
  covariance_.setZero();
  for (std::size_t i = 0; i < dts_.size(); ++i) integrate(dts_[i], accs_[i], gyrs_[i]);
}

const ImuPreintegration::Matrix15& ImuPreintegration::sqrtInformation() const {
  if (sqrt_information_stale_) {
    const Matrix15 info = covariance_.inverse();
    sqrt_information_ = Eigen::LLT<Matrix15>(0.5 * (info + info.transpose())).matrixL().transpose();
    sqrt_information_stale_ = false;
  }
  return sqrt_information_;
}

void ImuPreintegration::integrate(double dt, const Eigen::Vector3d& acc1,
                                  const Eigen::Vector3d& gyr1) {
  const Eigen::Vector3d& acc0 = last_acc_;
  const Eigen::Vector3d& gyr0 = last_gyr_;
  const Eigen::Vector3d& ba = linearized_ba_;
  const Eigen::Vector3d& bg = linearized_bg_;

  // Midpoint integration of the mean.
  const Eigen::Vector3d w = 0.5 * (gyr0 + gyr1) - bg;
  const Eigen::Quaterniond q1 = (delta_q_ * expQuaternion(w * dt)).normalized();
  const Eigen::Matrix3d R0 = delta_q_.toRotationMatrix();
  const Eigen::Matrix3d R1 = q1.toRotationMatrix();
  const Eigen::Vector3d a0 = acc0 - ba, a1 = acc1 - ba;
  const Eigen::Vector3d a = 0.5 * (R0 * a0 + R1 * a1);
  const Eigen::Vector3d p1 = delta_p_ + delta_v_ * dt + 0.5 * a * dt * dt;
  const Eigen::Vector3d v1 = delta_v_ + a * dt;

  // Error-state transition F (15x15) and noise input G (15x18) of the same scheme.
  // Noise order: n_a0, n_g0, n_a1, n_g1, n_ba, n_bg.
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d Wx = skew(w), A0x = skew(a0), A1x = skew(a1);
  const double dt2 = dt * dt;
  Matrix15 F = Matrix15::Zero();
  F.block<3, 3>(kIdxP, kIdxP) = I;
  F.block<3, 3>(kIdxP, kIdxQ) = -0.25 * R0 * A0x * dt2 - 0.25 * R1 * A1x * (I - Wx * dt) * dt2;
  F.block<3, 3>(kIdxP, kIdxV) = I * dt;
  F.block<3, 3>(kIdxP, kIdxBa) = -0.25 * (R0 + R1) * dt2;
  F.block<3, 3>(kIdxP, kIdxBg) = 0.25 * R1 * A1x * dt2 * dt;
  F.block<3, 3>(kIdxQ, kIdxQ) = I - Wx * dt;
  F.block<3, 3>(kIdxQ, kIdxBg) = -I * dt;
  F.block<3, 3>(kIdxV, kIdxQ) = -0.5 * R0 * A0x * dt - 0.5 * R1 * A1x * (I - Wx * dt) * dt;
  F.block<3, 3>(kIdxV, kIdxV) = I;
  F.block<3, 3>(kIdxV, kIdxBa) = -0.5 * (R0 + R1) * dt;
  F.block<3, 3>(kIdxV, kIdxBg) = 0.5 * R1 * A1x * dt2;
  F.block<3, 3>(kIdxBa, kIdxBa) = I;
  F.block<3, 3>(kIdxBg, kIdxBg) = I;

  Eigen::Matrix<double, 15, 18> G = Eigen::Matrix<double, 15, 18>::Zero();
  G.block<3, 3>(kIdxP, 0) = 0.25 * R0 * dt2;
  G.block<3, 3>(kIdxP, 3) = -0.125 * R1 * A1x * dt2 * dt;
  G.block<3, 3>(kIdxP, 6) = 0.25 * R1 * dt2;
  G.block<3, 3>(kIdxP, 9) = G.block<3, 3>(kIdxP, 3);
  G.block<3, 3>(kIdxQ, 3) = 0.5 * I * dt;
  G.block<3, 3>(kIdxQ, 9) = 0.5 * I * dt;
  G.block<3, 3>(kIdxV, 0) = 0.5 * R0 * dt;
  G.block<3, 3>(kIdxV, 3) = -0.25 * R1 * A1x * dt2;
  G.block<3, 3>(kIdxV, 6) = 0.5 * R1 * dt;
  G.block<3, 3>(kIdxV, 9) = G.block<3, 3>(kIdxV, 3);
  G.block<3, 3>(kIdxBa, 12) = I;
  G.block<3, 3>(kIdxBg, 15) = I;

  // Sample noise sigma^2 = density^2 / dt, doubled: the midpoint rule averages two samples
  // per step and the model treats them as independent, which would halve the variance that
  // a continuous white noise of this density accumulates. Bias random walk over dt: rw^2 dt.
  Eigen::Matrix<double, 18, 1> q;
  const double na = 2.0 * noise_.acc_noise_density * noise_.acc_noise_density / dt;
  const double ng = 2.0 * noise_.gyr_noise_density * noise_.gyr_noise_density / dt;
  const double wa = noise_.acc_random_walk * noise_.acc_random_walk * dt;
  const double wg = noise_.gyr_random_walk * noise_.gyr_random_walk * dt;
  q << Eigen::Vector3d::Constant(na), Eigen::Vector3d::Constant(ng), Eigen::Vector3d::Constant(na),
      Eigen::Vector3d::Constant(ng), Eigen::Vector3d::Constant(wa), Eigen::Vector3d::Constant(wg);

  jacobian_ = F * jacobian_;
  covariance_ = F * covariance_ * F.transpose() + G * q.asDiagonal() * G.transpose();
  sqrt_information_stale_ = true;

  delta_p_ = p1;
  delta_q_ = q1;
  delta_v_ = v1;
  sum_dt_ += dt;
  last_acc_ = acc1;
  last_gyr_ = gyr1;
}

Eigen::Vector3d ImuPreintegration::correctedDeltaP(const Eigen::Vector3d& ba,
                                                   const Eigen::Vector3d& bg) const {
  return delta_p_ + jacobian_.block<3, 3>(kIdxP, kIdxBa) * (ba - linearized_ba_) +
         jacobian_.block<3, 3>(kIdxP, kIdxBg) * (bg - linearized_bg_);
}

Eigen::Quaterniond ImuPreintegration::correctedDeltaQ(const Eigen::Vector3d& bg) const {
  return delta_q_ *
         smallAngleQuaternion(jacobian_.block<3, 3>(kIdxQ, kIdxBg) * (bg - linearized_bg_));
}

Eigen::Vector3d ImuPreintegration::correctedDeltaV(const Eigen::Vector3d& ba,
                                                   const Eigen::Vector3d& bg) const {
  return delta_v_ + jacobian_.block<3, 3>(kIdxV, kIdxBa) * (ba - linearized_ba_) +
         jacobian_.block<3, 3>(kIdxV, kIdxBg) * (bg - linearized_bg_);
}

Eigen::Matrix<double, 15, 1> ImuPreintegration::residual(
    const Eigen::Vector3d& Pi, const Eigen::Quaterniond& Qi, const Eigen::Vector3d& Vi,
    const Eigen::Vector3d& Bai, const Eigen::Vector3d& Bgi, const Eigen::Vector3d& Pj,
    const Eigen::Quaterniond& Qj, const Eigen::Vector3d& Vj, const Eigen::Vector3d& Baj,
    const Eigen::Vector3d& Bgj, const Eigen::Vector3d& gravity) const {
  const double T = sum_dt_;
  const Eigen::Quaterniond Qi_inv = Qi.inverse();
  Eigen::Matrix<double, 15, 1> r;
  r.segment<3>(kIdxP) =
      Qi_inv * (Pj - Pi - Vi * T - 0.5 * gravity * T * T) - correctedDeltaP(Bai, Bgi);
  r.segment<3>(kIdxQ) = 2.0 * (correctedDeltaQ(Bgi).inverse() * (Qi_inv * Qj)).vec();
  r.segment<3>(kIdxV) = Qi_inv * (Vj - Vi - gravity * T) - correctedDeltaV(Bai, Bgi);
  r.segment<3>(kIdxBa) = Baj - Bai;
  r.segment<3>(kIdxBg) = Bgj - Bgi;
  return r;
}

}  // namespace alvio
