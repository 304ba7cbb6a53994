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

#include <algorithm>
#include <cstdio>
#include <memory>
#include <sstream>

#include "alvio/common/clock_jump.h"
#include "alvio/common/error.h"
#include "alvio/logging/fresh_log_names.h"
#include "alvio/logging/mrpt_logger.h"
#include "conversions.h"
#include "core_log_route.h"
#include "guarded_nodelet.h"
#include "nodelet_config.h"
#include "shared_tracked_frame.h"

namespace alvio_ros {

class LoggerNodelet : public GuardedNodelet {
 public:
  ~LoggerNodelet() override { closeLog("shutting down"); }

 private:
  void init() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    const NodeletConfig config(nh, pnh);
    config.rejectUnusedOverrides();
    const alvio::Config& c = config.config();
    // The launch files pass "" when no output_dir is given: the config's folder then.
    output_dir_ = param(pnh, "output_dir", std::string());
    if (output_dir_.empty()) output_dir_ = c.logger.out_dir;
    const std::string imu_topic = param(pnh, "imu_topic", c.topics.imu);
    const std::string frame_topic = param(pnh, "frame_topic", "tracker/frame");
    const std::string estimator_ns = param(pnh, "estimator", "estimator");
    requireParam(!output_dir_.empty(), pnh, "output_dir",
                 "is not set (nor logger.out_dir in the configuration): nowhere to log");
    c.logger.validate(config.describe() + ": logger");
    options_ = c.logger;
    options_.out_dir = output_dir_;  // the parameter wins over the config
    camera_ = c.camera;

    std::ostringstream os;
    os << "alvio nodelets\n  config: " << config.describe()
       << "\n  camera: " << c.camera.distortion_model << " " << c.camera.width << "x"
       << c.camera.height << " @ " << c.camera.rate_hz << " Hz\n  topics: " << imu_topic << ", "
       << frame_topic << ", " << estimator_ns << "/{odometry,status,window,points,lines}";
    header_ = os.str();
    openLog(header_);

    imu_sub_ = nh.subscribe(imu_topic, 2000, &LoggerNodelet::onImu, this);
    frame_sub_ = nh.subscribe(frame_topic, 20, &LoggerNodelet::onFrame, this);
    odometry_sub_ = nh.subscribe(estimator_ns + "/odometry", 50, &LoggerNodelet::onOdometry, this);
    status_sub_ = nh.subscribe(estimator_ns + "/status", 50, &LoggerNodelet::onStatus, this);
    window_sub_ = nh.subscribe(estimator_ns + "/window", 2, &LoggerNodelet::onWindow, this);
    points_sub_ = nh.subscribe(estimator_ns + "/points", 2, &LoggerNodelet::onPoints, this);
    lines_sub_ = nh.subscribe(estimator_ns + "/lines", 2, &LoggerNodelet::onLines, this);
  }

  // Into files no earlier log has (alvio.rawlog, else alvio_1.rawlog ...): a robot's earlier
  // run, this nodelet before a reload, or the run before a clock jump may have logged here.
  void openLog(const std::string& first_line) {
    logger_ = std::make_unique<alvio::MrptLogger>(alvio::freshLogNames(options_, output_dir_),
                                                  camera_, output_dir_);
    logger_->log(alvio::LogLevel::kInfo, first_line);
    alvio::MrptLogger* logger = logger_.get();
    log_route_.setListener([logger](alvio::LogLevel level, const std::string& message) {
      logger->log(level, message);
    });
    const alvio::LoggerPaths& p = logger_->paths();
    NODELET_INFO("logging into %s (rawlog %s, scene %s, text %s)", output_dir_.c_str(),
                 p.rawlog.empty() ? "off" : p.rawlog.c_str(),
                 p.scene.empty() ? "off" : p.scene.c_str(),
                 p.text.empty() ? "off" : p.text.c_str());
  }

  void closeLog(const std::string& why) {
    log_route_.clearListener();  // waits for a core message being written
    if (!logger_) return;
    logger_->flushStats();
    logger_->log(alvio::LogLevel::kInfo, why + ": " + std::to_string(frames_) + " frames, " +
                                             std::to_string(poses_) + " poses");
    const alvio::MapSnapshot map = snapshot();
    logger_->finish(&map);
    logger_.reset();
  }

