#include <gtest/gtest.h>

#include <ceres/sized_cost_function.h>

#include <Eigen/Eigenvalues>
#include <random>

#include "alvio/common/rotation.h"
#include "alvio/estimator/factors/imu_factor.h"
#include "alvio/estimator/factors/marginalization.h"
#include "alvio/estimator/factors/point_projection_factor.h"
#include "alvio/estimator/point_noise.h"
#include "alvio/estimator/pose_manifold.h"
#include "factor_check.h"

using namespace alvio;

namespace {
std::mt19937 rng(1234);
double uniform(double a, double b) {
  return std::uniform_real_distribution<double>(a, b)(rng);
}
Eigen::Vector3d randomVector(double s) {
  return {uniform(-s, s), uniform(-s, s), uniform(-s, s)};
}
Eigen::Quaterniond randomRotation() {
  return Eigen::Quaterniond(Eigen::AngleAxisd(uniform(0, 3), randomVector(1).normalized()));
}
// H^+ of a symmetric positive semi-definite H: eigenvalues up to `relative_tolerance` of the
// largest count as zero. The reference the priors are checked against.
Eigen::MatrixXd pseudoInverse(const Eigen::MatrixXd& H, double relative_tolerance) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(H);
  const Eigen::ArrayXd ev = es.eigenvalues().array();
  const Eigen::VectorXd inv = (ev > relative_tolerance * ev.maxCoeff()).select(ev.inverse(), 0.0);
  return es.eigenvectors() * inv.asDiagonal() * es.eigenvectors().transpose();
}
void setPose(double* pose, const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
  Eigen::Map<Eigen::Vector3d>{pose} = p;
  Eigen::Map<Eigen::Quaterniond>{pose + 3} = q;
}
Eigen::Isometry3d eurocTbc() {
  Eigen::Matrix4d m;
  m << 0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975, 0.999557249008,
      0.0149672133247, 0.025715529948, -0.064676986768, -0.0257744366974, 0.00375618835797,
      0.999660727178, 0.00981073058949, 0, 0, 0, 1;
  Eigen::Isometry3d T(m);
  T.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();
  return T;
}
}  // namespace

TEST(PointProjectionFactor, AnalyticJacobiansMatchNumeric) {
  const Eigen::Isometry3d T_b_c = eurocTbc();
  for (int trial = 0; trial < 20; ++trial) {
    double pose_i[7], pose_j[7], inv_depth[1];
    setPose(pose_i, randomVector(2), randomRotation());
    // Pose j near pose i so the point stays in front of the camera.
    const Eigen::Quaterniond qj =
        Eigen::Map<Eigen::Quaterniond>(pose_i + 3) * expQuaternion(randomVector(0.2));
    setPose(pose_j, Eigen::Map<Eigen::Vector3d>(pose_i) + randomVector(0.3), qj);
    inv_depth[0] = uniform(0.1, 0.5);
    PointProjectionFactor f({uniform(-0.4, 0.4), uniform(-0.3, 0.3)}, {uniform(-0.4, 0.4), 0.1},
                            T_b_c, 460.0 / 1.5);
    const auto check = test::checkJacobians(f, {pose_i, pose_j, inv_depth});
    EXPECT_LT(check.max_rel_error, 1e-5) << "trial " << trial;
  }
}

TEST(PointProjectionFactor, TimeShiftJacobianMatchesNumeric) {
  const Eigen::Isometry3d T_b_c = eurocTbc();
  for (int trial = 0; trial < 20; ++trial) {
    double pose_i[7], pose_j[7], inv_depth[1], td[1] = {uniform(-0.05, 0.05)};
    setPose(pose_i, randomVector(2), randomRotation());
    const Eigen::Quaterniond qj =
        Eigen::Map<Eigen::Quaterniond>(pose_i + 3) * expQuaternion(randomVector(0.2));
    setPose(pose_j, Eigen::Map<Eigen::Vector3d>(pose_i) + randomVector(0.3), qj);
    inv_depth[0] = uniform(0.1, 0.5);
    PointProjectionFactor f({uniform(-0.4, 0.4), uniform(-0.3, 0.3)}, {uniform(-0.4, 0.4), 0.1},
                            T_b_c, 460.0 / 1.5);
    f.estimateTimeShift(randomVector(0.5).head<2>(), randomVector(0.5).head<2>());
    ASSERT_EQ(f.parameter_block_sizes().size(), 4u);
    const auto check = test::checkJacobians(f, {pose_i, pose_j, inv_depth, td});
    EXPECT_LT(check.max_rel_error, 1e-5) << "trial " << trial;
  }
}

