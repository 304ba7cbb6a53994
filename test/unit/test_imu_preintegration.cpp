#include <gtest/gtest.h>

#include <random>

#include "alvio/common/rotation.h"
#include "alvio/imu/imu_preintegration.h"

using namespace alvio;

namespace {
const Eigen::Vector3d kGravity(0, 0, -9.81);
constexpr double kDt = 0.005;

// Constant body rotation rate w and constant world acceleration a_w from R0.
struct ConstantMotion {
  Eigen::Matrix3d R0 =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  Eigen::Vector3d w{0.3, -0.5, 0.8};
  Eigen::Vector3d a_w{0.7, -0.4, 0.25};
  Eigen::Matrix3d R(double t) const { return R0 * expQuaternion(w * t).toRotationMatrix(); }
  Eigen::Vector3d acc(double t) const { return R(t).transpose() * (a_w - kGravity); }
};

ImuPreintegration integrate(const ConstantMotion& m, double T, const Eigen::Vector3d& ba,
                            const Eigen::Vector3d& bg, const Eigen::Vector3d& bias_in_data_a,
                            const Eigen::Vector3d& bias_in_data_g) {
  ImuPreintegration pre(m.acc(0) + bias_in_data_a, m.w + bias_in_data_g, ba, bg, ImuNoise());
  const int n = static_cast<int>(std::lround(T / kDt));
  for (int k = 1; k <= n; ++k) pre.push(kDt, m.acc(k * kDt) + bias_in_data_a, m.w + bias_in_data_g);
  return pre;
}
}  // namespace

