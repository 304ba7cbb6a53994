#pragma once
// Where the shared EuRoC files of a sequence are (ground truth, cam0 time
// stamps, real IMU), so that `--trajectory MH_05` works without long paths.
// The shared data folder is $ALVIO_SHARED_DATA, or ../shared/data next to the
// source tree.

#include <optional>
#include <string>

namespace alvio::sim {

struct EurocSequenceFiles {
  std::string name;              ///< e.g. "MH_05_difficult"
  std::string ground_truth;      ///< TUM, body frame, 200 Hz
  std::string ground_truth_csv;  ///< original 17-column EuRoC CSV ("" if not shared)
  std::string cam_timestamps;    ///< cam0 stamps [ns], one per line ("" if not shared)
  std::string imu;               ///< real imu0 data.csv ("" if not shared)
};

/// The shared data folder, or "" when there is none.
std::string findSharedDataDir();

/// Files of a sequence given as "MH_05", "MH05", "mh_05" or "MH_05_difficult";
/// nullopt if the name is not an EuRoC sequence or its ground truth is absent.
std::optional<EurocSequenceFiles> findEurocSequence(const std::string& name);

}  // namespace alvio::sim