TEST(PointProjectionFactor, TimeShiftMovesTheObservationsAlongTheirVelocities) {
  // td later than the stamp: the frame's pose saw each point td * velocity before where the
  // image shows it, so the factor at td equals the plain one at the moved observations.
  const Eigen::Isometry3d T_b_c = eurocTbc();
  double pose_i[7], pose_j[7], inv_depth[1] = {0.3}, td[1] = {0.03};
  setPose(pose_i, {0.1, 0.2, 0.3}, randomRotation());
  setPose(pose_j, {0.3, 0.1, 0.2}, Eigen::Map<Eigen::Quaterniond>(pose_i + 3));
  const Eigen::Vector2d obs_i(0.1, -0.2), obs_j(0.05, 0.1), vel_i(0.4, -0.1), vel_j(-0.3, 0.2);
  PointProjectionFactor shifted(obs_i, obs_j, T_b_c, 300.0);
  shifted.estimateTimeShift(vel_i, vel_j);
  const PointProjectionFactor moved(obs_i - td[0] * vel_i, obs_j - td[0] * vel_j, T_b_c, 300.0);
  double r_shifted[2], r_moved[2];
  const double* with_td[4] = {pose_i, pose_j, inv_depth, td};
  ASSERT_TRUE(shifted.Evaluate(with_td, r_shifted, nullptr));
  ASSERT_TRUE(moved.Evaluate(with_td, r_moved, nullptr));
  EXPECT_NEAR(r_shifted[0], r_moved[0], 1e-9);
  EXPECT_NEAR(r_shifted[1], r_moved[1], 1e-9);
  EXPECT_GT(std::abs(r_shifted[0] - 0.0) + std::abs(r_shifted[1]), 0.0);
}

TEST(PointProjectionFactor, ZeroResidualAtTruth) {
  const Eigen::Isometry3d T_b_c = eurocTbc();
  const Eigen::Vector3d p_w(2, 1, 5);
  double pose_i[7], pose_j[7];
  setPose(pose_i, Eigen::Vector3d(0, 0, 0), Eigen::Quaterniond::Identity());
  setPose(pose_j, Eigen::Vector3d(0.3, -0.1, 0.2),
          expQuaternion(Eigen::Vector3d(0.05, 0.1, -0.02)));
  auto project = [&](const double* pose) {
    const Eigen::Isometry3d T_w_c =
        Eigen::Translation3d(posePosition(pose)) * poseRotation(pose) * T_b_c;
    const Eigen::Vector3d p_c = T_w_c.inverse() * p_w;
    return std::make_pair(Eigen::Vector2d(p_c.head<2>() / p_c.z()), p_c.z());
  };
  const auto [obs_i, depth_i] = project(pose_i);
  const auto [obs_j, depth_j] = project(pose_j);
  double inv_depth[1] = {1.0 / depth_i};
  PointProjectionFactor f(obs_i, obs_j, T_b_c, 1.0);
  double r[2];
  const double* params[] = {pose_i, pose_j, inv_depth};
  f.Evaluate(params, r, nullptr);
  EXPECT_LT(Eigen::Vector2d(r[0], r[1]).norm(), 1e-12);
  inv_depth[0] *= 1.2;
  f.Evaluate(params, r, nullptr);
  EXPECT_GT(Eigen::Vector2d(r[0], r[1]).norm(), 1e-4);
}

TEST(PointNoise, WithoutDriftEverySightingHasTheWhiteNoiseExactly) {
  // Bit for bit, so that drift 0 gives the trajectories of before the drift term.
  for (double sigma : {1.5, 1.5 * (1 + 7e-4), 0.3})
    for (double dt : {0.0, 0.05, 1.7, 12.0})
      EXPECT_EQ(pointObservationSigmaPx(sigma, 0, dt), sigma);
}

