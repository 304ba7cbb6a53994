#include "alvio/calibration/time_shift.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "alvio/common/error.h"
#include "alvio/common/rotation.h"
#include "alvio/frontend/gyro_rotation.h"

namespace alvio {
namespace {

// Longer: a constant bias no longer makes a constant difference of the rotation vectors' rates.
constexpr double kMaxPairGapS = 0.2;
constexpr std::size_t kMinPairs = 20;

}  // namespace

void TimeShiftOptions::validate() const {
  if (!(max_shift_s > 0 && max_shift_s <= 1.0))
    throw Error("time shift: the search must reach a shift in (0, 1] s, got " +
                std::to_string(max_shift_s));
  if (!(step_s > 0 && step_s <= max_shift_s / 2))
    throw Error("time shift: the step must be in (0, max shift / 2], got " +
                std::to_string(step_s));
}

TimeShiftEstimate estimateTimeShift(const std::vector<FrameRotation>& rotations,
                                    const std::vector<ImuSample>& imu, const Eigen::Matrix3d& R_b_c,
                                    const TimeShiftOptions& options) {
  options.validate();
  if (imu.size() < 2) throw Error("time shift: fewer than 2 IMU samples");
  GyroRotation gyro(R_b_c);
  for (const ImuSample& s : imu) gyro.add(s);
  const int64_t reach_ns = secToNs(options.max_shift_s);

  // Only the pairs inside the IMU's span at every trial: each trial is scored on the same data.
  std::vector<const FrameRotation*> pairs;
  double sum_sq_rate = 0;
  for (const FrameRotation& r : rotations) {
    const double dt = nsToSec(r.t1_ns - r.t0_ns);
    if (!(dt > 0) || dt > kMaxPairGapS) continue;
    if (!gyro.cameraRotation(r.t0_ns - reach_ns, r.t1_ns + reach_ns)) continue;
    pairs.push_back(&r);
    sum_sq_rate += r.rotation.squaredNorm() / (dt * dt);
  }
  if (pairs.size() < kMinPairs) {
    std::ostringstream os;
    os << "time shift: " << pairs.size() << " image pairs lie inside the IMU's span at every "
       << "shift up to " << options.max_shift_s << " s, " << kMinPairs << " needed";
    throw Error(os.str());
  }

  TimeShiftEstimate e;
  e.pairs = pairs.size();
  e.rms_rate_rps = std::sqrt(sum_sq_rate / static_cast<double>(pairs.size()));
  const int steps = static_cast<int>(std::floor(options.max_shift_s / options.step_s));
  std::vector<Eigen::Vector3d> mean_residual;
  for (int k = -steps; k <= steps; ++k) {
    const double shift = k * options.step_s;
    std::vector<Eigen::Vector3d> residuals;
    residuals.reserve(pairs.size());
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    const int64_t shift_ns = secToNs(shift);
    for (const FrameRotation* r : pairs) {
      // R_c1_c0 from the gyroscope; the pair's rotation is R_c0_c1's.
      const Eigen::Matrix3d R_c1_c0 =
          *gyro.cameraRotation(r->t0_ns + shift_ns, r->t1_ns + shift_ns);
      const Eigen::Vector3d gyro_rotation = logQuaternion(Eigen::Quaterniond(R_c1_c0.transpose()));
      residuals.push_back((gyro_rotation - r->rotation) / nsToSec(r->t1_ns - r->t0_ns));
      mean += residuals.back();
    }
    mean /= static_cast<double>(pairs.size());
    double cost = 0;
    for (const Eigen::Vector3d& v : residuals) cost += (v - mean).squaredNorm();
    e.trial_shift_s.push_back(shift);
    e.cost.push_back(cost / static_cast<double>(pairs.size()));
    mean_residual.push_back(mean);
  }
  const std::size_t best =
      static_cast<std::size_t>(std::min_element(e.cost.begin(), e.cost.end()) - e.cost.begin());
  e.shift_s = e.trial_shift_s[best];
  e.gyro_bias_rps = mean_residual[best];
  e.at_search_edge = best == 0 || best + 1 == e.cost.size();
  if (!e.at_search_edge) {
    // The parabola through the best trial and its neighbours.
    const double c0 = e.cost[best - 1], c1 = e.cost[best], c2 = e.cost[best + 1];
    const double curvature = c0 - 2 * c1 + c2;
    if (curvature > 0) e.shift_s += 0.5 * (c0 - c2) / curvature * options.step_s;
  }
  return e;
}

}  // namespace alvio
