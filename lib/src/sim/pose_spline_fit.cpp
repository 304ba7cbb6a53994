#include "alvio/sim/pose_spline_fit.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "alvio/common/angles.h"
#include "alvio/common/error.h"
#include "alvio/sim/so3.h"

namespace alvio::sim {
namespace {

// Pose at time t by linear/slerp interpolation of the samples (for initial values).
StampedPose interpolateSamples(const Trajectory& s, double t) {
  if (t <= s.front().t) return s.front();
  if (t >= s.back().t) return s.back();
  const auto it = std::lower_bound(s.begin(), s.end(), t,
                                   [](const StampedPose& p, double x) { return p.t < x; });
  const StampedPose& b = *it;
  const StampedPose& a = *(it - 1);
  const double f = (t - a.t) / (b.t - a.t);
  StampedPose out;
  out.t = t;
  out.p = a.p + f * (b.p - a.p);
  out.q = a.q.slerp(f, b.q);
  return out;
}

struct PositionSampleCost {
  PositionSampleCost(const Eigen::Vector3d& p, double u, double inv_sigma)
      : p_(p), inv_sigma_(inv_sigma) {
    double dw[4], ddw[4];
    cubicBSplineWeights(u, w_, dw, ddw);
  }
  template <typename T>
  bool operator()(const T* c0, const T* c1, const T* c2, const T* c3, T* r) const {
    for (int k = 0; k < 3; ++k)
      r[k] = (T(w_[0]) * c0[k] + T(w_[1]) * c1[k] + T(w_[2]) * c2[k] + T(w_[3]) * c3[k] - p_[k]) *
             inv_sigma_;
    return true;
  }
  Eigen::Vector3d p_;
  double w_[4];
  double inv_sigma_;
};

struct PositionSmoothnessCost {
  explicit PositionSmoothnessCost(double weight) : weight_(weight) {}
  template <typename T>
  bool operator()(const T* a, const T* b, const T* c, T* r) const {
    for (int k = 0; k < 3; ++k) r[k] = (a[k] - T(2) * b[k] + c[k]) * weight_;
    return true;
  }
  double weight_;
};

// Ceres stores quaternions as [w, x, y, z].
template <typename T>
Eigen::Quaternion<T> toQuat(const T* q) {
  return Eigen::Quaternion<T>(q[0], q[1], q[2], q[3]);
}

struct RotationSampleCost {
  RotationSampleCost(const Eigen::Quaterniond& q, double u, double inv_sigma)
      : q_inv_(q.conjugate()), inv_sigma_(inv_sigma) {
    double dw[3];
    cumulativeBSplineWeights(u, w_, dw);
  }
  template <typename T>
  bool operator()(const T* q0, const T* q1, const T* q2, const T* q3, T* r) const {
    const Eigen::Quaternion<T> Q[4] = {toQuat(q0), toQuat(q1), toQuat(q2), toQuat(q3)};
    Eigen::Quaternion<T> q = Q[0];
    for (int j = 0; j < 3; ++j) {
      const Eigen::Matrix<T, 3, 1> d = so3Log<T>(Q[j].conjugate() * Q[j + 1]);
      q = q * so3Exp<T>(d * T(w_[j]));
    }
    const Eigen::Matrix<T, 3, 1> e = so3Log<T>(q_inv_.cast<T>() * q);
    for (int k = 0; k < 3; ++k) r[k] = e[k] * inv_sigma_;
    return true;
  }
  Eigen::Quaterniond q_inv_;
  double w_[3];
  double inv_sigma_;
};

struct RotationSmoothnessCost {
  explicit RotationSmoothnessCost(double weight) : weight_(weight) {}
  template <typename T>
  bool operator()(const T* a, const T* b, const T* c, T* r) const {
    const Eigen::Matrix<T, 3, 1> d1 = so3Log<T>(toQuat(a).conjugate() * toQuat(b));
    const Eigen::Matrix<T, 3, 1> d2 = so3Log<T>(toQuat(b).conjugate() * toQuat(c));
    for (int k = 0; k < 3; ++k) r[k] = (d2[k] - d1[k]) * weight_;
    return true;
  }
  double weight_;
};

ceres::Solver::Options solverOptions(const SplineFitOptions& o) {
  ceres::Solver::Options s;
  s.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  s.max_num_iterations = o.max_iterations;
  s.num_threads = 1;  // determinism
  s.function_tolerance = 1e-10;
  s.logging_type = ceres::SILENT;
  return s;
}

}  // namespace

std::string SplineFitReport::summary() const {
  std::ostringstream os;
  os << std::fixed << std::setprecision(4) << "spline fit over " << samples
     << " poses: position RMS " << position_rms_m << " m, max " << position_max_m
     << " m (at t=" << std::setprecision(3) << max_error_time << "), rotation RMS "
     << std::setprecision(4) << rotation_rms_deg << " deg, max " << rotation_max_deg << " deg";
  return os.str();
}

PoseSpline fitPoseSpline(const Trajectory& samples, const SplineFitOptions& o,
                         SplineFitReport* report) {
  if (samples.size() < 2) throw Error("spline fit needs at least 2 poses");
  const double t0 = samples.front().t;
  const double dt = o.knot_spacing_s;
  const int segments =
      std::max(1, static_cast<int>(std::ceil((samples.back().t - t0) / dt - 1e-9)));
  const int n = segments + 3;

  // Initial values: the samples at the controls' times, with a continuous quaternion sign.
  Vector3dList positions(n);
  std::vector<Eigen::Vector4d, Eigen::aligned_allocator<Eigen::Vector4d>> quats(n);
  Eigen::Quaterniond previous = samples.front().q;
  for (int j = 0; j < n; ++j) {
    const StampedPose p = interpolateSamples(samples, t0 + (j - 1) * dt);
    positions[j] = p.p;
    Eigen::Quaterniond q = p.q;
    if (q.dot(previous) < 0) q.coeffs() = -q.coeffs();
    previous = q;
    quats[j] << q.w(), q.x(), q.y(), q.z();
  }

  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem position_problem, rotation_problem(problem_options);
  ceres::QuaternionManifold quaternion_manifold;
  // Regularisation weights: the second difference over dt^2 is the acceleration.
  const double position_weight = 1.0 / (o.acceleration_sigma * dt * dt);
  const double rotation_weight = 1.0 / (o.angular_acceleration_sigma * dt * dt);
  for (const StampedPose& s : samples) {
    const double x = (s.t - t0) / dt;
    const int i = std::clamp(static_cast<int>(std::floor(x)), 0, segments - 1);
    const double u = std::clamp(x - i, 0.0, 1.0);
    position_problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<PositionSampleCost, 3, 3, 3, 3, 3>(
            new PositionSampleCost(s.p, u, 1.0 / o.position_sigma_m)),
        new ceres::HuberLoss(o.huber_threshold), positions[i].data(), positions[i + 1].data(),
        positions[i + 2].data(), positions[i + 3].data());
    rotation_problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<RotationSampleCost, 3, 4, 4, 4, 4>(
            new RotationSampleCost(s.q, u, 1.0 / o.rotation_sigma_rad)),
        new ceres::HuberLoss(o.huber_threshold), quats[i].data(), quats[i + 1].data(),
        quats[i + 2].data(), quats[i + 3].data());
  }
  for (int j = 1; j + 1 < n; ++j) {
    position_problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<PositionSmoothnessCost, 3, 3, 3, 3>(
            new PositionSmoothnessCost(position_weight)),
        nullptr, positions[j - 1].data(), positions[j].data(), positions[j + 1].data());
    rotation_problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<RotationSmoothnessCost, 3, 4, 4, 4>(
            new RotationSmoothnessCost(rotation_weight)),
        nullptr, quats[j - 1].data(), quats[j].data(), quats[j + 1].data());
  }
  for (int j = 0; j < n; ++j)
    if (rotation_problem.HasParameterBlock(quats[j].data()))
      rotation_problem.SetManifold(quats[j].data(), &quaternion_manifold);

  ceres::Solver::Summary summary;
  ceres::Solve(solverOptions(o), &position_problem, &summary);
  if (!summary.IsSolutionUsable())
    throw Error("spline fit (position) failed: " + summary.BriefReport());
  ceres::Solve(solverOptions(o), &rotation_problem, &summary);
  if (!summary.IsSolutionUsable())
    throw Error("spline fit (rotation) failed: " + summary.BriefReport());

  QuaternionList rotations(n);
  for (int j = 0; j < n; ++j)
    rotations[j] = Eigen::Quaterniond(quats[j][0], quats[j][1], quats[j][2], quats[j][3]);
  PoseSpline spline(t0, dt, std::move(positions), std::move(rotations));
  if (report) *report = evaluateSplineFit(spline, samples);
  return spline;
}

SplineFitReport evaluateSplineFit(const PoseSpline& spline, const Trajectory& samples) {
  SplineFitReport r;
  double sum_p = 0, sum_r = 0;
  for (const StampedPose& s : samples) {
    if (!spline.contains(s.t)) continue;
    const BodyState st = spline.state(s.t);
    const double ep = (st.p_w - s.p).norm();
    const double er = so3Log(Eigen::Quaterniond(s.q.conjugate() * st.q_w_b)).norm() * kRadToDeg;
    sum_p += ep * ep;
    sum_r += er * er;
    if (ep > r.position_max_m) {
      r.position_max_m = ep;
      r.max_error_time = s.t;
    }
    r.rotation_max_deg = std::max(r.rotation_max_deg, er);
    ++r.samples;
  }
  if (r.samples > 0) {
    r.position_rms_m = std::sqrt(sum_p / r.samples);
    r.rotation_rms_deg = std::sqrt(sum_r / r.samples);
  }
  return r;
}

}  // namespace alvio::sim
