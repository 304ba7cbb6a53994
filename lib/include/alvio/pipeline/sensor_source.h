#pragma once
// A time-ordered stream of IMU samples and camera images from a recorded
// dataset. The EuRoC folder source lives here; the rosbag source is in the
// ROS-side tools (lib/ has no ROS).

#include <functional>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "alvio/common/types.h"

namespace alvio {

struct SensorMessage {
  enum class Kind { kImu, kImage };
  Kind kind = Kind::kImu;
  ImuSample imu;                        ///< kImu
  int64_t t_ns = 0;                     ///< time of either kind
  std::function<cv::Mat()> load_image;  ///< kImage: the 8-bit grey image (empty Mat if unreadable)
};

class SensorSource {
 public:
  virtual ~SensorSource() = default;
  /// The next message in time order; false at the end.
  virtual bool next(SensorMessage* message) = 0;
  virtual std::size_t imageCount() const = 0;
  /// Ground truth body poses, when the dataset has them.
  virtual std::optional<Trajectory> groundTruth() const { return std::nullopt; }
  virtual std::string description() const = 0;
};

/// An EuRoC/ASL folder (mav0/cam0, mav0/imu0, optional ground truth). Unsorted or duplicate
/// stamps are sorted/dropped with a warning.
class EurocSource : public SensorSource {
 public:
  explicit EurocSource(const std::string& root);
  bool next(SensorMessage* message) override;
  std::size_t imageCount() const override { return images_.size(); }
  std::optional<Trajectory> groundTruth() const override { return ground_truth_; }
  std::string description() const override { return "EuRoC folder " + root_; }

 private:
  std::string root_;
  std::vector<ImageRecord> images_;
  std::vector<ImuSample> imu_;
  std::optional<Trajectory> ground_truth_;
  std::size_t next_image_ = 0, next_imu_ = 0;
};

}  // namespace alvio
