#include "alvio/geometry/line_quality.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "alvio/common/angles.h"
#include "alvio/geometry/line_projection_factor.h"
#include "alvio/geometry/orthonormal_line.h"
#include "alvio/geometry/orthonormal_line_manifold.h"

namespace alvio {

bool imageLineEndpointDistances(const PluckerLine& line_c, const Eigen::Vector2d& start_norm,
                                const Eigen::Vector2d& end_norm, double* start, double* end) {
  const Eigen::Vector3d& l = line_c.normalisedImageLine();
  const double norm = l.head<2>().norm();
  if (norm < 1e-12) return false;
  *start = std::abs(start_norm.homogeneous().dot(l)) / norm;
  *end = std::abs(end_norm.homogeneous().dot(l)) / norm;
  return true;
}

bool lineEndpointDistances(const PluckerLine& line_w, const LineView& view, double* start,
                           double* end) {
  return imageLineEndpointDistances(line_w.transformed(view.T_w_c.inverse()), view.start_norm,
                                    view.end_norm, start, end);
}

double lineReprojectionRms(const PluckerLine& line_w, const LineViews& views) {
  if (views.empty()) return 0;
  double sum = 0;
  for (const LineView& v : views) {
    double a = 0, b = 0;
    if (!lineEndpointDistances(line_w, v, &a, &b)) return std::numeric_limits<double>::infinity();
    sum += a * a + b * b;
  }
  return std::sqrt(sum / (2.0 * static_cast<double>(views.size())));
}

double lineCrossParallax(const Eigen::Vector3d& start_w, const Eigen::Vector3d& end_w,
                         const LineViews& views) {
  if (views.size() < 2 || (end_w - start_w).norm() <= 0) return 0;
  const Eigen::Vector3d mid = 0.5 * (start_w + end_w);
  const Eigen::Vector3d u = (end_w - start_w).normalized();
  Eigen::Vector3d mean_ray = Eigen::Vector3d::Zero();
  std::vector<double> distances;
  distances.reserve(views.size());
  for (const LineView& v : views) {
    const Eigen::Vector3d ray = mid - v.T_w_c.translation();
    distances.push_back(ray.norm());
    if (distances.back() > 0) mean_ray += ray / distances.back();
  }
  mean_ray -= u * u.dot(mean_ray);
  if (mean_ray.norm() < 1e-9) return 0;  // seen end-on
  // Moving along n (normal of the plane spanned by the line and the ray) turns that plane.
  const Eigen::Vector3d n = u.cross(mean_ray.normalized());
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const LineView& v : views) {
    const double x = n.dot(v.T_w_c.translation());
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  auto median = distances.begin() + static_cast<std::ptrdiff_t>(distances.size() / 2);
  std::nth_element(distances.begin(), median, distances.end());
  return *median > 0 ? (hi - lo) / *median : 0;
}

namespace {
// Covariance of the four tangent parameters of the orthonormal representation at x: the
// inverse of the views' information, whitened by sigma. False when the views leave a
// direction unconstrained.
bool tangentCovariance(const double* x, const LineViews& views, double sigma, Eigen::Matrix4d* C) {
  Eigen::Matrix<double, 4, 4, Eigen::RowMajor> plus_jacobian;
  OrthonormalLineManifold().PlusJacobian(x, plus_jacobian.data());
  Eigen::Matrix4d H = Eigen::Matrix4d::Zero();
  for (const auto& v : views) {
    const LineProjectionFactor f(v.start_norm, v.end_norm, Eigen::Isometry3d::Identity(),
                                 1.0 / sigma);
    double pose[7];
    poseToParameters(v.T_w_c, pose);
    const double* params[] = {pose, x};
    Eigen::Vector2d r;
    Eigen::Matrix<double, 2, 4, Eigen::RowMajor> J;
    double* jacobians[] = {nullptr, J.data()};
    if (!f.Evaluate(params, r.data(), jacobians)) continue;
    const Eigen::Matrix<double, 2, 4> Jt = J * plus_jacobian;
    H += Jt.transpose() * Jt;
  }
  const Eigen::FullPivLU<Eigen::Matrix4d> lu(H);
  if (!lu.isInvertible()) return false;
  *C = lu.inverse();
  return true;
}

// dtheta_x and dtheta_z turn the direction.
double directionStdDeg(const Eigen::Matrix4d& C) {
  return std::sqrt(std::max(0.0, C(0, 0) + C(2, 2))) * kRadToDeg;
}
}  // namespace

double lineDirectionStdDeg(const PluckerLine& line_w, const LineViews& views, double sigma) {
  double x[4];
  OrthonormalLine::fromPlucker(line_w).toParameters(x);
  Eigen::Matrix4d C;
  return tangentCovariance(x, views, sigma, &C) ? directionStdDeg(C)
                                                : LineUncertainty().direction_std_deg;
}

LineUncertainty lineUncertainty(const PluckerLine& line_w, const Eigen::Vector3d& midpoint_w,
                                const LineViews& views, double sigma) {
  double x[4];
  OrthonormalLine::fromPlucker(line_w).toParameters(x);
  LineUncertainty u;
  Eigen::Matrix4d C;
  if (!tangentCovariance(x, views, sigma, &C)) return u;
  u.direction_std_deg = directionStdDeg(C);
  // How the line's point nearest the midpoint moves with each tangent step (central
  // differences; the step is small against any line a camera resolves).
  const auto nearest = [&](const double* xp) {
    const PluckerLine l = pluckerFromParameters(xp);
    const Eigen::Vector3d d = l.d.normalized();
    const Eigen::Vector3d p = l.closestPointToOrigin();
    return Eigen::Vector3d(p + d * d.dot(midpoint_w - p));
  };
  const OrthonormalLineManifold manifold;
  Eigen::Matrix<double, 3, 4> Jm;
  const double h = 1e-6;
  for (int k = 0; k < 4; ++k) {
    double step[4] = {0, 0, 0, 0}, plus[4], minus[4];
    step[k] = h;
    manifold.Plus(x, step, plus);
    step[k] = -h;
    manifold.Plus(x, step, minus);
    Jm.col(k) = (nearest(plus) - nearest(minus)) / (2 * h);
  }
  u.midpoint_std_m = std::sqrt(std::max(0.0, (Jm * C * Jm.transpose()).trace()));
  return u;
}

}  // namespace alvio
