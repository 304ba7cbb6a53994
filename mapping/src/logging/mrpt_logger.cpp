#include "alvio/logging/mrpt_logger.h"

#include <mrpt/core/Clock.h>
#include <mrpt/img/CImage.h>
#include <mrpt/img/TCamera.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/obs/CObservationImage.h>
#include <mrpt/obs/CObservationRobotPose.h>
#include <mrpt/opengl/CFrustum.h>
#include <mrpt/opengl/CGridPlaneXY.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CPointCloud.h>
#include <mrpt/opengl/CSetOfLines.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <mrpt/opengl/stock_objects.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/system/COutputLogger.h>
#include <mrpt/system/datetime.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <mutex>
#include <sstream>

#include "alvio/common/error.h"
#include "alvio/eval/alignment.h"

namespace alvio {

namespace fs = std::filesystem;

namespace {

// Frames may reach the logger after IMU samples up to this much newer; older data is
// written even if no frame has come since (e.g. images and poses switched off).
constexpr int64_t kReorderWindowNs = 500'000'000;

// Data time -> MRPT timestamp. Same value as mrpt::Clock::fromDouble(t_ns * 1e-9) but in
// integer arithmetic, so EuRoC's 1.4e18 ns stamps keep their 100 ns resolution.
mrpt::Clock::time_point mrptTime(int64_t t_ns) {
  static const mrpt::Clock::time_point epoch = mrpt::Clock::fromDouble(0.0);
  return epoch + std::chrono::duration_cast<mrpt::Clock::duration>(std::chrono::nanoseconds(t_ns));
}

constexpr int64_t kNsPerS = 1'000'000'000;
// The rawlog being written; renamed to its name when complete.
constexpr const char* kPartialSuffix = ".part";

std::string nineDigits(int64_t v) {
  std::string s = std::to_string(v);
  return std::string(9 - std::min<std::size_t>(9, s.size()), '0') + s;
}

mrpt::poses::CPose3D toCPose3D(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  return mrpt::poses::CPose3D::FromRotationAndTranslation(R, t);
}

mrpt::poses::CPose3D toCPose3D(const StampedPose& p) {
  return toCPose3D(p.q.normalized().toRotationMatrix(), p.p);
}

mrpt::img::TCamera toTCamera(const CameraOptions& c) {
  mrpt::img::TCamera cam;
  cam.cameraName = MrptLogger::kCameraLabel;
  cam.ncols = static_cast<uint32_t>(c.width);
  cam.nrows = static_cast<uint32_t>(c.height);
  cam.setIntrinsicParamsFromValues(c.intrinsics[0], c.intrinsics[1], c.intrinsics[2],
                                   c.intrinsics[3]);
  const auto& d = c.distortion_coefficients;
  if (c.distortion_model == "equidistant") {
    cam.setDistortionKannalaBrandt(d[0], d[1], d[2], d[3]);
  } else if (!d.empty()) {  // radial-tangential: k1 k2 p1 p2 [k3]
    cam.setDistortionPlumbBob(d[0], d[1], d[2], d[3], d.size() > 4 ? d[4] : 0.0);
  }
  return cam;
}

// CFrustum points along its +X axis (y left, z up); a camera looks along +Z (x right,
// y down). Columns: the frustum's axes in camera coordinates.
Eigen::Matrix3d frustumInCamera() {
  Eigen::Matrix3d R;
  R.col(0) = Eigen::Vector3d::UnitZ();
  R.col(1) = -Eigen::Vector3d::UnitX();
  R.col(2) = -Eigen::Vector3d::UnitY();
  return R;
}

mrpt::system::VerbosityLevel toMrptLevel(LogLevel level) {
  switch (level) {
    case LogLevel::kDebug:
      return mrpt::system::LVL_DEBUG;
    case LogLevel::kInfo:
      return mrpt::system::LVL_INFO;
    case LogLevel::kWarn:
      return mrpt::system::LVL_WARN;
    case LogLevel::kError:
      return mrpt::system::LVL_ERROR;
  }
  return mrpt::system::LVL_INFO;
}

const char* levelTag(mrpt::system::VerbosityLevel level) {
  switch (level) {
    case mrpt::system::LVL_DEBUG:
      return "DEBUG";
    case mrpt::system::LVL_INFO:
      return "INFO ";
    case mrpt::system::LVL_WARN:
      return "WARN ";
    case mrpt::system::LVL_ERROR:
      return "ERROR";
    default:
      return "?    ";
  }
}

// Drop points closer than `step` to the last kept one (keeping the last): a 200 Hz ground
// truth would otherwise put tens of thousands of segments in every snapshot.
std::vector<Eigen::Vector3d> thinned(const std::vector<Eigen::Vector3d>& points, double step) {
  std::vector<Eigen::Vector3d> out;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (out.empty() || i + 1 == points.size() || (points[i] - out.back()).norm() >= step)
      out.push_back(points[i]);
  return out;
}

mrpt::opengl::CSetOfLines::Ptr lineStrip(const std::vector<Eigen::Vector3d>& points,
                                         const std::string& name, uint8_t r, uint8_t g, uint8_t b) {
  auto lines = mrpt::opengl::CSetOfLines::Create();
  lines->setName(name);
  lines->setColor_u8(r, g, b);
  lines->setLineWidth(2.0f);
  for (std::size_t i = 1; i < points.size(); ++i)
    lines->appendLine(points[i - 1].x(), points[i - 1].y(), points[i - 1].z(), points[i].x(),
                      points[i].y(), points[i].z());
  return lines;
}

}  // namespace

struct MrptLogger::Impl {
  LoggerOptions options;
  CameraOptions camera;
  LoggerPaths paths;
  LoggerCounts counts;
  std::atomic<bool> finished{false};

