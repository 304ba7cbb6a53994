// alvio_micro_bench: Google Benchmark micro-benchmarks of the hot paths: line detection and
// tracking, point tracking, corner detection, CLAHE and the undistortion on a fixed frame pair,
// IMU preintegration, factor evaluation and one estimator step (window optimisation) on a
// synthetic scenario. Built by ./alvio build, never run in CI (timings on shared machines are
// for people, not for assertions).
//
//   alvio_micro_bench [--benchmark_filter=Line] [google benchmark flags]
//
// The frame pair comes from the demo sequence: $ALVIO_BENCH_DATA, else out/demo/sim
// (./alvio demo renders it).
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <optional>

#include "alvio/camera/camera_model.h"
#include "alvio/common/error.h"
#include "alvio/common/heap_retention.h"
#include "alvio/config/config.h"
#include "alvio/estimator/estimator.h"
#include "alvio/estimator/factors/imu_factor.h"
#include "alvio/estimator/factors/point_projection_factor.h"
#include "alvio/frontend/clahe.h"
#include "alvio/frontend/corner_detector.h"
#include "alvio/frontend/gaussian_blur_8u.h"
#include "alvio/frontend/gyro_rotation.h"
#include "alvio/frontend/min_eigen_response.h"
#include "alvio/frontend/optical_flow_pyramid.h"
#include "alvio/frontend/point_tracker.h"
#include "alvio/frontend/pyramidal_klt.h"
#include "alvio/geometry/line_projection_factor.h"
#include "alvio/imu/imu_preintegration.h"
#include "alvio/io/euroc_dataset.h"
#include "alvio/lines/image_undistorter.h"
#include "alvio/lines/line_detector.h"
#include "alvio/lines/line_tracker.h"
#include "synthetic_scenario.h"

namespace fs = std::filesystem;
using namespace alvio;

namespace {

const Config& config() {
  static const Config c = Config::load(Config::defaultPath());
  return c;
}

// Two consecutive frames of the demo flight (mid-sequence, the camera moving), and the
// camera's rotation from a to b by the gyroscope (the line flow starts from it).
struct FramePair {
  cv::Mat a, b;
  std::optional<Eigen::Matrix3d> R_b_a;
};

const FramePair& framePair() {
  static const FramePair pair = [] {
    const char* env = std::getenv("ALVIO_BENCH_DATA");
    const fs::path dir = env ? fs::path(env) : fs::path(ALVIO_SOURCE_DIR) / "out/demo/sim";
    const fs::path images = dir / "mav0/cam0/data";
    if (!fs::is_directory(images))
      throw Error("no frames in " + images.string() +
                  ": run ./alvio demo (or set ALVIO_BENCH_DATA to an EuRoC folder)");
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(images)) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    if (files.size() < 2) throw Error(images.string() + " has fewer than two images");
    const std::size_t k = files.size() / 2;
    FramePair p{cv::imread(files[k].string(), cv::IMREAD_GRAYSCALE),
                cv::imread(files[k + 1].string(), cv::IMREAD_GRAYSCALE), std::nullopt};
    if (p.a.empty() || p.b.empty()) throw Error("cannot read " + files[k].string());
    GyroRotation gyro(config().camera.T_b_c.linear());
    // Named: a range-for over a temporary's member reference would read freed memory.
    const EurocDataset dataset(dir.string());
    for (const ImuSample& s : dataset.imu()) gyro.add(s);
    // EuRoC names each image by its time stamp in ns.
    p.R_b_a = gyro.cameraRotation(std::stoll(files[k].stem().string()),
                                  std::stoll(files[k + 1].stem().string()));
    return p;
  }();
  return pair;
}

void detectLines(benchmark::State& state, const std::string& method, double fld_scale = 1.0,
                 bool refine_edges = false) {
  const FramePair& f = framePair();
  LineDetectorOptions options = config().lines.detector;
  options.method = method;
  options.fld_scale = fld_scale;
  options.refine_edges = refine_edges;
  LineDetector detector(options, f.a.size());
  std::size_t n = 0;
  for (auto _ : state) n = detector.detect(f.a).size();
  state.counters["lines"] = static_cast<double>(n);
}
void BM_LineDetectionLsd(benchmark::State& state) {
  detectLines(state, "lsd");
}
void BM_LineDetectionOpenCvLsd(benchmark::State& state) {
  detectLines(state, "opencv_lsd");
}
void BM_LineDetectionLsdRefined(benchmark::State& state) {
  detectLines(state, "lsd", 1.0, true);
}
void BM_LineDetectionFld(benchmark::State& state) {
  detectLines(state, "fld");
}
void BM_LineDetectionFldHalfScale(benchmark::State& state) {
  detectLines(state, "fld", 0.5);
}
BENCHMARK(BM_LineDetectionLsd)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LineDetectionOpenCvLsd)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LineDetectionLsdRefined)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LineDetectionFld)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LineDetectionFldHalfScale)->Unit(benchmark::kMillisecond);