TEST(PointNoise, VarianceGrowsLinearlyWithTheTimeSinceTheAnchor) {
  const double s0 = 1.5, q = 1.0;
  EXPECT_EQ(pointObservationSigmaPx(s0, q, 0), s0);
  EXPECT_NEAR(pointObservationSigmaPx(s0, q, 1.5), std::sqrt(2.25 + 1.5), 1e-12);
  const auto added = [&](double dt) {
    return std::pow(pointObservationSigmaPx(s0, q, dt), 2) - s0 * s0;
  };
  EXPECT_NEAR(added(2.0), 2 * added(1.0), 1e-12);
  EXPECT_NEAR(added(0.5), 0.5 * q, 1e-12);
  // A sighting before the anchor's (not made by the estimator) is as far from it as one after.
  EXPECT_EQ(pointObservationSigmaPx(s0, q, -0.7), pointObservationSigmaPx(s0, q, 0.7));
}

TEST(ImuFactor, AnalyticJacobiansMatchNumeric) {
  ImuNoise noise;
  ImuPreintegration pre(Eigen::Vector3d(0.1, 0.2, 9.8), Eigen::Vector3d(0.01, 0.02, 0.3),
                        Eigen::Vector3d(0.01, 0.02, -0.01), Eigen::Vector3d(0.001, 0.002, 0.003),
                        noise);
  for (int k = 0; k < 40; ++k)
    pre.push(0.005, Eigen::Vector3d(0.3 * std::sin(0.1 * k), 0.2, 9.7 + 0.1 * std::cos(0.2 * k)),
             Eigen::Vector3d(0.1, -0.2 * std::sin(0.05 * k), 0.3));
  ImuFactor f(&pre, Eigen::Vector3d(0, 0, -9.81));
  // The rotation-residual Jacobians use the usual small-angle form (exact when the
  // residual rotation is zero): far from consistent states they are good to ~1e-4.
  for (int trial = 0; trial < 20; ++trial) {
    double pose_i[7], sb_i[9], pose_j[7], sb_j[9];
    setPose(pose_i, randomVector(2), randomRotation());
    setPose(pose_j, randomVector(2), randomRotation());
    for (int i = 0; i < 9; ++i) {
      sb_i[i] = uniform(-0.5, 0.5) * (i < 3 ? 2 : 0.1);
      sb_j[i] = uniform(-0.5, 0.5) * (i < 3 ? 2 : 0.1);
    }
    const auto check = test::checkJacobians(f, {pose_i, sb_i, pose_j, sb_j});
    EXPECT_LT(check.max_rel_error, 1e-3) << "trial " << trial;
  }
  // Near states consistent with the measurement they are exact to numerical precision.
  for (int trial = 0; trial < 20; ++trial) {
    double pose_i[7], sb_i[9], pose_j[7], sb_j[9];
    const Eigen::Quaterniond qi = randomRotation();
    const Eigen::Vector3d pi = randomVector(2), vi = randomVector(1);
    const Eigen::Vector3d g(0, 0, -9.81);
    const double T = pre.sumDt();
    setPose(pose_i, pi, qi);
    setPose(pose_j, pi + vi * T + 0.5 * g * T * T + qi * pre.deltaP(), qi * pre.deltaQ());
    Eigen::Map<Eigen::Matrix<double, 9, 1>> si(sb_i), sj(sb_j);
    si << vi, pre.linearizedBa(), pre.linearizedBg();
    sj << vi + g * T + qi * pre.deltaV(), pre.linearizedBa(), pre.linearizedBg();
    const auto check = test::checkJacobians(f, {pose_i, sb_i, pose_j, sb_j});
    EXPECT_LT(check.max_rel_error, 2e-6) << "trial " << trial;
  }
}

// Three poses and the inverse depth of a point anchored in the first, seen from the others.
struct ThreeViews {
  ThreeViews() {
    setPose(pose0, Eigen::Vector3d(0, 0, 0), Eigen::Quaterniond::Identity());
    setPose(pose1, Eigen::Vector3d(0.2, 0.1, 0), expQuaternion(Eigen::Vector3d(0.02, 0.05, 0.01)));
    setPose(pose2, Eigen::Vector3d(0.4, 0.1, 0.1), expQuaternion(Eigen::Vector3d(0.03, 0.1, 0.0)));
  }
  double pose0[7], pose1[7], pose2[7], inv_depth[1] = {0.25};
};

