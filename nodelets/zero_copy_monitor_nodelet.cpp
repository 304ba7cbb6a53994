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
    const std::string image_topic = param(pnh, "image_topic", "/cam0/image_raw");
    const std::string frame_topic = param(pnh, "frame_topic", "tracker/frame");
    report_pub_ = pnh.advertise<alvio::ZeroCopyReport>("report", 1, true);
    image_sub_ = nh.subscribe(image_topic, 20, &ZeroCopyMonitorNodelet::onImage, this);
    frame_sub_ = nh.subscribe(frame_topic, 20, &ZeroCopyMonitorNodelet::onFrame, this);
  }

  void onImage(const sensor_msgs::ImageConstPtr& image) {
    ++report_.camera_images;
    // Held until matched, so that a freed image's address cannot be reused by a copy.
    recent_[toNs(image->header.stamp)] = image;
    while (recent_.size() > 30) recent_.erase(recent_.begin());
  }

  void onFrame(const SharedTrackedFrame::ConstPtr& frame) {
    ++report_.frames;
    const auto it = recent_.find(toNs(frame->features.header.stamp));
    if (it == recent_.end() || !frame->image) {
      ++report_.unmatched;
    } else {
      const sensor_msgs::Image& a = *it->second;
      const sensor_msgs::Image& b = *frame->image;
      if (&a == &b && a.data.data() == b.data.data())
        ++report_.shared;
      else if (a.data.size() == b.data.size() &&
               std::memcmp(a.data.data(), b.data.data(), a.data.size()) == 0)
        ++report_.copied;
      else
        ++report_.unmatched;
      recent_.erase(recent_.begin(), std::next(it));
    }
    report_pub_.publish(boost::make_shared<alvio::ZeroCopyReport>(report_));
  }

  alvio::ZeroCopyReport report_;
  std::map<int64_t, sensor_msgs::ImageConstPtr> recent_;
  ros::Publisher report_pub_;
  ros::Subscriber image_sub_, frame_sub_;
};

}  // namespace alvio_ros

PLUGINLIB_EXPORT_CLASS(alvio_ros::ZeroCopyMonitorNodelet, nodelet::Nodelet)
