// alvio_line_bench: lines per frame, track lengths and time per frame of the line front end
// (optical-flow tracker and descriptor baseline) on image folders, beside a KLT point front end
// (goodFeaturesToTrack + calcOpticalFlowPyrLK) on the same frames as the speed reference. On
// an EuRoC mav0/cam0/data folder the line flow starts from the gyroscope's rotation (imu0), as
// in the pipeline; other folders run without it.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <optional>
#include <set>
#include <sstream>

#include "alvio/common/arg_parser.h"
#include "alvio/common/error.h"
#include "alvio/config/config.h"
#include "alvio/frontend/gyro_rotation.h"
#include "alvio/io/euroc_dataset.h"
#include "alvio/io/trajectory_io.h"
#include "alvio/lines/line_tracker.h"

using namespace alvio;
namespace fs = std::filesystem;

namespace {
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

struct Summary {
  double median = 0, p95 = 0, mean = 0;
};
Summary summarise(std::vector<double> v) {
  Summary s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  auto at = [&](double q) {
    return v[std::min(v.size() - 1, std::size_t(q * (v.size() - 1) + 0.5))];
  };
  s.median = at(0.5);
  s.p95 = at(0.95);
  for (double x : v) s.mean += x / v.size();
  return s;
}
nlohmann::json toJson(const Summary& s) {
  return {{"median", s.median}, {"p95", s.p95}, {"mean", s.mean}};
}

struct ImageFolder {
  std::vector<cv::Mat> images;
  std::vector<int64_t> stamps_ns;  // from EuRoC's file names (nanoseconds); empty otherwise
};

ImageFolder loadImages(const std::string& dir) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string ext = e.path().extension().string();
    if (ext == ".png" || ext == ".jpg" || ext == ".jpeg") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());  // EuRoC names are timestamps of equal length
  ImageFolder folder;
  bool stamped = true;
  for (const auto& f : files) {
    cv::Mat g = cv::imread(f.string(), cv::IMREAD_GRAYSCALE);
    if (g.empty()) throw Error("cannot read image " + f.string());
    folder.images.push_back(g);
    const std::string stem = f.stem().string();
    stamped = stamped && !stem.empty() && stem.size() <= 19 &&
              std::all_of(stem.begin(), stem.end(), [](char c) { return c >= '0' && c <= '9'; });
    if (stamped) folder.stamps_ns.push_back(std::stoll(stem));
  }
  if (!stamped) folder.stamps_ns.clear();
  if (folder.images.size() < 2) throw Error(dir + ": need at least two images");
  return folder;
}

// The camera's rotation since the previous frame for every frame of an EuRoC cam0/data folder,
// from the gyroscope in the sibling imu0/data.csv, as the pipeline gives it to the line
// tracker. Empty when the folder is not one, so that the trackers run without it.
std::vector<std::optional<Eigen::Matrix3d>> gyroRotations(const std::string& dir,
                                                          const std::vector<int64_t>& stamps_ns,
                                                          const Config& config,
                                                          std::string* source) {
  fs::path data = fs::path(dir).lexically_normal();
  if (!data.has_filename()) data = data.parent_path();  // a trailing separator
  const fs::path imu_csv = data.parent_path().parent_path() / "imu0" / "data.csv";
  if (stamps_ns.empty() || !fs::exists(imu_csv)) {
    *source = "none (not an EuRoC mav0/cam0/data folder with imu0/data.csv beside it)";
    return {};
  }
  GyroRotation gyro(config.camera.T_b_c.linear());
  for (const ImuSample& s : readEurocImuCsv(imu_csv.string(), TimeOrderPolicy::kSortAndDedup))
    gyro.add(s);
  std::vector<std::optional<Eigen::Matrix3d>> rotations(stamps_ns.size());
  for (std::size_t k = 1; k < stamps_ns.size(); ++k)
    rotations[k] = gyro.cameraRotation(stamps_ns[k - 1], stamps_ns[k]);
  *source = imu_csv.string();
  return rotations;
}

