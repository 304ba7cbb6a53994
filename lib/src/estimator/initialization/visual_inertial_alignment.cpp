#include "alvio/estimator/initialization/visual_inertial_alignment.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

namespace alvio {
namespace {

// Gyroscope bias from the rotations between consecutive frames. Each residual is linear in
// the bias's offset from the preintegration's own linearisation bias, which after a reset is
// the bias kept from the run before, not zero: solve for the bias itself.
Eigen::Vector3d solveGyroBias(const std::vector<AlignmentFrame>& frames) {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (std::size_t k = 1; k < frames.size(); ++k) {
    const ImuPreintegration& pre = *frames[k].imu;
    const Eigen::Quaterniond q_ij(frames[k - 1].R_c0_b.transpose() * frames[k].R_c0_b);
    const Eigen::Matrix3d J = pre.jacobian().block<3, 3>(kIdxQ, kIdxBg);
    const Eigen::Vector3d r = 2.0 * (pre.deltaQ().inverse() * q_ij).vec();
    A += J.transpose() * J;
    b += J.transpose() * (r + J * pre.linearizedBg());
  }
  return A.ldlt().solve(b);
}

// Two unit vectors orthogonal to g (and each other).
Eigen::Matrix<double, 3, 2> tangentBasis(const Eigen::Vector3d& g) {
  const Eigen::Vector3d a = g.normalized();
  Eigen::Vector3d tmp(0, 0, 1);
  if ((a - tmp).norm() < 1e-6) tmp = Eigen::Vector3d(1, 0, 0);
  const Eigen::Vector3d b = (tmp - a * a.dot(tmp)).normalized();
  Eigen::Matrix<double, 3, 2> B;
  B.col(0) = b;
  B.col(1) = a.cross(b);
  return B;
}

// Scales the normal equations (not zz) for a better-conditioned solve.
constexpr double kConditioning = 1000.0;

// The normal equations over [v_0..v_n (body frames), gravity terms, 100 s].
struct LinearSystem {
  Eigen::MatrixXd A;
  Eigen::VectorXd b;
  double zz = 0;  ///< sum of z'z: with x'b it gives the residuals' sum of squares
  int rows = 0;   ///< of the stacked system
};

// Builds the normal equations. With `g_fixed` given, gravity is g_fixed + B w (2 unknowns);
// otherwise it is 3 unknowns. Scale is estimated as 100 s so the unknowns are of similar
// magnitude.
LinearSystem buildLinearSystem(const std::vector<AlignmentFrame>& frames,
                               const Eigen::Vector3d& t_b_c, const Eigen::Vector3d* g_fixed,
                               const Eigen::Matrix<double, 3, 2>* B) {
  const int n_frames = static_cast<int>(frames.size());
  const int n_g = g_fixed ? 2 : 3;
  const int n = 3 * n_frames + n_g + 1;
  const int extra = n_g + 1;
  LinearSystem sys;
  sys.A = Eigen::MatrixXd::Zero(n, n);
  sys.b = Eigen::VectorXd::Zero(n);
  sys.rows = 6 * (n_frames - 1);
  for (int k = 1; k < n_frames; ++k) {
    const auto& fi = frames[k - 1];
    const auto& fj = frames[k];
    const ImuPreintegration& pre = *fj.imu;
    const double dt = pre.sumDt();
    const Eigen::Matrix3d RiT = fi.R_c0_b.transpose();
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(6, 6 + extra);
    Eigen::VectorXd z(6);
    H.block<3, 3>(0, 0) = -dt * Eigen::Matrix3d::Identity();
    H.block<3, 3>(3, 0) = -Eigen::Matrix3d::Identity();
    H.block<3, 3>(3, 3) = RiT * fj.R_c0_b;
    const Eigen::Matrix3d Gp = RiT * dt * dt / 2, Gv = RiT * dt;
    z.head<3>() = pre.deltaP() + RiT * fj.R_c0_b * t_b_c - t_b_c;
    z.tail<3>() = pre.deltaV();
    if (g_fixed) {
      H.block<3, 2>(0, 6) = Gp * *B;
      H.block<3, 2>(3, 6) = Gv * *B;
      z.head<3>() -= Gp * *g_fixed;
      z.tail<3>() -= Gv * *g_fixed;
    } else {
      H.block<3, 3>(0, 6) = Gp;
      H.block<3, 3>(3, 6) = Gv;
    }
    H.block<3, 1>(0, 6 + n_g) = RiT * (fj.p_c0_c - fi.p_c0_c) / 100.0;
    sys.zz += z.squaredNorm();
    const Eigen::MatrixXd HtH = H.transpose() * H;
    const Eigen::VectorXd Htz = H.transpose() * z;
    const int iv = 3 * (k - 1);
    sys.A.block(iv, iv, 6, 6) += HtH.topLeftCorner(6, 6);
    sys.b.segment(iv, 6) += Htz.head(6);
    sys.A.bottomRightCorner(extra, extra) += HtH.bottomRightCorner(extra, extra);
    sys.b.tail(extra) += Htz.tail(extra);
    sys.A.block(iv, n - extra, 6, extra) += HtH.topRightCorner(6, extra);
    sys.A.block(n - extra, iv, extra, 6) += HtH.bottomLeftCorner(extra, 6);
  }
  sys.A *= kConditioning;
  sys.b *= kConditioning;
  return sys;
}

struct LinearSolution {
  Eigen::VectorXd x;  ///< [v_0..v_n, gravity terms, 100 s]
  /// The last unknown's (100 s) standard deviation for rows of unit noise: how weakly the
  /// window's motion ties the scale down, whatever the noise.
  double scale_sigma_per_noise = 0;
  double residual_rms = 0;  ///< of the rows (m, m/s)
};

// Solves the system; with `quality`, also the scale's spread and the residuals' (the
// unrefined first solve only needs x).
LinearSolution solveLinear(const LinearSystem& sys, bool quality) {
  const int n = static_cast<int>(sys.b.size());
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(sys.A);
  LinearSolution solution;
  solution.x = ldlt.solve(sys.b);
  if (!quality) return solution;
  const double inverse_ss = kConditioning * ldlt.solve(Eigen::VectorXd::Unit(n, n - 1))[n - 1];
  solution.scale_sigma_per_noise = std::sqrt(std::max(0.0, inverse_ss));
  if (sys.rows > n) {
    const double rss = sys.zz - solution.x.dot(sys.b) / kConditioning;
    solution.residual_rms = std::sqrt(std::max(0.0, rss) / (sys.rows - n));
  }
  return solution;
}

}  // namespace

bool alignVisualInertial(std::vector<AlignmentFrame>& frames, const Eigen::Vector3d& t_b_c,
                         double gravity_magnitude, AlignmentResult* result) {
  if (frames.size() < 3) {
    result->failure = "fewer than 3 frames";
    return false;
  }
  result->gyro_bias = solveGyroBias(frames);
  for (std::size_t k = 1; k < frames.size(); ++k)
    frames[k].imu->repropagate(Eigen::Vector3d::Zero(), result->gyro_bias);

  const int n_frames = static_cast<int>(frames.size());
  Eigen::VectorXd x = solveLinear(buildLinearSystem(frames, t_b_c, nullptr, nullptr), false).x;
  Eigen::Vector3d g = x.segment<3>(3 * n_frames);
  double scale = x[3 * n_frames + 3] / 100.0;
  if (std::abs(g.norm() - gravity_magnitude) > 1.0 || scale < 0) {
    result->failure = "implausible linear solution: |g| = " + std::to_string(g.norm()) +
                      " m/s^2, scale = " + std::to_string(scale);
    return false;
  }
  // Refine with the gravity magnitude fixed: iterate on its 2-DoF tangent space.
  Eigen::Vector3d g0 = g.normalized() * gravity_magnitude;
  LinearSolution refined;
  for (int it = 0; it < 4; ++it) {
    const Eigen::Matrix<double, 3, 2> B = tangentBasis(g0);
    refined = solveLinear(buildLinearSystem(frames, t_b_c, &g0, &B), true);
    x = refined.x;
    g0 = (g0 + B * x.segment<2>(3 * n_frames)).normalized() * gravity_magnitude;
  }
  scale = x[3 * n_frames + 2] / 100.0;
  if (scale < 0) {
    result->failure = "negative scale after gravity refinement";
    return false;
  }
  // sigma(s) / s = noise / (100 s / sigma per noise): the quotient is a length.
  const double motion = 100.0 * scale / refined.scale_sigma_per_noise;
  result->scale_motion_m = std::isfinite(motion) ? motion : 0.0;
  result->residual_rms = refined.residual_rms;
  result->gravity_c0 = g0;
  result->scale = scale;
  result->velocities_body.clear();
  for (int k = 0; k < n_frames; ++k) result->velocities_body.push_back(x.segment<3>(3 * k));
  return true;
}

}  // namespace alvio
