// alvio/ZeroCopyMonitorNodelet: checks that the tracker's frames carry the camera's
// own image messages. Loaded into the pipeline's manager it should report every
// frame as `shared` (the frame's image is the pointer roscpp delivered on the camera
// topic); in another process, or behind a copying transport, frames are `copied`.
// Used by the integration test; handy to verify a robot's launch file.
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <pluginlib/class_list_macros.hpp>

#include <alvio/ZeroCopyReport.h>

#include <cstring>
#include <iterator>
#include <map>

#include "conversions.h"
#include "guarded_nodelet.h"
#include "nodelet_config.h"
#include "shared_tracked_frame.h"

namespace alvio_ros {

class ZeroCopyMonitorNodelet : public GuardedNodelet {
 private:
  void init() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    // The tracker's camera topic by default: the same `config_file`'s topics.image.
    const NodeletConfig config(nh, pnh);
    const std::string image_topic = param(pnh, "image_topic", config.config().topics.image);
    const std::string frame_topic = param(pnh, "frame_topic", "tracker/frame");
    report_pub_ = pnh.advertise<alvio::ZeroCopyReport>("report", 1, true);
    image_sub_ = nh.subscribe(image_topic, 20, &ZeroCopyMonitorNodelet::onImage, this);
    frame_sub_ = nh.subscribe(frame_topic, 20, &ZeroCopyMonitorNodelet::onFrame, this);
  }

  void onImage(const sensor_msgs::ImageConstPtr& image) {
    ++report_.camera_images;
    const int64_t stamp = toNs(image->header.stamp);
    // Across processes a frame can arrive before the image it was made from.
    const auto waiting = pending_.find(stamp);
    if (waiting != pending_.end()) {
      classify(*image, *waiting->second->image);
      // Images arrive in order: a frame older than this image will never find its own.
      report_.unmatched += static_cast<uint32_t>(std::distance(pending_.begin(), waiting));
      pending_.erase(pending_.begin(), std::next(waiting));
      report_pub_.publish(boost::make_shared<alvio::ZeroCopyReport>(report_));
      return;
    }
    // Held until matched, so that a freed image's address cannot be reused by a copy. 100
    // images let the tracker fall 5 s behind on a loaded machine.
    recent_[stamp] = image;
    while (recent_.size() > 100) recent_.erase(recent_.begin());
  }

  void onFrame(const SharedTrackedFrame::ConstPtr& frame) {
    ++report_.frames;
    if (!frame->image)
      ++report_.unmatched;
    else
      match(frame);
    report_pub_.publish(boost::make_shared<alvio::ZeroCopyReport>(report_));
  }

  void match(const SharedTrackedFrame::ConstPtr& frame) {
    // The camera's stamp: the frame's own is on the IMU's clock (camera.timeshift_cam_imu).
    const int64_t stamp = toNs(frame->image->header.stamp);
    const auto it = recent_.find(stamp);
    if (it != recent_.end()) {
      classify(*it->second, *frame->image);
      recent_.erase(recent_.begin(), std::next(it));
      return;
    }
    pending_[stamp] = frame;
    while (pending_.size() > 30) {
      pending_.erase(pending_.begin());
      ++report_.unmatched;
    }
  }

  void classify(const sensor_msgs::Image& camera, const sensor_msgs::Image& in_frame) {
    if (&camera == &in_frame && camera.data.data() == in_frame.data.data())
      ++report_.shared;
    else if (camera.data.size() == in_frame.data.size() &&
             std::memcmp(camera.data.data(), in_frame.data.data(), camera.data.size()) == 0)
      ++report_.copied;
    else
      ++report_.unmatched;
  }

  alvio::ZeroCopyReport report_;
  std::map<int64_t, sensor_msgs::ImageConstPtr> recent_;
  std::map<int64_t, SharedTrackedFrame::ConstPtr> pending_;  // frames whose image is not here yet
  ros::Publisher report_pub_;
  ros::Subscriber image_sub_, frame_sub_;
};

}  // namespace alvio_ros

PLUGINLIB_EXPORT_CLASS(alvio_ros::ZeroCopyMonitorNodelet, nodelet::Nodelet)
