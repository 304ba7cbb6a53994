#include "alvio/sim/sequence_generator.h"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <mutex>
#include <sstream>
#include <thread>

#include "alvio/common/angles.h"
#include "alvio/common/error.h"
#include "alvio/common/logging.h"
#include "alvio/common/progress_bar.h"
#include "alvio/io/euroc_dataset.h"
#include "alvio/io/trajectory_io.h"
#include "alvio/sim/edge_projection.h"
#include "alvio/sim/euroc_sequences.h"
#include "alvio/sim/imu_simulator.h"
#include "alvio/sim/procedural_trajectories.h"
#include "alvio/sim/scene_appearance.h"
#include "alvio/sim/scene_file.h"
#include "alvio/sim/so3.h"

namespace alvio::sim {
namespace fs = std::filesystem;

namespace {

// Built-in paths get stamps from this epoch (2020-09-13), like real recordings.
constexpr double kProceduralEpoch = 1600000000.0;

struct Inputs {
  std::string scene_path;
  std::string procedural;       ///< built-in path name, or ""
  std::string trajectory_path;  ///< ground-truth file, or ""
  bool trajectory_is_euroc_csv = false;
  std::string imu_path;  ///< real IMU file, "" for synthetic
  std::string stamps_path;
};

Inputs resolveInputs(const SequenceOptions& o) {
  Inputs in;
  in.scene_path = o.scene.empty() ? defaultScenePath() : resolveScenePath(o.scene);
  if (o.trajectory.empty())
    throw Error("no trajectory given (a ground-truth file, MH_05, figure8)");
  std::optional<EurocSequenceFiles> euroc;
  if (isProceduralTrajectoryName(o.trajectory)) {
    in.procedural = o.trajectory;
  } else if (fs::exists(o.trajectory)) {
    in.trajectory_path = o.trajectory;
  } else {
    euroc = findEurocSequence(o.trajectory);
    if (!euroc)
      throw Error("trajectory '" + o.trajectory +
                  "' is neither a file, nor a built-in path (figure8, corridor), nor an EuRoC "
                  "sequence found in the shared data (" +
                  (findSharedDataDir().empty() ? std::string("none found; set ALVIO_SHARED_DATA")
                                               : findSharedDataDir()) +
                  ")");
    in.trajectory_path = euroc->ground_truth;
  }
  if (o.imu == "real") {
    if (!euroc || euroc->imu.empty())
      throw Error(
          "--imu real needs an EuRoC sequence name with a shared real IMU file "
          "(MH_03, MH_05, V1_02); give the imu0 data.csv path otherwise");
    in.imu_path = euroc->imu;
  } else if (o.imu != "synthetic") {
    if (!fs::exists(o.imu)) throw Error("IMU file '" + o.imu + "' not found");
    in.imu_path = o.imu;
  }
  // With the real IMU the ground truth must be the real one: prefer the original CSV
  // (it has velocities and biases) when it is shared.
  if (!in.imu_path.empty() && euroc && !euroc->ground_truth_csv.empty()) {
    in.trajectory_path = euroc->ground_truth_csv;
    in.trajectory_is_euroc_csv = true;
  }
  if (!in.imu_path.empty() && !in.procedural.empty())
    throw Error("a real IMU needs the ground truth of its own sequence, not a built-in path");
  if (!o.cam_timestamps.empty()) {
    if (!fs::exists(o.cam_timestamps))
      throw Error("cam0 timestamp file '" + o.cam_timestamps + "' not found");
    in.stamps_path = o.cam_timestamps;
  } else if (euroc) {
    in.stamps_path = euroc->cam_timestamps;
  }
  return in;
}

std::vector<int64_t> readStamps(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error("cannot open timestamp file '" + path + "'");
  std::vector<int64_t> stamps;
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    const std::string field = line.substr(0, line.find_first_of(", \t"));
    try {
      stamps.push_back(std::stoll(field));
    } catch (const std::exception&) {
      throw Error(path + ":" + std::to_string(n) + ": expected a time stamp in ns, got '" + field +
                  "'");
    }
  }
  std::sort(stamps.begin(), stamps.end());
  stamps.erase(std::unique(stamps.begin(), stamps.end()), stamps.end());
  return stamps;
}

bool startsMoving(const Trajectory& t) {
  for (const StampedPose& p : t) {
    if (p.t > t.front().t + 1.0) break;
    if ((p.p - t.front().p).norm() > 0.01 || p.q.angularDistance(t.front().q) > 0.5 * kDegToRad)
      return true;
  }
  return false;
}

void prepareOutputFolder(const fs::path& out) {
  if (fs::exists(out / "mav0") && !fs::exists(out / "sim_info.yaml"))
    throw Error("'" + out.string() +
                "' holds a mav0 folder that the simulator did not write; refusing to overwrite it");
  fs::remove_all(out / "mav0");
  fs::remove(out / "groundtruth.tum");
  fs::remove(out / "scene_edges.csv");
  fs::remove(out / "sim_info.yaml");
  fs::create_directories(out / "mav0" / "cam0" / "data");
  fs::create_directories(out / "mav0" / "imu0");
  fs::create_directories(out / "mav0" / "state_groundtruth_estimate0");
}

double seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

}  // namespace

