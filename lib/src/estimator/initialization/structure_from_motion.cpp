#include "alvio/estimator/initialization/structure_from_motion.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/rotation.h>
#include <ceres/solver.h>

#include <Eigen/SVD>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "alvio/common/logging.h"

namespace alvio {
namespace {
// A frame's pose is solved from this many triangulated points at the least. 15 stopped the
// low-texture corridor from initialising again after a reset (11-14 points seen); 10 (VINS-
// Mono's limit) kept it from initialising at all on one noise seed (6-9 seen from 7 s on).
constexpr std::size_t kMinPnpPoints = 6;
}  // namespace

bool relativePoseFromEssential(const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& corr,
                               Eigen::Matrix3d* R_a_b, Eigen::Vector3d* t_a_b) {
  if (corr.size() < 15) return false;
  std::vector<cv::Point2f> a, b;
  for (const auto& [xa, xb] : corr) {
    a.emplace_back(xa.x(), xa.y());
    b.emplace_back(xb.x(), xb.y());
  }
  // The five-point algorithm, not the eight-point fundamental matrix: indoor scenes are
  // often dominated by one plane, where the eight-point solution is degenerate.
  // Normalised coordinates: the threshold 1 / 460 is about one pixel.
  cv::Mat mask;
  const cv::Mat E =
      cv::findEssentialMat(a, b, 1.0, cv::Point2d(0, 0), cv::RANSAC, 0.999, 1.0 / 460.0, mask);
  if (E.rows != 3 || E.cols != 3) return false;
  cv::Mat R, t;
  const int inliers = cv::recoverPose(E, a, b, cv::Mat::eye(3, 3, CV_64F), R, t, mask);
  if (inliers <= 12) return false;
  Eigen::Matrix3d R_b_a;
  Eigen::Vector3d t_b_a;
  cv::cv2eigen(R, R_b_a);
  cv::cv2eigen(t, t_b_a);
  *R_a_b = R_b_a.transpose();
  *t_a_b = -R_b_a.transpose() * t_b_a;
  return true;
}

namespace {

using Pose = std::pair<Eigen::Matrix3d, Eigen::Vector3d>;  // T_ref_c

// Linear triangulation from two cameras (poses T_ref_c) of normalised observations.
Eigen::Vector3d triangulateTwoViews(const Pose& c0, const Pose& c1, const Eigen::Vector2d& x0,
                                    const Eigen::Vector2d& x1) {
  auto projection = [](const Pose& c) {
    Eigen::Matrix<double, 3, 4> P;
    P.leftCols<3>() = c.first.transpose();
    P.rightCols<1>() = -c.first.transpose() * c.second;
    return P;
  };
  const auto P0 = projection(c0), P1 = projection(c1);
  Eigen::Matrix4d A;
  A.row(0) = x0.x() * P0.row(2) - P0.row(0);
  A.row(1) = x0.y() * P0.row(2) - P0.row(1);
  A.row(2) = x1.x() * P1.row(2) - P1.row(0);
  A.row(3) = x1.y() * P1.row(2) - P1.row(1);
  const Eigen::Vector4d X =
      Eigen::JacobiSVD<Eigen::Matrix4d>(A, Eigen::ComputeFullV).matrixV().col(3);
  return X.head<3>() / X[3];
}

// Reprojection error of a point in a camera given world-to-camera rotation (angle-axis)
// and translation, for the bundle adjustment.
struct ReprojectionError {
  explicit ReprojectionError(const Eigen::Vector2d& obs) : obs_(obs) {}
  template <typename T>
  bool operator()(const T* const q_c_ref, const T* const t_c_ref, const T* const point,
                  T* residual) const {
    T p[3];
    ceres::QuaternionRotatePoint(q_c_ref, point, p);
    for (int i = 0; i < 3; ++i) p[i] += t_c_ref[i];
    residual[0] = p[0] / p[2] - T(obs_.x());
    residual[1] = p[1] / p[2] - T(obs_.y());
    return true;
  }
  Eigen::Vector2d obs_;
};

}  // namespace

bool cameraPoseFromPoints(const std::vector<Eigen::Vector3d>& points,
                          const std::vector<Eigen::Vector2d>& observations,
                          Eigen::Matrix3d* R_ref_c, Eigen::Vector3d* t_ref_c) {
  if (points.size() < kMinPnpPoints) return false;
  std::vector<cv::Point3f> obj;
  std::vector<cv::Point2f> img;
  for (std::size_t i = 0; i < points.size(); ++i) {
    obj.emplace_back(points[i].x(), points[i].y(), points[i].z());
    img.emplace_back(observations[i].x(), observations[i].y());
  }
  // Initial guess: world-to-camera of the given pose.
  const Eigen::Matrix3d R_c_ref = R_ref_c->transpose();
  const Eigen::Vector3d t_c_ref = -R_c_ref * *t_ref_c;
  cv::Mat R_cv, rvec, tvec;
  cv::eigen2cv(R_c_ref, R_cv);
  cv::Rodrigues(R_cv, rvec);
  cv::eigen2cv(t_c_ref, tvec);
  if (!cv::solvePnP(obj, img, cv::Mat::eye(3, 3, CV_64F), cv::noArray(), rvec, tvec, true))
    return false;
  cv::Rodrigues(rvec, R_cv);
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  cv::cv2eigen(R_cv, R);
  cv::cv2eigen(tvec, t);
  *R_ref_c = R.transpose();
  *t_ref_c = -R.transpose() * t;
  return true;
}

bool reconstructStructure(int num_frames, int ref, const Eigen::Matrix3d& R_ref_last,
                          const Eigen::Vector3d& t_ref_last, const std::vector<SfmTrack>& tracks,
                          SfmResult* result) {
  const int last = num_frames - 1;
  std::vector<Pose> pose(num_frames);
  std::vector<bool> known(num_frames, false);
  pose[ref] = {Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()};
  pose[last] = {R_ref_last, t_ref_last};
  known[ref] = known[last] = true;
  std::map<int, Eigen::Vector3d> points;

  auto sightingIn = [](const SfmTrack& t, int frame, Eigen::Vector2d* x) {
    for (const auto& [f, xy] : t.sightings)
      if (f == frame) {
        *x = xy;
        return true;
      }
    return false;
  };
  auto triangulatePair = [&](int a, int b) {
    for (const auto& t : tracks) {
      if (points.count(t.id)) continue;
      Eigen::Vector2d xa, xb;
      if (sightingIn(t, a, &xa) && sightingIn(t, b, &xb))
        points[t.id] = triangulateTwoViews(pose[a], pose[b], xa, xb);
    }
  };
  auto solvePnP = [&](int frame, const Pose& guess) {
    std::vector<Eigen::Vector3d> pts;
    std::vector<Eigen::Vector2d> obs;
    for (const auto& t : tracks) {
      Eigen::Vector2d x;
      const auto it = points.find(t.id);
      if (it != points.end() && sightingIn(t, frame, &x)) {
        pts.push_back(it->second);
        obs.push_back(x);
      }
    }
    if (pts.size() < kMinPnpPoints) {
      logDebug("sfm: frame ", frame, " sees only ", pts.size(), " triangulated points");
      return false;
    }
    Pose p = guess;
    if (!cameraPoseFromPoints(pts, obs, &p.first, &p.second)) {
      logDebug("sfm: PnP failed for frame ", frame);
      return false;
    }
    pose[frame] = p;
    known[frame] = true;
    return true;
  };

  // Grow from the reference/last pair towards both ends of the window.
  triangulatePair(ref, last);
  for (int i = ref + 1; i < last; ++i) {
    if (!solvePnP(i, pose[i - 1])) return false;
    triangulatePair(i, last);
  }
  for (int i = ref + 1; i < last; ++i) triangulatePair(ref, i);
  for (int i = ref - 1; i >= 0; --i) {
    if (!solvePnP(i, pose[i + 1])) return false;
    triangulatePair(i, ref);
  }
  for (const auto& t : tracks) {
    if (points.count(t.id) || t.sightings.size() < 2) continue;
    const auto& first = t.sightings.front();
    const auto& lastSeen = t.sightings.back();
    points[t.id] =
        triangulateTwoViews(pose[first.first], pose[lastSeen.first], first.second, lastSeen.second);
  }

  // Points behind a camera that sees them come from near-degenerate triangulations: drop
  // them, and give up when they are many (the relative pose was probably wrong).
  int dropped = 0;
  for (auto it = points.begin(); it != points.end();) {
    bool behind = false;
    for (const auto& t : tracks) {
      if (t.id != it->first) continue;
      for (const auto& [f, xy] : t.sightings)
        behind |= (pose[f].first.transpose() * (it->second - pose[f].second)).z() <= 0;
      break;
    }
    if (behind) {
      it = points.erase(it);
      ++dropped;
    } else {
      ++it;
    }
  }
  if (dropped > static_cast<int>(points.size()) / 4) {
    logDebug("sfm: ", dropped, " points behind the cameras vs ", points.size(), " in front");
    return false;
  }
  if (logLevel() <= LogLevel::kDebug) {
    for (int f = 0; f < num_frames; ++f) {
      double err = 0;
      int cnt = 0, behind = 0;
      for (const auto& t : tracks) {
        auto it = points.find(t.id);
        Eigen::Vector2d x;
        if (it == points.end() || !sightingIn(t, f, &x)) continue;
        const Eigen::Vector3d p = pose[f].first.transpose() * (it->second - pose[f].second);
        behind += p.z() < 0;
        err += (p.head<2>() / p.z() - x).norm();
        ++cnt;
      }
      logDebug("sfm: frame ", f, ": ", cnt, " points, mean error ", cnt ? err / cnt * 458 : 0,
               " px, ", behind, " behind");
    }
  }
  // Bundle adjustment with the reference pose fixed and the last translation fixed (scale).
  std::vector<Eigen::Vector4d> q(num_frames);  // w x y z, world-to-camera
  std::vector<Eigen::Vector3d> tr(num_frames);
  ceres::Problem problem;
  ceres::QuaternionManifold* quaternion_manifold = new ceres::QuaternionManifold();
  for (int i = 0; i < num_frames; ++i) {
    const Eigen::Quaterniond qc(pose[i].first.transpose());
    q[i] << qc.w(), qc.x(), qc.y(), qc.z();
    tr[i] = -pose[i].first.transpose() * pose[i].second;
    problem.AddParameterBlock(q[i].data(), 4, quaternion_manifold);  // shared; owned by problem
    problem.AddParameterBlock(tr[i].data(), 3);
    if (i == ref) {
      problem.SetParameterBlockConstant(q[i].data());
      problem.SetParameterBlockConstant(tr[i].data());
    }
    if (i == last) problem.SetParameterBlockConstant(tr[i].data());
  }
  std::map<int, Eigen::Vector3d> ba_points = points;
  for (const auto& t : tracks) {
    auto it = ba_points.find(t.id);
    if (it == ba_points.end()) continue;
    for (const auto& [f, xy] : t.sightings) {
      auto* cost =
          new ceres::AutoDiffCostFunction<ReprojectionError, 2, 4, 3, 3>(new ReprojectionError(xy));
      problem.AddResidualBlock(cost, nullptr, q[f].data(), tr[f].data(), it->second.data());
    }
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_SCHUR;
  options.max_num_iterations = 30;
  options.logging_type = ceres::SILENT;  // no per-iteration log line formatted for nothing
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  if (summary.termination_type != ceres::CONVERGENCE && summary.final_cost > 5e-3) {
    logDebug("sfm: bundle adjustment did not converge: ", summary.BriefReport());
    return false;
  }

  result->q_ref_c.resize(num_frames);
  result->t_ref_c.resize(num_frames);
  for (int i = 0; i < num_frames; ++i) {
    const Eigen::Quaterniond q_c_ref(q[i][0], q[i][1], q[i][2], q[i][3]);
    result->q_ref_c[i] = q_c_ref.normalized().inverse();
    result->t_ref_c[i] = -(result->q_ref_c[i] * tr[i]);
  }
  result->points = ba_points;
  return true;
}

}  // namespace alvio
