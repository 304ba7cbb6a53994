#include "rosbag_source.h"

#include <cv_bridge/cv_bridge.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>

#include <opencv2/imgproc.hpp>
#include <set>

#include "alvio/common/error.h"
#include "alvio/common/logging.h"

namespace alvio {

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
    impl_->bag.open(path, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    throw Error("cannot open rosbag '" + path + "': " + e.what());
  }
  impl_->image_topic = topics.image;
  impl_->imu_topic = topics.imu;
  rosbag::View all(impl_->bag);
  std::set<std::string> present;
  for (const auto* c : all.getConnections()) present.insert(c->topic);
  for (const auto& t : {topics.image, topics.imu})
    if (!present.count(t)) {
      std::string list;
      for (const auto& p : present) list += (list.empty() ? "" : ", ") + p;
      throw Error("rosbag '" + path + "' has no topic '" + t + "' (topics: " + list +
                  "); set topics.image / topics.imu in the config");
    }
  image_count_ = rosbag::View(impl_->bag, rosbag::TopicQuery(topics.image)).size();
  impl_->view = std::make_unique<rosbag::View>(
      impl_->bag, rosbag::TopicQuery(std::vector<std::string>{topics.image, topics.imu}));
  impl_->it = impl_->view->begin();
}

RosbagSource::~RosbagSource() = default;

bool RosbagSource::next(SensorMessage* m) {
  for (; impl_->it != impl_->view->end(); ++impl_->it) {
    const rosbag::MessageInstance& msg = *impl_->it;
    if (msg.getTopic() == impl_->imu_topic) {
      const auto imu = msg.instantiate<sensor_msgs::Imu>();
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
    const auto image = msg.instantiate<sensor_msgs::Image>();
    if (!image) continue;
    m->kind = SensorMessage::Kind::kImage;
    m->t_ns = static_cast<int64_t>(image->header.stamp.toNSec());
    m->load_image = [image]() -> cv::Mat {
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
