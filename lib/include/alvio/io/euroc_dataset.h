#pragma once
// EuRoC / ASL dataset folders: mav0/cam0/data.csv + images, mav0/imu0/data.csv,
// mav0/state_groundtruth_estimate0/data.csv, and their sensor.yaml files.

#include <optional>
#include <string>
#include <vector>

#include "alvio/common/types.h"
#include "alvio/config/sensor_options.h"
#include "alvio/io/time_order.h"

namespace alvio {

class EurocDataset {
 public:
  /// `root` may be the folder holding mav0/ or mav0/ itself. Throws alvio::Error
  /// naming the missing folder or file.
  explicit EurocDataset(const std::string& root, TimeOrderPolicy policy = TimeOrderPolicy::kStrict);

  const std::string& mav0() const { return mav0_; }
  /// cam0 frames in time order; image paths are absolute.
  const std::vector<ImageRecord>& images() const { return images_; }
  const std::vector<ImuSample>& imu() const { return imu_; }
  /// Ground truth, when state_groundtruth_estimate0/data.csv exists.
  const std::optional<GroundTruth>& groundTruth() const { return ground_truth_; }
  /// cam0/sensor.yaml and imu0/sensor.yaml, when present.
  std::optional<CameraOptions> cameraCalibration() const;
  std::optional<ImuOptions> imuCalibration() const;

 private:
  std::string mav0_;
  std::vector<ImageRecord> images_;
  std::vector<ImuSample> imu_;
  std::optional<GroundTruth> ground_truth_;
};

// Readers of the single files, usable on their own.
std::vector<ImageRecord> readEurocImageCsv(const std::string& csv_path,
                                           const std::string& image_dir,
                                           TimeOrderPolicy policy = TimeOrderPolicy::kStrict);
std::vector<ImuSample> readEurocImuCsv(const std::string& csv_path,
                                       TimeOrderPolicy policy = TimeOrderPolicy::kStrict);
/// 17-column state_groundtruth_estimate0 CSV (or at least the 8 pose columns).
GroundTruth readEurocGroundTruthCsv(const std::string& csv_path,
                                    TimeOrderPolicy policy = TimeOrderPolicy::kStrict);

// Writers (all atomic), used by the simulator to produce ASL folders.
void writeEurocImageCsv(const std::string& csv_path, const std::vector<int64_t>& stamps_ns);
void writeEurocImuCsv(const std::string& csv_path, const std::vector<ImuSample>& imu);
void writeEurocGroundTruthCsv(const std::string& csv_path, const GroundTruth& gt);
void writeEurocCameraYaml(const std::string& path, const CameraOptions& camera);
void writeEurocImuYaml(const std::string& path, const ImuOptions& imu);

}  // namespace alvio
