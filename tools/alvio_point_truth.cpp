// alvio_point_truth: the point tracker scored against the simulator's true scene, and the
// estimator run on corrected observations, to tell front-end error from back-end error.
// A track's 3D point is where the ray through its first observation meets the scene
// (ground-truth camera pose); every later observation is compared with that point's true
// projection. With --oracle the estimator is fed those true projections instead of the
// tracked positions (same tracks, same IDs; lines as tracked, or none with --no-lines);
// --drop-px keeps the tracked positions but drops those further than that from the truth.
// --out writes trajectory.tum, point_errors.csv (per frame) and point_observations.csv (per
// observation of a visible track point: age, pixel, error, frame-to-frame flow, depth), and
// the map files alvio_run writes (octomap.bt, lines.csv, ...), for alvio_map_truth.
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
#include "alvio/common/timing.h"
#include "alvio/config/config.h"
#include "alvio/config/yaml_reader.h"
#include "alvio/eval/trajectory_evaluation.h"
#include "alvio/eval/trajectory_interpolation.h"
#include "alvio/io/euroc_dataset.h"
#include "alvio/io/trajectory_io.h"
#include "alvio/mapping/map_observer.h"
#include "alvio/pipeline/offline_runner.h"
#include "alvio/pipeline/vio_pipeline.h"
#include "alvio/sim/sequence_scene.h"

using namespace alvio;
namespace fs = std::filesystem;

namespace {

struct PointTruthOptions {
  bool oracle = false;
  double oracle_noise_px = 0;
  double drop_px = 0;  // 0: keep all
};

// Scores each frame's tracked points against the scene and, in the oracle and drop modes,
// changes what the estimator is fed. Writes the two CSV files when given an output folder.
class PointTruth {
 public:
  PointTruth(const PointTruthOptions& options, const sim::Scene& scene, const CameraModel& camera,
             const Eigen::Isometry3d& T_b_c, const std::string& out_dir)
      : options_(options), scene_(scene), camera_(camera), T_b_c_(T_b_c) {
    if (out_dir.empty()) return;
    errors_csv_.open((fs::path(out_dir) / "point_errors.csv").string());
    errors_csv_ << "t,points,median_err_px,mean_along_flow_px,mean_across_flow_px,"
                   "mean_err_x_px,mean_err_y_px,median_flow_px_per_frame\n";
    obs_csv_.open((fs::path(out_dir) / "point_observations.csv").string());
    obs_csv_ << "t,id,age,u,v,err_x_px,err_y_px,flow_x_px,flow_y_px,depth_m\n";
  }

  void process(const StampedPose& body, FeatureFrame* frame);
  const std::vector<double>& errors() const { return all_errors_; }

 private:
  struct TrackTruth {
    Eigen::Vector3d point_w;
    Eigen::Vector2d last_xy;  // tracked position in the previous frame
    bool valid = false;
  };