// The reference point front end, VINS-Mono style without the RANSAC: track the previous
// corners with pyramidal KLT, then top up to 150 with goodFeaturesToTrack outside a 30 px mask
// around the tracked ones (VINS skips the detection when none is missing: a static camera
// costs little). With `always_detect` goodFeaturesToTrack runs on every frame.
class KltPointFrontEnd {
 public:
  explicit KltPointFrontEnd(bool always_detect) : always_detect_(always_detect) {}
  double process(const cv::Mat& gray) {
    const auto start = Clock::now();
    std::vector<cv::Point2f> kept;
    if (!prev_.empty() && !points_.empty()) {
      std::vector<cv::Point2f> moved;
      std::vector<uchar> status;
      std::vector<float> err;
      cv::calcOpticalFlowPyrLK(prev_, gray, points_, moved, status, err, cv::Size(21, 21), 3);
      const cv::Rect inside(0, 0, gray.cols, gray.rows);
      for (std::size_t i = 0; i < moved.size(); ++i)
        if (status[i] && inside.contains(cv::Point(cvRound(moved[i].x), cvRound(moved[i].y))))
          kept.push_back(moved[i]);
    }
    const int wanted = kMaxCorners - static_cast<int>(kept.size());
    if (wanted > 0 || always_detect_) {
      cv::Mat mask(gray.size(), CV_8UC1, cv::Scalar(255));
      for (const auto& p : kept) cv::circle(mask, p, kMinDistance, cv::Scalar(0), -1);
      std::vector<cv::Point2f> fresh;
      cv::goodFeaturesToTrack(gray, fresh, std::max(wanted, 1), 0.01, kMinDistance, mask);
      kept.insert(kept.end(), fresh.begin(),
                  fresh.begin() + std::max(0, std::min<int>(wanted, fresh.size())));
    }
    points_ = std::move(kept);
    prev_ = gray;
    return msSince(start);
  }
  void reset() {
    prev_.release();
    points_.clear();
  }

 private:
  static constexpr int kMaxCorners = 150;
  static constexpr int kMinDistance = 30;
  bool always_detect_;
  cv::Mat prev_;
  std::vector<cv::Point2f> points_;
};

// Results of one line tracker over a sequence: timings of every repeat, and the tracking
// figures of the first one.
struct LineRun {
  std::vector<double> undistort_ms, detect_ms, track_ms, total_ms;
  std::vector<double> lines_per_frame, detected_per_frame;
  std::map<int, int> track_length;  // id -> frames observed
  std::set<int> first_ids;
  int continued = 0, observations_after_first = 0, merged = 0, clipped = 0;
  int survivors_of_first_frame = 0, first_frame_lines = 0;
};

void drawFrame(const LineTracker& tracker, const cv::Mat& image, const LineFrame& f,
               const std::string& path) {
  cv::Mat canvas;
  cv::cvtColor(tracker.undistorter().undistort(image), canvas, cv::COLOR_GRAY2BGR);
  for (const auto& o : f.lines) {
    const cv::Scalar colour((o.id * 67) % 256, (o.id * 151) % 256, (o.id * 223) % 256);
    const cv::Point a(cvRound(o.start_px.x()), cvRound(o.start_px.y()));
    const cv::Point b(cvRound(o.end_px.x()), cvRound(o.end_px.y()));
    cv::line(canvas, a, b, colour, 2, cv::LINE_AA);
    cv::putText(canvas, std::to_string(o.id), (a + b) / 2, cv::FONT_HERSHEY_SIMPLEX, 0.4, colour);
  }
  cv::imwrite(path, canvas);
}

// Account frame k of a run; `first_repeat` runs also collect the tracking figures.
void record(const LineFrame& f, std::size_t k, std::size_t frames, bool first_repeat,
            LineRun* run) {
  if (k > 0) {  // frame 0 has nothing to track: timings from the second frame on
    run->undistort_ms.push_back(f.stats.undistort_ms);
    run->detect_ms.push_back(f.stats.detect_ms);
    run->track_ms.push_back(f.stats.track_ms);
    run->total_ms.push_back(f.stats.undistort_ms + f.stats.detect_ms + f.stats.track_ms);
  }
  if (!first_repeat) return;
  run->lines_per_frame.push_back(static_cast<double>(f.lines.size()));
  run->detected_per_frame.push_back(f.stats.detected);
  for (const auto& o : f.lines) ++run->track_length[o.id];
  if (k == 0) {
    for (const auto& o : f.lines) run->first_ids.insert(o.id);
    run->first_frame_lines = static_cast<int>(f.lines.size());
  } else {
    run->continued += f.stats.tracked;
    run->observations_after_first += static_cast<int>(f.lines.size());
    run->merged += f.stats.merged;
    run->clipped += f.stats.clipped;
  }
  if (k + 1 == frames)
    for (const auto& o : f.lines) run->survivors_of_first_frame += run->first_ids.count(o.id);
}

