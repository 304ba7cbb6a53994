#pragma once
// Conversions between ROS messages and the core's types, shared by the nodelets.

#include <alvio/MapKeyframe.h>
#include <alvio/TrackedFeatures.h>
#include <geometry_msgs/Pose.h>
#include <ros/time.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/Header.h>
#include <visualization_msgs/Marker.h>

#include <Eigen/Geometry>
#include <string>
#include <utility>
#include <vector>

#include "alvio/common/timing.h"
#include "alvio/common/types.h"
#include "alvio/estimator/estimator.h"
#include "alvio/frontend/feature_frame.h"
#include "alvio/mapping/keyframe_landmarks.h"

namespace alvio_ros {

ros::Time toRosTime(int64_t t_ns);
inline int64_t toNs(const ros::Time& t) {
  return static_cast<int64_t>(t.toNSec());
}

alvio::ImuSample fromMsg(const sensor_msgs::Imu& msg);

/// The tracker's frame as a message; `header` is the image's, its stamp replaced by the frame's
/// time on the IMU's clock (camera.timeshift_cam_imu).
void toMsg(const alvio::FeatureFrame& frame, const alvio::FrameTiming& timing,
           const std_msgs::Header& header, alvio::TrackedFeatures* msg);
/// The estimator's input from the tracker's message (t_ns from the header stamp).
alvio::FeatureFrame fromMsg(const alvio::TrackedFeatures& msg);

geometry_msgs::Pose toPose(const Eigen::Vector3d& p, const Eigen::Quaterniond& q);
geometry_msgs::Pose toPose(const Eigen::Isometry3d& T);
Eigen::Isometry3d fromPose(const geometry_msgs::Pose& pose);

/// Keyframe landmarks for the map, lines with their direction uncertainty (the map's
/// MapBuilder decides which to keep).
void toMsg(const alvio::KeyframeLandmarks& keyframe, uint8_t kind, const std_msgs::Header& header,
           alvio::MapKeyframe* msg);
alvio::KeyframeLandmarks fromMsg(const alvio::MapKeyframe& msg);

/// An x, y, z (float32) cloud.
void toCloud(const std::vector<Eigen::Vector3d>& points, const std_msgs::Header& header,
             sensor_msgs::PointCloud2* cloud);
/// Points of an x, y, z cloud (any float32 cloud with those fields).
std::vector<Eigen::Vector3d> fromCloud(const sensor_msgs::PointCloud2& cloud);

using Segments = std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>;
/// One LINE_LIST marker holding every segment.
visualization_msgs::Marker lineListMarker(const Segments& segments, const std_msgs::Header& header,
                                          const std::string& ns, float r, float g, float b,
                                          double width_m);
/// The segments of a LINE_LIST marker.
Segments fromLineList(const visualization_msgs::Marker& marker);

}  // namespace alvio_ros