  // Rawlog: observations wait in time order until nothing older can come.
  mrpt::io::CFileGZOutputStream rawlog_stream;
  mrpt::serialization::CArchive::UniquePtr rawlog;
  std::multimap<int64_t, mrpt::obs::CObservation::Ptr> pending;
  int64_t newest_ns = std::numeric_limits<int64_t>::min();
  std::size_t images_seen = 0;
  mrpt::img::TCamera tcamera;
  mrpt::poses::CPose3D camera_on_body;

  // Scenes: the trajectories so far.
  Trajectory estimated, ground_truth;
  double next_scene_t = std::numeric_limits<double>::quiet_NaN();

  // Text log.
  mrpt::system::COutputLogger text{"alvio"};
  std::ofstream text_out;
  std::mutex text_mutex;  // log() may come from the core's log sink on any thread

  // Throughput: the frames since the last stats line.
  struct Period {
    double start_t = std::numeric_limits<double>::quiet_NaN(), last_t = 0;
    int frames = 0, tracking_frames = 0, imu = 0;
    double points = 0, landmarks = 0, pipeline_ms = 0;
    std::chrono::steady_clock::time_point wall_start;
  } period;

  // The scene period starts with the first data.
  void noteTime(double t) {
    if (std::isnan(next_scene_t)) next_scene_t = t + options.scene_period_s;
  }

  void queue(int64_t t_ns, mrpt::obs::CObservation::Ptr obs) {
    pending.emplace(t_ns, std::move(obs));
  }

  void flushUpTo(int64_t t_ns) {
    auto it = pending.begin();
    for (; it != pending.end() && it->first <= t_ns; ++it) *rawlog << *it->second;
    pending.erase(pending.begin(), it);
  }

  void openText(const std::string& path) {
    text_out.open(path, std::ios::out | std::ios::trunc);
    if (!text_out) throw Error("logger: cannot open text log " + path);
    text.logging_enable_console_output = false;  // the core's stderr output stays as it is
    text.setMinLoggingLevel(toMrptLevel(options.textLevel()));
    text.logRegisterCallback([this](std::string_view msg, mrpt::system::VerbosityLevel level,
                                    std::string_view /*logger*/, mrpt::Clock::time_point stamp) {
      std::lock_guard<std::mutex> lock(text_mutex);
      text_out << mrpt::system::dateTimeLocalToString(stamp) << " [" << levelTag(level) << "] "
               << msg;
      if (msg.empty() || msg.back() != '\n') text_out << '\n';
      ++counts.text_lines;
    });
  }

