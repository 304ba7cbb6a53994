// alvio/EstimatorNodelet: the sliding-window estimator. Subscribes to the IMU and
// to the tracker's ~frame, pairs them in a bounded queue (FrameImuSynchronizer)
// and runs the estimator in its own thread, so that callbacks never block and a
// slow frame cannot stall the IMU. Publishes the pose (odometry, path, TF), the
// window's landmarks for display, keyframe landmarks for the mapping nodelet and
// a status per frame; writes trajectory.tum into output_dir on shutdown.
#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>
#include <visualization_msgs/MarkerArray.h>
#include <pluginlib/class_list_macros.hpp>

#include <alvio/MapKeyframe.h>
#include <alvio/PipelineStatus.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <memory>
#include <mutex>
#include <thread>

#include "alvio/common/error.h"
#include "alvio/estimator/estimator.h"
#include "alvio/io/trajectory_io.h"
#include "alvio/mapping/estimator_keyframe_feed.h"
#include "alvio/pipeline/frame_imu_sync.h"
#include "alvio/pipeline/odometry_covariance.h"
#include "conversions.h"
#include "core_log_route.h"
#include "guarded_nodelet.h"
#include "nodelet_config.h"
#include "shared_tracked_frame.h"

namespace alvio_ros {

class EstimatorNodelet : public GuardedNodelet {
 public:
  ~EstimatorNodelet() override {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    if (worker_.joinable()) worker_.join();
    writeTrajectory();
    logLineRetirement();
  }

 private:
  using Sync = alvio::FrameImuSynchronizer<SharedTrackedFrame::ConstPtr>;
  using Clock = std::chrono::steady_clock;

  void init() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    const NodeletConfig config(nh, pnh);
    config.rejectUnusedOverrides();
    const alvio::Config& c = config.config();
    const std::string imu_topic = param(pnh, "imu_topic", c.topics.imu);
    const std::string frame_topic = param(pnh, "frame_topic", "tracker/frame");
    world_frame_ = param(pnh, "world_frame", "world");
    body_frame_ = param(pnh, "body_frame", "body");
    const std::string camera_frame = param(pnh, "camera_frame", "cam0");
    publish_tf_ = param(pnh, "publish_tf", true);
    alvio::FrameImuSyncOptions sync_options;
    const int frame_queue =
        param(pnh, "frame_queue_size", static_cast<int>(sync_options.max_frames));
    const int imu_queue = param(pnh, "imu_queue_size", static_cast<int>(sync_options.max_imu));
    output_dir_ = param(pnh, "output_dir", "");
    path_max_poses_ = param(pnh, "path_max_poses", 10000);
    flush_after_s_ = param(pnh, "flush_after_s", 1.0);
    line_max_std_deg_ = param(pnh, "line_max_direction_std_deg", -1.0);
    requireParam(!imu_topic.empty(), pnh, "imu_topic", "is empty");
    requireParam(!world_frame_.empty(), pnh, "world_frame", "is empty");
    requireParam(!body_frame_.empty(), pnh, "body_frame", "is empty");
    requireParam(frame_queue > 0, pnh, "frame_queue_size", "must be positive");
    requireParam(imu_queue > 0, pnh, "imu_queue_size", "must be positive");
    requireParam(path_max_poses_ > 0, pnh, "path_max_poses", "must be positive");
    requireParam(flush_after_s_ > 0, pnh, "flush_after_s", "must be positive");
    sync_options.max_frames = static_cast<std::size_t>(frame_queue);
    sync_options.max_imu = static_cast<std::size_t>(imu_queue);
    sync_ = Sync(sync_options);

    T_b_c_ = c.camera.T_b_c;
    config_ = c;
    estimator_ = std::make_unique<alvio::Estimator>(c.estimator, c.camera, c.imu);
    feed_ = std::make_unique<alvio::EstimatorKeyframeFeed>(c.camera.T_b_c);
    covariance_ = std::make_unique<alvio::OdometryCovariance>(c.odometry_covariance);
    path_.header.frame_id = world_frame_;