// Detection + undistortion + tracking, alternating between the two frames so that tracks
// live on (the steady state of the flow tracker: mostly Type 1 lines).
// detect_every as configured (the flow tracker's default detects on every other frame, so the
// time is the mean over both kinds of frame), or 1 for the paper's tracker.
void trackLines(benchmark::State& state, const std::string& kind, int detect_every = 0) {
  const FramePair& f = framePair();
  LineTrackerOptions options = config().lines;
  options.tracker = kind;
  if (detect_every > 0) options.flow.detect_every = detect_every;
  auto tracker = createLineTracker(config().camera, options);
  double t = 0;
  tracker->track(f.a, t);
  bool odd = true;
  double tracked = 0;
  for (auto _ : state) {
    t += 0.05;
    // Back from b to a the camera turns the other way.
    std::optional<Eigen::Matrix3d> R = f.R_b_a;
    if (R && !odd) R = Eigen::Matrix3d(R->transpose());
    const LineFrame out = tracker->track(odd ? f.b : f.a, t, R);
    odd = !odd;
    tracked = static_cast<double>(out.lines.size());
  }
  state.counters["lines"] = tracked;
}
void BM_LineTrackingFlow(benchmark::State& state) {
  trackLines(state, "flow");
}
void BM_LineTrackingFlowDetectEveryFrame(benchmark::State& state) {
  trackLines(state, "flow", 1);
}
void BM_LineTrackingDescriptor(benchmark::State& state) {
  trackLines(state, "descriptor");
}
BENCHMARK(BM_LineTrackingFlow)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LineTrackingFlowDetectEveryFrame)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LineTrackingDescriptor)->Unit(benchmark::kMillisecond);

// Arg 0: KLT alone; 1: with points.anchors as configured (each track aligned to its anchored
// patch; the default warp is affine); 2: that without the forward-backward check; 3: the
// anchors with the shift alone.
void BM_PointTracking(benchmark::State& state) {
  const FramePair& f = framePair();
  PointTrackerOptions options = config().points;
  options.anchors.enabled = state.range(0) != 0;
  if (state.range(0) == 3) options.anchors.warp = "translation";
  options.forward_backward_check = state.range(0) != 2;
  PointTracker tracker(options, CameraModel::create(config().camera));
  int64_t t = 0;
  tracker.track(f.a, t);
  bool odd = true;
  double n = 0;
  for (auto _ : state) {
    t += 50000000;
    n = static_cast<double>(tracker.track(odd ? f.b : f.a, t).points.size());
    odd = !odd;
  }
  state.counters["points"] = n;
}
BENCHMARK(BM_PointTracking)->Unit(benchmark::kMillisecond)->DenseRange(0, 3)->ArgName("anchors");

