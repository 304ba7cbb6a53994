#pragma once
// The input of the offline tools: a rosbag or an EuRoC/ASL folder, by the path's extension.

#include <memory>
#include <string>

#include "alvio/config/sensor_options.h"
#include "alvio/pipeline/sensor_source.h"

namespace alvio {

/// A `.bag` file (its topics from `topics`) or an EuRoC folder (containing mav0/).
std::unique_ptr<SensorSource> openDataset(const std::string& path, const TopicOptions& topics);

}  // namespace alvio