// A prior built from factors must reproduce their cost to second order for the kept
// states, once the dropped states are optimised out.
TEST(Marginalization, PriorJacobiansMatchNumericAndKeepsInformation) {
  const Eigen::Isometry3d T_b_c = eurocTbc();
  ThreeViews views;
  auto& [pose0, pose1, pose2, inv_depth] = views;
  auto info = std::make_shared<MarginalizationInfo>();
  // pose0 and the point are dropped; pose1 and pose2 are kept.
  info->addResidualBlock(new PointProjectionFactor({0.1, 0.05}, {0.05, 0.06}, T_b_c, 100.0),
                         nullptr, {pose0, pose1, inv_depth}, {0, 2});
  info->addResidualBlock(new PointProjectionFactor({0.1, 0.05}, {0.02, 0.055}, T_b_c, 100.0),
                         new ceres::HuberLoss(1.0), {pose0, pose2, inv_depth}, {0, 2});
  ASSERT_TRUE(info->marginalize());
  EXPECT_EQ(info->keptTangentSize(), 12);
  MarginalizationFactor prior(info);
  // At and away from the linearisation point, the factor's Jacobians are exact.
  EXPECT_LT(test::checkJacobians(prior, {pose1, pose2}).max_rel_error, 1e-6);
  pose1[0] += 0.05;
  pose2[5] += 0.2;
  Eigen::Map<Eigen::Quaterniond>{pose2 + 3}.normalize();
  EXPECT_LT(test::checkJacobians(prior, {pose1, pose2}).max_rel_error, 1e-6);
  // The map from old to new addresses is honoured.
  double shifted1[7], shifted2[7];
  const auto blocks = info->keptBlocks({{pose1, shifted1}, {pose2, shifted2}});
  EXPECT_EQ(blocks, (std::vector<double*>{shifted1, shifted2}));
}

// The prior must not care about the sign of a quaternion parameter.
TEST(Marginalization, PriorIgnoresQuaternionSign) {
  const Eigen::Isometry3d T_b_c = eurocTbc();
  ThreeViews views;
  auto& [pose0, pose1, pose2, inv_depth] = views;
  auto info = std::make_shared<MarginalizationInfo>();
  info->addResidualBlock(new PointProjectionFactor({0.1, 0.05}, {0.05, 0.06}, T_b_c, 100.0),
                         nullptr, {pose0, pose1, inv_depth}, {0, 2});
  info->addResidualBlock(new PointProjectionFactor({0.1, 0.05}, {0.02, 0.055}, T_b_c, 100.0),
                         nullptr, {pose0, pose2, inv_depth}, {0, 2});
  ASSERT_TRUE(info->marginalize());
  MarginalizationFactor prior(info);
  pose1[1] += 0.01;
  const int n = info->keptTangentSize();
  Eigen::VectorXd r1(n), r2(n);
  const double* params[] = {pose1, pose2};
  prior.Evaluate(params, r1.data(), nullptr);
  for (int i = 3; i < 7; ++i) pose2[i] = -pose2[i];
  prior.Evaluate(params, r2.data(), nullptr);
  EXPECT_LT((r1 - r2).norm(), 1e-12);
  EXPECT_LT(test::checkJacobians(prior, {pose1, pose2}).max_rel_error, 1e-6);
}

// r = A [x1; x2] + b over two Euclidean blocks of sizes 3 and 5.
class LinearFactor : public ceres::SizedCostFunction<10, 3, 5> {
 public:
  LinearFactor(const Eigen::Matrix<double, 10, 8>& A, const Eigen::Matrix<double, 10, 1>& b)
      : A_(A), b_(b) {}
  bool Evaluate(double const* const* x, double* residuals, double** jacobians) const override {
    Eigen::Matrix<double, 8, 1> xx;
    xx << Eigen::Map<const Eigen::Vector3d>(x[0]),
        Eigen::Map<const Eigen::Matrix<double, 5, 1>>(x[1]);
    Eigen::Map<Eigen::Matrix<double, 10, 1>> r(residuals);
    r = A_ * xx + b_;
    if (jacobians && jacobians[0]) {
      Eigen::Map<Eigen::Matrix<double, 10, 3, Eigen::RowMajor>> J1(jacobians[0]);
      J1 = A_.leftCols<3>();
    }
    if (jacobians && jacobians[1]) {
      Eigen::Map<Eigen::Matrix<double, 10, 5, Eigen::RowMajor>> J2(jacobians[1]);
      J2 = A_.rightCols<5>();
    }
    return true;
  }