// KLT alone on the frame pair's CLAHE images, 150 corners, all levels: OpenCV's
// calcOpticalFlowPyrLK against alvio's trackPyramidalKlt (the same tracks bit for bit). Arg:
// the window (21 the point tracker's, 15 the line tracker's).
struct KltInput {
  std::vector<cv::Mat> from, to;
  std::vector<cv::Point2f> corners;
};
KltInput kltInput(int window) {
  const FramePair& f = framePair();
  const cv::Ptr<cv::CLAHE> clahe = cv::createCLAHE(3.0, cv::Size(8, 8));
  cv::Mat a, b;
  clahe->apply(f.a, a);
  clahe->apply(f.b, b);
  KltInput in;
  cv::goodFeaturesToTrack(a, in.corners, 150, 0.01, 30);
  const cv::Size win(window, window);
  cv::buildOpticalFlowPyramid(a, in.from, win, 3, true, cv::BORDER_REFLECT_101, cv::BORDER_CONSTANT,
                              false);
  cv::buildOpticalFlowPyramid(b, in.to, win, 3, true, cv::BORDER_REFLECT_101, cv::BORDER_CONSTANT,
                              false);
  return in;
}
const cv::TermCriteria kKltStop(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
void BM_KltOpenCv(benchmark::State& state) {
  const int window = static_cast<int>(state.range(0));
  const KltInput in = kltInput(window);
  std::vector<cv::Point2f> tracked;
  std::vector<uchar> status;
  for (auto _ : state)
    cv::calcOpticalFlowPyrLK(in.from, in.to, in.corners, tracked, status, cv::noArray(),
                             cv::Size(window, window), 3, kKltStop);
}
BENCHMARK(BM_KltOpenCv)->Unit(benchmark::kMillisecond)->Arg(21)->Arg(15)->ArgName("window");
// Second arg: 1 the widest vectors (AVX2 where the CPU has them), 0 SSE2 alone.
void BM_KltAlvio(benchmark::State& state) {
  const int window = static_cast<int>(state.range(0));
  const Vectors vectors = state.range(1) ? Vectors::kWidest : Vectors::kBaseline;
  const KltInput in = kltInput(window);
  std::vector<cv::Point2f> tracked;
  std::vector<uchar> status;
  for (auto _ : state)
    trackPyramidalKlt(in.from, in.to, in.corners, &tracked, &status, cv::Size(window, window), 3,
                      kKltStop, false, vectors);
}
BENCHMARK(BM_KltAlvio)
    ->Unit(benchmark::kMillisecond)
    ->ArgsProduct({{21, 15}, {1, 0}})
    ->ArgNames({"window", "widest"});

// The KLT pyramid with gradients of one frame, 3 levels above the first: OpenCV's
// buildOpticalFlowPyramid against alvio's buildOpticalFlowPyramid8u (the same bytes). Arg: the
// window, whose size is the border's. On one thread, as alvio_run's timing runs: OpenCV would
// split pyrDown over its pool.
struct OneOpenCvThread {
  OneOpenCvThread() : threads(cv::getNumThreads()) { cv::setNumThreads(1); }
  ~OneOpenCvThread() { cv::setNumThreads(threads); }
  int threads;
};
void BM_PyramidOpenCv(benchmark::State& state) {
  const int window = static_cast<int>(state.range(0));
  const OneOpenCvThread one_thread;
  std::vector<cv::Mat> pyramid;
  for (auto _ : state) {
    pyramid.clear();  // a fresh pyramid, as the trackers build one per frame
    cv::buildOpticalFlowPyramid(framePair().a, pyramid, cv::Size(window, window), 3, true,
                                cv::BORDER_REFLECT_101, cv::BORDER_CONSTANT, false);
  }
}
BENCHMARK(BM_PyramidOpenCv)->Unit(benchmark::kMillisecond)->Arg(21)->Arg(15)->ArgName("window");
// Second arg, refill: 1 builds into the last pyramid's buffers, as the trackers do with the one
// from two frames back; 0 into fresh ones, as OpenCV's above.
void BM_PyramidAlvio(benchmark::State& state) {
  const int window = static_cast<int>(state.range(0));
  const bool refill = state.range(1) != 0;
  const OneOpenCvThread one_thread;
  std::vector<cv::Mat> pyramid;
  for (auto _ : state) {
    if (!refill) pyramid.clear();
    buildOpticalFlowPyramid8u(framePair().a, cv::Size(window, window), 3, &pyramid);
  }
}
BENCHMARK(BM_PyramidAlvio)
    ->Unit(benchmark::kMillisecond)
    ->ArgsProduct({{21, 15}, {0, 1}})
    ->ArgNames({"window", "refill"});

// New corners for a frame that still tracks 120: the point tracker's discs around those,
// 30 wanted. OpenCV's goodFeaturesToTrack against alvio's CornerDetector (the same corners).
cv::Mat trackedCornersMask(const cv::Mat& image) {
  const PointTrackerOptions& o = config().points;
  std::vector<cv::Point2f> tracked;
  cv::goodFeaturesToTrack(image, tracked, 120, o.quality_level, o.min_distance_px);
  cv::Mat mask(image.size(), CV_8UC1, cv::Scalar(255));
  for (const cv::Point2f& p : tracked) cv::circle(mask, p, o.min_distance_px, 0, -1);
  return mask;
}
void BM_CornerDetectionOpenCv(benchmark::State& state) {
  const cv::Mat& image = framePair().a;
  const cv::Mat mask = trackedCornersMask(image);
  const PointTrackerOptions& o = config().points;
  std::vector<cv::Point2f> corners;
  for (auto _ : state)
    cv::goodFeaturesToTrack(image, corners, 30, o.quality_level, o.min_distance_px, mask);
  state.counters["corners"] = static_cast<double>(corners.size());
}
BENCHMARK(BM_CornerDetectionOpenCv)->Unit(benchmark::kMillisecond);
void BM_CornerDetection(benchmark::State& state) {
  const cv::Mat& image = framePair().a;
  const cv::Mat mask = trackedCornersMask(image);
  const PointTrackerOptions& o = config().points;
  CornerDetector detector;
  std::size_t n = 0;
  for (auto _ : state)
    n = detector.detect(image, 30, o.quality_level, o.min_distance_px, mask).size();
  state.counters["corners"] = static_cast<double>(n);
}
BENCHMARK(BM_CornerDetection)->Unit(benchmark::kMillisecond);

// The Shi-Tomasi response alone, over the whole frame: OpenCV's and the detector's own.
void BM_CornerResponseOpenCv(benchmark::State& state) {
  const cv::Mat& image = framePair().a;
  cv::Mat response;
  for (auto _ : state) cv::cornerMinEigenVal(image, response, 3, 3);
}
BENCHMARK(BM_CornerResponseOpenCv)->Unit(benchmark::kMillisecond);
void BM_CornerResponse(benchmark::State& state) {
  const cv::Mat& image = framePair().a;
  MinEigenResponse calculator;
  cv::Mat response;
  for (auto _ : state) calculator.compute(image, &response);
}
BENCHMARK(BM_CornerResponse)->Unit(benchmark::kMillisecond);

// Each frame's preprocessing: CLAHE for the point tracker, the undistortion for the lines.
void BM_Clahe(benchmark::State& state) {
  const PointTrackerOptions& o = config().points;
  Clahe clahe(o.clahe_clip_limit, o.clahe_tiles);
  cv::Mat out;
  for (auto _ : state) clahe.apply(framePair().a, out);
}
BENCHMARK(BM_Clahe)->Unit(benchmark::kMillisecond);
void BM_Undistortion(benchmark::State& state) {
  const ImageUndistorter undistorter(config().camera);
  for (auto _ : state) benchmark::DoNotOptimize(undistorter.undistort(framePair().a).data);
}
BENCHMARK(BM_Undistortion)->Unit(benchmark::kMillisecond);

// LSD's blur before it halves the image (sigma 0.6 / 0.5, 11 taps), alvio's and OpenCV's,
// on one thread (OpenCV would split its rows over its pool).
void BM_LsdBlur(benchmark::State& state) {
  GaussianBlur8u blur(11, 1.2);
  if (!blur.ownCode()) state.SkipWithError("OpenCV's weights could not be read");
  cv::Mat out;
  for (auto _ : state) blur.apply(framePair().a, out);
}
BENCHMARK(BM_LsdBlur)->Unit(benchmark::kMillisecond);
void BM_LsdBlurOpenCv(benchmark::State& state) {
  const OneOpenCvThread one_thread;
  cv::Mat out;
  for (auto _ : state) cv::GaussianBlur(framePair().a, out, cv::Size(11, 11), 1.2);
}
BENCHMARK(BM_LsdBlurOpenCv)->Unit(benchmark::kMillisecond);

// One frame interval of IMU at 200 Hz (10 midpoint steps with covariance propagation).
void BM_ImuPreintegration(benchmark::State& state) {
  const Eigen::Vector3d acc(0.3, -0.2, 9.9), gyr(0.1, 0.2, -0.05);
  for (auto _ : state) {
    ImuPreintegration pre(acc, gyr, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), ImuNoise());
    for (int i = 0; i < 10; ++i) pre.push(0.005, acc + 0.01 * i * acc, gyr);
    benchmark::DoNotOptimize(pre.correctedDeltaP(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()));
  }
}
BENCHMARK(BM_ImuPreintegration)->Unit(benchmark::kMicrosecond);

