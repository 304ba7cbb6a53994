// alvio_euroc_to_bag: an EuRoC/ASL folder (a recording, or one the simulator rendered)
// as a rosbag with mono8 sensor_msgs/Image and sensor_msgs/Imu on the configured
// topics, in time order, optionally only a time window; and the ground truth of that
// window as a TUM file. The ROS tests and `alvio ros-demo` play such bags.
#include <rosbag/bag.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>

#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>

#include "alvio/common/arg_parser.h"
#include "alvio/common/error.h"
#include "alvio/config/config.h"
#include "alvio/io/euroc_dataset.h"
#include "alvio/io/trajectory_io.h"

using namespace alvio;

namespace {

ros::Time rosTime(int64_t t_ns) {
  ros::Time t;
  t.fromNSec(static_cast<uint64_t>(t_ns));
  return t;
}

sensor_msgs::Image imageMessage(const cv::Mat& gray, int64_t t_ns, uint32_t seq) {
  sensor_msgs::Image m;
  m.header.stamp = rosTime(t_ns);
  m.header.frame_id = "cam0";
  m.header.seq = seq;
  m.height = static_cast<uint32_t>(gray.rows);
  m.width = static_cast<uint32_t>(gray.cols);
  m.encoding = "mono8";
  m.is_bigendian = 0;
  m.step = static_cast<uint32_t>(gray.cols);
  m.data.resize(gray.total());
  for (int r = 0; r < gray.rows; ++r)  // row by row: a cv::Mat row may be padded
    std::copy(gray.ptr<uint8_t>(r), gray.ptr<uint8_t>(r) + gray.cols, &m.data[r * gray.cols]);
  return m;
}

sensor_msgs::Imu imuMessage(const ImuSample& s, uint32_t seq) {
  sensor_msgs::Imu m;
  m.header.stamp = rosTime(s.t_ns);
  m.header.frame_id = "imu0";
  m.header.seq = seq;
  m.orientation_covariance[0] = -1;  // no orientation estimate
  m.angular_velocity.x = s.gyr.x();
  m.angular_velocity.y = s.gyr.y();
  m.angular_velocity.z = s.gyr.z();
  m.linear_acceleration.x = s.acc.x();
  m.linear_acceleration.y = s.acc.y();
  m.linear_acceleration.z = s.acc.z();
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  ArgParser args("alvio_euroc_to_bag",
                 "Write an EuRoC/ASL folder (or a time window of it) as a rosbag with\n"
                 "/cam0/image_raw (mono8) and /imu0, or the topics of --config.");
  args.option("dataset", "EuRoC folder (containing mav0/)", "", true);
  args.option("out", "output .bag file (written as <out>.tmp, then renamed)", "", true);
  args.option("start", "skip this many seconds after the first image", "0");
  args.option("duration", "seconds of images to write (0: all)", "0");
  args.option("groundtruth", "also write the ground truth of the window here (TUM)");
  args.option("config", "configuration whose topics.image / topics.imu name the topics",
              Config::defaultPath());
  try {
    if (!args.parse(argc, argv)) return 0;
    const Config config = Config::load(args.get("config"));
    const EurocDataset data(args.get("dataset"));
    const auto& images = data.images();
    if (images.empty()) throw Error(args.get("dataset") + ": no images");
    const int64_t t_first = images.front().t_ns;
    const int64_t t_begin = t_first + static_cast<int64_t>(args.getDouble("start") * 1e9);
    const double duration = args.getDouble("duration");
    const int64_t t_end =
        duration > 0 ? t_begin + static_cast<int64_t>(duration * 1e9) : images.back().t_ns;

    // Images in [t_begin, t_end]; IMU from 0.5 s before the first to the first sample after
    // the last, so the first and the last image both have IMU around them.
    std::vector<const ImageRecord*> chosen;
    for (const auto& im : images)
      if (im.t_ns >= t_begin && im.t_ns <= t_end) chosen.push_back(&im);
    if (chosen.empty()) throw Error("no images in the requested window");
    const int64_t imu_from = chosen.front()->t_ns - 500000000;
    const int64_t imu_to = chosen.back()->t_ns;

    const std::string out = args.get("out");
    if (const auto dir = std::filesystem::path(out).parent_path(); !dir.empty())
      std::filesystem::create_directories(dir);
    rosbag::Bag bag(out + ".tmp", rosbag::bagmode::Write);
    std::size_t i = 0, k = 0, imu_written = 0;
    uint32_t image_seq = 0, imu_seq = 0;
    const auto& imu = data.imu();
    bool past_end = false;
    while (i < chosen.size() || (k < imu.size() && !past_end)) {
      // IMU first on equal stamps, as a driver would deliver it.
      const bool take_imu =
          k < imu.size() && !past_end && (i >= chosen.size() || imu[k].t_ns <= chosen[i]->t_ns);
      if (take_imu) {
        if (imu[k].t_ns >= imu_from) {
          bag.write(config.topics.imu, rosTime(imu[k].t_ns), imuMessage(imu[k], imu_seq++));
          ++imu_written;
        }
        past_end = imu[k].t_ns > imu_to;
        ++k;
        continue;
      }
      const cv::Mat gray = cv::imread(chosen[i]->path, cv::IMREAD_GRAYSCALE);
      if (gray.empty()) throw Error("cannot read " + chosen[i]->path);
      bag.write(config.topics.image, rosTime(chosen[i]->t_ns),
                imageMessage(gray, chosen[i]->t_ns, image_seq++));
      ++i;
    }
    bag.close();
    std::filesystem::rename(out + ".tmp", out);
    std::cout << "bag written to " << out << ": " << chosen.size() << " images, " << imu_written
              << " IMU samples, " << (chosen.back()->t_ns - chosen.front()->t_ns) * 1e-9 << " s\n";

    if (args.isSet("groundtruth")) {
      if (!data.groundTruth()) throw Error(args.get("dataset") + " has no ground truth");
      Trajectory gt;
      for (const auto& s : *data.groundTruth())
        if (s.t_ns >= imu_from && s.t_ns <= imu_to + 100000000)
          gt.push_back({s.t_ns * 1e-9, s.p, s.q});
      writeTumTrajectory(args.get("groundtruth"), gt);
      std::cout << "ground truth written to " << args.get("groundtruth") << ": " << gt.size()
                << " poses\n";
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "alvio_euroc_to_bag: error: " << e.what() << "\n";
    return 2;
  }
}