std::string hashText(const std::string& text) {
  uint64_t h = 0xcbf29ce484222325ULL;
  for (const unsigned char c : text) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  std::ostringstream os;
  os << std::hex << std::setw(16) << std::setfill('0') << h;
  return os.str();
}

std::string fileHash(const std::string& path) {
  if (path.empty()) return "-";
  std::ifstream in(path, std::ios::binary);
  if (!in) return "missing";
  std::stringstream ss;
  ss << in.rdbuf();
  return hashText(ss.str());
}

std::string describeSequenceInputs(const SequenceOptions& o) {
  const Inputs in = resolveInputs(o);
  std::ostringstream os;
  os.precision(12);
  const auto& c = o.config.camera;
  const auto& imu = o.config.imu;
  const auto& s = o.camera.sensor;
  // Files by content hash, not by path: moving the checkout or the shared data does
  // not invalidate cached sequences.
  os << "simulator: " << kSimulatorVersion << "\n"
     << "scene: " << fs::path(in.scene_path).filename().string() << " " << fileHash(in.scene_path)
     << "\n"
     << "trajectory: " << o.trajectory << " " << fileHash(in.trajectory_path) << "\n"
     << "imu: " << o.imu << " " << fileHash(in.imu_path) << "\n"
     << "cam_timestamps: " << fileHash(in.stamps_path) << "\n"
     << "start: " << o.start_s << " duration: " << o.duration_s << " still: " << o.still_s
     << " seed: " << o.seed << " texture: " << o.texture << "\n"
     << "illumination: " << o.illumination.describe() << "\n"
     << "sensor: " << s.exposure_dn << " " << s.target_mean_dn << " " << s.optical_blur_sigma_px
     << " " << s.vignetting << " " << s.read_noise_dn << " " << s.shot_noise_dn << " "
     << s.add_noise << "\n"
     << "blur: " << o.camera.exposure_time_s << " " << o.camera.motion_blur_samples
     << " edge_samples: " << o.camera.render.edge_samples << "\n"
     << "camera: " << c.distortion_model << " " << c.width << "x" << c.height;
  for (double v : c.intrinsics) os << " " << v;
  for (double v : c.distortion_coefficients) os << " " << v;
  for (int i = 0; i < 16; ++i) os << " " << c.T_b_c.matrix()(i / 4, i % 4);
  os << " " << c.rate_hz << "\n"
     << "imu_noise: " << imu.gyroscope_noise_density << " " << imu.gyroscope_random_walk << " "
     << imu.accelerometer_noise_density << " " << imu.accelerometer_random_walk << " "
     << imu.rate_hz << " " << imu.gravity_magnitude << "\n"
     << "fit: " << o.fit.knot_spacing_s << " " << o.fit.position_sigma_m << " "
     << o.fit.rotation_sigma_rad << " " << o.fit.acceleration_sigma << " "
     << o.fit.angular_acceleration_sigma << " " << o.fit.huber_threshold << "\n";
  return os.str();
}

std::string SequenceSummary::summary() const {
  std::ostringstream os;
  os << std::fixed << std::setprecision(2) << frames << " frames over "
     << last_frame_s - first_frame_s << " s, " << imu_samples << " IMU samples (" << imu_mode
     << "), rendered in " << render_seconds << " s (" << frames / std::max(render_seconds, 1e-9)
     << " frames/s), total " << total_seconds << " s; " << fit.summary();
  return os.str();
}