 private:
  Eigen::Matrix<double, 10, 8> A_;
  Eigen::Matrix<double, 10, 1> b_;
};

// A prior formed from one factor alone (the path of every frame that is not a keyframe: the
// last prior, its second-newest pose dropped) equals the Schur complement of that factor's
// information, also when the dropped block is not fully constrained.
TEST(Marginalization, PriorOfOneFactorEqualsSchurComplement) {
  std::mt19937 gen(3);
  std::normal_distribution<double> normal;
  for (bool deficient : {false, true}) {
    Eigen::Matrix<double, 10, 8> A;
    Eigen::Matrix<double, 10, 1> b;
    for (int i = 0; i < A.size(); ++i) A.data()[i] = 100 * normal(gen);
    for (int i = 0; i < b.size(); ++i) b[i] = normal(gen);
    if (deficient) A.col(2) = A.col(0) - 0.5 * A.col(1);  // x1 only constrained in 2 directions
    double x1[3] = {0.1, -0.2, 0.3}, x2[5] = {0.5, 0.4, -0.1, 0.2, 0.0};
    auto info = std::make_shared<MarginalizationInfo>();
    info->addResidualBlock(new LinearFactor(A, b), nullptr, {x1, x2}, {0});
    ASSERT_TRUE(info->marginalize());
    Eigen::Matrix<double, 8, 1> x;
    x << Eigen::Map<Eigen::Vector3d>(x1), Eigen::Map<Eigen::Matrix<double, 5, 1>>(x2);
    const Eigen::MatrixXd H = A.transpose() * A;
    const Eigen::VectorXd g = A.transpose() * (A * x + b);
    const Eigen::MatrixXd H11_inv = pseudoInverse(H.topLeftCorner(3, 3), 1e-9);
    const Eigen::MatrixXd H22 =
        H.bottomRightCorner(5, 5) - H.bottomLeftCorner(5, 3) * H11_inv * H.topRightCorner(3, 5);
    const Eigen::VectorXd g2 = g.tail(5) - H.bottomLeftCorner(5, 3) * H11_inv * g.head(3);
    const Eigen::MatrixXd& J = info->linearizedJacobian();
    EXPECT_EQ(J.rows(), deficient ? 8 : 7) << "one row per direction x1 takes";
    EXPECT_LT((J.transpose() * J - H22).norm() / H22.norm(), 1e-10) << deficient;
    EXPECT_LT((J.transpose() * info->linearizedResidual() - g2).norm() / g2.norm(), 1e-10)
        << deficient;
    MarginalizationFactor prior(info);
    EXPECT_EQ(prior.num_residuals(), J.rows());
    EXPECT_LT(test::checkJacobians(prior, {x2}).max_rel_error, 1e-6);
  }
}