  // The clock going back (a bag played again, a clock reset) starts a new run in the estimator
  // and the map; the log follows into new files, so that no rawlog mixes two clocks and no
  // scene two world frames. The IMU decides, as in the estimator: it comes straight from the
  // sensor, while frames and poses lag behind the tracker and the estimator.
  void startNewLogIfClockJumpedBack(int64_t t_ns) {
    if (const int64_t jump_ns = imu_clock_.follow(t_ns)) {
      char back[32];
      std::snprintf(back, sizeof(back), "%.2f s", jump_ns * 1e-9);
      NODELET_WARN("clock jumped back %s: the log goes on in new files", back);
      const std::string closed = logger_ ? logger_->paths().rawlog : "";
      closeLog(std::string("clock jumped back ") + back + ": log closed");
      window_.reset();
      points_.reset();
      lines_.reset();
      frames_ = poses_ = 0;
      ++runs_;
      try {
        openLog(header_ + "\n  run " + std::to_string(runs_ + 1) + ": the clock jumped back " +
                back + (closed.empty() ? "" : "; before it: " + closed));
      } catch (const alvio::Error& e) {  // the folder went away or filled up: stop logging
        NODELET_ERROR("logging stopped: %s", e.what());
      }
    }
  }

  // After a clock jump, frames and poses still on the old clock (the tracker's and the
  // estimator's queues) belong to the closed log: they lie ahead of the new clock by the jump.
  bool onOldClock(const ros::Time& stamp) const {
    return runs_ > 0 && imu_clock_.aheadByAJump(toNs(stamp));
  }

  void onImu(const sensor_msgs::ImuConstPtr& msg) {
    startNewLogIfClockJumpedBack(toNs(msg->header.stamp));
    if (logger_) logger_->addImu(fromMsg(*msg));
  }

  void onFrame(const SharedTrackedFrame::ConstPtr& frame) {
    if (!logger_ || onOldClock(frame->features.header.stamp)) return;
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
    if (!logger_ || onOldClock(msg->header.stamp)) return;
    ++poses_;
    const Eigen::Isometry3d T = fromPose(msg->pose.pose);
    logger_->addPose(
        {msg->header.stamp.toSec(), T.translation(), Eigen::Quaterniond(T.rotation())});
  }

  void onStatus(const alvio::PipelineStatus::ConstPtr& msg) {
    if (!logger_ || onOldClock(msg->header.stamp)) return;
    alvio::FrameStats stats;
    stats.t = msg->header.stamp.toSec();
    stats.tracked_points = msg->tracked_points;
    stats.window_landmarks = msg->window_points;
    stats.pipeline_ms = msg->frontend_ms + msg->estimator_ms;
    stats.tracking = msg->state == alvio::PipelineStatus::TRACKING;
    logger_->addFrameStats(stats);
    if (logger_->sceneDue(stats.t)) logger_->writeScene(stats.t, snapshot());
  }

  void onWindow(const geometry_msgs::PoseArray::ConstPtr& msg) {
    if (!onOldClock(msg->header.stamp)) window_ = msg;
  }
  void onPoints(const sensor_msgs::PointCloud2::ConstPtr& msg) {
    if (!onOldClock(msg->header.stamp)) points_ = msg;
  }
  void onLines(const visualization_msgs::MarkerArray::ConstPtr& msg) {
    if (msg->markers.empty() || !onOldClock(msg->markers.front().header.stamp)) lines_ = msg;
  }

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
  std::string output_dir_, header_;
  alvio::LoggerOptions options_;
  alvio::CameraOptions camera_;
  std::unique_ptr<alvio::MrptLogger> logger_;
  alvio::ClockWatch imu_clock_;
  int runs_ = 0;  // clock jumps so far
  geometry_msgs::PoseArray::ConstPtr window_;
  sensor_msgs::PointCloud2::ConstPtr points_;
  visualization_msgs::MarkerArray::ConstPtr lines_;
  std::size_t frames_ = 0, poses_ = 0;
  ros::Subscriber imu_sub_, frame_sub_, odometry_sub_, status_sub_, window_sub_, points_sub_,
      lines_sub_;
};

}  // namespace alvio_ros

PLUGINLIB_EXPORT_CLASS(alvio_ros::LoggerNodelet, nodelet::Nodelet)
