// alvio_sim: rendered EuRoC-style sequences (images + synthetic or real IMU +
// ground truth) in a simulated indoor scene; see `alvio_sim --help`.
#include <rosbag/bag.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <thread>

#include "alvio/common/arg_parser.h"
#include "alvio/common/error.h"
#include "alvio/common/logging.h"
#include "alvio/common/progress_bar.h"
#include "alvio/io/euroc_dataset.h"
#include "alvio/io/trajectory_io.h"
#include "alvio/sim/benchmark_set.h"
#include "alvio/sim/euroc_sequences.h"
#include "alvio/sim/pose_spline_fit.h"
#include "alvio/sim/procedural_trajectories.h"
#include "alvio/sim/scene_appearance.h"
#include "alvio/sim/scene_file.h"
#include "alvio/sim/sequence_generator.h"

using namespace alvio;
using namespace alvio::sim;
namespace fs = std::filesystem;

namespace {

ros::Time rosTime(int64_t t_ns) {
  return ros::Time(static_cast<uint32_t>(t_ns / 1000000000),
                   static_cast<uint32_t>(t_ns % 1000000000));
}

// A rosbag with /cam0/image_raw (mono8) and /imu0 from a written ASL folder.
void writeBag(const std::string& folder, const std::string& bag_path, const TopicOptions& topics,
              bool progress) {
  const EurocDataset data(folder);
  rosbag::Bag bag(bag_path + ".tmp", rosbag::bagmode::Write);
  std::size_t i = 0, k = 0;
  const auto& images = data.images();
  const auto& imu = data.imu();
  ProgressBar bar("bag", images.size() + imu.size(), progress);
  uint32_t image_seq = 0, imu_seq = 0;
  while (i < images.size() || k < imu.size()) {
    // Time order across both streams; IMU first on ties, as a driver would deliver it.
    if (k < imu.size() && (i >= images.size() || imu[k].t_ns <= images[i].t_ns)) {
      sensor_msgs::Imu m;
      m.header.stamp = rosTime(imu[k].t_ns);
      m.header.frame_id = "imu0";
      m.header.seq = imu_seq++;
      m.orientation_covariance[0] = -1;  // no orientation estimate
      m.angular_velocity.x = imu[k].gyr.x();
      m.angular_velocity.y = imu[k].gyr.y();
      m.angular_velocity.z = imu[k].gyr.z();
      m.linear_acceleration.x = imu[k].acc.x();
      m.linear_acceleration.y = imu[k].acc.y();
      m.linear_acceleration.z = imu[k].acc.z();
      bag.write(topics.imu, m.header.stamp, m);
      ++k;
    } else {
      const cv::Mat1b img = cv::imread(images[i].path, cv::IMREAD_GRAYSCALE);
      if (img.empty()) throw Error("cannot read " + images[i].path);
      sensor_msgs::Image m;
      m.header.stamp = rosTime(images[i].t_ns);
      m.header.frame_id = "cam0";
      m.header.seq = image_seq++;
      m.height = img.rows;
      m.width = img.cols;
      m.encoding = "mono8";
      m.is_bigendian = 0;
      m.step = img.cols;
      m.data.assign(img.data, img.data + img.total());
      bag.write(topics.image, m.header.stamp, m);
      ++i;
    }
    if ((i + k) % 500 == 0) bar.update(i + k);
  }
  bag.close();
  bar.finish();
  fs::rename(bag_path + ".tmp", bag_path);
}

double cpuSeconds() {
  return static_cast<double>(std::clock()) / CLOCKS_PER_SEC;
}

// Frames/s of the renderer alone (no PNG, no disk): frames spread over the trajectory,
// rendered one at a time with all threads inside a frame, and frame-parallel.
void measureSpeed(const SequenceOptions& o, int frames) {
  const SceneFile scene = loadSceneFile(o.scene.empty() ? defaultScenePath() : o.scene);
  AppearanceOptions ao;
  ao.texture_density = parseTextureDensity(o.texture);
  ao.threads = 2;
  auto t0 = std::chrono::steady_clock::now();
  const SceneAppearance appearance(scene.scene, ao);
  const double appearance_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  Trajectory all;
  if (isProceduralTrajectoryName(o.trajectory)) {
    ProceduralPathOptions pp;
    pp.duration_s = 60;
    pp.T_b_c = o.config.camera.T_b_c;
    pp.figure_eight = scene.figure_eight;
    pp.corridor = scene.corridor;
    all = makeProceduralTrajectory(o.trajectory, pp);
  } else {
    const auto euroc = findEurocSequence(o.trajectory);
    all = readTrajectory(euroc ? euroc->ground_truth : o.trajectory);
  }
  const PoseSpline spline = fitPoseSpline(all, o.fit);
  const auto camera = CameraModel::create(o.config.camera);
  std::cout << "scene " << scene.scene.name << ": " << scene.scene.quads().size() << " quads, "
            << "textures and light maps built in " << appearance_s << " s\n";
  for (int threads : {1, 2}) {
    CameraSimulationOptions co = o.camera;
    co.render.threads = 1;
    co.illumination = o.illumination;
    CameraSimulator sim(scene.scene, appearance, *camera, o.config.camera.T_b_c, co);
    sim.setExposureFromViews(
        spline, {spline.startTime() + 1, 0.5 * (spline.startTime() + spline.endTime())});
    std::vector<double> times;
    const double span = spline.endTime() - spline.startTime() - 2;
    for (int i = 0; i < frames; ++i)
      times.push_back(spline.startTime() + 1 + span * (i + 0.5) / frames);
    std::atomic<int> next{0};
    const double c0 = cpuSeconds();
    t0 = std::chrono::steady_clock::now();
    std::vector<std::thread> pool;
    for (int k = 0; k < threads; ++k)
      pool.emplace_back([&] {
        for (int i; (i = next++) < frames;) sim.render(spline, times[i], times[i] - times[0]);
      });
    for (auto& t : pool) t.join();
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double cpu = cpuSeconds() - c0;
    std::cout << "threads " << threads << ": " << frames / wall << " frames/s (wall), "
              << 1000 * cpu / frames << " ms CPU per frame\n";
  }
}

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  ArgParser args(
      "alvio sim",
      "Render an EuRoC-style sequence (cam0 images, IMU, ground truth) in a simulated\n"
      "indoor scene. The camera model, T_b_c and IMU noise come from --config.\n"
      "  alvio sim --trajectory MH_05 --out DIR            synthetic IMU along MH_05\n"
      "  alvio sim --trajectory MH_05 --imu real --out DIR  the real EuRoC IMU of MH_05\n"
      "  alvio sim --trajectory figure8 --duration 30 --out DIR\n"
      "  alvio sim --benchmark DIR [--only sim_MH_05_dim]  the standard set, cached\n"
      "  alvio sim --demo DIR                              30 s figure eight (the demo input)");
  args.option("scene", "scene YAML file or name in config/scenes (default: machine_hall)");
  args.option("trajectory",
              "ground-truth file (TUM or EuRoC CSV), EuRoC name (MH_01..MH_05, V1_02), or a "
              "built-in path: figure8, corridor");
  args.option("imu", "synthetic | real (the sequence's EuRoC IMU) | an imu0 data.csv", "synthetic");
  args.option("timestamps", "cam0 time stamps [ns] file (default: the EuRoC list, else 20 Hz)");
  args.option("start", "skip this many seconds of the trajectory", "0");
  args.option("duration", "seconds to simulate (0: all; built-in paths: 30)", "0");
  args.option("still",
              "seconds of standstill prepended to a trajectory that starts moving "
              "(synthetic IMU; -1: automatic)",
              "-1");
  args.option("seed", "seed of all noise (same seed: byte-identical output)", "1");
  args.option("texture", "rich | medium | poor | a density in [0, 1]", "rich");
  args.option("illumination",
              "normal | dim | flicker | dark | key=value list (gain, flicker, flicker_hz, "
              "dark_period, dark_duration, dark_gain, dark_first, transition)",
              "normal");
  args.option("motion-blur", "exposure time in ms for motion blur, optionally :samples (e.g. 8:3)",
              "0");
  args.option("vignetting", "0 (none) .. 1 (full cos^4)", "0.35");
  args.option("noise", "read noise in DN (0: no sensor noise)", "1.2");
  args.option("config", "alvio configuration (camera, IMU)", "");
  args.option("threads", "frames rendered in parallel", "2");
  args.option("out", "output folder (EuRoC ASL layout)");
  args.flag("bag", "also write <out>/<name>.bag with /cam0/image_raw and /imu0");
  args.option("benchmark", "build the standard benchmark set into this folder");
  args.option("only", "with --benchmark: comma-separated sequence names");
  args.flag("force", "with --benchmark: rebuild even if up to date");
  args.option("demo", "write the demo sequence (30 s figure eight, machine hall) into this folder");
  args.option("preview", "render one frame at --start into this PNG and exit");
  args.option("measure-speed",
              "render this many frames along --trajectory (no output) with 1 and 2 threads and "
              "report frames/s and CPU time per frame");
  args.flag("quiet", "no progress output");
  try {
    if (!args.parse(argc, argv)) return 0;
    SequenceOptions o;
    o.config = Config::load(args.isSet("config") ? args.get("config") : Config::defaultPath());
    o.scene = args.get("scene");
    o.trajectory = args.get("trajectory");
    o.imu = args.get("imu");
    o.cam_timestamps = args.get("timestamps");
    o.start_s = args.getDouble("start");
    o.duration_s = args.getDouble("duration");
    o.still_s = args.getDouble("still");
    o.seed = static_cast<uint64_t>(args.getInt("seed"));
    o.texture = args.get("texture");
    parseTextureDensity(o.texture);  // validate early
    o.illumination = parseIllumination(args.get("illumination"));
    {
      const std::string mb = args.get("motion-blur");
      const auto colon = mb.find(':');
      o.camera.exposure_time_s = std::stod(mb.substr(0, colon)) * 1e-3;
      o.camera.motion_blur_samples = colon == std::string::npos
                                         ? (o.camera.exposure_time_s > 0 ? 3 : 1)
                                         : std::stoi(mb.substr(colon + 1));
    }
    o.camera.sensor.vignetting = args.getDouble("vignetting");
    o.camera.sensor.read_noise_dn = args.getDouble("noise");
    o.camera.sensor.add_noise = o.camera.sensor.read_noise_dn > 0;
    o.threads = std::max(1, args.getInt("threads"));
    o.progress = !args.isSet("quiet");
    if (args.isSet("quiet")) setLogLevel(LogLevel::kWarn);

    if (args.isSet("benchmark")) {
      const auto results = buildBenchmark(args.get("benchmark"), o, splitList(args.get("only")),
                                          args.isSet("force"));
      for (const auto& r : results) {
        std::cout << r.name << ": " << (r.rebuilt ? r.summary.summary() : "up to date") << "\n";
        if (args.isSet("bag") && r.rebuilt) {
          const std::string folder = args.get("benchmark") + "/" + r.name;
          writeBag(folder, folder + "/" + r.name + ".bag", o.config.topics, o.progress);
        }
      }
      return 0;
    }

    std::string out = args.get("out");
    if (args.isSet("demo")) {
      out = args.get("demo");
      if (o.trajectory.empty()) o.trajectory = "figure8";
      if (o.duration_s <= 0) o.duration_s = 30;
    }
    if (o.trajectory.empty()) throw Error("--trajectory is required (or --benchmark / --demo)");

    if (args.isSet("measure-speed")) {
      measureSpeed(o, std::max(1, args.getInt("measure-speed")));
      return 0;
    }
    if (args.isSet("preview")) {
      SequenceOptions p = o;
      const std::string tmp =
          (fs::temp_directory_path() / ("alvio_sim_preview_" + std::to_string(::getpid())))
              .string();
      p.duration_s = 0.15;
      p.still_s = 0;
      p.progress = false;
      generateSequence(p, tmp);
      const EurocDataset d(tmp);
      fs::copy_file(d.images().front().path, args.get("preview"),
                    fs::copy_options::overwrite_existing);
      fs::remove_all(tmp);
      std::cout << "preview written to " << args.get("preview") << "\n";
      return 0;
    }
    if (out.empty()) throw Error("--out is required");
    const SequenceSummary s = generateSequence(o, out);
    std::cout << s.summary() << "\n";
    if (args.isSet("bag")) {
      const std::string bag = out + "/" + fs::path(out).filename().string() + ".bag";
      writeBag(out, bag, o.config.topics, o.progress);
      std::cout << "bag written to " << bag << "\n";
    }
    return 0;
  } catch (const Error& e) {
    std::cerr << "alvio sim: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "alvio sim: error: " << e.what() << "\n";
    return 2;
  }
}