// A random walk on a kept coordinate (the camera's time shift) adds its variance to the prior's
// covariance and keeps the prior's mean.
TEST(Marginalization, RandomWalkWidensAKeptCoordinateAndKeepsTheMean) {
  std::mt19937 gen(5);
  std::normal_distribution<double> normal;
  Eigen::Matrix<double, 10, 8> A;
  Eigen::Matrix<double, 10, 1> b;
  for (int i = 0; i < A.size(); ++i) A.data()[i] = 10 * normal(gen);
  for (int i = 0; i < b.size(); ++i) b[i] = normal(gen);
  double x1[3] = {0.1, -0.2, 0.3}, x2[5] = {0.05, 0.4, -0.1, 0.2, 0.0};
  // The first kept coordinate as a block of its own: x2 = [shift, rest].
  class Split : public ceres::CostFunction {
   public:
    explicit Split(const LinearFactor* f) : f_(f) {
      set_num_residuals(10);
      *mutable_parameter_block_sizes() = {3, 1, 4};
    }
    bool Evaluate(double const* const* x, double* r, double** J) const override {
      double x2[5] = {x[1][0], x[2][0], x[2][1], x[2][2], x[2][3]};
      const double* xx[2] = {x[0], x2};
      Eigen::Matrix<double, 10, 5, Eigen::RowMajor> J2;
      double* jj[2] = {J ? J[0] : nullptr, J2.data()};
      if (!f_->Evaluate(xx, r, J ? jj : nullptr)) return false;
      if (J && J[1]) Eigen::Map<Eigen::Matrix<double, 10, 1>>{J[1]} = J2.col(0);
      if (J && J[2])
        Eigen::Map<Eigen::Matrix<double, 10, 4, Eigen::RowMajor>>{J[2]} = J2.rightCols<4>();
      return true;
    }

   private:
    std::unique_ptr<const LinearFactor> f_;
  };
  const double q = 0.3;
  auto info = std::make_shared<MarginalizationInfo>();
  info->addResidualBlock(new Split(new LinearFactor(A, b)), nullptr, {x1, x2, x2 + 1}, {0});
  info->addRandomWalk(x2, q);
  ASSERT_TRUE(info->marginalize());
  Eigen::Matrix<double, 8, 1> x;
  x << Eigen::Map<Eigen::Vector3d>(x1), Eigen::Map<Eigen::Matrix<double, 5, 1>>(x2);
  const Eigen::MatrixXd H = A.transpose() * A;
  const Eigen::VectorXd g = A.transpose() * (A * x + b);
  const Eigen::MatrixXd H11_inv = H.topLeftCorner(3, 3).inverse();
  const Eigen::MatrixXd H22 =
      H.bottomRightCorner(5, 5) - H.bottomLeftCorner(5, 3) * H11_inv * H.topRightCorner(3, 5);
  const Eigen::VectorXd g2 = g.tail(5) - H.bottomLeftCorner(5, 3) * H11_inv * g.head(3);
  Eigen::MatrixXd P = H22.inverse();
  const Eigen::VectorXd mean = -P * g2;
  P(0, 0) += q;
  const Eigen::MatrixXd H_walked = P.inverse();
  const Eigen::MatrixXd& J = info->linearizedJacobian();
  const Eigen::VectorXd g_prior = J.transpose() * info->linearizedResidual();
  EXPECT_LT((J.transpose() * J - H_walked).norm() / H_walked.norm(), 1e-9);
  EXPECT_LT((-(J.transpose() * J).inverse() * g_prior - mean).norm() / mean.norm(), 1e-9);
  // The other coordinates keep much of what they knew: the walk is not a reset.
  EXPECT_GT(H_walked(1, 1), 0.1 * H22(1, 1));
  EXPECT_LT(H_walked(0, 0), 1.0 / q);
}

// A rank-deficient information, at the scale of a window's prior, becomes as many rows as it
// has rank, each non-zero, and reproduces the information and gradient.
TEST(Marginalization, FactorPriorKeepsRankAndInformation) {
  std::mt19937 gen(7);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 69, rank = n - 4 - trial % 3;  // four gauge directions or more
    Eigen::MatrixXd A(rank, n);
    for (int i = 0; i < A.size(); ++i) A.data()[i] = 1e3 * normal(gen);
    const Eigen::MatrixXd H = A.transpose() * A;
    Eigen::VectorXd r0(rank);
    for (int i = 0; i < rank; ++i) r0[i] = normal(gen);
    const Eigen::VectorXd g = A.transpose() * r0;
    Eigen::MatrixXd J;
    Eigen::VectorXd r;
    factorPrior(H, g, &J, &r);
    ASSERT_EQ(J.rows(), rank) << "trial " << trial;
    EXPECT_EQ((J.rowwise().norm().array() > 0).count(), rank) << "trial " << trial;
    EXPECT_LT((J.transpose() * J - H).norm() / H.norm(), 1e-10) << "trial " << trial;
    EXPECT_LT((J.transpose() * r - g).norm() / g.norm(), 1e-8) << "trial " << trial;
    // |r|^2 = g^T H^+ g is the part of |r0|^2 that the states can explain: no more than
    // |r0|^2. Noise pivots kept as directions would inflate it.
    EXPECT_LE(r.norm(), r0.norm() * (1 + 1e-9)) << "trial " << trial;
  }
}