nlohmann::json lineReport(const LineRun& first) {
  double mean_len = 0;
  int max_len = 0;
  for (const auto& [id, len] : first.track_length) {
    mean_len += double(len) / first.track_length.size();
    max_len = std::max(max_len, len);
  }
  return {
      {"lines_per_frame", toJson(summarise(first.lines_per_frame))},
      {"detected_per_frame", toJson(summarise(first.detected_per_frame))},
      {"tracks", first.track_length.size()},
      {"mean_track_length_frames", mean_len},
      {"max_track_length_frames", max_len},
      {"continued_fraction", first.observations_after_first
                                 ? double(first.continued) / first.observations_after_first
                                 : 0.0},
      {"first_frame_lines_alive_at_last_frame",
       first.first_frame_lines ? double(first.survivors_of_first_frame) / first.first_frame_lines
                               : 0.0},
      {"type3_merged", first.merged},
      {"type4_clipped", first.clipped},
      {"ms",
       {{"undistort", toJson(summarise(first.undistort_ms))},
        {"detect", toJson(summarise(first.detect_ms))},
        {"track", toJson(summarise(first.track_ms))},
        {"total", toJson(summarise(first.total_ms))}}}};
}

void printSequence(const std::string& name, const nlohmann::json& j) {
  std::cout << "\n== " << name << " (" << j["frames"] << " frames, " << j["repeats"]
            << " timing repeats; gyroscope: " << j["gyroscope"].get<std::string>() << ")\n";
  std::cout << std::fixed << std::setprecision(2);
  for (const char* tracker : {"flow", "descriptor"}) {
    const auto& t = j[tracker];
    std::cout << "  " << std::setw(10) << std::left << tracker << std::right << " lines/frame "
              << t["lines_per_frame"]["mean"].get<double>() << " (LSD >= min length "
              << t["detected_per_frame"]["mean"].get<double>() << ")  tracks " << t["tracks"]
              << "  mean track length " << t["mean_track_length_frames"].get<double>()
              << " frames (max " << t["max_track_length_frames"] << ")  continued "
              << 100 * t["continued_fraction"].get<double>() << " %  frame-0 lines alive at end "
              << 100 * t["first_frame_lines_alive_at_last_frame"].get<double>() << " %  type3 "
              << t["type3_merged"] << "  type4 " << t["type4_clipped"] << "\n";
    const auto& ms = t["ms"];
    std::cout << "             ms median/p95: undistort " << ms["undistort"]["median"].get<double>()
              << "/" << ms["undistort"]["p95"].get<double>() << "  detect "
              << ms["detect"]["median"].get<double>() << "/" << ms["detect"]["p95"].get<double>()
              << "  track " << ms["track"]["median"].get<double>() << "/"
              << ms["track"]["p95"].get<double>() << "  total "
              << ms["total"]["median"].get<double>() << "/" << ms["total"]["p95"].get<double>()
              << "  ("
              << ms["total"]["median"].get<double>() / j["points"]["ms"]["median"].get<double>()
              << "x points)\n";
  }
  std::cout << "  points     ms median/p95: " << j["points"]["ms"]["median"].get<double>() << "/"
            << j["points"]["ms"]["p95"].get<double>()
            << "  (KLT + goodFeaturesToTrack topping up to 150, VINS-Mono style)\n";
  std::cout << "  points+    ms median/p95: "
            << j["points_detect_every_frame"]["ms"]["median"].get<double>() << "/"
            << j["points_detect_every_frame"]["ms"]["p95"].get<double>()
            << "  (same, goodFeaturesToTrack on every frame)\n";
}
}  // namespace

