#pragma once
// cv_bridge wraps an image message's buffer as height x step bytes without checking that
// the buffer holds them: a truncated or inconsistent message would be read out of bounds.
// Checked here before any conversion, by the tracker nodelet and the rosbag reader.

#include <sensor_msgs/Image.h>

#include <string>

namespace alvio_ros {

/// Why the message cannot be an image ("" when its sizes are consistent).
std::string imageMessageProblem(const sensor_msgs::Image& image);

}  // namespace alvio_ros