// Residuals and all Jacobians of one factor of each kind.
struct FactorInputs {
  double pose_i[7] = {0.1, 0.2, 0.3, 0, 0, 0, 1};
  double pose_j[7] = {0.3, 0.1, 0.35, 0.01, 0.02, 0.0, 0.9997};
  double speed_bias_i[9] = {0.5, 0, 0, 0, 0, 0, 0, 0, 0};
  double speed_bias_j[9] = {0.5, 0.02, 0, 0, 0, 0, 0, 0, 0};
  double inverse_depth = 0.25;
  double line[4] = {0.1, -0.2, 0.3, 0.4};  // orthonormal (quaternion part normalised below)
  double residuals[15];
  double jac[4][15 * 9];
  FactorInputs() {
    Eigen::Map<Eigen::Quaterniond> q(pose_j + 3);
    q.normalize();
  }
};

void BM_ImuFactor(benchmark::State& state) {
  const Eigen::Vector3d acc(0.3, -0.2, 9.9), gyr(0.1, 0.2, -0.05);
  ImuPreintegration pre(acc, gyr, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), ImuNoise());
  for (int i = 0; i < 10; ++i) pre.push(0.005, acc, gyr);
  ImuFactor factor(&pre, Eigen::Vector3d(0, 0, 9.81));
  FactorInputs in;
  const double* params[4] = {in.pose_i, in.speed_bias_i, in.pose_j, in.speed_bias_j};
  double* jacobians[4] = {in.jac[0], in.jac[1], in.jac[2], in.jac[3]};
  for (auto _ : state) benchmark::DoNotOptimize(factor.Evaluate(params, in.residuals, jacobians));
}
BENCHMARK(BM_ImuFactor)->Unit(benchmark::kMicrosecond);

