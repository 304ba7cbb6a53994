// alvio/LoggerNodelet: the MRPT run logger (alvio::MrptLogger: .rawlog, .3Dscene,
// alvio.log) fed from the pipeline's topics. In the pipeline's manager the images
// come inside the tracker's frames, as the very pointers the camera driver
// published (no copy). Closes its files on shutdown.
#include <cv_bridge/cv_bridge.h>
#include <geometry_msgs/PoseArray.h>
#include <nav_msgs/Odometry.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/MarkerArray.h>
#include <pluginlib/class_list_macros.hpp>

#include <alvio/PipelineStatus.h>

#include <filesystem>
#include <memory>
#include <sstream>

#include "alvio/common/error.h"
#include "alvio/logging/mrpt_logger.h"
#include "conversions.h"
#include "core_log_route.h"
#include "guarded_nodelet.h"
#include "nodelet_config.h"
#include "shared_tracked_frame.h"

namespace alvio_ros {

class LoggerNodelet : public GuardedNodelet {
 public:
  ~LoggerNodelet() override {
    log_route_.clearListener();
    if (!logger_) return;
    logger_->flushStats();
    logger_->log(alvio::LogLevel::kInfo, "shutting down: " + std::to_string(frames_) + " frames, " +
                                             std::to_string(poses_) + " poses");
    const alvio::MapSnapshot map = snapshot();
    logger_->finish(&map);
  }

 private:
  void init() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    const NodeletConfig config(nh, pnh);
    config.rejectUnusedOverrides();
    const alvio::Config& c = config.config();
    const std::string output_dir = param(pnh, "output_dir", c.logger.out_dir);
    const std::string imu_topic = param(pnh, "imu_topic", c.topics.imu);
    const std::string frame_topic = param(pnh, "frame_topic", "tracker/frame");
    const std::string estimator_ns = param(pnh, "estimator", "estimator");
    requireParam(!output_dir.empty(), pnh, "output_dir",
                 "is not set (nor logger.out_dir in the configuration): nowhere to log");
    c.logger.validate(config.describe() + ": logger");
    logger_ =
        std::make_unique<alvio::MrptLogger>(freshNames(c.logger, output_dir), c.camera, output_dir);

    std::ostringstream os;
    os << "alvio nodelets\n  config: " << config.describe()
       << "\n  camera: " << c.camera.distortion_model << " " << c.camera.width << "x"
       << c.camera.height << " @ " << c.camera.rate_hz << " Hz\n  topics: " << imu_topic << ", "
       << frame_topic << ", " << estimator_ns << "/{odometry,status,window,points,lines}";
    logger_->log(alvio::LogLevel::kInfo, os.str());
    alvio::MrptLogger* logger = logger_.get();
    log_route_.setListener([logger](alvio::LogLevel level, const std::string& message) {
      logger->log(level, message);
    });

    imu_sub_ = nh.subscribe(imu_topic, 2000, &LoggerNodelet::onImu, this);
    frame_sub_ = nh.subscribe(frame_topic, 20, &LoggerNodelet::onFrame, this);
    odometry_sub_ = nh.subscribe(estimator_ns + "/odometry", 50, &LoggerNodelet::onOdometry, this);
    status_sub_ = nh.subscribe(estimator_ns + "/status", 50, &LoggerNodelet::onStatus, this);
    window_sub_ = nh.subscribe(estimator_ns + "/window", 2, &LoggerNodelet::onWindow, this);
    points_sub_ = nh.subscribe(estimator_ns + "/points", 2, &LoggerNodelet::onPoints, this);
    lines_sub_ = nh.subscribe(estimator_ns + "/lines", 2, &LoggerNodelet::onLines, this);
    const alvio::LoggerPaths& p = logger_->paths();
    NODELET_INFO("logging into %s (rawlog %s, scene %s, text %s)", output_dir.c_str(),
                 p.rawlog.empty() ? "off" : p.rawlog.c_str(),
                 p.scene.empty() ? "off" : p.scene.c_str(),
                 p.text.empty() ? "off" : p.text.c_str());
  }