  void writeStats() {
    const double t = period.last_t;
    const double wall_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - period.wall_start).count();
    const double span = t - period.start_t;
    std::ostringstream os;
    os << std::fixed << std::setprecision(2) << "t=" << period.start_t << "+" << span
       << "s: " << period.frames << " frames (" << std::setprecision(1)
       << (wall_s > 0 ? period.frames / wall_s : 0.0) << " fps wall, "
       << (wall_s > 0 ? span / wall_s : 0.0) << "x real time, pipeline "
       << period.pipeline_ms / std::max(1, period.frames) << " ms/frame), " << period.imu
       << " IMU, tracked points " << std::setprecision(0)
       << period.points / std::max(1, period.frames) << ", window landmarks "
       << period.landmarks / std::max(1, period.frames) << ", tracking " << period.tracking_frames
       << "/" << period.frames;
    text.logStr(mrpt::system::LVL_INFO, os.str());
  }

  void resetPeriod(double t) {
    period = Period();
    period.start_t = t;
    period.wall_start = std::chrono::steady_clock::now();
  }

  // The ground truth aligned onto the estimate (position + yaw, the directions VIO cannot
  // observe), so the two trajectories overlay in the scene. Raw when too few poses match.
  std::vector<Eigen::Vector3d> alignedGroundTruth() const {
    std::vector<Eigen::Vector3d> out;
    out.reserve(ground_truth.size());
    Points3 est, gt;
    for (const auto& e : estimated) {
      auto it = std::lower_bound(ground_truth.begin(), ground_truth.end(), e.t,
                                 [](const StampedPose& p, double t) { return p.t < t; });
      const StampedPose* best = nullptr;
      for (auto c : {it, it == ground_truth.begin() ? it : std::prev(it)})
        if (c != ground_truth.end() && (!best || std::abs(c->t - e.t) < std::abs(best->t - e.t)))
          best = &*c;
      if (best && std::abs(best->t - e.t) < 0.02) {
        est.push_back(e.p);
        gt.push_back(best->p);
      }
    }
    Similarity3 T;
    if (gt.size() >= 10) {
      try {
        T = alignPoints(gt, est, AlignmentMode::kPosYaw);
      } catch (const Error&) {
        T = Similarity3();  // degenerate (e.g. no motion yet): draw unaligned
      }
    }
    for (const auto& g : ground_truth) out.push_back(T.apply(g.p));
    return out;
  }

  mrpt::opengl::COpenGLScene buildScene(const MapSnapshot& map) const {
    using namespace mrpt::opengl;
    COpenGLScene scene;
    std::vector<Eigen::Vector3d> est;
    for (const auto& p : estimated) est.push_back(p.p);

    // Grid sized to what there is to see.
    Eigen::Vector3d lo(-5, -5, 0), hi(5, 5, 0);
    for (const auto& p : est) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    auto grid = CGridPlaneXY::Create(std::floor(lo.x()) - 1, std::ceil(hi.x()) + 1,
                                     std::floor(lo.y()) - 1, std::ceil(hi.y()) + 1, 0, 1);
    grid->setName("grid");
    grid->setColor_u8(200, 200, 200);
    scene.insert(grid);
    auto world = stock_objects::CornerXYZSimple(0.5f, 2.0f);
    world->setName("world");
    scene.insert(world);

    constexpr double kStep = 0.01;  // m
    scene.insert(lineStrip(thinned(est, kStep), "trajectory_estimated", 0, 90, 255));
    if (!ground_truth.empty())
      scene.insert(
          lineStrip(thinned(alignedGroundTruth(), kStep), "trajectory_ground_truth", 0, 170, 0));

    auto points = CPointCloud::Create();
    points->setName("window_points");
    points->setColor_u8(220, 0, 0);
    points->setPointSize(3.0f);
    for (const auto& p : map.points) points->insertPoint(p.x(), p.y(), p.z());
    scene.insert(points);

    auto lines = CSetOfLines::Create();
    lines->setName("landmark_lines");
    lines->setColor_u8(200, 0, 200);
    lines->setLineWidth(2.0f);
    for (const auto& [a, b] : map.lines)
      lines->appendLine(a.x(), a.y(), a.z(), b.x(), b.y(), b.z());
    scene.insert(lines);

    auto keyframes = CSetOfObjects::Create();
    keyframes->setName("keyframes");
    const mrpt::img::TCamera& cam = tcamera;
    const Eigen::Matrix3d R_c_f = frustumInCamera();
    const Eigen::Matrix3d R_b_c = camera.T_b_c.linear();
    for (const auto& kf : map.keyframes) {
      auto frustum = CFrustum::Create(cam, 2.5e-4);  // far plane 0.11 m at fu = 458 px
      frustum->setColor_u8(255, 140, 0);
      const Eigen::Matrix3d R_w_b = kf.q.normalized().toRotationMatrix();
      const Eigen::Vector3d p_w_c = R_w_b * camera.T_b_c.translation() + kf.p;
      frustum->setPose(toCPose3D(R_w_b * R_b_c * R_c_f, p_w_c));
      keyframes->insert(frustum);
    }
    scene.insert(keyframes);

    if (!estimated.empty()) {
      auto body = stock_objects::CornerXYZSimple(0.3f, 3.0f);
      body->setName("body");
      body->setPose(toCPose3D(estimated.back()));
      scene.insert(body);
    }
    return scene;
  }
};

