#include "alvio/geometry/line_triangulation.h"

#include <ceres/loss_function.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>

#include "alvio/common/angles.h"
#include "alvio/common/error.h"
#include "alvio/config/yaml_reader.h"
#include "alvio/geometry/line_projection_factor.h"
#include "alvio/geometry/orthonormal_line.h"
#include "alvio/geometry/orthonormal_line_manifold.h"

namespace alvio {
namespace {

Eigen::Vector3d homogeneous(const Eigen::Vector2d& p) {
  return {p.x(), p.y(), 1.0};
}

// The back-projected plane of a view in the world frame: a . x + b = 0, |a| = 1.
struct Plane {
  Eigen::Vector3d a;
  double b;
};
Plane backProjectedPlane(const LineView& v) {
  const Eigen::Vector3d a_c = homogeneous(v.start_norm).cross(homogeneous(v.end_norm));
  const Eigen::Vector3d a = (v.T_w_c.linear() * a_c).normalized();
  return {a, -a.dot(v.T_w_c.translation())};
}

// Are both endpoints' rays of the view met by the line at a depth >= min_depth?
bool inFrontOf(const PluckerLine& line_w, const LineView& v, double min_depth) {
  const Eigen::Matrix3d& R = v.T_w_c.linear();
  for (const Eigen::Vector2d& p : {v.start_norm, v.end_norm}) {
    double s, depth;  // the ray direction has unit z in the camera, so t is the depth
    if (!closestPointOnLineToRay(line_w, v.T_w_c.translation(), R * homogeneous(p), &s, &depth))
      return false;
    if (depth < min_depth) return false;
  }
  return true;
}

// sin of the angle between the planes, or a negative value if the pair is degenerate.
double pairConditioning(const LineView& a, const LineView& b, const LineTriangulationOptions& o,
                        LineTriangulationStatus* status) {
  const Eigen::Vector3d baseline = b.T_w_c.translation() - a.T_w_c.translation();
  if (baseline.norm() < o.min_baseline) {
    *status = LineTriangulationStatus::kBaselineTooSmall;
    return -1.0;
  }
  const Plane pa = backProjectedPlane(a), pb = backProjectedPlane(b);
  const Eigen::Vector3d base_dir = baseline.normalized();
  const double min_epipole_sin = std::sin(o.min_epipole_angle_deg * kDegToRad);
  if (std::abs(pa.a.dot(base_dir)) < min_epipole_sin ||
      std::abs(pb.a.dot(base_dir)) < min_epipole_sin) {
    *status = LineTriangulationStatus::kNearEpipole;
    return -1.0;
  }
  const double plane_sin = pa.a.cross(pb.a).norm();
  if (plane_sin < std::sin(o.min_plane_angle_deg * kDegToRad)) {
    *status = LineTriangulationStatus::kPlanesNearlyParallel;
    return -1.0;
  }
  *status = LineTriangulationStatus::kOk;
  return plane_sin;
}
}  // namespace

LineTriangulationOptions LineTriangulationOptions::load(const YamlReader& yaml,
                                                        const std::string& prefix) {
  LineTriangulationOptions o;
  const std::string p = prefix.empty() ? "" : prefix + ".";
  o.min_plane_angle_deg = yaml.getDouble(p + "min_plane_angle_deg", o.min_plane_angle_deg);
  o.min_epipole_angle_deg = yaml.getDouble(p + "min_epipole_angle_deg", o.min_epipole_angle_deg);
  o.min_baseline = yaml.getDouble(p + "min_baseline", o.min_baseline);
  o.min_depth = yaml.getDouble(p + "min_depth", o.min_depth);
  o.refine_max_iterations = yaml.getInt(p + "refine_max_iterations", o.refine_max_iterations);
  o.refine_huber_scale = yaml.getDouble(p + "refine_huber_scale", o.refine_huber_scale);
  o.extent_min_ray_angle_deg =
      yaml.getDouble(p + "extent_min_ray_angle_deg", o.extent_min_ray_angle_deg);
  o.extent_trim_fraction = yaml.getDouble(p + "extent_trim_fraction", o.extent_trim_fraction);
  o.validate(yaml.path() + ": " + prefix);
  return o;
}

void LineTriangulationOptions::validate(const std::string& where) const {
  auto check = [&](bool ok, const std::string& key, const std::string& what) {
    if (!ok) throw Error(where + "." + key + " " + what);
  };
  check(min_plane_angle_deg > 0 && min_plane_angle_deg < 90, "min_plane_angle_deg",
        "must be in (0, 90)");
  check(min_epipole_angle_deg >= 0 && min_epipole_angle_deg < 90, "min_epipole_angle_deg",
        "must be in [0, 90)");
  check(min_baseline > 0, "min_baseline", "must be positive");
  check(min_depth >= 0, "min_depth", "must not be negative");
  check(refine_max_iterations >= 0, "refine_max_iterations", "must not be negative");
  check(refine_huber_scale >= 0, "refine_huber_scale", "must not be negative");
  check(extent_trim_fraction >= 0 && extent_trim_fraction < 0.5, "extent_trim_fraction",
        "must be in [0, 0.5)");
  check(extent_min_ray_angle_deg >= 0 && extent_min_ray_angle_deg < 90, "extent_min_ray_angle_deg",
        "must be in [0, 90)");
}

const char* toString(LineTriangulationStatus status) {
  switch (status) {
    case LineTriangulationStatus::kOk:
      return "ok";
    case LineTriangulationStatus::kTooFewViews:
      return "too few views";
    case LineTriangulationStatus::kBaselineTooSmall:
      return "baseline too small";
    case LineTriangulationStatus::kNearEpipole:
      return "line through the epipole";
    case LineTriangulationStatus::kPlanesNearlyParallel:
      return "planes nearly parallel";
    case LineTriangulationStatus::kBehindCamera:
      return "behind a camera";
    case LineTriangulationStatus::kRefinementFailed:
      return "refinement failed";
  }
  return "unknown";
}

LineTriangulationStatus triangulateLine(const LineView& a, const LineView& b,
                                        const LineTriangulationOptions& options,
                                        PluckerLine* line_w) {
  LineTriangulationStatus status;
  if (pairConditioning(a, b, options, &status) < 0.0) return status;
  const Plane pa = backProjectedPlane(a), pb = backProjectedPlane(b);
  // Entries of L* = pi_a pi_b^T - pi_b pi_a^T.
  const PluckerLine line(pa.b * pb.a - pb.b * pa.a, pa.a.cross(pb.a));
  if (!inFrontOf(line, a, options.min_depth) || !inFrontOf(line, b, options.min_depth))
    return LineTriangulationStatus::kBehindCamera;
  *line_w = line.normalized();
  return LineTriangulationStatus::kOk;
}

LineTriangulationStatus triangulateLineMultiView(const LineViews& views,
                                                 const LineTriangulationOptions& options,
                                                 PluckerLine* line_w) {
  if (views.size() < 2) return LineTriangulationStatus::kTooFewViews;
  // Rank the pairs by plane angle; the first one that triangulates seeds the refinement.
  struct Pair {
    double score;
    std::size_t i, j;
  };
  std::vector<Pair> pairs;
  LineTriangulationStatus first_failure = LineTriangulationStatus::kTooFewViews;
  for (std::size_t i = 0; i < views.size(); ++i) {
    for (std::size_t j = i + 1; j < views.size(); ++j) {
      LineTriangulationStatus status;
      const double score = pairConditioning(views[i], views[j], options, &status);
      if (score >= 0.0)
        pairs.push_back({score, i, j});
      else if (first_failure == LineTriangulationStatus::kTooFewViews)
        first_failure = status;
    }
  }
  std::sort(pairs.begin(), pairs.end(),
            [](const Pair& x, const Pair& y) { return x.score > y.score; });
  for (const Pair& pair : pairs) {
    PluckerLine line;
    const LineTriangulationStatus status =
        triangulateLine(views[pair.i], views[pair.j], options, &line);
    if (status != LineTriangulationStatus::kOk) {
      first_failure = status;
      continue;
    }
    if (views.size() > 2 && options.refine_max_iterations > 0) {
      if (!refineLine(views, options, &line)) return LineTriangulationStatus::kRefinementFailed;
      for (const LineView& v : views)
        if (!inFrontOf(line, v, options.min_depth)) return LineTriangulationStatus::kBehindCamera;
    }
    *line_w = line;
    return LineTriangulationStatus::kOk;
  }
  return first_failure;
}

bool refineLine(const LineViews& views, const LineTriangulationOptions& options,
                PluckerLine* line_w) {
  double line_params[4];
  OrthonormalLine::fromPlucker(*line_w).toParameters(line_params);
  std::vector<std::array<double, 7>> poses(views.size());

  OrthonormalLineManifold manifold;
  std::unique_ptr<ceres::LossFunction> loss;
  if (options.refine_huber_scale > 0.0)
    loss = std::make_unique<ceres::HuberLoss>(options.refine_huber_scale);
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  problem.AddParameterBlock(line_params, 4, &manifold);
  for (std::size_t k = 0; k < views.size(); ++k) {
    poseToParameters(views[k].T_w_c, poses[k].data());
    // The camera pose stands in for the body pose: T_b_c = identity.
    auto* factor = new LineProjectionFactor(views[k].start_norm, views[k].end_norm,
                                            Eigen::Isometry3d::Identity());
    problem.AddResidualBlock(factor, loss.get(), poses[k].data(), line_params);
    problem.SetParameterBlockConstant(poses[k].data());
  }
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = options.refine_max_iterations;
  solver_options.logging_type = ceres::SILENT;
  solver_options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  if (!summary.IsSolutionUsable()) return false;
  *line_w = pluckerFromParameters(line_params).normalized();
  return true;
}

bool closestPointOnLineToRay(const PluckerLine& line, const Eigen::Vector3d& o,
                             const Eigen::Vector3d& r, double* s_line, double* t_ray) {
  // Minimise |p0 + s u - o - t r|^2 with u = d/|d|; the normal equations give t, then s.
  const Eigen::Vector3d u = line.d.normalized();
  const Eigen::Vector3d w0 = line.closestPointToOrigin() - o;
  const double ur = u.dot(r), rr = r.squaredNorm();
  const double denom = rr - ur * ur;  // |r|^2 sin^2(angle)
  if (denom < 1e-12 * rr) return false;
  const double uw = u.dot(w0);
  *t_ray = (r.dot(w0) - uw * ur) / denom;
  *s_line = *t_ray * ur - uw;
  return true;
}

bool lineExtent(const PluckerLine& line_w, const LineViews& views, Eigen::Vector3d* start_w,
                Eigen::Vector3d* end_w, const LineTriangulationOptions& options) {
  const Eigen::Vector3d u = line_w.d.normalized();
  const double max_cos = std::cos(options.extent_min_ray_angle_deg * kDegToRad);
  // Each view's observed part [lo, hi] along the line.
  std::vector<double> los, his;
  for (const LineView& v : views) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const Eigen::Vector2d& p : {v.start_norm, v.end_norm}) {
      const Eigen::Vector3d ray = v.T_w_c.linear() * homogeneous(p);
      if (std::abs(u.dot(ray)) > max_cos * ray.norm()) continue;
      double s, t;
      if (!closestPointOnLineToRay(line_w, v.T_w_c.translation(), ray, &s, &t) || t <= 0.0)
        continue;
      lo = std::min(lo, s);
      hi = std::max(hi, s);
    }
    if (lo > hi) continue;
    los.push_back(lo);
    his.push_back(hi);
  }
  if (los.empty()) return false;
  // The union, without the views reaching furthest out at each end.
  const std::size_t k = static_cast<std::size_t>(options.extent_trim_fraction * los.size());
  std::nth_element(los.begin(), los.begin() + k, los.end());
  std::nth_element(his.begin(), his.begin() + k, his.end(), std::greater<double>());
  const double s_min = los[k], s_max = std::max(his[k], s_min);
  const Eigen::Vector3d p0 = line_w.closestPointToOrigin();
  *start_w = p0 + s_min * u;
  *end_w = p0 + s_max * u;
  return true;
}

}  // namespace alvio