  PointTruthOptions options_;
  const sim::Scene& scene_;
  const CameraModel& camera_;
  Eigen::Isometry3d T_b_c_;
  std::mt19937 rng_{7};
  std::normal_distribution<double> noise_{0.0, 1.0};
  std::unordered_map<int, TrackTruth> tracks_;
  std::vector<double> all_errors_;
  std::ofstream errors_csv_, obs_csv_;
};

void PointTruth::process(const StampedPose& body, FeatureFrame* frame) {
  const bool filter = options_.oracle || options_.drop_px > 0;
  const Eigen::Isometry3d T_w_c = body.T_w_b() * T_b_c_;
  const Eigen::Isometry3d T_c_w = T_w_c.inverse();
  const double fx = camera_.fx();
  std::vector<double> errs;
  std::vector<double> flows;
  Eigen::Vector2d sum_err = Eigen::Vector2d::Zero();
  double sum_along = 0, sum_across = 0;
  int within_3px = 0;  // the means leave out errors of 3 px and more (wrong tracks)
  std::vector<PointObservation> kept;
  for (const PointObservation& o : frame->points) {
    TrackTruth& tt = tracks_[o.id];
    if (o.track_count == 1 || !tt.valid) {
      const Eigen::Vector3d ray =
          (T_w_c.linear() * Eigen::Vector3d(o.xy.x(), o.xy.y(), 1)).normalized();
      const auto hit = scene_.intersect(T_w_c.translation(), ray);
      tt.valid = hit.has_value() && o.track_count == 1;
      if (tt.valid) tt.point_w = T_w_c.translation() + hit->t * ray;
      tt.last_xy = o.xy;
      continue;
    }
    const Eigen::Vector2d flow = (o.xy - tt.last_xy) * fx;
    tt.last_xy = o.xy;
    const Eigen::Vector3d p_c = T_c_w * tt.point_w;
    if (p_c.z() <= 0.05) continue;
    const Eigen::Vector2d xy_true = p_c.head<2>() / p_c.z();
    const Eigen::Vector2d err = (o.xy - xy_true) * fx;
    const bool visible = scene_.isVisible(tt.point_w, T_w_c.translation(), 0.01);
    if (visible) {
      if (obs_csv_.is_open())
        obs_csv_ << std::fixed << std::setprecision(4) << frame->t() << ',' << o.id << ','
                 << o.track_count << ',' << o.px.x() << ',' << o.px.y() << ',' << err.x() << ','
                 << err.y() << ',' << flow.x() << ',' << flow.y() << ',' << p_c.z() << '\n';
      errs.push_back(err.norm());
      all_errors_.push_back(err.norm());
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
    if (options_.oracle) {
      if (!visible) continue;
      PointObservation c = o;
      c.xy = xy_true + Eigen::Vector2d(noise_(rng_), noise_(rng_)) * options_.oracle_noise_px / fx;
      c.px = camera_.distort(c.xy);
      if (camera_.inImage(c.px)) kept.push_back(c);
    } else if (options_.drop_px > 0 && visible && err.norm() < options_.drop_px) {
      kept.push_back(o);
    }
  }
  if (filter) {
    // A new track's first observation is exact by construction (its point was cast through
    // it).
    for (const PointObservation& o : frame->points)
      if (o.track_count == 1 && tracks_[o.id].valid) kept.push_back(o);
    frame->points = std::move(kept);
  }
  if (errors_csv_.is_open() && !errs.empty()) {
    const double n = std::max(1, within_3px);
    errors_csv_ << std::fixed << std::setprecision(4) << frame->t() << ',' << errs.size() << ','
                << percentile(errs, 50) << ',' << sum_along / n << ',' << sum_across / n << ','
                << sum_err.x() / n << ',' << sum_err.y() / n << ',' << percentile(flows, 50)
                << '\n';
  }
}

}  // namespace

int main(int argc, char** argv) {
  ArgParser args("alvio_point_truth",
                 "Point tracks against the simulator's true scene; --oracle runs the estimator\n"
                 "on the true projections of the same tracks.\n"
                 "Usage: alvio_point_truth [--config FILE] [options] SEQUENCE_DIR");
  args.option("config", "configuration (default: the installed config/euroc.yaml)", "");
  args.option(
      "out", "folder for trajectory.tum, point_errors.csv, point_observations.csv and the map", "");
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
    const YamlReader config_yaml =
        Config::readYaml(args.isSet("config") ? args.get("config") : Config::defaultPath());
    Config config = Config::load(config_yaml);
    const MappingOptions mapping = MappingOptions::load(config_yaml, "mapping");
    if (args.isSet("no-lines")) config.estimator.use_lines = false;
    const int max_frames = args.getInt("frames");
    const std::string out_dir = args.get("out");
    if (!out_dir.empty()) fs::create_directories(out_dir);

    sim::requireRenderedGroundTruth(seq);
    const EurocDataset data(seq);
    const Trajectory gt = readTrajectory((fs::path(seq) / "groundtruth.tum").string());
    const sim::SceneFile scene = sim::loadSequenceScene(seq);
    VioPipeline pipeline(config);
    PointTruth truth(
        {args.isSet("oracle"), args.getDouble("oracle-noise-px"), args.getDouble("drop-px")},
        scene.scene, pipeline.camera(), config.camera.T_b_c, out_dir);

    // The same map alvio_run builds, so that alvio_map_truth can score the oracle's map.
    std::unique_ptr<MapObserver> map;
    if (!out_dir.empty() && mapping.enabled) {
      map = std::make_unique<MapObserver>(mapping, config.camera.T_b_c);
      map->onStart({config, seq, out_dir, &gt});
    }
    Trajectory estimate;
    std::size_t next_imu = 0;
    const auto& imu = data.imu();
    int frame_index = 0;
    for (const ImageRecord& rec : data.images()) {
      if (max_frames > 0 && frame_index >= max_frames) break;
      ++frame_index;
      while (next_imu < imu.size() && imu[next_imu].t_ns <= rec.t_ns)
        pipeline.addImu(imu[next_imu++]);
      if (next_imu < imu.size()) pipeline.addImu(imu[next_imu++]);
      const cv::Mat gray = cv::imread(rec.path, cv::IMREAD_GRAYSCALE);
      if (gray.empty()) throw Error("cannot read " + rec.path);
      const PipelineOutput out = pipeline.addImage(gray, rec.t_ns, [&](FeatureFrame* frame) {
        if (const auto body = interpolatePose(gt, frame->t())) truth.process(*body, frame);
      });
      if (map) map->onFrame({rec.t_ns, gray, out, pipeline});
      if (out.has_pose) {
        StampedPose p;
        p.t = out.state.t;
        p.p = out.state.p;
        p.q = out.state.q;
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
              << estimate.size() << " resets " << pipeline.estimator().resetCount() << " ATE "
              << e.ate_translation_m.rmse << " m; point error median "
              << percentile(truth.errors(), 50) << " px over " << truth.errors().size()
              << " observations\n";
    if (map) map->onFinish(RunResult());
    if (!out_dir.empty())
      writeTumTrajectory((fs::path(out_dir) / "trajectory.tum").string(), estimate);
    return 0;
  } catch (const std::exception& ex) {
    std::cerr << "alvio_point_truth: error: " << ex.what() << "\n";
    return 1;
  }
}