int main(int argc, char** argv) {
  ArgParser args("alvio_line_bench",
                 "Line front end benchmark: lines per frame, track lengths (optical flow vs\n"
                 "descriptor baseline) and time per frame, beside a KLT point front end.\n"
                 "Usage: alvio_line_bench [options] IMAGE_DIR...");
  args.option("config", "configuration (camera + lines)", "");
  args.option("repeat", "timing repeats over each sequence", "3");
  args.option("draw", "write the tracked lines of every frame as PNGs into this folder");
  args.option("json", "write every figure to this JSON file");
  try {
    if (!args.parse(argc, argv)) return 0;
    if (args.positional().empty()) throw Error("give at least one image folder");
    const Config config =
        Config::load(args.isSet("config") ? args.get("config") : Config::defaultPath());
    const int repeats = std::max(1, args.getInt("repeat"));
    const std::string draw = args.isSet("draw") ? args.get("draw") : "";
    if (!draw.empty()) fs::create_directories(draw);
    cv::setNumThreads(1);  // per-frame cost on one core, as in a pipeline thread

    nlohmann::json report = nlohmann::json::object();
    for (const std::string& dir : args.positional()) {
      const ImageFolder folder = loadImages(dir);
      const std::vector<cv::Mat>& images = folder.images;
      std::string gyro_source;
      const auto rotations = gyroRotations(dir, folder.stamps_ns, config, &gyro_source);
      nlohmann::json seq = {{"folder", dir},
                            {"frames", images.size()},
                            {"repeats", repeats},
                            {"gyroscope", gyro_source}};
      // The front ends take turns on every frame, so that the load of the machine (shared
      // cores) weighs on all of them alike.
      const std::vector<std::string> types = {"flow", "descriptor"};
      std::vector<LineRun> runs(types.size());
      std::vector<double> point_ms, point_always_ms;
      for (int r = 0; r < repeats; ++r) {
        std::vector<std::unique_ptr<LineTracker>> trackers;  // fresh IDs every repeat
        for (const std::string& type : types) {
          LineTrackerOptions options = config.lines;
          options.tracker = type;
          trackers.push_back(createLineTracker(config.camera, options));
        }
        KltPointFrontEnd points(false), points_always(true);
        for (std::size_t k = 0; k < images.size(); ++k) {
          // Rotate the order every frame: whoever runs first after a new image pays for the
          // cold caches.
          for (std::size_t step = 0; step < types.size() + 2; ++step) {
            const std::size_t i = (step + k) % (types.size() + 2);
            if (i == types.size() || i == types.size() + 1) {
              const bool always = i == types.size() + 1;
              const double ms = (always ? points_always : points).process(images[k]);
              if (k > 0) (always ? point_always_ms : point_ms).push_back(ms);
              continue;
            }
            const double t = folder.stamps_ns.empty() ? 0.05 * k : folder.stamps_ns[k] * 1e-9;
            const LineFrame f = rotations.empty() ? trackers[i]->track(images[k], t)
                                                  : trackers[i]->track(images[k], t, rotations[k]);
            record(f, k, images.size(), r == 0, &runs[i]);
            if (r == 0 && !draw.empty()) {
              std::ostringstream name;
              name << types[i] << "_" << std::setw(4) << std::setfill('0') << k << ".png";
              drawFrame(*trackers[i], images[k], f, (fs::path(draw) / name.str()).string());
            }
          }
        }
      }
      for (std::size_t i = 0; i < types.size(); ++i) seq[types[i]] = lineReport(runs[i]);
      seq["points"] = {{"ms", toJson(summarise(point_ms))}};
      seq["points_detect_every_frame"] = {{"ms", toJson(summarise(point_always_ms))}};
      printSequence(dir, seq);
      report[fs::path(dir).lexically_normal().string()] = seq;
    }
    if (args.isSet("json")) writeFileAtomically(args.get("json"), report.dump(2) + "\n");
    return 0;
  } catch (const Error& e) {
    std::cerr << "alvio_line_bench: error: " << e.what() << "\n";
    return 2;
  } catch (const cv::Exception& e) {
    std::cerr << "alvio_line_bench: OpenCV error: " << e.what() << "\n";
    return 2;
  }
}