  // A robot's earlier run, or this nodelet before a reload, may have logged into the same
  // folder: never overwrite it, number the new files instead (alvio_1.rawlog, alvio_1.log).
  static alvio::LoggerOptions freshNames(alvio::LoggerOptions options, const std::string& dir) {
    const std::string name = options.name, text = options.text_file;
    const auto stem = std::filesystem::path(text).stem().string();
    const auto ext = std::filesystem::path(text).extension().string();
    for (int n = 1;; ++n) {
      const std::filesystem::path d(options.out_dir.empty() ? dir : options.out_dir);
      if (!std::filesystem::exists(d / (options.name + ".rawlog")) &&
          !std::filesystem::exists(d / (options.name + ".3Dscene")) &&
          !std::filesystem::exists(d / options.text_file))
        return options;
      options.name = name + "_" + std::to_string(n);
      options.text_file = stem + "_" + std::to_string(n) + ext;
    }
  }

  void onImu(const sensor_msgs::ImuConstPtr& msg) { logger_->addImu(fromMsg(*msg)); }

  void onFrame(const SharedTrackedFrame::ConstPtr& frame) {
    ++frames_;
    if (!frame->image) return;
    try {
      // Shared with the message for mono8: no copy.
      const auto gray = cv_bridge::toCvShare(frame->image, "mono8");
      logger_->addImage(toNs(frame->features.header.stamp), gray->image);
    } catch (const cv_bridge::Exception& e) {
      NODELET_WARN_THROTTLE(5.0, "image not logged: %s", e.what());
    }
  }

  void onOdometry(const nav_msgs::Odometry::ConstPtr& msg) {
    ++poses_;
    const Eigen::Isometry3d T = fromPose(msg->pose.pose);
    logger_->addPose(
        {msg->header.stamp.toSec(), T.translation(), Eigen::Quaterniond(T.rotation())});
  }

  void onStatus(const alvio::PipelineStatus::ConstPtr& msg) {
    alvio::FrameStats stats;
    stats.t = msg->header.stamp.toSec();
    stats.tracked_points = msg->tracked_points;
    stats.window_landmarks = msg->window_points;
    stats.pipeline_ms = msg->frontend_ms + msg->estimator_ms;
    stats.tracking = msg->state == alvio::PipelineStatus::TRACKING;
    logger_->addFrameStats(stats);
    if (logger_->sceneDue(stats.t)) logger_->writeScene(stats.t, snapshot());
  }

  void onWindow(const geometry_msgs::PoseArray::ConstPtr& msg) { window_ = msg; }
  void onPoints(const sensor_msgs::PointCloud2::ConstPtr& msg) { points_ = msg; }
  void onLines(const visualization_msgs::MarkerArray::ConstPtr& msg) { lines_ = msg; }

  // The estimator's window as last published.
  alvio::MapSnapshot snapshot() const {
    alvio::MapSnapshot map;
    if (window_)
      for (const auto& pose : window_->poses) {
        const Eigen::Isometry3d T = fromPose(pose);
        map.keyframes.push_back(
            {window_->header.stamp.toSec(), T.translation(), Eigen::Quaterniond(T.rotation())});
      }
    if (points_) map.points = fromCloud(*points_);
    if (lines_)
      for (const auto& marker : lines_->markers)
        for (const auto& segment : fromLineList(marker)) map.lines.push_back(segment);
    return map;
  }

  CoreLogRoute log_route_;
  std::unique_ptr<alvio::MrptLogger> logger_;
  geometry_msgs::PoseArray::ConstPtr window_;
  sensor_msgs::PointCloud2::ConstPtr points_;
  visualization_msgs::MarkerArray::ConstPtr lines_;
  std::size_t frames_ = 0, poses_ = 0;
  ros::Subscriber imu_sub_, frame_sub_, odometry_sub_, status_sub_, window_sub_, points_sub_,
      lines_sub_;
};

}  // namespace alvio_ros

PLUGINLIB_EXPORT_CLASS(alvio_ros::LoggerNodelet, nodelet::Nodelet)
