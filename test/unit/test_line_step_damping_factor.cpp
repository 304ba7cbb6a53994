// LineStepDampingFactor: zero where the solve started, the manifold's difference near the log
// map's cut, analytic Jacobians against central differences, its two 2-row halves, and what it
// is for: a line that one view leaves free no longer takes a wild Gauss-Newton step.
#include <gtest/gtest.h>

#include <ceres/problem.h>
#include <ceres/solver.h>

#include <cmath>
#include <random>
#include <stdexcept>

#include "alvio/estimator/factors/line_step_damping_factor.h"
#include "alvio/geometry/line_projection_factor.h"
#include "alvio/geometry/orthonormal_line.h"
#include "alvio/geometry/orthonormal_line_manifold.h"
#include "line_test_utils.h"

using namespace alvio;
using test::numericJacobian;

namespace {
Eigen::Vector4d evaluate(const LineStepDampingFactor& f, const double* x) {
  Eigen::Vector4d r;
  const double* params[1] = {x};
  EXPECT_TRUE(f.Evaluate(params, r.data(), nullptr));
  return r;
}
}  // namespace

TEST(LineStepDampingFactor, ZeroAtTheStartAndWeightedManifoldDifferenceAway) {
  const double start[4] = {0.3, -0.2, 0.5, 0.7};
  const LineStepDampingFactor f(start, 10.0);
  EXPECT_LT(evaluate(f, start).norm(), 1e-12);
  const OrthonormalLineManifold manifold;
  const double delta[4] = {0.01, -0.02, 0.005, 0.03};
  double moved[4];
  manifold.Plus(start, delta, moved);
  const Eigen::Vector4d r = evaluate(f, moved);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(r[k], 10.0 * delta[k], 1e-9) << k;
}

TEST(LineStepDampingFactor, SmallAcrossTheLogMapsCut) {
  // Two parameter vectors of nearly the same rotation by pi, on either side of the cut:
  // theta and -theta differ by 2 pi in the ambient coordinates, by 0.002 rad as rotations.
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, -1).normalized();
  const Eigen::Vector3d a = (M_PI - 0.001) * axis, b = -(M_PI - 0.001) * axis;
  const double start[4] = {a.x(), a.y(), a.z(), 0.4};
  const double x[4] = {b.x(), b.y(), b.z(), 0.4};
  const LineStepDampingFactor f(start, 1.0);
  EXPECT_NEAR(evaluate(f, x).norm(), 0.002, 1e-6);
}

TEST(LineStepDampingFactor, AnalyticJacobianMatchesNumeric) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < 50; ++k) {
    const Eigen::Vector3d axis = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    const Eigen::Vector3d theta = (0.1 + 2.9 * (u(rng) + 1) / 2) * axis;
    const double start[4] = {theta.x(), theta.y(), theta.z(), 0.8 * u(rng) + 0.7};
    Eigen::Vector4d x;
    for (int i = 0; i < 4; ++i) x[i] = start[i] + 0.3 * u(rng);
    const LineStepDampingFactor f(start, 3.0);
    Eigen::Vector4d r;
    Eigen::Matrix<double, 4, 4, Eigen::RowMajor> J;
    double* jacobians[1] = {J.data()};
    const double* params[1] = {x.data()};
    ASSERT_TRUE(f.Evaluate(params, r.data(), jacobians));
    const Eigen::MatrixXd J_num = numericJacobian(
        [&](const Eigen::VectorXd& p) -> Eigen::VectorXd { return evaluate(f, p.data()); }, x);
    EXPECT_LT((J_num - J).norm(), 1e-6 * (1.0 + J_num.norm())) << "\n" << J << "\n" << J_num;
  }
}

