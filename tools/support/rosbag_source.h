#pragma once
// A rosbag as a SensorSource: sensor_msgs/Image (mono8, or colour converted to
// grey) and sensor_msgs/Imu on the configured topics, in bag-time order.

#include <memory>
#include <string>

#include "alvio/config/sensor_options.h"
#include "alvio/pipeline/sensor_source.h"

namespace alvio {

class RosbagSource : public SensorSource {
 public:
  /// Throws alvio::Error naming the file when it cannot be opened, or the topics when the
  /// bag lacks them.
  RosbagSource(const std::string& path, const TopicOptions& topics);
  ~RosbagSource() override;
  /// Throws alvio::Error naming the file when the bag turns out corrupted or truncated;
  /// single messages that do not deserialize are skipped and counted.
  bool next(SensorMessage* message) override;
  std::size_t badMessages() const;
  std::size_t imageCount() const override { return image_count_; }
  std::string description() const override { return "rosbag " + path_; }

 private:
  void open(const TopicOptions& topics);
  bool nextMessage(SensorMessage* message);
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string path_;
  std::size_t image_count_ = 0;
};

}  // namespace alvio
