#include "dataset_source.h"

#include <filesystem>

#include "rosbag_source.h"

namespace alvio {

std::unique_ptr<SensorSource> openDataset(const std::string& path, const TopicOptions& topics) {
  if (std::filesystem::path(path).extension() == ".bag")
    return std::make_unique<RosbagSource>(path, topics);
  return std::make_unique<EurocSource>(path);
}

}  // namespace alvio
