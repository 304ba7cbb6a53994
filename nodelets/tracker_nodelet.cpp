// alvio/TrackerNodelet: the visual front end. Subscribes to the camera through
// image_transport, tracks points and lines (alvio::FrontEnd) and publishes ~frame:
// the features together with the very image it received (SharedTrackedFrame), so
// that the estimator and logger nodelets of the same manager get it without a copy.
// With the gyroscope's flow on (points.gyro_flow, lines.flow.gyro_flow) it also
// subscribes to the IMU, and an image waits until an IMU sample after it has come:
// the trackers then get exactly the rotation the offline runner gives them.
#include <cv_bridge/cv_bridge.h>
#include <image_transport/image_transport.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <pluginlib/class_list_macros.hpp>

#include <alvio/PipelineStatus.h>

#include <algorithm>
#include <memory>
#include <optional>
#include <vector>

#include "alvio/common/clock_jump.h"
#include "alvio/common/error.h"
#include "alvio/pipeline/frame_imu_sync.h"
#include "alvio/pipeline/front_end.h"
#include "conversions.h"
#include "core_log_route.h"
#include "guarded_nodelet.h"
#include "image_message_check.h"
#include "nodelet_config.h"
#include "shared_tracked_frame.h"

namespace alvio_ros {

// Callbacks come from getNodeHandle()'s single-threaded queue: they never run at once.
class TrackerNodelet : public GuardedNodelet {
 private:
  struct PendingImage {
    sensor_msgs::ImageConstPtr image;
    cv_bridge::CvImageConstPtr gray;
    ros::WallTime received;
  };
  using Sync = alvio::FrameImuSynchronizer<PendingImage>;

  void init() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    const NodeletConfig config(nh, pnh);
    config.rejectUnusedOverrides();
    const std::string image_topic = param(pnh, "image_topic", config.config().topics.image);
    const std::string transport = param(pnh, "image_transport", "raw");
    const std::string status_topic = param(pnh, "status_topic", "estimator/status");
    // As many images as the estimator's frame queue (1 s at 20 Hz): a busy moment delays frames
    // instead of losing them (docs/benchmarks.md, sixty-fourth session).
    const int queue =
        param(pnh, "queue_size", static_cast<int>(alvio::FrameImuSyncOptions().max_frames));
    const std::string imu_topic = param(pnh, "imu_topic", config.config().topics.imu);
    requireParam(!image_topic.empty(), pnh, "image_topic", "is empty");
    requireParam(queue > 0, pnh, "queue_size", "must be positive");
    uses_gyro_ = config.config().points.gyro_flow ||
                 (config.config().estimator.use_lines && config.config().lines.flow.gyro_flow);
    requireParam(!uses_gyro_ || !imu_topic.empty(), pnh, "imu_topic",
                 "is empty, but points.gyro_flow or lines.flow.gyro_flow needs the gyroscope");

    config_ = config.config();
    front_end_ = std::make_unique<alvio::FrontEnd>(config_);
    frame_period_ns_ = static_cast<int64_t>(1e9 / config.config().camera.rate_hz);

    frame_pub_ = pnh.advertise<SharedTrackedFrame>("frame", 10);
    status_sub_ = nh.subscribe(status_topic, 10, &TrackerNodelet::onStatus, this);
    if (uses_gyro_)
      imu_sub_ = nh.subscribe(imu_topic, 2000, &TrackerNodelet::onImu, this,
                              ros::TransportHints().tcpNoDelay());
    transport_ = std::make_unique<image_transport::ImageTransport>(nh);
    image_sub_ = transport_->subscribe(
        image_topic, queue, &TrackerNodelet::onImage, this,
        image_transport::TransportHints(transport, ros::TransportHints(), pnh));
    const std::string gyro =
        uses_gyro_ ? "flow from the gyroscope on " + imu_sub_.getTopic() : "no gyroscope";
    NODELET_INFO("tracking %s (%s) with %s; points%s; %s; publishing %s",
                 image_sub_.getTopic().c_str(), transport.c_str(), config.describe().c_str(),
                 front_end_->tracksLines() ? " and lines" : " only", gyro.c_str(),
                 frame_pub_.getTopic().c_str());
  }