SequenceSummary generateSequence(const SequenceOptions& o, const std::string& out_dir) {
  const auto t_start_wall = std::chrono::steady_clock::now();
  const Inputs in = resolveInputs(o);
  const bool real_imu = !in.imu_path.empty();
  SequenceSummary summary;
  summary.imu_mode = real_imu ? "real: " + in.imu_path : "synthetic";

  // --- the scene and the trajectory samples
  SceneFile scene_file = loadSceneFile(in.scene_path);
  Trajectory samples;
  if (!in.procedural.empty()) {
    ProceduralPathOptions p;
    p.duration_s = o.start_s + (o.duration_s > 0 ? o.duration_s : 30.0);
    p.T_b_c = o.config.camera.T_b_c;
    p.figure_eight = scene_file.figure_eight;
    p.corridor = scene_file.corridor;
    p.start_time_s = kProceduralEpoch;
    samples = makeProceduralTrajectory(in.procedural, p);
  } else {
    samples =
        readTrajectory(in.trajectory_path, TrajectoryFormat::kAuto, TimeOrderPolicy::kSortAndDedup);
  }
  if (samples.size() < 10) throw Error("trajectory '" + o.trajectory + "' has too few poses");
  const double t_from = samples.front().t + o.start_s;
  const double t_to =
      o.duration_s > 0 ? std::min(samples.back().t, t_from + o.duration_s) : samples.back().t;
  if (!(t_to > t_from + 0.1))
    throw Error("--start/--duration leave less than 0.1 s of the trajectory");
  Trajectory window;
  for (const StampedPose& p : samples)
    if (p.t >= t_from - 1.0 && p.t <= t_to + 1.0) window.push_back(p);

  // --- a standstill before a trajectory that starts moving (synthetic IMU only)
  double still = 0;
  if (!real_imu && in.procedural.empty() && o.start_s == 0) {
    still = o.still_s >= 0 ? o.still_s : (startsMoving(window) ? 2.0 : 0.0);
  }
  Trajectory fit_samples;
  if (still > 0) {
    const StampedPose first = window.front();
    for (double t = first.t - still; t < first.t - 0.25; t += 0.005) {
      StampedPose p = first;
      p.t = t;
      fit_samples.push_back(p);
    }
  }
  fit_samples.insert(fit_samples.end(), window.begin(), window.end());
  const PoseSpline spline = fitPoseSpline(fit_samples, o.fit);
  Trajectory measured;
  for (const StampedPose& p : window)
    if (p.t >= t_from && p.t <= t_to) measured.push_back(p);
  summary.fit = evaluateSplineFit(spline, measured);
  logInfo("trajectory ", o.trajectory, ": ", summary.fit.summary(),
          still > 0 ? " (" + std::to_string(still) + " s standstill prepended)" : std::string());

  // --- time range, IMU and camera stamps
  double begin = std::max(spline.startTime(), t_from - still);
  double end = std::min(spline.endTime(), t_to);
  std::vector<ImuSample> real_samples;
  if (real_imu) {
    real_samples = readEurocImuCsv(in.imu_path, TimeOrderPolicy::kSortAndDedup);
    if (real_samples.empty()) throw Error("IMU file '" + in.imu_path + "' is empty");
    begin = std::max(begin, real_samples.front().t());
    end = std::min(end, real_samples.back().t());
  }
  // Whole milliseconds inside the range, so that regular stamps look like real ones.
  const int64_t begin_ns = static_cast<int64_t>(std::ceil(begin * 1e3)) * 1000000;
  const int64_t end_ns = static_cast<int64_t>(std::floor(end * 1e3)) * 1000000;
  std::vector<int64_t> frames;
  if (!in.stamps_path.empty()) {
    const std::vector<int64_t> all = readStamps(in.stamps_path);
    for (int64_t t : all)
      if (t >= begin_ns && t <= end_ns) frames.push_back(t);
    if (frames.size() >= 2 && still > 0) {
      // Continue the real stamps' rhythm back into the prepended standstill.
      const int64_t period = frames[1] - frames[0];
      while (frames.front() - period >= begin_ns)
        frames.insert(frames.begin(), frames.front() - period);
    }
  } else {
    frames = regularStamps(begin_ns, end_ns, o.config.camera.rate_hz);
  }
  if (frames.empty()) throw Error("no camera frame falls inside the trajectory's time range");

  std::vector<ImuSample> imu;
  GroundTruth gt;
  if (real_imu) {
    for (const ImuSample& m : real_samples)
      if (m.t_ns >= begin_ns && m.t_ns <= end_ns) imu.push_back(m);
    // The real ground truth; velocities from the spline when the file has none.
    const GroundTruth states =
        in.trajectory_is_euroc_csv
            ? readEurocGroundTruthCsv(in.trajectory_path, TimeOrderPolicy::kSortAndDedup)
            : GroundTruth();
    if (in.trajectory_is_euroc_csv) {
      for (const GroundTruthState& s : states)
        if (s.t_ns >= begin_ns && s.t_ns <= end_ns) gt.push_back(s);
    } else {
      for (const StampedPose& p : measured) {
        const int64_t t = secToNs(p.t);
        if (t < begin_ns || t > end_ns) continue;
        GroundTruthState s;
        s.t_ns = t;
        s.p = p.p;
        s.q = p.q;
        s.v = spline.state(p.t).v_w;
        gt.push_back(s);
      }
    }
  } else {
    ImuSimulationOptions io;
    io.imu = o.config.imu;
    io.seed = o.seed;
    const SimulatedImu sim =
        simulateImu(spline, regularStamps(begin_ns, end_ns, o.config.imu.rate_hz), io);
    imu = sim.samples;
    gt = sim.states;
  }

  // --- render
  const fs::path out(out_dir);
  prepareOutputFolder(out);
  AppearanceOptions ao;
  ao.texture_density = parseTextureDensity(o.texture);
  ao.threads = std::max(1, o.threads);
  const SceneAppearance appearance(scene_file.scene, ao);
  CameraSimulationOptions co = o.camera;
  co.illumination = o.illumination;
  co.seed = o.seed;
  co.render.threads = 1;  // frames are rendered in parallel instead
  const auto camera = CameraModel::create(o.config.camera);
  CameraSimulator simulator(scene_file.scene, appearance, *camera, o.config.camera.T_b_c, co);
  const double t0 = nsToSec(frames.front());
  {
    // Exposure from 8 views spread over the sequence (fixed afterwards).
    std::vector<double> times;
    for (int k = 0; k < 8; ++k) times.push_back(nsToSec(frames[(frames.size() - 1) * k / 7]));
    simulator.setExposureFromViews(spline, times);
  }
  summary.exposure_dn = simulator.exposure();

  const auto t_render = std::chrono::steady_clock::now();
  const int n = static_cast<int>(frames.size());
  std::atomic<int> next{0}, done{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  const fs::path image_dir = out / "mav0" / "cam0" / "data";
  auto worker = [&] {
    try {
      for (int i; (i = next++) < n;) {
        const double t = nsToSec(frames[i]);
        const cv::Mat1b image = simulator.render(spline, t, t - t0);
        const std::string path = (image_dir / (std::to_string(frames[i]) + ".png")).string();
        if (!cv::imwrite(path, image)) throw Error("cannot write image " + path);
        ++done;
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(failure_mutex);
      if (!failure) failure = std::current_exception();
      next = n;
    }
  };
  {
    ProgressBar bar("render " + out.filename().string(), n, o.progress);
    std::vector<std::thread> pool;
    for (int k = 0; k < std::max(1, o.threads); ++k) pool.emplace_back(worker);
    while (done < n && !failure) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      std::ostringstream rate;
      rate << std::fixed << std::setprecision(1) << done / std::max(seconds(t_render), 1e-3)
           << " frames/s";
      bar.update(done, rate.str());
    }
    for (auto& t : pool) t.join();
    if (failure) std::rethrow_exception(failure);
    bar.finish();
  }
  summary.render_seconds = seconds(t_render);

  // --- write the ASL folder
  writeEurocImageCsv((out / "mav0" / "cam0" / "data.csv").string(), frames);
  writeEurocCameraYaml((out / "mav0" / "cam0" / "sensor.yaml").string(), o.config.camera);
  writeEurocImuCsv((out / "mav0" / "imu0" / "data.csv").string(), imu);
  writeEurocImuYaml((out / "mav0" / "imu0" / "sensor.yaml").string(), o.config.imu);
  writeEurocGroundTruthCsv((out / "mav0" / "state_groundtruth_estimate0" / "data.csv").string(),
                           gt);
  Trajectory tum;
  for (const GroundTruthState& s : gt) {
    StampedPose p;
    p.t = nsToSec(s.t_ns);
    p.p = s.p;
    p.q = s.q;
    tum.push_back(p);
  }
  writeTumTrajectory((out / "groundtruth.tum").string(), tum);
  writeSceneEdgesCsv((out / "scene_edges.csv").string(), scene_file.scene);

  summary.frames = n;
  summary.imu_samples = static_cast<int>(imu.size());
  summary.first_frame_s = nsToSec(frames.front());
  summary.last_frame_s = nsToSec(frames.back());
  summary.total_seconds = seconds(t_start_wall);
  std::ostringstream info;
  info << "# Written by the alvio simulator. The inputs (hash "
       << hashText(describeSequenceInputs(o)) << "):\n";
  std::istringstream desc(describeSequenceInputs(o));
  for (std::string line; std::getline(desc, line);) info << "#   " << line << "\n";
  info << std::setprecision(10) << "frames: " << n << "\nimu_samples: " << imu.size()
       << "\nimu_mode: " << (real_imu ? "real" : "synthetic") << "\nstill_prepended_s: " << still
       << "\nexposure_dn: " << summary.exposure_dn
       << "\nspline_fit:\n  poses: " << summary.fit.samples
       << "\n  position_rms_m: " << summary.fit.position_rms_m
       << "\n  position_max_m: " << summary.fit.position_max_m
       << "\n  rotation_rms_deg: " << summary.fit.rotation_rms_deg
       << "\n  rotation_max_deg: " << summary.fit.rotation_max_deg << "\n";
  writeFileAtomically((out / "sim_info.yaml").string(), info.str());
  logInfo("sequence written to ", out.string(), ": ", summary.summary());
  return summary;
}

}  // namespace alvio::sim
