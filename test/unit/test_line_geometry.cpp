// Plucker lines, the orthonormal representation, its Ceres manifold and the SO(3) helpers.
#include <gtest/gtest.h>

#include <cmath>

#include "alvio/geometry/orthonormal_line.h"
#include "alvio/geometry/orthonormal_line_manifold.h"
#include "alvio/geometry/plucker_line.h"
#include "alvio/geometry/so3_utils.h"
#include "line_test_utils.h"

using namespace alvio;
using test::numericJacobian;

namespace {
constexpr double kPi = 3.14159265358979323846;

PluckerLine randomLine(std::mt19937& rng) {
  return PluckerLine::fromPoints(test::randomVector(rng, 3.0), test::randomVector(rng, 3.0));
}

Eigen::Vector4d randomLineParameters(std::mt19937& rng) {
  Eigen::Vector4d x;
  OrthonormalLine::fromPlucker(randomLine(rng)).toParameters(x.data());
  return x;
}

Eigen::Vector4d plus(const Eigen::Vector4d& x, const Eigen::Vector4d& delta) {
  Eigen::Vector4d out;
  OrthonormalLineManifold().Plus(x.data(), delta.data(), out.data());
  return out;
}

Eigen::Vector4d minus(const Eigen::Vector4d& y, const Eigen::Vector4d& x) {
  Eigen::Vector4d out;
  OrthonormalLineManifold().Minus(y.data(), x.data(), out.data());
  return out;
}
}  // namespace

TEST(So3, ExpLogRoundTripIncludingSmallAndNearPiAngles) {
  std::mt19937 rng(1);
  for (double angle : {0.0, 1e-9, 1e-4, 0.3, 2.0, kPi - 1e-6}) {
    for (int k = 0; k < 5; ++k) {
      const Eigen::Vector3d theta = test::randomVector(rng, 1.0).normalized() * angle;
      const Eigen::Matrix3d R = expSO3(theta);
      EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
      EXPECT_LT((expSO3(logSO3(R)) - R).norm(), 1e-9) << "angle " << angle;
      if (angle < kPi - 1e-3) {
        EXPECT_LT((logSO3(R) - theta).norm(), 1e-9);
      }
    }
  }
}

TEST(So3, RightJacobianAndItsInverse) {
  std::mt19937 rng(2);
  for (double angle : {0.0, 1e-7, 0.5, 2.5, kPi}) {
    const Eigen::Vector3d theta = test::randomVector(rng, 1.0).normalized() * angle;
    // Exp(theta + dtheta) = Exp(theta) Exp(Jr dtheta): compare Log(Exp(theta)^T Exp(theta + h)).
    const Eigen::Matrix3d R = expSO3(theta);
    const Eigen::MatrixXd numeric = numericJacobian(
        [&](const Eigen::VectorXd& dt) -> Eigen::VectorXd {
          return logSO3(R.transpose() * expSO3(theta + Eigen::Vector3d(dt)));
        },
        Eigen::VectorXd::Zero(3));
    EXPECT_LT((numeric - rightJacobianSO3(theta)).norm(), 1e-7) << "angle " << angle;
    EXPECT_LT(
        (rightJacobianSO3(theta) * rightJacobianInverseSO3(theta) - Eigen::Matrix3d::Identity())
            .norm(),
        1e-9)
        << "angle " << angle;
  }
}

TEST(So3, QuaternionRotationJacobiansMatchNumeric) {
  std::mt19937 rng(3);
  for (int k = 0; k < 10; ++k) {
    // Off the unit sphere too: Ceres differentiates in the ambient space.
    Eigen::Vector4d q_coeffs = test::randomRotation(rng).coeffs() * (k % 2 ? 1.0 : 1.3);
    const Eigen::Vector3d v = test::randomVector(rng, 2.0);
    auto rotate = [&](const Eigen::VectorXd& c, bool transpose) -> Eigen::VectorXd {
      const Eigen::Quaterniond q(c[3], c[0], c[1], c[2]);
      const Eigen::Matrix3d R = q.toRotationMatrix();
      return transpose ? Eigen::Vector3d(R.transpose() * v) : Eigen::Vector3d(R * v);
    };
    const Eigen::Quaterniond q(q_coeffs[3], q_coeffs[0], q_coeffs[1], q_coeffs[2]);
    EXPECT_LT(
        (numericJacobian([&](const Eigen::VectorXd& c) { return rotate(c, false); }, q_coeffs) -
         rotationJacobianWrtQuaternion(q, v))
            .norm(),
        1e-7);
    EXPECT_LT(
        (numericJacobian([&](const Eigen::VectorXd& c) { return rotate(c, true); }, q_coeffs) -
         inverseRotationJacobianWrtQuaternion(q, v))
            .norm(),
        1e-7);
  }
}

