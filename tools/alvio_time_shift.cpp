// alvio_time_shift: the camera-to-IMU time shift (Kalibr's timeshift_cam_imu) of a recording,
// from its images and gyroscope alone. The point tracker follows corners without the
// gyroscope's help, each pair of consecutive images gives the camera's rotation, and the shift
// is where the gyroscope's rotation over the same interval agrees best
// (alvio/calibration/time_shift.h). Rotate the camera briskly about all its axes while
// recording; translation and a constant gyroscope bias do not matter.
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>

#include "alvio/calibration/frame_rotation.h"
#include "alvio/calibration/time_shift.h"
#include "alvio/common/arg_parser.h"
#include "alvio/common/error.h"
#include "alvio/common/logging.h"
#include "alvio/common/progress_bar.h"
#include "alvio/config/config.h"
#include "alvio/pipeline/front_end.h"
#include "alvio/pipeline/sensor_source.h"
#include "dataset_source.h"

using namespace alvio;

namespace {

// Below this the rotation barely moves within a shift's worth of time (MH_03's flight: 0.36).
constexpr double kMinRmsRateRps = 0.2;
constexpr int kMinPoints = 20;  // common to two images, for their rotation

void writeCurve(const std::string& path, const TimeShiftEstimate& e) {
  std::ofstream out(path);
  if (!out) throw Error("cannot write '" + path + "'");
  out << "shift_s,cost_rad2_per_s2\n";
  for (std::size_t i = 0; i < e.cost.size(); ++i)
    out << e.trial_shift_s[i] << "," << e.cost[i] << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  ArgParser args("alvio_time_shift",
                 "Estimate the camera-to-IMU time shift (Kalibr's timeshift_cam_imu: t_imu =\n"
                 "t_cam + shift) of a recording from its images and gyroscope, for the config's\n"
                 "camera.timeshift_cam_imu.");
  args.option("dataset", "EuRoC folder (containing mav0/) or .bag file", "", true);
  args.option("config", "YAML configuration (camera, topics)", Config::defaultPath());
  args.option("max-shift", "search shifts from -max to +max (s)", "0.2");
  args.option("step", "between trial shifts (s); the minimum is refined between them", "0.001");
  args.option("max-frames", "use the first N images (-1: all)", "-1");
  args.option("curve", "write each trial shift's cost here (CSV)");
  args.flag("quiet", "no progress bar");
  try {
    if (!args.parse(argc, argv)) return 0;
    Config config = Config::load(args.get("config"));
    // Corners tracked on their own: the gyroscope would start each track where the current
    // shift puts it. Lines add nothing to a rotation.
    config.points.gyro_flow = false;
    config.estimator.use_lines = false;
    const std::unique_ptr<SensorSource> source = openDataset(args.get("dataset"), config.topics);
    TimeShiftOptions options;
    options.max_shift_s = args.getDouble("max-shift");
    options.step_s = args.getDouble("step");
    try {
      options.validate();  // before the pass over the recording, not after it
    } catch (const Error& e) {
      throw Error(std::string("--max-shift / --step: ") + e.what());
    }
    const int max_frames = args.getInt("max-frames");
    const std::size_t total = max_frames > 0
                                  ? std::min<std::size_t>(max_frames, source->imageCount())
                                  : source->imageCount();

    FrontEnd front_end(config);
    std::vector<ImuSample> imu;
    std::vector<FrameRotation> rotations;
    std::optional<FeatureFrame> previous;
    std::size_t images = 0, unreadable = 0;
    ProgressBar progress("alvio_time_shift", total, !args.isSet("quiet"));
    SensorMessage m;
    while (images < total && source->next(&m)) {
      if (m.kind == SensorMessage::Kind::kImu) {
        imu.push_back(m.imu);
        continue;
      }
      ++images;
      const cv::Mat image = m.load_image();
      if (image.cols != config.camera.width || image.rows != config.camera.height) {
        ++unreadable;  // unreadable, or not the configured camera.resolution
        previous.reset();
        continue;
      }
      FeatureFrame frame = front_end.track(image, m.t_ns);
      if (previous)
        if (auto r =
                rotationBetween(*previous, frame, kMinPoints, 1.0 / config.camera.intrinsics[0]))
          rotations.push_back(*r);
      previous = std::move(frame);
      progress.update(images, std::to_string(rotations.size()) + " rotations");
    }
    // The IMU past the last image by the search's reach: the last pairs need it at positive
    // shifts.
    const int64_t last_image_ns = m.t_ns;
    while (source->next(&m) && m.t_ns <= last_image_ns + secToNs(options.max_shift_s + 0.1))
      if (m.kind == SensorMessage::Kind::kImu) imu.push_back(m.imu);
    progress.finish();
    if (unreadable > 0)
      logWarn(unreadable, " images could not be read or are not ", config.camera.width, "x",
              config.camera.height, " (camera.resolution): skipped");

    const TimeShiftEstimate e =
        estimateTimeShift(rotations, imu, config.camera.T_b_c.rotation(), options);
    if (args.isSet("curve")) writeCurve(args.get("curve"), e);

    const double at_zero = e.cost[e.cost.size() / 2];
    std::cout << "image pairs: " << e.pairs << ", camera rotating at " << e.rms_rate_rps
              << " rad/s RMS\n"
              << "angular-velocity mismatch: " << std::sqrt(at_zero) << " rad/s RMS at shift 0, "
              << std::sqrt(*std::min_element(e.cost.begin(), e.cost.end())) << " at the estimate\n"
              << "gyroscope bias seen (camera frame): " << e.gyro_bias_rps.transpose()
              << " rad/s\n";
    if (config.camera.timeshift_cam_imu != 0)
      std::cout << "(the config's camera.timeshift_cam_imu, " << config.camera.timeshift_cam_imu
                << " s, is not used: the estimate is from the raw stamps)\n";
    if (e.at_search_edge)
      logWarn("the best shift is at the end of the search: widen it with --max-shift");
    if (e.rms_rate_rps < kMinRmsRateRps)
      logWarn("the camera rotates at only ", e.rms_rate_rps, " rad/s RMS: rotate it more (at ",
              "least ", kMinRmsRateRps, ") for a reliable estimate");
    std::cout << "camera:\n  timeshift_cam_imu: " << e.shift_s << "\n";
    std::cout << "TIMESHIFT_CAM_IMU=" << e.shift_s << "\n";
    return e.at_search_edge ? 3 : 0;
  } catch (const Error& e) {
    std::cerr << "alvio_time_shift: error: " << e.what() << "\n";
    return 1;
  }
}