    odometry_pub_ = pnh.advertise<nav_msgs::Odometry>("odometry", 50);
    path_pub_ = pnh.advertise<nav_msgs::Path>("path", 1);
    points_pub_ = pnh.advertise<sensor_msgs::PointCloud2>("points", 2);
    lines_pub_ = pnh.advertise<visualization_msgs::MarkerArray>("lines", 2);
    window_pub_ = pnh.advertise<geometry_msgs::PoseArray>("window", 2);
    keyframes_pub_ = pnh.advertise<alvio::MapKeyframe>("keyframes", 100);
    status_pub_ = pnh.advertise<alvio::PipelineStatus>("status", 50);
    if (publish_tf_) {
      tf_ = std::make_unique<tf2_ros::TransformBroadcaster>();
      if (!camera_frame.empty()) {
        // The camera's mounting, for displays of the camera's view.
        static_tf_ = std::make_unique<tf2_ros::StaticTransformBroadcaster>();
        geometry_msgs::TransformStamped t;
        t.header.frame_id = body_frame_;
        t.child_frame_id = camera_frame;
        const geometry_msgs::Pose p = toPose(T_b_c_);
        t.transform.translation.x = p.position.x;
        t.transform.translation.y = p.position.y;
        t.transform.translation.z = p.position.z;
        t.transform.rotation = p.orientation;
        static_tf_->sendTransform(t);
      }
    }

    worker_ = std::thread(&EstimatorNodelet::run, this);
    imu_sub_ = nh.subscribe(imu_topic, 2000, &EstimatorNodelet::onImu, this,
                            ros::TransportHints().tcpNoDelay());
    frame_sub_ = nh.subscribe(frame_topic, 10, &EstimatorNodelet::onFrame, this);
    NODELET_INFO("estimating from %s and %s with %s; %s -> %s%s", imu_sub_.getTopic().c_str(),
                 frame_sub_.getTopic().c_str(), config.describe().c_str(), world_frame_.c_str(),
                 body_frame_.c_str(),
                 output_dir_.empty() ? "" : (", trajectory to " + output_dir_).c_str());
  }