TEST(PluckerLine, TransformMatchesTransformedPoints) {
  std::mt19937 rng(4);
  for (int k = 0; k < 20; ++k) {
    const Eigen::Vector3d p = test::randomVector(rng, 5.0), q = test::randomVector(rng, 5.0);
    const Eigen::Isometry3d T_b_a = test::randomPose(rng, 3.0);
    const PluckerLine moved = PluckerLine::fromPoints(p, q).transformed(T_b_a);
    const PluckerLine expected = PluckerLine::fromPoints(T_b_a * p, T_b_a * q);
    EXPECT_LT((moved.n - expected.n).norm(), 1e-9);
    EXPECT_LT((moved.d - expected.d).norm(), 1e-9);
    EXPECT_NEAR(moved.n.dot(moved.d), 0.0, 1e-9);
  }
}

TEST(PluckerLine, DistancesAndClosestPoint) {
  // The line x = 2, z = 1 (along y): distance sqrt(5) from the origin, closest point (2, 0, 1).
  const PluckerLine line = PluckerLine::fromPoints({2, -1, 1}, {2, 4, 1});
  EXPECT_NEAR(line.distanceToOrigin(), std::sqrt(5.0), 1e-12);
  EXPECT_LT((line.closestPointToOrigin() - Eigen::Vector3d(2, 0, 1)).norm(), 1e-12);
  EXPECT_NEAR(line.distanceTo({0, 7, 1}), 2.0, 1e-12);
  EXPECT_NEAR(line.distanceTo({2, 3, 1}), 0.0, 1e-12);
}

TEST(PluckerLine, ProjectionIsTheImageLineOfProjectedPoints) {
  std::mt19937 rng(5);
  const double fx = 458.6, fy = 457.3, cx = 367.2, cy = 248.4;
  for (int k = 0; k < 20; ++k) {
    const Eigen::Isometry3d T_c_w = test::randomPose(rng, 1.0);
    // Points in front of the camera, expressed in the world.
    const Eigen::Vector3d p_c(0.5, -0.2, 3.0), q_c(-0.7, 0.4, 5.0);
    const Eigen::Vector3d p_c2 = p_c + test::randomVector(rng, 0.3);
    const Eigen::Vector3d q_c2 = q_c + test::randomVector(rng, 0.3);
    const PluckerLine L_w = PluckerLine::fromPoints(T_c_w.inverse() * p_c2, T_c_w.inverse() * q_c2);
    const Eigen::Vector3d l = L_w.transformed(T_c_w).normalisedImageLine();
    for (const Eigen::Vector3d& x : {p_c2, q_c2, Eigen::Vector3d(0.3 * p_c2 + 0.7 * q_c2)}) {
      EXPECT_NEAR(pointToImageLineDistance(x.head<2>() / x.z(), l), 0.0, 1e-9);
      const Eigen::Vector2d px(fx * x.x() / x.z() + cx, fy * x.y() / x.z() + cy);
      EXPECT_NEAR(pointToImageLineDistance(px, pixelImageLine(l, fx, fy, cx, cy)), 0.0, 1e-7);
    }
  }
}