MrptLogger::MrptLogger(const LoggerOptions& options, const CameraOptions& camera,
                       const std::string& out_dir)
    : impl_(std::make_unique<Impl>()) {
  Impl& d = *impl_;
  options.validate("logger");
  d.options = options;
  d.camera = camera;
  const fs::path dir = options.out_dir.empty() ? fs::path(out_dir) : fs::path(options.out_dir);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error("logger: cannot create " + dir.string() + ": " + ec.message());
  const std::string base = (dir / options.name).string();

  if (options.text_log) {
    d.paths.text = (dir / options.text_file).string();
    d.openText(d.paths.text);
  }
  if (options.log_imu || options.log_images || options.log_poses || options.log_ground_truth) {
    d.paths.rawlog = base + ".rawlog";
    // Streamed into a side file and renamed by finish(): a killed run leaves the previous
    // rawlog intact (a cut gzip stream would not load) and its own data in .part.
    std::string why;
    if (!d.rawlog_stream.open(d.paths.rawlog + kPartialSuffix, 1, why))
      throw Error("logger: cannot open " + d.paths.rawlog + kPartialSuffix + ": " + why);
    d.rawlog = mrpt::serialization::archiveUniquePtrFrom(d.rawlog_stream);
    if (options.log_images) {
      // MRPT's convention: images of X.rawlog live in X_Images/, referenced by file name.
      d.paths.images_dir = base + "_Images";
      fs::create_directories(d.paths.images_dir, ec);
      if (ec) throw Error("logger: cannot create " + d.paths.images_dir + ": " + ec.message());
    }
  }
  if (options.scenes) {
    d.paths.scene = base + ".3Dscene";
    if (options.keep_scene_snapshots) {
      d.paths.scenes_dir = base + "_scenes";
      fs::create_directories(d.paths.scenes_dir, ec);
      if (ec) throw Error("logger: cannot create " + d.paths.scenes_dir + ": " + ec.message());
    }
  }
  d.tcamera = toTCamera(camera);
  d.camera_on_body = toCPose3D(camera.T_b_c.linear(), camera.T_b_c.translation());
}

MrptLogger::~MrptLogger() {
  try {
    finish();
  } catch (const std::exception& e) {
    logToStderr(LogLevel::kError, std::string("logger: closing failed: ") + e.what());
  }
}

const LoggerOptions& MrptLogger::options() const {
  return impl_->options;
}
const LoggerPaths& MrptLogger::paths() const {
  return impl_->paths;
}
LoggerCounts MrptLogger::counts() const {
  return impl_->counts;
}

void MrptLogger::log(LogLevel level, const std::string& message) {
  if (!impl_->options.text_log || impl_->finished) return;
  impl_->text.logStr(toMrptLevel(level), message);
}

