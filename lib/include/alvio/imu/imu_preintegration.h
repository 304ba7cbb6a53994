#pragma once
// IMU preintegration between two keyframes (Forster et al. / VINS-Mono): the
// relative motion (dp, dq, dv) measured by the IMU in the first frame's body
// frame, its first-order Jacobians with respect to the biases, and its
// covariance. Midpoint integration; re-propagated when the bias estimate moves
// too far for the first-order correction to hold.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

namespace alvio {

/// Continuous-time IMU noise (densities and random walks, as in the config), with an
/// inflation factor applied to every sigma.
struct ImuNoise {
  double acc_noise_density = 2.0e-3;
  double gyr_noise_density = 1.6968e-4;
  double acc_random_walk = 3.0e-3;
  double gyr_random_walk = 1.9393e-5;
};

/// Indices of the 15-dimensional error state.
enum ImuStateIndex { kIdxP = 0, kIdxQ = 3, kIdxV = 6, kIdxBa = 9, kIdxBg = 12 };

class ImuPreintegration {
 public:
  using Matrix15 = Eigen::Matrix<double, 15, 15>;

  ImuPreintegration(const Eigen::Vector3d& acc0, const Eigen::Vector3d& gyr0,
                    const Eigen::Vector3d& ba, const Eigen::Vector3d& bg, const ImuNoise& noise);

  /// Add the next sample, `dt` seconds after the previous one.
  void push(double dt, const Eigen::Vector3d& acc, const Eigen::Vector3d& gyr);
  /// Integrate all samples again from scratch with new linearisation biases.
  void repropagate(const Eigen::Vector3d& ba, const Eigen::Vector3d& bg);

  /// dp, dq, dv corrected to first order for biases (ba, bg).
  Eigen::Vector3d correctedDeltaP(const Eigen::Vector3d& ba, const Eigen::Vector3d& bg) const;
  Eigen::Quaterniond correctedDeltaQ(const Eigen::Vector3d& bg) const;
  Eigen::Vector3d correctedDeltaV(const Eigen::Vector3d& ba, const Eigen::Vector3d& bg) const;

  /// 15-vector residual [p, q, v, ba, bg] between two body states, unweighted.
  Eigen::Matrix<double, 15, 1> residual(const Eigen::Vector3d& Pi, const Eigen::Quaterniond& Qi,
                                        const Eigen::Vector3d& Vi, const Eigen::Vector3d& Bai,
                                        const Eigen::Vector3d& Bgi, const Eigen::Vector3d& Pj,
                                        const Eigen::Quaterniond& Qj, const Eigen::Vector3d& Vj,
                                        const Eigen::Vector3d& Baj, const Eigen::Vector3d& Bgj,
                                        const Eigen::Vector3d& gravity) const;

  double sumDt() const { return sum_dt_; }
  const Eigen::Vector3d& deltaP() const { return delta_p_; }
  const Eigen::Quaterniond& deltaQ() const { return delta_q_; }
  const Eigen::Vector3d& deltaV() const { return delta_v_; }
  const Eigen::Vector3d& linearizedBa() const { return linearized_ba_; }
  const Eigen::Vector3d& linearizedBg() const { return linearized_bg_; }
  const Matrix15& jacobian() const { return jacobian_; }
  const Matrix15& covariance() const { return covariance_; }
  /// L^T of the covariance's inverse (r^T Info r = |L^T r|^2), upper triangular: what the IMU
  /// factor weighs its residual by. Worked out once per covariance, not per factor and solve.
  const Matrix15& sqrtInformation() const;
  std::size_t sampleCount() const { return dts_.size(); }
  const std::vector<double>& dts() const { return dts_; }
  const std::vector<Eigen::Vector3d>& accs() const { return accs_; }
  const std::vector<Eigen::Vector3d>& gyrs() const { return gyrs_; }

 private:
  void integrate(double dt, const Eigen::Vector3d& acc1, const Eigen::Vector3d& gyr1);

  ImuNoise noise_;
  Eigen::Vector3d acc0_, gyr0_;          // first sample of the interval
  Eigen::Vector3d last_acc_, last_gyr_;  // previous sample while integrating
  Eigen::Vector3d linearized_ba_, linearized_bg_;
  double sum_dt_ = 0;
  Eigen::Vector3d delta_p_ = Eigen::Vector3d::Zero();
  Eigen::Quaterniond delta_q_ = Eigen::Quaterniond::Identity();
  Eigen::Vector3d delta_v_ = Eigen::Vector3d::Zero();
  Matrix15 jacobian_ = Matrix15::Identity();
  Matrix15 covariance_ = Matrix15::Zero();
  mutable Matrix15 sqrt_information_;
  mutable bool sqrt_information_stale_ = true;  // covariance_ changed since it was worked out
  std::vector<double> dts_;
  std::vector<Eigen::Vector3d> accs_, gyrs_;
};

}  // namespace alvio