  // Callbacks only queue, so they never wait for the estimator.
  void onImu(const sensor_msgs::ImuConstPtr& msg) {
    bool dropped = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      const std::size_t overflow_before = sync_.counts().imu_overflow;
      switch (sync_.addImu(fromMsg(*msg))) {
        case alvio::ImuAdded::kQueued:
          dropped = sync_.counts().imu_overflow != overflow_before;
          break;
        case alvio::ImuAdded::kLate:
          dropped = true;
          break;
        case alvio::ImuAdded::kNewRun:
          // The worker restarts the estimator; the frames queued from the old clock are gone.
          NODELET_WARN("IMU clock jumped back %.2f s: the estimator starts a new run",
                       sync_.lastClockJumpNs() * 1e-9);
          restart_ = true;
          break;
      }
    }
    if (dropped)
      NODELET_WARN_THROTTLE(2.0,
                            "IMU sample at %.3f s dropped (not after the previous one, or no "
                            "camera frame for %zu samples)",
                            msg->header.stamp.toSec(), sync_.options().max_imu);
    wake_.notify_one();
  }

  void onFrame(const SharedTrackedFrame::ConstPtr& msg) {
    alvio::FrameAdded added;
    bool overflow = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      const int64_t t_ns = toNs(msg->features.header.stamp);
      const std::size_t overflow_before = sync_.counts().frames_overflow;
      added = sync_.addFrame(t_ns, msg);
      overflow = sync_.counts().frames_overflow != overflow_before;
    }
    const double t = msg->features.header.stamp.toSec();
    switch (added) {
      case alvio::FrameAdded::kQueued:
      case alvio::FrameAdded::kHeld:  // the clock jump is told when the IMU follows
        break;
      case alvio::FrameAdded::kLate:
        NODELET_WARN_THROTTLE(2.0, "frame at %.3f s dropped: not after the previous frame", t);
        break;
      case alvio::FrameAdded::kOldClock:
        // Tracked before the clock jump that restarted the run: not part of the new run.
        NODELET_WARN_THROTTLE(2.0, "frame at %.3f s is from before the clock jump: dropped", t);
        break;
    }
    if (overflow)
      NODELET_WARN_THROTTLE(2.0,
                            "frame queue full (%zu frames): oldest frame dropped (the estimator "
                            "is too slow, or the IMU is behind the camera)",
                            sync_.options().max_frames);
    wake_.notify_one();
  }

  // The finished run's trajectory is kept as trajectory_run<N>.tum; trajectory.tum and the
  // path hold the new run's.
  void restart() {
    ++finished_runs_;
    writeTrajectory("trajectory_run" + std::to_string(finished_runs_) + ".tum");
    earlier_resets_ += estimator_->resetCount() + 1;
    estimator_ = std::make_unique<alvio::Estimator>(config_.estimator, config_.camera, config_.imu);
    feed_ = std::make_unique<alvio::EstimatorKeyframeFeed>(config_.camera.T_b_c);
    covariance_->startNewRun();
    trajectory_.clear();
    path_.poses.clear();
    last_event_.clear();
    frames_ = 0;
    flushed_ = false;
  }

  void run() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!stop_) {
      if (restart_) {
        restart_ = false;
        lock.unlock();
        restart();
        lock.lock();
        continue;
      }
      std::optional<Sync::Ready> ready = sync_.pop();
      if (!ready) {
        wake_.wait_for(lock, std::chrono::milliseconds(200));
        if (!stop_ && !flushed_ && frames_ > 0 &&
            Clock::now() - last_frame_wall_ > std::chrono::duration<double>(flush_after_s_)) {
          lock.unlock();
          flushWindowToMap();
          lock.lock();
        }
        continue;
      }
      dropped_frames_ = sync_.counts().droppedFrames();
      dropped_imu_ = sync_.counts().droppedImu();
      lock.unlock();
      try {
        process(*ready);
      } catch (const std::exception& e) {
        NODELET_ERROR_THROTTLE(2.0, "frame at %.3f s failed: %s", ready->t_ns * 1e-9, e.what());
      }
      lock.lock();
    }
  }

  void process(const Sync::Ready& ready) {
    for (const alvio::ImuSample& s : ready.imu) estimator_->addImu(s);
    const alvio::TrackedFeatures& features = ready.frame->features;
    const auto start = Clock::now();
    const int resets_before = estimator_->resetCount();
    const bool has_pose = estimator_->addFrame(fromMsg(features));
    const std::vector<alvio::EstimatorEvent> events = estimator_->takeEvents();
    const alvio::LineSegments3 retired = estimator_->takeRetiredLines();
    const double estimator_ms =
        std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    ++frames_;
    last_frame_wall_ = Clock::now();
    flushed_ = false;

    std_msgs::Header header;
    header.stamp = features.header.stamp;  // the image's time on the IMU's clock
    header.frame_id = world_frame_;
    if (has_pose) {
      const alvio::BodyState state = estimator_->latestState();
      publishPose(header, state);
      publishMapInput(state, retired);
    }
    const ros::WallTime odometry_out = ros::WallTime::now();
    publishWindow(header);
    for (const auto& e : events) last_event_ = e.message;
    auto status = boost::make_shared<alvio::PipelineStatus>();
    status->header = header;
    const bool first_frame_of_new_run = finished_runs_ > 0 && frames_ == 1;
    const bool reset = first_frame_of_new_run || estimator_->resetCount() != resets_before;
    status->state = reset      ? alvio::PipelineStatus::RESET
                    : has_pose ? alvio::PipelineStatus::TRACKING
                               : alvio::PipelineStatus::INITIALISING;
    status->message = last_event_;
    // A new run after a clock jump counts as a reset too.
    status->reset_count = earlier_resets_ + estimator_->resetCount();
    status->frames = frames_;
    status->dropped_frames = static_cast<uint32_t>(dropped_frames_);
    status->dropped_imu = static_cast<uint32_t>(dropped_imu_ + estimator_->droppedImu());
    status->tracked_points = static_cast<int32_t>(features.points.size());
    status->window_points = static_cast<int32_t>(estimator_->points().landmarks().size());
    status->window_lines = static_cast<int32_t>(estimator_->lineSegments().size());
    status->frontend_ms = features.stats.total_ms;
    status->estimator_ms = estimator_ms;
    status->time_shift_s = estimator_->timeShift();
    status->latency_ms =
        features.received.isZero()
            ? -1.0  // a sender that does not fill it in
            : (ros::Time(odometry_out.sec, odometry_out.nsec) - features.received).toSec() * 1e3;
    status_pub_.publish(status);
  }

  void publishPose(const std_msgs::Header& header, const alvio::BodyState& state) {
    trajectory_.push_back({state.t, state.p, state.q});
    auto odometry = boost::make_shared<nav_msgs::Odometry>();
    odometry->header = header;
    odometry->child_frame_id = body_frame_;
    odometry->pose.pose = toPose(state.p, state.q);
    // nav_msgs/Odometry: the twist is in the child (body) frame.
    const Eigen::Vector3d v_b = state.q.conjugate() * state.v;
    // At the frame's stamp: the sample after it lags up to one IMU period, on a fast turn
    // several times the gyroscope's noise.
    const Eigen::Vector3d w_b = estimator_->gyroAtLatestFrame() - state.bg;
    odometry->twist.twist.linear.x = v_b.x();
    odometry->twist.twist.linear.y = v_b.y();
    odometry->twist.twist.linear.z = v_b.z();
    odometry->twist.twist.angular.x = w_b.x();
    odometry->twist.twist.angular.y = w_b.y();
    odometry->twist.twist.angular.z = w_b.z();
    covariance_->addPose(state.t, state.p);  // a pause since the last one is an outage
    // A calibrated error model (config odometry_covariance), not the window's marginal.
    const alvio::Covariance6 pose_cov = covariance_->pose(), twist_cov = covariance_->twist();
    std::copy(pose_cov.begin(), pose_cov.end(), odometry->pose.covariance.begin());
    std::copy(twist_cov.begin(), twist_cov.end(), odometry->twist.covariance.begin());
    odometry_pub_.publish(odometry);

    if (tf_) {
      geometry_msgs::TransformStamped t;
      t.header = header;
      t.child_frame_id = body_frame_;
      t.transform.translation.x = state.p.x();
      t.transform.translation.y = state.p.y();
      t.transform.translation.z = state.p.z();
      t.transform.rotation = odometry->pose.pose.orientation;
      tf_->sendTransform(t);
    }

    geometry_msgs::PoseStamped pose;
    pose.header = header;
    pose.pose = odometry->pose.pose;
    path_.poses.push_back(pose);
    if (path_.poses.size() > static_cast<std::size_t>(path_max_poses_))
      path_.poses.erase(path_.poses.begin());
    if (path_pub_.getNumSubscribers() > 0) {
      path_.header.stamp = header.stamp;
      path_pub_.publish(boost::make_shared<nav_msgs::Path>(path_));
    }
  }

  // The window for displays and the logger: keyframe poses, points, 3D lines.
  void publishWindow(const std_msgs::Header& header) {
    if (estimator_->status() != alvio::EstimatorStatus::kTracking) return;
    if (window_pub_.getNumSubscribers() > 0) {
      auto poses = boost::make_shared<geometry_msgs::PoseArray>();
      poses->header = header;
      for (const auto& s : estimator_->windowStates()) poses->poses.push_back(toPose(s.p, s.q));
      window_pub_.publish(poses);
    }
    if (points_pub_.getNumSubscribers() > 0) {
      std::vector<Eigen::Vector3d> points;
      for (const auto& [id, p] : estimator_->landmarkPositions()) points.push_back(p);
      auto cloud = boost::make_shared<sensor_msgs::PointCloud2>();
      toCloud(points, header, cloud.get());
      points_pub_.publish(cloud);
    }
    if (lines_pub_.getNumSubscribers() > 0) {
      Segments segments;
      for (const auto& l : estimator_->lineSegments(line_max_std_deg_))
        segments.emplace_back(l.start, l.end);
      auto markers = boost::make_shared<visualization_msgs::MarkerArray>();
      markers->markers.push_back(
          lineListMarker(segments, header, "window_lines", 0.1f, 0.8f, 1.0f, 0.02));
      lines_pub_.publish(markers);
    }
  }

  // What the offline runner's MapObserver feeds the map: the points anchored in the keyframe
  // leaving the window, and the lines retiring from it (all of them, with their direction
  // uncertainty: the map applies its own threshold).
  void publishMapInput(const alvio::BodyState& state, const alvio::LineSegments3& retired) {
    if (auto keyframe = feed_->poll(*estimator_)) publishKeyframe(*keyframe, 0);
    if (!retired.empty())
      publishKeyframe(alvio::retiredLinesKeyframe(state, T_b_c_, retired),
                      alvio::MapKeyframe::RETIRED_LINES);
  }

  void publishKeyframe(const alvio::KeyframeLandmarks& keyframe, uint8_t kind) {
    std_msgs::Header header;
    header.stamp.fromSec(keyframe.t);
    header.frame_id = world_frame_;
    auto msg = boost::make_shared<alvio::MapKeyframe>();
    toMsg(keyframe, kind, header, msg.get());
    keyframes_pub_.publish(msg);
  }

  // When the frames stop (end of a bag, camera gone), the window's landmarks are the best
  // estimates there will be: hand them to the map, as the offline runner does at its end.
  void flushWindowToMap() {
    const auto keyframes = feed_->flush(*estimator_);
    for (const auto& keyframe : keyframes)
      publishKeyframe(keyframe, alvio::MapKeyframe::KEYFRAME_POINTS);
    flushed_ = true;
    if (!keyframes.empty())
      NODELET_INFO(
          "no frame for %.1f s: the landmarks of the window's %zu keyframes went to the map",
          flush_after_s_, keyframes.size());
  }

  // What the map filter let through, as alvio_run reports it (since the last restart).
  void logLineRetirement() const {
    if (!estimator_) return;
    const alvio::LineRetirementCounts& c = estimator_->lineRetirementCounts();
    if (c.tracks() == 0) return;
    NODELET_INFO("lines for the map: %s",
                 alvio::describeLineRetirement(
                     c, alvio::lineMapLimits(config_.estimator, config_.lines.map_edges))
                     .c_str());
    if (alvio::fitLimitLooksTooTight(c)) NODELET_WARN("%s", alvio::kFitLimitHint);
  }

  void writeTrajectory(const std::string& name = "trajectory.tum") {
    if (output_dir_.empty() || trajectory_.empty()) return;
    try {
      std::filesystem::create_directories(output_dir_);
      const std::string path = output_dir_ + "/" + name;
      alvio::writeTumTrajectory(path, trajectory_);
      NODELET_INFO("%zu poses written to %s", trajectory_.size(), path.c_str());
    } catch (const std::exception& e) {
      NODELET_ERROR("cannot write the trajectory into %s: %s", output_dir_.c_str(), e.what());
    }
  }

  CoreLogRoute log_route_;
  // Parameters.
  std::string world_frame_, body_frame_, output_dir_;
  bool publish_tf_ = true;
  int path_max_poses_ = 10000;
  double flush_after_s_ = 1.0, line_max_std_deg_ = -1;
  Eigen::Isometry3d T_b_c_ = Eigen::Isometry3d::Identity();
  alvio::Config config_;

  // Shared between the callbacks and the worker (under mutex_).
  std::mutex mutex_;
  std::condition_variable wake_;
  Sync sync_;
  bool stop_ = false, restart_ = false;

  // The worker's.
  std::thread worker_;
  std::unique_ptr<alvio::Estimator> estimator_;
  std::unique_ptr<alvio::EstimatorKeyframeFeed> feed_;
  std::unique_ptr<alvio::OdometryCovariance> covariance_;
  alvio::Trajectory trajectory_;
  int finished_runs_ = 0, earlier_resets_ = 0;
  nav_msgs::Path path_;
  std::string last_event_;
  uint32_t frames_ = 0;
  std::size_t dropped_frames_ = 0, dropped_imu_ = 0;
  Clock::time_point last_frame_wall_;
  bool flushed_ = false;

  ros::Subscriber imu_sub_, frame_sub_;
  ros::Publisher odometry_pub_, path_pub_, points_pub_, lines_pub_, window_pub_, keyframes_pub_,
      status_pub_;
  std::unique_ptr<tf2_ros::TransformBroadcaster> tf_;
  std::unique_ptr<tf2_ros::StaticTransformBroadcaster> static_tf_;
};

}  // namespace alvio_ros

PLUGINLIB_EXPORT_CLASS(alvio_ros::EstimatorNodelet, nodelet::Nodelet)