  void onImu(const sensor_msgs::ImuConstPtr& msg) {
    const alvio::ImuSample sample = fromMsg(*msg);
    if (sync_.addImu(sample) == alvio::ImuAdded::kNewRun)
      // A new run (a bag played again): images of the old clock still waiting are not part of it.
      NODELET_WARN("IMU clock jumped back %.2f s: images waiting for the IMU are dropped",
                   sync_.lastClockJumpNs() * 1e-9);
    release();
  }

  // Track every image whose IMU has come, oldest first.
  void release() {
    while (std::optional<Sync::Ready> ready = sync_.pop()) track(ready->frame, ready->imu);
  }

  void onImage(const sensor_msgs::ImageConstPtr& image) {
    const ros::WallTime received = ros::WallTime::now();
    const std::string problem = imageMessageProblem(*image);
    if (!problem.empty()) {
      NODELET_ERROR_THROTTLE(5.0, "image at %.3f s is malformed: %s: skipped",
                             image->header.stamp.toSec(), problem.c_str());
      return;
    }
    cv_bridge::CvImageConstPtr gray;
    try {
      // mono8 is shared, not copied; other encodings are converted.
      gray = cv_bridge::toCvShare(image, "mono8");
    } catch (const cv_bridge::Exception& e) {
      NODELET_ERROR_THROTTLE(5.0, "image with encoding '%s' cannot be converted to mono8: %s",
                             image->encoding.c_str(), e.what());
      return;
    }
    // The tracker would throw out of the callback and take the manager down with it.
    if (gray->image.cols != config_.camera.width || gray->image.rows != config_.camera.height) {
      NODELET_ERROR_THROTTLE(5.0, "image is %dx%d but camera.resolution is [%d, %d]: skipped",
                             gray->image.cols, gray->image.rows, config_.camera.width,
                             config_.camera.height);
      return;
    }
    // A camera stamped late by the shift, on a clock that starts at 0 (simulated time).
    if (config_.camera.imuClockNs(toNs(image->header.stamp)) <= 0) {
      NODELET_WARN_THROTTLE(5.0,
                            "image at %.3f s comes before 0 s on the IMU's clock "
                            "(camera.timeshift_cam_imu %.3f s): skipped",
                            image->header.stamp.toSec(), config_.camera.timeshift_cam_imu);
      return;
    }
    PendingImage pending{image, gray, received};
    if (!uses_gyro_) {
      track(pending, {});
      return;
    }
    const int64_t t_ns = config_.camera.imuClockNs(toNs(image->header.stamp));
    const std::size_t overflow_before = sync_.counts().frames_overflow;
    switch (sync_.addFrame(t_ns, std::move(pending))) {
      case alvio::FrameAdded::kQueued:
        break;
      case alvio::FrameAdded::kHeld:
        NODELET_WARN_THROTTLE(2.0,
                              "image clock jumped back to %.3f s before the IMU's on %s: images "
                              "wait for the IMU's new clock",
                              t_ns * 1e-9, imu_sub_.getTopic().c_str());
        break;
      case alvio::FrameAdded::kLate:
        NODELET_WARN_THROTTLE(5.0, "image at %.3f s is not after the previous one: skipped",
                              t_ns * 1e-9);
        break;
      case alvio::FrameAdded::kOldClock:
        NODELET_WARN_THROTTLE(2.0, "image at %.3f s is from before the clock jump: dropped",
                              t_ns * 1e-9);
        break;
    }
    if (sync_.counts().frames_overflow != overflow_before)
      NODELET_WARN_THROTTLE(5.0,
                            "%zu images waited for the IMU on %s (points.gyro_flow, "
                            "lines.flow.gyro_flow): the oldest was dropped",
                            sync_.options().max_frames, imu_sub_.getTopic().c_str());
    release();
  }