// The prior's information equals the dense Schur complement of the full system.
TEST(Marginalization, PriorEqualsDenseSchurComplement) {
  const Eigen::Isometry3d T_b_c = eurocTbc();
  double poses[3][7], depths[4][1];
  for (int k = 0; k < 3; ++k)
    setPose(poses[k], Eigen::Vector3d(0.2 * k, 0.05 * k, 0.02 * k),
            expQuaternion(Eigen::Vector3d(0.01 * k, 0.03 * k, -0.02 * k)));
  const Eigen::Vector2d obs[4] = {{0.1, 0.05}, {-0.2, 0.1}, {0.05, -0.15}, {0.3, 0.2}};
  struct F {
    std::unique_ptr<PointProjectionFactor> f;
    int pose_j, depth;
  };
  std::vector<F> factors;
  auto info = std::make_shared<MarginalizationInfo>();
  for (int l = 0; l < 4; ++l) {
    depths[l][0] = 0.2 + 0.05 * l;
    // Odd landmarks meet their poses in the other order, so their blocks do not lie in the
    // states' order and scatter in several runs.
    for (int k = 1; k < 3; ++k) {
      const int j = l % 2 ? 3 - k : k;
      const Eigen::Vector2d o_j = obs[l] + Eigen::Vector2d(0.01 * j, -0.02 * j);
      factors.push_back({std::make_unique<PointProjectionFactor>(obs[l], o_j, T_b_c, 50.0), j, l});
      info->addResidualBlock(new PointProjectionFactor(obs[l], o_j, T_b_c, 50.0), nullptr,
                             {poses[0], poses[j], depths[l]}, {0, 2});
    }
  }
  ASSERT_TRUE(info->marginalize());
  // Dense system in tangent space: [pose0 (6), depths (4), pose1 (6), pose2 (6)].
  const int N = 6 + 4 + 12;
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(N, N);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(N);
  for (const auto& fa : factors) {
    const double* params[] = {poses[0], poses[fa.pose_j], depths[fa.depth]};
    Eigen::Vector2d r;
    Eigen::Matrix<double, 2, 7, Eigen::RowMajor> J0, J1;
    Eigen::Vector2d Jd;
    double* jac[] = {J0.data(), J1.data(), Jd.data()};
    fa.f->Evaluate(params, r.data(), jac);
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(2, N);
    J.block(0, 0, 2, 6) = J0 * posePlusJacobian(poses[0]);
    J.block(0, 6 + fa.depth, 2, 1) = Jd;
    J.block(0, 10 + 6 * (fa.pose_j - 1), 2, 6) = J1 * posePlusJacobian(poses[fa.pose_j]);
    H += J.transpose() * J;
    g += J.transpose() * r;
  }
  const int m = 10, n = 12;
  const Eigen::MatrixXd Hmm = H.topLeftCorner(m, m);
  const Eigen::MatrixXd Hmm_inv = pseudoInverse(Hmm, 1e-9);
  const Eigen::MatrixXd Hrr =
      H.bottomRightCorner(n, n) - H.bottomLeftCorner(n, m) * Hmm_inv * H.topRightCorner(m, n);
  const Eigen::VectorXd gr = g.tail(n) - H.bottomLeftCorner(n, m) * Hmm_inv * g.head(m);
  const Eigen::MatrixXd& Jp = info->linearizedJacobian();
  ASSERT_EQ(info->keptAddresses(), (std::vector<double*>{poses[1], poses[2]}));
  EXPECT_LT((Jp.transpose() * Jp - Hrr).norm() / Hrr.norm(), 1e-8);
  EXPECT_LT((Jp.transpose() * info->linearizedResidual() - gr).norm() / gr.norm(), 1e-8);
  // Eight residuals leave the kept states' information rank deficient: the prior has one
  // row per direction it constrains, and none for the others.
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> kept_es(Hrr);
  const int rank = static_cast<int>(
      (kept_es.eigenvalues().array() > 1e-9 * kept_es.eigenvalues().maxCoeff()).count());
  ASSERT_LT(rank, n);
  EXPECT_EQ(Jp.rows(), rank);
  EXPECT_EQ((Jp.rowwise().norm().array() > 0).count(), rank);
}