TEST(ImuPreintegration, MatchesClosedFormConstantMotion) {
  const ConstantMotion m;
  const double T = 2.0;
  const auto pre = integrate(m, T, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                             Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  EXPECT_NEAR(pre.sumDt(), T, 1e-12);
  const Eigen::Quaterniond dq_true = expQuaternion(m.w * T);
  const Eigen::Vector3d dv_true = m.R0.transpose() * (m.a_w - kGravity) * T;
  const Eigen::Vector3d dp_true = m.R0.transpose() * 0.5 * (m.a_w - kGravity) * T * T;
  EXPECT_LT(pre.deltaQ().angularDistance(dq_true), 1e-9);
  EXPECT_LT((pre.deltaV() - dv_true).norm(), 2e-4);
  EXPECT_LT((pre.deltaP() - dp_true).norm(), 2e-4);
  // The residual between the true states is (nearly) zero.
  const Eigen::Vector3d v0(1, 2, -0.5), p0(3, 4, 5);
  const Eigen::Vector3d vT = v0 + m.a_w * T, pT = p0 + v0 * T + 0.5 * m.a_w * T * T;
  const Eigen::Vector3d z = Eigen::Vector3d::Zero();
  const auto r = pre.residual(p0, Eigen::Quaterniond(m.R0), v0, z, z, pT,
                              Eigen::Quaterniond(m.R(T)), vT, z, z, kGravity);
  EXPECT_LT(r.norm(), 5e-4);
}

TEST(ImuPreintegration, BiasJacobiansPredictBiasChange) {
  const ConstantMotion m;
  const Eigen::Vector3d z = Eigen::Vector3d::Zero();
  const auto pre = integrate(m, 1.0, z, z, z, z);
  const Eigen::Vector3d dba(0.02, -0.01, 0.03), dbg(0.003, 0.002, -0.004);
  // Integrating data with the bias removed at a new linearisation point...
  const auto exact = integrate(m, 1.0, dba, dbg, z, z);
  // ...is what the first-order correction predicts from the old one.
  // (Second-order terms remain: |dbg|^2 T^2 |a| is about 1e-4.)
  EXPECT_LT((pre.correctedDeltaP(dba, dbg) - exact.deltaP()).norm(), 5e-4);
  EXPECT_LT((pre.correctedDeltaV(dba, dbg) - exact.deltaV()).norm(), 5e-4);
  EXPECT_LT(pre.correctedDeltaQ(dbg).normalized().angularDistance(exact.deltaQ()), 5e-5);
  // And without the correction the error is much larger (the test can fail).
  EXPECT_GT((pre.deltaV() - exact.deltaV()).norm(), 1e-2);
}

TEST(ImuPreintegration, RepropagateEqualsFreshIntegration) {
  const ConstantMotion m;
  const Eigen::Vector3d z = Eigen::Vector3d::Zero();
  auto pre = integrate(m, 1.0, z, z, z, z);
  const Eigen::Vector3d ba(0.1, 0.2, -0.1), bg(0.01, -0.02, 0.03);
  pre.repropagate(ba, bg);
  const auto fresh = integrate(m, 1.0, ba, bg, z, z);
  EXPECT_LT((pre.deltaP() - fresh.deltaP()).norm(), 1e-12);
  EXPECT_LT((pre.covariance() - fresh.covariance()).norm(), 1e-15);
  EXPECT_EQ(pre.linearizedBa(), ba);
}

// The propagated covariance of dp, dq, dv matches Monte-Carlo integration of
// white noise of the configured density (samples shared between steps, as in reality).
TEST(ImuPreintegration, CovarianceMatchesMonteCarlo) {
  const ConstantMotion m;
  const Eigen::Vector3d z = Eigen::Vector3d::Zero();
  ImuNoise noise;
  noise.acc_noise_density = 0.02;
  noise.gyr_noise_density = 0.002;
  const double T = 1.0;
  const int n = static_cast<int>(T / kDt);
  const double sa = noise.acc_noise_density / std::sqrt(kDt);
  const double sg = noise.gyr_noise_density / std::sqrt(kDt);
  ImuPreintegration model(m.acc(0), m.w, z, z, noise);
  for (int k = 1; k <= n; ++k) model.push(kDt, m.acc(k * kDt), m.w);

  std::mt19937 rng(7);
  std::normal_distribution<double> N(0, 1);
  const int trials = 3000;
  std::vector<Eigen::Matrix<double, 9, 1>> errs;
  for (int trial = 0; trial < trials; ++trial) {
    auto sample = [&](double s) -> Eigen::Vector3d {
      return Eigen::Vector3d(N(rng), N(rng), N(rng)) * s;
    };
    ImuPreintegration p(m.acc(0) + sample(sa), m.w + sample(sg), z, z, noise);
    for (int k = 1; k <= n; ++k) p.push(kDt, m.acc(k * kDt) + sample(sa), m.w + sample(sg));
    Eigen::Matrix<double, 9, 1> e;
    e.segment<3>(0) = p.deltaP() - model.deltaP();
    e.segment<3>(3) = 2.0 * (model.deltaQ().inverse() * p.deltaQ()).vec();
    e.segment<3>(6) = p.deltaV() - model.deltaV();
    errs.push_back(e);
  }
  Eigen::Matrix<double, 9, 9> cov = Eigen::Matrix<double, 9, 9>::Zero();
  for (const auto& e : errs) cov += e * e.transpose();
  cov /= trials;
  const Eigen::Matrix<double, 9, 9> predicted = model.covariance().topLeftCorner<9, 9>();
  // Compare the variances (diagonal): within 15 % (Monte-Carlo error with 3000 trials ~3 %).
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(cov(i, i) / predicted(i, i), 1.0, 0.15) << "state " << i;
}

// The cached square root of the information follows every change of the covariance.
TEST(ImuPreintegration, SqrtInformationFollowsTheCovariance) {
  const Eigen::Vector3d acc(0.3, -0.2, 9.81), gyr(0.1, 0.05, -0.2);
  ImuPreintegration pre(acc, gyr, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), ImuNoise());
  auto expected = [&] {
    const ImuPreintegration::Matrix15 info = pre.covariance().inverse();
    return ImuPreintegration::Matrix15(
        Eigen::LLT<ImuPreintegration::Matrix15>(0.5 * (info + info.transpose()))
            .matrixL()
            .transpose());
  };
  for (int i = 0; i < 3; ++i) pre.push(0.005, acc, gyr);
  const ImuPreintegration::Matrix15 first = pre.sqrtInformation();
  EXPECT_EQ(first, expected());
  pre.push(0.005, acc, gyr);
  EXPECT_NE(pre.sqrtInformation(), first);
  EXPECT_EQ(pre.sqrtInformation(), expected());
  const ImuPreintegration::Matrix15 before = pre.sqrtInformation();
  pre.repropagate(Eigen::Vector3d(0.1, 0, 0), Eigen::Vector3d(0, 0.01, 0));
  // New biases turn the integrated rotations, and so the covariance.
  EXPECT_NE(pre.sqrtInformation(), before);
  EXPECT_EQ(pre.sqrtInformation(), expected());
}