void MrptLogger::addImu(const ImuSample& s) {
  Impl& d = *impl_;
  if (d.finished) return;
  d.noteTime(s.t());
  ++d.period.imu;
  if (!d.options.log_imu) return;
  auto obs = mrpt::obs::CObservationIMU::Create();
  obs->sensorLabel = kImuLabel;
  obs->timestamp = mrptTime(s.t_ns);
  // The IMU frame is the body frame: identity sensor pose.
  using namespace mrpt::obs;
  obs->set(IMU_X_ACC, s.acc.x());
  obs->set(IMU_Y_ACC, s.acc.y());
  obs->set(IMU_Z_ACC, s.acc.z());
  obs->set(IMU_WX, s.gyr.x());
  obs->set(IMU_WY, s.gyr.y());
  obs->set(IMU_WZ, s.gyr.z());
  d.queue(s.t_ns, obs);
  ++d.counts.imu;
  d.newest_ns = std::max(d.newest_ns, s.t_ns);
  d.flushUpTo(d.newest_ns - kReorderWindowNs);
}

void MrptLogger::addGroundTruth(const StampedPose& T_w_b) {
  Impl& d = *impl_;
  if (d.finished) return;
  if (d.options.scenes) d.ground_truth.push_back(T_w_b);
  if (!d.options.log_ground_truth || !d.rawlog) return;
  const int64_t t_ns = secToNs(T_w_b.t);
  auto obs = mrpt::obs::CObservationRobotPose::Create();
  obs->sensorLabel = kGroundTruthLabel;
  obs->timestamp = mrptTime(t_ns);
  obs->pose.mean = toCPose3D(T_w_b);  // covariance: zero, the ground truth is taken as exact
  d.queue(t_ns, obs);
  ++d.counts.ground_truth;
  d.newest_ns = std::max(d.newest_ns, t_ns);
  d.flushUpTo(d.newest_ns - kReorderWindowNs);
}

void MrptLogger::addImage(int64_t t_ns, const cv::Mat& image) {
  Impl& d = *impl_;
  if (d.finished) return;
  d.noteTime(nsToSec(t_ns));
  if (!d.options.log_images) return;
  if (d.images_seen++ % static_cast<std::size_t>(d.options.image_decimation) != 0) return;
  if (image.empty()) return;
  auto obs = mrpt::obs::CObservationImage::Create();
  obs->sensorLabel = kCameraLabel;
  obs->timestamp = mrptTime(t_ns);
  obs->cameraParams = d.tcamera;
  obs->cameraPose = d.camera_on_body;
  // Saved now, referenced by file name relative to <name>_Images/ (as rawlog-grabber and
  // RawLogViewer expect), so the rawlog itself stays small. Named like MRPT's own
  // externals ("img_<label>_<seconds>"), with every nanosecond digit.
  const std::string file = "img_" + std::string(kCameraLabel) + "_" +
                           std::to_string(t_ns / kNsPerS) + "." + nineDigits(t_ns % kNsPerS) +
                           ".png";
  obs->image = mrpt::img::CImage(image, mrpt::img::SHALLOW_COPY);
  if (!obs->image.saveToFile((fs::path(d.paths.images_dir) / file).string()))
    throw Error("logger: cannot write image " + d.paths.images_dir + "/" + file);
  obs->image.setExternalStorage(file);
  obs->image.unload();
  d.queue(t_ns, obs);
  ++d.counts.images;
  d.flushUpTo(t_ns);
}