TEST(OrthonormalLine, RoundTripThroughPlucker) {
  std::mt19937 rng(6);
  for (int k = 0; k < 50; ++k) {
    const PluckerLine line = randomLine(rng);
    const OrthonormalLine o = OrthonormalLine::fromPlucker(line);
    EXPECT_LT((o.U.transpose() * o.U - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    EXPECT_NEAR(o.U.determinant(), 1.0, 1e-12);
    EXPECT_GE(o.phi, 0.0);
    EXPECT_LE(o.phi, kPi / 2);
    const PluckerLine back = o.toPlucker();
    EXPECT_NEAR(back.n.squaredNorm() + back.d.squaredNorm(), 1.0, 1e-12);
    EXPECT_TRUE(test::sameLine(back, line, 1e-10));
    // Orientation is kept too: d points the same way.
    EXPECT_GT(back.d.dot(line.d), 0.0);
    EXPECT_NEAR(back.distanceToOrigin(), line.distanceToOrigin(), 1e-9);

    // And through the 4-double parameter block.
    double x[4];
    o.toParameters(x);
    EXPECT_LE(Eigen::Vector3d(x[0], x[1], x[2]).norm(), kPi + 1e-12);
    EXPECT_TRUE(test::sameLine(pluckerFromParameters(x), line, 1e-10));
  }
}

TEST(OrthonormalLine, LineThroughTheOrigin) {
  const PluckerLine line(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 2));
  const OrthonormalLine o = OrthonormalLine::fromPlucker(line);
  EXPECT_NEAR(o.phi, kPi / 2, 1e-12);
  EXPECT_LT((o.U.transpose() * o.U - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_TRUE(test::sameLine(o.toPlucker(), line, 1e-12));
}

TEST(OrthonormalLine, PluckerJacobianWrtTangentMatchesNumeric) {
  std::mt19937 rng(7);
  for (int k = 0; k < 20; ++k) {
    const Eigen::Vector4d x = randomLineParameters(rng);
    const Eigen::MatrixXd numeric = numericJacobian(
        [&](const Eigen::VectorXd& delta) -> Eigen::VectorXd {
          const PluckerLine L = pluckerFromParameters(plus(x, delta).data());
          Eigen::VectorXd nd(6);
          nd << L.n, L.d;
          return nd;
        },
        Eigen::VectorXd::Zero(4));
    EXPECT_LT((numeric - pluckerJacobianWrtTangent(x.data())).norm(), 1e-7);
  }
}

TEST(OrthonormalLineManifold, PlusMinusAreInverse) {
  std::mt19937 rng(8);
  for (int k = 0; k < 50; ++k) {
    const Eigen::Vector4d x = randomLineParameters(rng), y = randomLineParameters(rng);
    EXPECT_LT((plus(x, Eigen::Vector4d::Zero()) - x).norm(), 1e-12);
    EXPECT_LT(minus(x, x).norm(), 1e-12);
    // Plus(x, Minus(y, x)) = y.
    EXPECT_LT((plus(x, minus(y, x)) - y).norm(), 1e-9);
    // Minus(Plus(x, delta), x) = delta for deltas within the injectivity radius.
    Eigen::Vector4d delta;
    delta << test::randomVector(rng, 1.0), std::uniform_real_distribution<double>(-3, 3)(rng);
    EXPECT_LT((minus(plus(x, delta), x) - delta).norm(), 1e-9);
  }
}

TEST(OrthonormalLineManifold, PlusMovesTheLineAsTheTangentSays) {
  // The tangent update is U <- U Exp(dtheta), phi <- phi + dphi.
  const Eigen::Vector4d x(0.3, -0.2, 1.1, 0.7);
  const Eigen::Vector4d delta(0.05, 0.1, -0.02, 0.3);
  const OrthonormalLine moved = OrthonormalLine::fromParameters(plus(x, delta).data());
  const OrthonormalLine start = OrthonormalLine::fromParameters(x.data());
  EXPECT_LT((moved.U - start.U * expSO3(delta.head<3>())).norm(), 1e-12);
  EXPECT_NEAR(moved.phi, 1.0, 1e-12);
  // phi wraps into (-pi, pi].
  EXPECT_NEAR(plus(Eigen::Vector4d(0, 0, 0, 3.0), Eigen::Vector4d(0, 0, 0, 0.5))[3], 3.5 - 2 * kPi,
              1e-12);
}

TEST(OrthonormalLineManifold, JacobiansMatchNumericIncludingNearPi) {
  std::mt19937 rng(9);
  OrthonormalLineManifold manifold;
  for (int k = 0; k < 30; ++k) {
    Eigen::Vector4d x = randomLineParameters(rng);
    if (k < 5) x.head<3>() = x.head<3>().normalized() * (kPi - 1e-3);  // near the cut
    if (k == 5) x.head<3>().setZero();
    Eigen::Matrix<double, 4, 4, Eigen::RowMajor> J_plus, J_minus;
    manifold.PlusJacobian(x.data(), J_plus.data());
    manifold.MinusJacobian(x.data(), J_minus.data());
    const Eigen::MatrixXd plus_numeric =
        numericJacobian([&](const Eigen::VectorXd& d) -> Eigen::VectorXd { return plus(x, d); },
                        Eigen::VectorXd::Zero(4), 1e-7);
    const Eigen::MatrixXd minus_numeric = numericJacobian(
        [&](const Eigen::VectorXd& y) -> Eigen::VectorXd { return minus(y, x); }, x, 1e-7);
    EXPECT_LT((plus_numeric - J_plus).norm(), 1e-6) << "x = " << x.transpose();
    EXPECT_LT((minus_numeric - J_minus).norm(), 1e-6) << "x = " << x.transpose();
    EXPECT_LT((J_minus * J_plus - Eigen::Matrix4d::Identity()).norm(), 1e-9);
  }
}