  // `imu`: the samples that came since the previous image (none without the gyroscope's flow).
  void track(const PendingImage& pending, const std::vector<alvio::ImuSample>& imu) {
    const sensor_msgs::ImageConstPtr& image = pending.image;
    const int64_t t_ns = config_.camera.imuClockNs(toNs(image->header.stamp));
    if (alvio::clockJumpedBack(t_ns, last_t_ns_)) {
      // A bag played again, a restarted simulation, a clock reset: a new run.
      NODELET_WARN("image clock jumped back %.2f s: the front end starts afresh",
                   (last_t_ns_ - t_ns) * 1e-9);
      front_end_ = std::make_unique<alvio::FrontEnd>(config_);
      last_t_ns_ = 0;
    }
    if (alvio::staleStamp(t_ns, last_t_ns_)) {
      NODELET_WARN_THROTTLE(5.0, "image stamps go back in time (%.3f s after %.3f s): skipped",
                            t_ns * 1e-9, last_t_ns_ * 1e-9);
      return;
    }
    if (last_t_ns_ != 0 && t_ns - last_t_ns_ > 3 * frame_period_ns_ / 2)
      NODELET_WARN_THROTTLE(5.0, "%.0f ms between images (camera rate %.0f Hz): frames were lost",
                            (t_ns - last_t_ns_) * 1e-6, 1e9 / frame_period_ns_);
    last_t_ns_ = t_ns;
    if (reset_pending_) {
      front_end_->resetPoints();
      reset_pending_ = false;
    }

    front_end_->setEstimatorTracking(estimator_tracking_);
    for (const alvio::ImuSample& s : imu) front_end_->addImu(s);

    alvio::FrameTiming timing;
    timing.t = t_ns * 1e-9;
    const alvio::FeatureFrame frame = front_end_->track(pending.gray->image, t_ns, &timing);
    auto out = boost::make_shared<SharedTrackedFrame>();
    toMsg(frame, timing, image->header, &out->features);
    out->features.received = ros::Time(pending.received.sec, pending.received.nsec);
    out->image = image;  // the received pointer itself: no copy
    frame_pub_.publish(out);
  }

  // After an estimator reset the point tracks start afresh, as in the offline pipeline. Whether
  // the estimator tracks decides, as there, whether the corners' anchors end tracks.
  void onStatus(const alvio::PipelineStatus::ConstPtr& status) {
    // A new run's first frame (after a clock jump) counts as a reset too, but this tracker
    // started afresh itself when the image clock jumped. A second reset a few frames into the
    // new run would leave the initialising window's first frames sharing no point with the
    // rest: the new run then starts differently from one started on the same data.
    const bool new_run = status->state == alvio::PipelineStatus::RESET && status->frames == 1;
    // Fewer resets than before: the estimator was restarted (reloaded, new run).
    if (status->reset_count > reset_count_ && !new_run) reset_pending_ = true;
    reset_count_ = status->reset_count;
    estimator_tracking_ = status->state == alvio::PipelineStatus::TRACKING;
  }

  CoreLogRoute log_route_;
  alvio::Config config_;
  std::unique_ptr<alvio::FrontEnd> front_end_;
  std::unique_ptr<image_transport::ImageTransport> transport_;
  image_transport::Subscriber image_sub_;
  ros::Subscriber status_sub_, imu_sub_;
  ros::Publisher frame_pub_;
  bool uses_gyro_ = false;
  Sync sync_;
  int64_t frame_period_ns_ = 50000000, last_t_ns_ = 0;
  int reset_count_ = 0;
  bool reset_pending_ = false;
  bool estimator_tracking_ = false;  // the latest status's, for the corners' anchors
};

}  // namespace alvio_ros

PLUGINLIB_EXPORT_CLASS(alvio_ros::TrackerNodelet, nodelet::Nodelet)