void MrptLogger::addPose(const StampedPose& T_w_b) {
  Impl& d = *impl_;
  if (d.finished) return;
  d.noteTime(T_w_b.t);
  if (d.options.scenes) d.estimated.push_back(T_w_b);
  if (!d.options.log_poses || !d.rawlog) return;
  const int64_t t_ns = secToNs(T_w_b.t);
  // CObservationRobotPose: a full 6-DoF pose (CPose3DPDFGaussian) from "an external
  // source", which is what a VIO estimate is to MRPT. CObservationOdometry would hold
  // only a planar CPose2D increment. The covariance is left zero: the odometry's
  // (odometry_covariance) is over rotations about the world's axes, MRPT's over yaw, pitch
  // and roll, which degenerate near ±90° of pitch: EuRoC's IMU frame flies with its x axis
  // up (pitch -67° at MH_05's start).
  auto obs = mrpt::obs::CObservationRobotPose::Create();
  obs->sensorLabel = kPoseLabel;
  obs->timestamp = mrptTime(t_ns);
  obs->pose.mean = toCPose3D(T_w_b);
  d.queue(t_ns, obs);
  ++d.counts.poses;
  d.flushUpTo(t_ns);
}

void MrptLogger::addFrameStats(const FrameStats& s) {
  Impl& d = *impl_;
  if (d.finished || !d.options.text_log) return;
  if (std::isnan(d.period.start_t)) d.resetPeriod(s.t);
  d.noteTime(s.t);
  d.period.last_t = s.t;
  ++d.period.frames;
  d.period.tracking_frames += s.tracking ? 1 : 0;
  d.period.points += s.tracked_points;
  d.period.landmarks += s.window_landmarks;
  d.period.pipeline_ms += s.pipeline_ms;
  if (s.t - d.period.start_t >= d.options.stats_period_s) {
    d.writeStats();
    d.resetPeriod(s.t);
  }
}

void MrptLogger::flushStats() {
  Impl& d = *impl_;
  if (d.finished || !d.options.text_log || d.period.frames == 0) return;
  d.writeStats();
  d.resetPeriod(d.period.last_t);
}

bool MrptLogger::sceneDue(double t) const {
  const Impl& d = *impl_;
  if (d.finished || !d.options.scenes || d.options.scene_period_s <= 0) return false;
  return !std::isnan(d.next_scene_t) && t >= d.next_scene_t;
}

void MrptLogger::writeScene(double t, const MapSnapshot& map) {
  Impl& d = *impl_;
  if (d.finished || !d.options.scenes) return;
  const auto scene = d.buildScene(map);
  const std::string tmp = d.paths.scene + ".tmp";
  if (!scene.saveToFile(tmp)) throw Error("logger: cannot write " + tmp);
  if (d.options.keep_scene_snapshots) {
    std::ostringstream name;
    name << std::fixed << std::setprecision(3) << d.options.name << "_" << t << ".3Dscene";
    fs::copy_file(tmp, fs::path(d.paths.scenes_dir) / name.str(),
                  fs::copy_options::overwrite_existing);
  }
  fs::rename(tmp, d.paths.scene);  // atomic on one file system: readers see old or new
  ++d.counts.scenes;
  if (d.options.scene_period_s > 0 && !std::isnan(d.next_scene_t))
    while (d.next_scene_t <= t) d.next_scene_t += d.options.scene_period_s;
}

void MrptLogger::finish(const MapSnapshot* final_map) {
  Impl& d = *impl_;
  if (d.finished) return;
  if (final_map && d.options.scenes) {
    const double t = d.estimated.empty() ? 0.0 : d.estimated.back().t;
    writeScene(t, *final_map);
  }
  flushStats();
  if (d.rawlog) {
    d.flushUpTo(std::numeric_limits<int64_t>::max());
    d.rawlog.reset();
    d.rawlog_stream.close();
    std::error_code ec;
    fs::rename(d.paths.rawlog + kPartialSuffix, d.paths.rawlog, ec);
    if (ec)
      throw Error("logger: cannot rename " + d.paths.rawlog + kPartialSuffix + ": " + ec.message());
  }
  if (d.options.text_log) {
    std::ostringstream os;
    os << "logger closed: " << d.counts.imu << " IMU, " << d.counts.images << " images, "
       << d.counts.poses << " poses, " << d.counts.ground_truth << " ground-truth poses, "
       << d.counts.scenes << " scenes";
    d.text.logStr(mrpt::system::LVL_INFO, os.str());
    std::lock_guard<std::mutex> lock(d.text_mutex);
    d.text_out.close();
  }
  d.finished = true;
}

}  // namespace alvio
