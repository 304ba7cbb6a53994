#include "rosbag_source.h"

#include <cv_bridge/cv_bridge.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>

#include <map>
#include <opencv2/imgproc.hpp>
#include <utility>

#include "alvio/common/error.h"
#include "alvio/common/logging.h"
#include "image_message_check.h"

namespace alvio {

namespace {

// A message that does not deserialize is skipped and counted.
template <typename T>
boost::shared_ptr<T> instantiateOrSkip(const rosbag::MessageInstance& msg, const std::string& path,
                                       std::size_t* bad) {
  try {
    return msg.instantiate<T>();
  } catch (const rosbag::BagException&) {
    throw;
  } catch (const std::exception& e) {
    if (++*bad <= 5)
      logWarn("rosbag '", path, "': message on '", msg.getTopic(), "' at ", msg.getTime(),
              " cannot be read (", e.what(), "): skipped");
    return nullptr;
  }
}

}  // namespace

struct RosbagSource::Impl {
  rosbag::Bag bag;
  std::unique_ptr<rosbag::View> view;
  rosbag::View::iterator it;
  std::string image_topic, imu_topic;
  std::size_t bad_messages = 0;
};

RosbagSource::RosbagSource(const std::string& path, const TopicOptions& topics)
    : impl_(std::make_unique<Impl>()), path_(path) {
  try {
    open(topics);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error("cannot read rosbag '" + path + "' (corrupted or truncated?): " + e.what());
  }
}

void RosbagSource::open(const TopicOptions& topics) {
  const std::string& path = path_;
  impl_->bag.open(path, rosbag::bagmode::Read);
  impl_->image_topic = topics.image;
  impl_->imu_topic = topics.imu;
  rosbag::View all(impl_->bag);
  std::map<std::string, std::string> present;  // topic -> message type
  for (const auto* c : all.getConnections()) present[c->topic] = c->datatype;
  const std::pair<std::string, std::string> expected[] = {{topics.image, "sensor_msgs/Image"},
                                                          {topics.imu, "sensor_msgs/Imu"}};
  for (const auto& [topic, type] : expected) {
    const auto it = present.find(topic);
    if (it == present.end()) {
      std::string list;
      for (const auto& p : present) list += (list.empty() ? "" : ", ") + p.first;
      throw Error("rosbag '" + path + "' has no topic '" + topic + "' (topics: " + list +
                  "); set topics.image / topics.imu in the config");
    }
    // Otherwise every message would fail to instantiate and the run would see no data.
    if (it->second != type)
      throw Error("rosbag '" + path + "': topic '" + topic + "' carries " + it->second +
                  ", expected " + type);
  }
  image_count_ = rosbag::View(impl_->bag, rosbag::TopicQuery(topics.image)).size();
  impl_->view = std::make_unique<rosbag::View>(
      impl_->bag, rosbag::TopicQuery(std::vector<std::string>{topics.image, topics.imu}));
  impl_->it = impl_->view->begin();
}

RosbagSource::~RosbagSource() {
  if (impl_->bad_messages > 0)
    logWarn("rosbag '", path_, "': ", impl_->bad_messages, " unreadable message(s) skipped");
}

std::size_t RosbagSource::badMessages() const {
  return impl_->bad_messages;
}

bool RosbagSource::next(SensorMessage* m) {
  try {
    return nextMessage(m);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    // A damaged chunk or record header (rosbag, or a bad_alloc from a garbage length):
    // the bag cannot be read on from here.
    throw Error("rosbag '" + path_ + "' is corrupted or truncated: " + e.what());
  }
}

bool RosbagSource::nextMessage(SensorMessage* m) {
  for (; impl_->it != impl_->view->end(); ++impl_->it) {
    const rosbag::MessageInstance& msg = *impl_->it;
    if (msg.getTopic() == impl_->imu_topic) {
      const auto imu = instantiateOrSkip<sensor_msgs::Imu>(msg, path_, &impl_->bad_messages);
      if (!imu) continue;
      m->kind = SensorMessage::Kind::kImu;
      m->imu.t_ns = static_cast<int64_t>(imu->header.stamp.toNSec());
      m->imu.acc = {imu->linear_acceleration.x, imu->linear_acceleration.y,
                    imu->linear_acceleration.z};
      m->imu.gyr = {imu->angular_velocity.x, imu->angular_velocity.y, imu->angular_velocity.z};
      m->t_ns = m->imu.t_ns;
      ++impl_->it;
      return true;
    }
    const auto image = instantiateOrSkip<sensor_msgs::Image>(msg, path_, &impl_->bad_messages);
    if (!image) continue;
    m->kind = SensorMessage::Kind::kImage;
    m->t_ns = static_cast<int64_t>(image->header.stamp.toNSec());
    m->load_image = [image]() -> cv::Mat {
      const std::string problem = alvio_ros::imageMessageProblem(*image);
      if (!problem.empty()) {
        logWarn("image message at ", image->header.stamp, " is malformed: ", problem);
        return cv::Mat();
      }
      try {
        const auto cv_image = cv_bridge::toCvShare(image);
        if (cv_image->image.type() == CV_8UC1) return cv_image->image.clone();
        return cv_bridge::toCvCopy(image, "mono8")->image;
      } catch (const cv_bridge::Exception& e) {
        logWarn("image with encoding '", image->encoding, "' cannot be converted: ", e.what());
        return cv::Mat();
      }
    };
    ++impl_->it;
    return true;
  }
  return false;
}

}  // namespace alvio
