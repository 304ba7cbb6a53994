#include "image_message_check.h"

#include <sensor_msgs/image_encodings.h>

#include <cstdint>

namespace alvio_ros {

std::string imageMessageProblem(const sensor_msgs::Image& image) {
  namespace enc = sensor_msgs::image_encodings;
  const auto sizes = std::to_string(image.width) + "x" + std::to_string(image.height) + ", step " +
                     std::to_string(image.step) + ", " + std::to_string(image.data.size()) +
                     " bytes";
  if (image.width == 0 || image.height == 0) return "empty image (" + sizes + ")";
  if (static_cast<uint64_t>(image.step) * image.height > image.data.size())
    return "data shorter than height x step (" + sizes + ")";
  int bytes_per_pixel = 0;
  try {
    bytes_per_pixel = enc::numChannels(image.encoding) * enc::bitDepth(image.encoding) / 8;
  } catch (const std::exception&) {
    return "unknown encoding '" + image.encoding + "'";
  }
  if (static_cast<uint64_t>(image.width) * bytes_per_pixel > image.step)
    return "step shorter than a row of " + image.encoding + " pixels (" + sizes + ")";
  return "";
}

}  // namespace alvio_ros
