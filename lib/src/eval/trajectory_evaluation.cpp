#include "alvio/eval/trajectory_evaluation.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "alvio/common/angles.h"
#include "alvio/common/error.h"

namespace alvio {

std::vector<std::pair<std::size_t, std::size_t>> associateByTime(const Trajectory& est,
                                                                 const Trajectory& gt,
                                                                 double max_dt) {
  struct Candidate {
    double dt;
    std::size_t e, g;
  };
  std::vector<Candidate> candidates;
  std::vector<double> gt_t(gt.size());
  for (std::size_t i = 0; i < gt.size(); ++i) gt_t[i] = gt[i].t;
  for (std::size_t e = 0; e < est.size(); ++e) {
    const double t = est[e].t;
    auto it = std::lower_bound(gt_t.begin(), gt_t.end(), t - max_dt);
    for (; it != gt_t.end() && *it < t + max_dt; ++it) {
      const double dt = std::abs(*it - t);
      if (dt < max_dt) candidates.push_back({dt, e, static_cast<std::size_t>(it - gt_t.begin())});
    }
  }
  // Greedy from the closest pair; ties broken by index so the result is deterministic.
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.dt != b.dt ? a.dt < b.dt : (a.e != b.e ? a.e < b.e : a.g < b.g);
  });
  std::vector<char> used_e(est.size(), 0), used_g(gt.size(), 0);
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (const auto& c : candidates) {
    if (used_e[c.e] || used_g[c.g]) continue;
    used_e[c.e] = used_g[c.g] = 1;
    pairs.emplace_back(c.e, c.g);
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

ErrorStats ErrorStats::of(std::vector<double> v) {
  ErrorStats s;
  s.count = v.size();
  if (v.empty()) return s;
  double sum = 0, sum_sq = 0;
  for (double x : v) {
    sum += x;
    sum_sq += x * x;
  }
  s.mean = sum / v.size();
  s.rmse = std::sqrt(sum_sq / v.size());
  s.std = std::sqrt(std::max(0.0, sum_sq / v.size() - s.mean * s.mean));
  std::sort(v.begin(), v.end());
  s.min = v.front();
  s.max = v.back();
  const std::size_t m = v.size() / 2;
  s.median = v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
  return s;
}

namespace {
double rotationAngleDeg(const Eigen::Matrix3d& R) {
  const double c = std::clamp((R.trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c) * kRadToDeg;
}
}  // namespace

EvaluationResult evaluateTrajectory(const Trajectory& est, const Trajectory& gt,
                                    const EvaluationOptions& options) {
  EvaluationResult r;
  r.est_poses = est.size();
  r.gt_poses = gt.size();
  const auto pairs = associateByTime(est, gt, options.max_dt);
  r.matched = pairs.size();
  if (pairs.size() < 3)
    throw Error("only " + std::to_string(pairs.size()) + " of " + std::to_string(est.size()) +
                " estimated poses have a ground-truth pose within " +
                std::to_string(options.max_dt) + " s (wrong files, or time offset?)");

  Points3 pe, pg;
  for (const auto& [e, g] : pairs) {
    pe.push_back(est[e].p);
    pg.push_back(gt[g].p);
  }
  r.alignment = alignPoints(pe, pg, options.alignment);
  const Similarity3& A = r.alignment;

  std::vector<Eigen::Matrix3d> R_est, R_gt;
  std::vector<double> rot_err;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const auto& [e, g] = pairs[k];
    r.t.push_back(gt[g].t);
    r.est_aligned.push_back(A.apply(pe[k]));
    r.gt_matched.push_back(pg[k]);
    r.translation_error_m.push_back((r.est_aligned.back() - pg[k]).norm());
    R_est.push_back(A.R * est[e].q.toRotationMatrix());
    R_gt.push_back(gt[g].q.toRotationMatrix());
    rot_err.push_back(rotationAngleDeg(R_gt.back().transpose() * R_est.back()));
  }
  r.ate_translation_m = ErrorStats::of(r.translation_error_m);
  r.ate_rotation_deg = ErrorStats::of(rot_err);

  // Relative errors over sub-trajectories of a fixed fraction of the path length.
  std::vector<double> dist(pairs.size(), 0.0);
  for (std::size_t k = 1; k < pairs.size(); ++k) dist[k] = dist[k - 1] + (pg[k] - pg[k - 1]).norm();
  r.path_length_m = dist.back();
  for (const double fraction : options.rpe_fractions) {
    RpeSegment seg;
    seg.fraction = fraction;
    seg.length_m = fraction * r.path_length_m;
    std::vector<double> trans, rot;
    if (seg.length_m > 0) {
      for (std::size_t i = 0; i < pairs.size(); ++i) {
        const auto it = std::lower_bound(dist.begin() + i, dist.end(), dist[i] + seg.length_m);
        if (it == dist.end()) break;
        const std::size_t j = it - dist.begin();
        // Relative motion i->j in each trajectory, then the error between them.
        const Eigen::Matrix3d dR_gt = R_gt[i].transpose() * R_gt[j];
        const Eigen::Vector3d dt_gt = R_gt[i].transpose() * (pg[j] - pg[i]);
        const Eigen::Matrix3d dR_est = R_est[i].transpose() * R_est[j];
        const Eigen::Vector3d dt_est = R_est[i].transpose() * (r.est_aligned[j] - r.est_aligned[i]);
        const Eigen::Vector3d t_err = dR_gt.transpose() * (dt_est - dt_gt);
        trans.push_back(100.0 * t_err.norm() / seg.length_m);
        rot.push_back(rotationAngleDeg(dR_gt.transpose() * dR_est) / seg.length_m);
      }
    }
    seg.translation_percent = ErrorStats::of(trans);
    seg.rotation_deg_per_m = ErrorStats::of(rot);
    r.rpe.push_back(seg);
  }
  return r;
}

}  // namespace alvio
