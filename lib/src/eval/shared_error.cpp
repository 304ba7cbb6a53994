#include "alvio/eval/shared_error.h"

#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include "alvio/common/error.h"

namespace alvio {

namespace {
Trajectory stampsOf(const EvaluationResult& r) {
  Trajectory t(r.t.size());
  for (std::size_t i = 0; i < r.t.size(); ++i) t[i].t = r.t[i];
  return t;
}

// Two passes, about the means: a one-pass variance of a nearly constant error is round-off.
double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  const double n = static_cast<double>(a.size());
  const double ma = std::accumulate(a.begin(), a.end(), 0.0) / n;
  const double mb = std::accumulate(b.begin(), b.end(), 0.0) / n;
  double ab = 0, aa = 0, bb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ab += (a[i] - ma) * (b[i] - mb);
    aa += (a[i] - ma) * (a[i] - ma);
    bb += (b[i] - mb) * (b[i] - mb);
  }
  return aa > 0 && bb > 0 ? ab / std::sqrt(aa * bb) : 0.0;
}
}  // namespace

SharedError sharedError(const EvaluationResult& a, const EvaluationResult& b, double max_dt) {
  const auto pairs = associateByTime(stampsOf(a), stampsOf(b), max_dt);
  if (pairs.size() < 3)
    throw Error("shared error: only " + std::to_string(pairs.size()) +
                " poses of the two runs share a time (within " + std::to_string(max_dt) + " s)");
  SharedError s;
  s.matched = pairs.size();
  double sq_a = 0, sq_b = 0, sq_c = 0, sq_d = 0;
  std::vector<double> axis_a[3], axis_b[3];
  for (const auto& [i, j] : pairs) {
    const Eigen::Vector3d ea = a.est_aligned[i] - a.gt_matched[i];
    const Eigen::Vector3d eb = b.est_aligned[j] - b.gt_matched[j];
    sq_a += ea.squaredNorm();
    sq_b += eb.squaredNorm();
    sq_c += (0.5 * (ea + eb)).squaredNorm();
    sq_d += (0.5 * (ea - eb)).squaredNorm();
    for (int k = 0; k < 3; ++k) {
      axis_a[k].push_back(ea[k]);
      axis_b[k].push_back(eb[k]);
    }
  }
  const double n = static_cast<double>(pairs.size());
  s.rms_a = std::sqrt(sq_a / n);
  s.rms_b = std::sqrt(sq_b / n);
  s.rms_shared = std::sqrt(sq_c / n);
  s.rms_difference = 2 * std::sqrt(sq_d / n);
  s.shared_fraction = sq_c + sq_d > 0 ? sq_c / (sq_c + sq_d) : 1.0;
  for (int k = 0; k < 3; ++k) s.axis_correlation[k] = correlation(axis_a[k], axis_b[k]);
  return s;
}

}  // namespace alvio