void BM_PointProjectionFactor(benchmark::State& state) {
  PointProjectionFactor factor(Eigen::Vector2d(0.1, -0.05), Eigen::Vector2d(0.12, -0.04),
                               config().camera.T_b_c, 300.0);
  FactorInputs in;
  const double* params[3] = {in.pose_i, in.pose_j, &in.inverse_depth};
  double* jacobians[3] = {in.jac[0], in.jac[1], in.jac[2]};
  for (auto _ : state) benchmark::DoNotOptimize(factor.Evaluate(params, in.residuals, jacobians));
}
BENCHMARK(BM_PointProjectionFactor)->Unit(benchmark::kMicrosecond);

void BM_LineProjectionFactor(benchmark::State& state) {
  LineProjectionFactor factor(Eigen::Vector2d(-0.2, 0.1), Eigen::Vector2d(0.3, 0.12),
                              config().camera.T_b_c, 300.0);
  FactorInputs in;
  // An orthonormal line block: unit quaternion (x, y, z, w) + angle; normalise the quaternion.
  Eigen::Map<Eigen::Vector4d> l(in.line);
  l.head<3>() *= 0.5;
  const double* params[2] = {in.pose_i, in.line};
  double* jacobians[2] = {in.jac[0], in.jac[1]};
  for (auto _ : state) benchmark::DoNotOptimize(factor.Evaluate(params, in.residuals, jacobians));
}
BENCHMARK(BM_LineProjectionFactor)->Unit(benchmark::kMicrosecond);

// One estimator step in steady state (window full, points and lines): IMU propagation,
// triangulation, the window optimisation and marginalisation. Each iteration is the next
// frame of a long synthetic flight, so the work is representative rather than repeated.
void BM_EstimatorStep(benchmark::State& state) {
  test::ScenarioOptions so;
  so.duration_s = 120;
  static const test::SyntheticScenario scenario(so, config().camera, config().imu);
  Estimator estimator(config().estimator, config().camera, config().imu);
  const auto& imu = scenario.imu();
  const auto& frames = scenario.frames();
  std::size_t next_imu = 0, next_frame = 0;
  auto feedFrame = [&] {
    const FeatureFrame& f = frames[next_frame++];
    while (next_imu < imu.size() && imu[next_imu].t_ns <= f.t_ns) estimator.addImu(imu[next_imu++]);
    estimator.addFrame(f);
  };
  while (next_frame < 200) feedFrame();  // initialise and fill the window (not timed)
  for (auto _ : state) {
    if (next_frame >= frames.size()) {
      state.SkipWithError("scenario exhausted: lower --benchmark_min_time");
      break;
    }
    feedFrame();
  }
}
BENCHMARK(BM_EstimatorStep)->Unit(benchmark::kMillisecond)->Iterations(400);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  // As in alvio_run: otherwise image-sized temporaries are page-faulted in again every
  // iteration, and the front-end figures would not be the pipeline's.
  retainFreedHeapMemory();
  try {
    benchmark::RunSpecifiedBenchmarks();
  } catch (const Error& e) {
    std::cerr << "alvio_micro_bench: error: " << e.what() << "\n";
    return 2;
  }
  benchmark::Shutdown();
  return 0;
}