TEST(LineStepDampingFactor, TwoHalvesAreTheFullFactorsRowsExactly) {
  const double start[4] = {0.9, -1.4, 0.6, 0.2};
  const double x[4] = {1.1, -1.2, 0.3, 0.5};
  const double* params[1] = {x};
  const LineStepDampingFactor full(start, 7.0);
  Eigen::Vector4d r;
  Eigen::Matrix<double, 4, 4, Eigen::RowMajor> J;
  double* jacobians[1] = {J.data()};
  ASSERT_TRUE(full.Evaluate(params, r.data(), jacobians));
  ASSERT_GT(r.norm(), 1.0);
  for (int half : {0, 1}) {
    const LineStepDampingHalfFactor f(start, 7.0, half);
    EXPECT_EQ(f.num_residuals(), 2);
    Eigen::Vector2d r_half;
    Eigen::Matrix<double, 2, 4, Eigen::RowMajor> J_half;
    double* half_jacobians[1] = {J_half.data()};
    ASSERT_TRUE(f.Evaluate(params, r_half.data(), half_jacobians));
    EXPECT_TRUE(r_half == r.segment<2>(2 * half)) << half;
    EXPECT_TRUE(J_half == J.middleRows<2>(2 * half)) << half;
    // Without Jacobians too.
    Eigen::Vector2d r_only;
    ASSERT_TRUE(f.Evaluate(params, r_only.data(), nullptr));
    EXPECT_TRUE(r_only == r_half);
  }
  EXPECT_THROW(LineStepDampingHalfFactor(start, 7.0, 2), std::invalid_argument);
}

TEST(LineStepDampingFactor, BoundsTheStepOfALineOneViewLeavesFree) {
  // One camera sees the line twice (two noisy segments): the line may turn and slide inside
  // its interpretation plane for nothing. Without damping the first Gauss-Newton step goes
  // far along those directions, the cost rises and the step is rejected; with it the step is
  // ten times shorter, taken, and the line fits.
  const Eigen::Isometry3d T_b_c = Eigen::Isometry3d::Identity();
  double pose[7];
  poseToParameters(Eigen::Isometry3d::Identity(), pose);
  struct FirstStep {
    double length, fit_sigma;
    bool taken;
  };
  auto firstStep = [&](double weight) {
    double line[4];
    OrthonormalLine::fromPlucker(PluckerLine::fromPoints({-1, 0.35, 4.2}, {1, 0.1, 5.3}))
        .toParameters(line);
    const double start[4] = {line[0], line[1], line[2], line[3]};
    ceres::Problem problem;
    problem.AddParameterBlock(pose, 7);
    problem.SetParameterBlockConstant(pose);
    problem.AddParameterBlock(line, 4, new OrthonormalLineManifold());
    const Eigen::Vector3d p0(-1, 0.3, 4), p1(1, 0.2, 5);
    const Eigen::Vector2d s = p0.head<2>() / p0.z(), e = p1.head<2>() / p1.z();
    for (const Eigen::Vector2d& noise :
         {Eigen::Vector2d(0.001, -0.0005), Eigen::Vector2d(-0.0008, 0.0007)})
      problem.AddResidualBlock(new LineProjectionFactor(s + noise, e - noise, T_b_c, 300.0),
                               nullptr, pose, line);
    if (weight > 0)
      problem.AddResidualBlock(new LineStepDampingFactor(start, weight), nullptr, line);
    ceres::Solver::Options options;
    options.max_num_iterations = 1;
    options.trust_region_strategy_type = ceres::DOGLEG;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    const ceres::IterationSummary& it = summary.iterations.back();
    // Four endpoint residuals in sigma units (the damping term is zero at the start).
    return FirstStep{it.step_norm, std::sqrt(2.0 * summary.final_cost / 4.0),
                     it.step_is_successful};
  };
  const FirstStep free_step = firstStep(0.0), damped = firstStep(10.0);
  EXPECT_GT(free_step.length, 1.0);
  EXPECT_FALSE(free_step.taken);
  EXPECT_GT(free_step.fit_sigma, 5.0);  // still the starting misfit
  EXPECT_LT(damped.length, 0.15);
  EXPECT_TRUE(damped.taken);
  EXPECT_LT(damped.fit_sigma, 0.5);
}
