// alvio_point_truth: the point tracker scored against the simulator's true scene, and the
// estimator run on corrected observations, to tell front-end error from back-end error.
// A track's 3D point is where the ray through its first observation meets the scene
// (ground-truth camera pose); every later observation is compared with that point's true
// projection. With --oracle the estimator is fed those true projections instead of the
// tracked positions (same tracks, same IDs; lines as tracked, or none with --no-lines);
// --drop-px keeps the tracked positions but drops those further than that from the truth.
// --out writes trajectory.tum, point_errors.csv (per frame) and point_observations.csv (per
// observation of a visible track point: age, pixel, error, frame-to-frame flow, depth).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <unordered_map>

#include "alvio/camera/camera_model.h"
#include "alvio/common/arg_parser.h"
#include "alvio/common/error.h"
#include "alvio/config/config.h"
#include "alvio/estimator/estimator.h"
#include "alvio/eval/trajectory_evaluation.h"
#include "alvio/eval/trajectory_interpolation.h"
#include "alvio/io/euroc_dataset.h"
#include "alvio/io/trajectory_io.h"
#include "alvio/pipeline/front_end.h"
#include "alvio/sim/sequence_scene.h"

using namespace alvio;
namespace fs = std::filesystem;

namespace {

struct TrackTruth {
  Eigen::Vector3d point_w;
  Eigen::Vector2d last_xy;  // tracked position in the previous frame
  bool valid = false;
};

Eigen::Isometry3d cameraPose(const StampedPose& body, const Eigen::Isometry3d& T_b_c) {
  Eigen::Isometry3d T_w_b = Eigen::Isometry3d::Identity();
  T_w_b.linear() = body.q.toRotationMatrix();
  T_w_b.translation() = body.p;
  return T_w_b * T_b_c;
}

// With a real IMU, groundtruth.tum is the real EuRoC ground truth, not the spline the images
// were rendered along (they differ by up to 1 degree), so the truth here would be wrong.
void requireRenderedGroundTruth(const std::string& seq) {
  const fs::path info = fs::path(seq) / "sim_info.yaml";
  std::ifstream in(info);
  if (!in) throw Error("cannot read " + info.string() + ": not a rendered sequence?");
  const std::string key = "#   imu: ";
  for (std::string line; std::getline(in, line);)
    if (line.rfind(key, 0) == 0) {
      if (line.rfind(key + "synthetic", 0) == 0) return;
      throw Error(info.string() + " says '" + line.substr(4) +
                  "': groundtruth.tum is then the real ground truth, not the trajectory the "
                  "images were rendered along; use a sequence with the synthetic IMU");
    }
  throw Error(info.string() + " has no '" + key + "' line: not a rendered sequence?");
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  ArgParser args("alvio_point_truth",
                 "Point tracks against the simulator's true scene; --oracle runs the estimator\n"
                 "on the true projections of the same tracks.\n"
                 "Usage: alvio_point_truth [--config FILE] [options] SEQUENCE_DIR");
  args.option("config", "configuration (default: the installed config/euroc.yaml)", "");
  args.option("out", "folder for trajectory.tum, point_errors.csv, point_observations.csv", "");
  args.option("frames", "frames to use (0: all)", "0");
  args.option("oracle-noise-px", "with --oracle: Gaussian noise added to the true positions", "0");
  args.option("drop-px", "drop tracked observations this far from the truth (0: keep all)", "0");
  args.flag("oracle", "feed the estimator the true projections of the tracked points");
  args.flag("no-lines", "points only");
  try {
    if (!args.parse(argc, argv)) return 0;
    const std::vector<std::string>& positional = args.positional();
    if (positional.size() != 1) throw Error("one SEQUENCE_DIR is required");
    const std::string seq = positional[0];
    Config config = Config::load(args.isSet("config") ? args.get("config") : Config::defaultPath());
    if (args.isSet("no-lines")) config.estimator.use_lines = false;
    const bool oracle = args.isSet("oracle");
    const double oracle_noise = args.getDouble("oracle-noise-px");
    const double drop_px = args.getDouble("drop-px");
    const int max_frames = args.getInt("frames");
    const std::string out_dir = args.get("out");
    if (!out_dir.empty()) fs::create_directories(out_dir);

    requireRenderedGroundTruth(seq);
    const EurocDataset data(seq);
    const Trajectory gt = readTrajectory((fs::path(seq) / "groundtruth.tum").string());
    const sim::SceneFile scene = sim::loadSequenceScene(seq);
    FrontEnd front_end(config);
    Estimator estimator(config.estimator, config.camera, config.imu);
    const CameraModel& camera = front_end.camera();
    const Eigen::Isometry3d& T_b_c = config.camera.T_b_c;
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0.0, 1.0);

    std::unordered_map<int, TrackTruth> tracks;
    Trajectory estimate;
    std::ofstream errors_csv;
    if (!out_dir.empty()) {
      errors_csv.open((fs::path(out_dir) / "point_errors.csv").string());
      errors_csv << "t,points,median_err_px,mean_along_flow_px,mean_across_flow_px,"
                    "mean_err_x_px,mean_err_y_px,median_flow_px_per_frame\n";
    }
    std::vector<double> all_errors;
    std::ofstream obs_csv;
    if (!out_dir.empty()) {
      obs_csv.open((fs::path(out_dir) / "point_observations.csv").string());
      obs_csv << "t,id,age,u,v,err_x_px,err_y_px,flow_x_px,flow_y_px,depth_m\n";
    }
    std::size_t next_imu = 0;
    const auto& imu = data.imu();
    int frame_index = 0;
    for (const ImageRecord& rec : data.images()) {
      if (max_frames > 0 && frame_index >= max_frames) break;
      ++frame_index;
      while (next_imu < imu.size() && imu[next_imu].t_ns <= rec.t_ns)
        estimator.addImu(imu[next_imu++]);
      if (next_imu < imu.size()) estimator.addImu(imu[next_imu++]);
      const cv::Mat gray = cv::imread(rec.path, cv::IMREAD_GRAYSCALE);
      if (gray.empty()) throw Error("cannot read " + rec.path);
      FeatureFrame frame = front_end.track(gray, rec.t_ns);
      const std::optional<StampedPose> body = interpolatePose(gt, frame.t());
      if (body) {
        const Eigen::Isometry3d T_w_c = cameraPose(*body, T_b_c);
        const Eigen::Isometry3d T_c_w = T_w_c.inverse();
        std::vector<double> errs;
        std::vector<double> flows;
        Eigen::Vector2d sum_err = Eigen::Vector2d::Zero();
        double sum_along = 0, sum_across = 0;
        int within_3px = 0;  // the means leave out errors of 3 px and more (wrong tracks)
        std::vector<PointObservation> kept;
        for (PointObservation& o : frame.points) {
          TrackTruth& tt = tracks[o.id];
          if (o.track_count == 1 || !tt.valid) {
            const Eigen::Vector3d ray = T_w_c.linear() * Eigen::Vector3d(o.xy.x(), o.xy.y(), 1);
            const auto hit = scene.scene.intersect(T_w_c.translation(), ray.normalized());
            tt.valid = hit.has_value() && o.track_count == 1;
            if (tt.valid) tt.point_w = T_w_c.translation() + hit->t * ray.normalized();
            tt.last_xy = o.xy;
            if (!oracle && drop_px <= 0) kept.push_back(o);
            continue;
          }
          const Eigen::Vector2d flow = (o.xy - tt.last_xy) * camera.fx();
          tt.last_xy = o.xy;
          const Eigen::Vector3d p_c = T_c_w * tt.point_w;
          if (p_c.z() <= 0.05) continue;
          const Eigen::Vector2d xy_true = p_c.head<2>() / p_c.z();
          const Eigen::Vector2d err = (o.xy - xy_true) * camera.fx();
          const bool visible = scene.scene.isVisible(tt.point_w, T_w_c.translation(), 0.01);
          if (visible && obs_csv.is_open())
            obs_csv << std::fixed << std::setprecision(4) << frame.t() << ',' << o.id << ','
                    << o.track_count << ',' << o.px.x() << ',' << o.px.y() << ',' << err.x() << ','
                    << err.y() << ',' << flow.x() << ',' << flow.y() << ',' << p_c.z() << '\n';
          if (visible) {
            errs.push_back(err.norm());
            all_errors.push_back(err.norm());
            flows.push_back(flow.norm());
            if (err.norm() < 3.0) {
              ++within_3px;
              sum_err += err;
              if (flow.norm() > 1e-6) {
                const Eigen::Vector2d f = flow.normalized();
                sum_along += err.dot(f);
                sum_across += f.x() * err.y() - f.y() * err.x();
              }
            }
          }
          if (oracle) {
            if (!visible) continue;
            PointObservation c = o;
            c.xy = xy_true + Eigen::Vector2d(noise(rng), noise(rng)) * oracle_noise / camera.fx();
            c.px = camera.distort(c.xy);
            if (!camera.inImage(c.px)) continue;
            kept.push_back(c);
          } else if (drop_px <= 0 || (visible && err.norm() < drop_px)) {
            kept.push_back(o);
          }
        }
        if (oracle || drop_px > 0) {
          // A new track's first observation is exact by construction (its point was cast
          // through it).
          for (const PointObservation& o : frame.points)
            if (o.track_count == 1 && tracks[o.id].valid) kept.push_back(o);
          frame.points = kept;
        }
        if (errors_csv.is_open() && !errs.empty()) {
          const double n = std::max(1, within_3px);
          errors_csv << std::fixed << std::setprecision(4) << frame.t() << ',' << errs.size() << ','
                     << median(errs) << ',' << sum_along / n << ',' << sum_across / n << ','
                     << sum_err.x() / n << ',' << sum_err.y() / n << ',' << median(flows) << '\n';
        }
      }
      const int resets_before = estimator.resetCount();
      const bool has_pose = estimator.addFrame(frame);
      // As VioPipeline: after a reset the tracks start again.
      if (estimator.resetCount() != resets_before) front_end.resetPoints();
      if (has_pose) {
        const BodyState st = estimator.latestState();
        StampedPose p;
        p.t = st.t;
        p.p = st.p;
        p.q = st.q;
        estimate.push_back(p);
      }
      if (frame_index % 200 == 0)
        std::cerr << "frame " << frame_index << " / " << data.images().size() << "\n";
    }
    if (estimate.empty())
      throw Error("the estimator gave no pose in " + std::to_string(frame_index) +
                  " frames (not initialised): nothing to evaluate");
    const EvaluationResult e = evaluateTrajectory(estimate, gt, EvaluationOptions());
    std::cout << std::fixed << std::setprecision(4) << "frames " << frame_index << " poses "
              << estimate.size() << " resets " << estimator.resetCount() << " ATE "
              << e.ate_translation_m.rmse << " m; point error median " << median(all_errors)
              << " px over " << all_errors.size() << " observations\n";
    if (!out_dir.empty())
      writeTumTrajectory((fs::path(out_dir) / "trajectory.tum").string(), estimate);
    return 0;
  } catch (const std::exception& ex) {
    std::cerr << "alvio_point_truth: " << ex.what() << "\n";
    return 1;
  }
}
