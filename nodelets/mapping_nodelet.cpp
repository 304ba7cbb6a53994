// alvio/MappingNodelet: the line map and OctoMap (alvio::MapBuilder) fed with the
// estimator's keyframe landmarks. Publishes the map (latched, at most once per
// publish_period), saves it on ~save_map and on shutdown into output_dir.
#include <nav_msgs/Odometry.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_srvs/Trigger.h>
#include <visualization_msgs/MarkerArray.h>
#include <pluginlib/class_list_macros.hpp>

#include <alvio/MapKeyframe.h>

#include <memory>
#include <mutex>

#include "alvio/common/clock_jump.h"
#include "alvio/common/error.h"
#include "alvio/mapping/map_builder.h"
#include "alvio/mapping/occupancy_map.h"
#include "conversions.h"
#include "core_log_route.h"
#include "guarded_nodelet.h"
#include "nodelet_config.h"

namespace alvio_ros {

class MappingNodelet : public GuardedNodelet {
 public:
  ~MappingNodelet() override {
    std::lock_guard<std::mutex> lock(mutex_);
    if (map_ && save_on_shutdown_ && !output_dir_.empty() && changed_since_save_) save(output_dir_);
  }

 private:
  void init() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    const NodeletConfig config(nh, pnh);
    options_ = alvio::MappingOptions::load(config.yaml(), "mapping");
    config.rejectUnusedOverrides();
    output_dir_ = param(pnh, "output_dir", "");
    world_frame_ = param(pnh, "world_frame", "world");
    save_on_shutdown_ = param(pnh, "save_on_shutdown", true);
    const double period = param(pnh, "publish_period", 1.0);
    const std::string keyframes_topic = param(pnh, "keyframes_topic", "estimator/keyframes");
    const std::string odometry_topic = param(pnh, "odometry_topic", "estimator/odometry");
    requireParam(period > 0, pnh, "publish_period", "must be positive");
    requireParam(!world_frame_.empty(), pnh, "world_frame", "is empty");
    map_ = std::make_unique<alvio::MapBuilder>(options_);

    lines_pub_ = pnh.advertise<visualization_msgs::MarkerArray>("lines", 1, true);
    occupied_pub_ = pnh.advertise<sensor_msgs::PointCloud2>("occupied", 1, true);
    save_srv_ = pnh.advertiseService("save_map", &MappingNodelet::onSave, this);
    keyframes_sub_ = nh.subscribe(keyframes_topic, 200, &MappingNodelet::onKeyframe, this);
    odometry_sub_ = nh.subscribe(odometry_topic, 200, &MappingNodelet::onOdometry, this);
    timer_ = pnh.createTimer(ros::Duration(period), &MappingNodelet::onTimer, this);
    NODELET_INFO("mapping %s with %s (OctoMap %.3f m); %s", keyframes_sub_.getTopic().c_str(),
                 config.describe().c_str(), options_.octomap.resolution,
                 output_dir_.empty() ? "output_dir is not set: the map is saved nowhere"
                                     : ("saving into " + output_dir_).c_str());
  }

  void onKeyframe(const alvio::MapKeyframe::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    // Keyframes leave the estimator's window well after their frame's odometry, so only the
    // odometry tells a clock jump; a keyframe far ahead of it is the old run's.
    if (odometry_clock_.aheadByAJump(toNs(msg->header.stamp))) return;
    map_->addKeyframe(fromMsg(*msg));
    changed_since_publish_ = changed_since_save_ = true;
  }

  void onOdometry(const nav_msgs::Odometry::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    startNewRunIfTimeJumpedBack(msg->header.stamp);
    const Eigen::Isometry3d T = fromPose(msg->pose.pose);
    map_->addTrajectoryPose(
        {msg->header.stamp.toSec(), T.translation(), Eigen::Quaterniond(T.rotation())});
    changed_since_save_ = true;
  }

  // The estimator starts a new run, in a new world frame, when time jumps back (a bag played
  // again): so does the map (on the odometry's stamps), as a map mixing two frames is worth
  // nothing. Like the estimator's trajectory (trajectory_run<N>.tum), the finished run's map is
  // kept, in run<N>/. Called under mutex_.
  void startNewRunIfTimeJumpedBack(const ros::Time& stamp) {
    if (const int64_t jump_ns = odometry_clock_.follow(toNs(stamp))) {
      NODELET_WARN("clock jumped back %.2f s: the map starts afresh (new run)", jump_ns * 1e-9);
      ++finished_runs_;
      if (!output_dir_.empty()) save(output_dir_ + "/run" + std::to_string(finished_runs_));
      map_ = std::make_unique<alvio::MapBuilder>(options_);
      changed_since_publish_ = changed_since_save_ = true;
    }
  }

  // Throttled, latched: a display that connects later still gets the last map.
  void onTimer(const ros::TimerEvent&) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!changed_since_publish_) return;
    changed_since_publish_ = false;
    std_msgs::Header header;
    header.stamp = ros::Time::now();
    header.frame_id = world_frame_;
    Segments segments;
    for (const auto& l : map_->lineMap().filteredLines()) segments.emplace_back(l.p0, l.p1);
    auto markers = boost::make_shared<visualization_msgs::MarkerArray>();
    markers->markers.push_back(
        lineListMarker(segments, header, "map_lines", 1.0f, 0.6f, 0.1f, 0.03));
    lines_pub_.publish(markers);
    auto cloud = boost::make_shared<sensor_msgs::PointCloud2>();
    toCloud(alvio::occupiedVoxelCentres(map_->occupancyMap().tree()), header, cloud.get());
    occupied_pub_.publish(cloud);
  }

  bool onSave(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (output_dir_.empty()) {
      response.success = false;
      response.message = "parameter " + getPrivateNodeHandle().resolveName("output_dir") +
                         " is not set: nowhere to save the map";
      return true;
    }
    response.success = save(output_dir_);
    response.message = response.success ? "map saved into " + output_dir_ : last_error_;
    return true;
  }

  // MapBuilder::save writes every file atomically (temp file, then rename).
  bool save(const std::string& dir) {
    try {
      map_->save(dir);
      changed_since_save_ = false;
      NODELET_INFO("map saved into %s:\n%s", dir.c_str(), map_->summary().toString().c_str());
      return true;
    } catch (const std::exception& e) {
      last_error_ = std::string("cannot save the map: ") + e.what();
      NODELET_ERROR("%s", last_error_.c_str());
      return false;
    }
  }

  CoreLogRoute log_route_;
  std::mutex mutex_;  // the timer, callbacks and service share one queue; the destructor not
  alvio::MappingOptions options_;
  std::unique_ptr<alvio::MapBuilder> map_;
  alvio::ClockWatch odometry_clock_;
  int finished_runs_ = 0;
  std::string output_dir_, world_frame_, last_error_;
  bool save_on_shutdown_ = true, changed_since_publish_ = false, changed_since_save_ = false;
  ros::Publisher lines_pub_, occupied_pub_;
  ros::ServiceServer save_srv_;
  ros::Subscriber keyframes_sub_, odometry_sub_;
  ros::Timer timer_;
};

}  // namespace alvio_ros

PLUGINLIB_EXPORT_CLASS(alvio_ros::MappingNodelet, nodelet::Nodelet)
