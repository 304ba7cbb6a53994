#include "alvio/calibration/time_shift.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "alvio/common/error.h"

namespace alvio {
namespace {

constexpr double kMaxPairGapS = 0.2;  // longer: the rotation vector no longer adds up linearly
constexpr std::size_t kMinPairs = 20;

// The gyroscope's integral from its first sample, at any time inside its span: the rate
// linear between samples.
class GyroIntegral {
 public:
  explicit GyroIntegral(const std::vector<ImuSample>& imu) : imu_(imu) {
    cumulative_.assign(imu.size(), Eigen::Vector3d::Zero());
    for (std::size_t i = 1; i < imu.size(); ++i)
      cumulative_[i] = cumulative_[i - 1] + 0.5 * (imu[i - 1].gyr + imu[i].gyr) * seconds(i - 1, i);
  }
  double first() const { return relative(imu_.front().t_ns); }
  double last() const { return relative(imu_.back().t_ns); }
  /// Seconds since the first sample.
  double relative(int64_t t_ns) const {
    return static_cast<double>(t_ns - imu_.front().t_ns) * 1e-9;
  }
  Eigen::Vector3d at(double t) const {
    std::size_t i = static_cast<std::size_t>(
        std::upper_bound(imu_.begin(), imu_.end(), t,
                         [&](double v, const ImuSample& s) { return v < relative(s.t_ns); }) -
        imu_.begin());
    i = std::clamp<std::size_t>(i, 1, imu_.size() - 1) - 1;
    const double h = seconds(i, i + 1), tau = t - relative(imu_[i].t_ns);
    const Eigen::Vector3d slope = (imu_[i + 1].gyr - imu_[i].gyr) / h;
    return cumulative_[i] + imu_[i].gyr * tau + 0.5 * slope * tau * tau;
  }

 private:
  double seconds(std::size_t i, std::size_t j) const {
    return static_cast<double>(imu_[j].t_ns - imu_[i].t_ns) * 1e-9;
  }
  const std::vector<ImuSample>& imu_;
  std::vector<Eigen::Vector3d> cumulative_;
};

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
  const GyroIntegral gyro(imu);
  const Eigen::Matrix3d R_c_b = R_b_c.transpose();

  // Only the pairs inside the IMU's span at every trial: each trial is scored on the same data.
  std::vector<const FrameRotation*> pairs;
  double sum_sq_rate = 0;
  for (const FrameRotation& r : rotations) {
    const double t0 = gyro.relative(r.t0_ns), t1 = gyro.relative(r.t1_ns);
    if (!(t1 > t0) || t1 - t0 > kMaxPairGapS) continue;
    if (t0 - options.max_shift_s < gyro.first() || t1 + options.max_shift_s > gyro.last()) continue;
    pairs.push_back(&r);
    sum_sq_rate += r.rotation.squaredNorm() / ((t1 - t0) * (t1 - t0));
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
    for (const FrameRotation* r : pairs) {
      const double t0 = gyro.relative(r->t0_ns) + shift, t1 = gyro.relative(r->t1_ns) + shift;
      const Eigen::Vector3d gyro_rotation = R_c_b * (gyro.at(t1) - gyro.at(t0));
      residuals.push_back((gyro_rotation - r->rotation) / (t1 - t0));
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
