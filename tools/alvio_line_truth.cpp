// alvio_line_truth: the line trackers (optical flow and the descriptor baseline) scored
// against the simulator's ground truth on rendered sequences: every tracked segment is
// associated with the true scene edge it lies on (projected with the ground-truth camera
// pose, occlusion included), and a track should stay on one edge. Prints and (--json) writes
// per tracker: track length, fraction of correct associations, fraction of tracks on one edge,
// Type 3 / Type 4 events, lines and time per frame.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>

#include "alvio/camera/camera_model.h"
#include "alvio/common/arg_parser.h"
#include "alvio/common/error.h"
#include "alvio/config/config.h"
#include "alvio/eval/line_track_truth.h"
#include "alvio/eval/trajectory_interpolation.h"
#include "alvio/frontend/gyro_rotation.h"
#include "alvio/io/euroc_dataset.h"
#include "alvio/io/trajectory_io.h"
#include "alvio/sim/edge_projection.h"
#include "alvio/sim/sequence_scene.h"

using namespace alvio;
namespace fs = std::filesystem;

namespace {

nlohmann::json toJson(const std::vector<EndpointErrorBin>& bins) {
  nlohmann::json out = nlohmann::json::array();
  for (const EndpointErrorBin& b : bins)
    out.push_back({{"min_length_px", b.min_length_px},
                   {"max_length_px", std::isinf(b.max_length_px) ? -1.0 : b.max_length_px},
                   {"endpoints", b.endpoints},
                   {"rms_px", b.rms_px},
                   {"median_px", b.median_px}});
  return out;
}

nlohmann::json toJson(const LineTrackTruthSummary& s) {
  return {{"frames", s.frames},
          {"observations", s.observations},
          {"lines_per_frame", s.lines_per_frame},
          {"associated_fraction", s.associated_fraction},
          {"tracks", s.tracks},
          {"mean_track_length_frames", s.mean_track_length_frames},
          {"median_track_length_frames", s.median_track_length_frames},
          {"evaluated_tracks", s.evaluated_tracks},
          {"correct_fraction", s.correct_fraction},
          {"strict_correct_fraction", s.strict_correct_fraction},
          {"single_edge_track_fraction", s.single_edge_track_fraction},
          {"median_endpoint_distance_px", s.median_endpoint_distance_px},
          {"endpoint_error_by_length", toJson(s.endpoint_error_by_length)},
          {"type3_merged", s.type3_merged},
          {"type4_clipped", s.type4_clipped},
          {"ms_per_frame", {{"mean", s.mean_ms}, {"median", s.median_ms}}}};
}

void print(const std::string& name, const LineTrackTruthSummary& s) {
  std::cout << std::fixed << std::setprecision(2) << "  " << std::setw(10) << std::left << name
            << std::right << " lines/frame " << s.lines_per_frame << "  on a true edge "
            << 100 * s.associated_fraction << " %  tracks " << s.tracks << "  mean length "
            << s.mean_track_length_frames << " frames (median " << s.median_track_length_frames
            << ")\n             correct associations " << 100 * s.correct_fraction << " % (strict "
            << 100 * s.strict_correct_fraction << " %)  tracks on one edge "
            << 100 * s.single_edge_track_fraction << " % of " << s.evaluated_tracks << "  type3 "
            << s.type3_merged << "  type4 " << s.type4_clipped << "  ms/frame " << s.mean_ms
            << " (median " << s.median_ms << ")  endpoint error median "
            << s.median_endpoint_distance_px
            << " px\n             endpoint error by length "
               "(px: endpoints, rms):";
  for (const EndpointErrorBin& b : s.endpoint_error_by_length) {
    std::cout << "  " << std::setprecision(0) << b.min_length_px;
    if (std::isinf(b.max_length_px))
      std::cout << "+";
    else
      std::cout << "-" << b.max_length_px;
    std::cout << ": " << b.endpoints << ", " << std::setprecision(2) << b.rms_px;
  }
  std::cout << "\n";
}

// The pinhole camera of the undistorted image the trackers report in (same K, no distortion).
std::unique_ptr<CameraModel> pinholeOf(const CameraOptions& camera) {
  CameraOptions pinhole = camera;
  pinhole.distortion_model = "none";
  pinhole.distortion_coefficients.clear();
  return CameraModel::create(pinhole);
}

}  // namespace

int main(int argc, char** argv) {
  ArgParser args("alvio_line_truth",
                 "Line trackers (flow, descriptor) against the simulator's true scene edges.\n"
                 "Usage: alvio_line_truth [options] SEQUENCE_DIR...\n"
                 "A sequence folder holds mav0/, groundtruth.tum, scene_edges.csv and "
                 "sim_info.yaml.");
  args.option("config", "configuration (camera + lines)", "");
  args.option("scene", "scene file or name (default: the one sim_info.yaml names)", "");
  args.option("first", "first frame to use", "0");
  args.option("max-frames", "frames to use at most (0 = all)", "0");
  args.option("every", "use every N-th frame", "1");
  args.option("max-distance-px", "endpoint distance to a true edge's image line", "3");
  args.option("max-angle-deg", "angle to a true edge's image line", "3");
  args.option("min-overlap", "fraction of a segment on the edge's visible part", "0.5");
  args.option("json", "write every figure to this JSON file");
  try {
    if (!args.parse(argc, argv)) return 0;
    if (args.positional().empty()) throw Error("give at least one sequence folder");
    const Config config =
        Config::load(args.isSet("config") ? args.get("config") : Config::defaultPath());
    const int first = std::max(0, args.getInt("first"));
    const int max_frames = std::max(0, args.getInt("max-frames"));
    const int every = std::max(1, args.getInt("every"));
    EdgeAssociationOptions association;
    association.max_endpoint_distance_px = args.getDouble("max-distance-px");
    association.max_angle_deg = args.getDouble("max-angle-deg");
    association.min_overlap_ratio = args.getDouble("min-overlap");
    const std::unique_ptr<CameraModel> pinhole = pinholeOf(config.camera);
    cv::setNumThreads(1);  // per-frame cost on one core, as in a pipeline thread

    nlohmann::json report = nlohmann::json::object();
    for (const std::string& dir : args.positional()) {
      if (!fs::exists(fs::path(dir) / "sim_stamp.txt"))
        throw Error(dir + ": no sim_stamp.txt (sequence incomplete or not simulated)");
      sim::requireRenderedGroundTruth(dir);  // the true edges are projected from its poses
      const sim::SceneFile scene = sim::loadSequenceScene(dir, args.get("scene"));
      const EurocDataset dataset(dir);
      const Trajectory gt = readTrajectory((fs::path(dir) / "groundtruth.tum").string());
      const std::vector<std::string> types = {"flow", "descriptor"};
      std::vector<std::unique_ptr<LineTracker>> trackers;
      std::vector<LineTrackTruth> scores;
      for (const std::string& type : types) {
        LineTrackerOptions options = config.lines;
        options.tracker = type;
        trackers.push_back(createLineTracker(config.camera, options));
        scores.emplace_back(association);
      }
      // The trackers get the gyroscope's rotation between the frames they see, as in the
      // pipeline (lines.flow.gyro_flow).
      GyroRotation gyro(config.camera.T_b_c.linear());
      for (const ImuSample& s : dataset.imu()) gyro.add(s);
      int64_t previous_ns = 0;
      double truth_ms = 0, visible_edges = 0;
      int used = 0;
      const auto& images = dataset.images();
      for (std::size_t k = first; k < images.size(); k += every) {
        if (max_frames > 0 && used >= max_frames) break;
        const double t = nsToSec(images[k].t_ns);
        const std::optional<StampedPose> body = interpolatePose(gt, t);
        if (!body) continue;  // no ground truth here: cannot score the frame
        const cv::Mat image = cv::imread(images[k].path, cv::IMREAD_GRAYSCALE);
        if (image.empty()) throw Error("cannot read image " + images[k].path);
        const auto start = std::chrono::steady_clock::now();
        ProjectedEdges truth;
        for (const sim::VisibleEdge& v :
             sim::projectVisibleEdges(scene.scene, *pinhole, body->T_w_b() * config.camera.T_b_c))
          truth.push_back({v.edge_id, v.a_px, v.b_px});
        truth_ms +=
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        visible_edges += truth.size();
        std::optional<Eigen::Matrix3d> R_cur_prev;
        if (previous_ns) R_cur_prev = gyro.cameraRotation(previous_ns, images[k].t_ns);
        previous_ns = images[k].t_ns;
        for (std::size_t i = 0; i < trackers.size(); ++i)
          scores[i].addFrame(trackers[i]->track(image, t, R_cur_prev), truth);
        ++used;
        if (used % 100 == 0) std::cerr << "\r" << dir << ": " << used << " frames" << std::flush;
      }
      std::cerr << "\n";
      if (used < 2) throw Error(dir + ": fewer than two frames with ground truth");
      nlohmann::json seq = {{"folder", dir},
                            {"first", first},
                            {"every", every},
                            {"frames", used},
                            {"visible_edges_per_frame", visible_edges / used},
                            {"truth_ms_per_frame", truth_ms / used},
                            {"association",
                             {{"max_endpoint_distance_px", association.max_endpoint_distance_px},
                              {"max_angle_deg", association.max_angle_deg},
                              {"min_overlap_ratio", association.min_overlap_ratio},
                              {"occlusion", "longest unoccluded run of each edge"}}}};
      std::cout << "\n== " << dir << " (" << used << " frames from " << first << ", every " << every
                << "; " << std::setprecision(1) << std::fixed << visible_edges / used
                << " true edges visible per frame)\n";
      for (std::size_t i = 0; i < types.size(); ++i) {
        const LineTrackTruthSummary s = scores[i].summarise();
        seq[types[i]] = toJson(s);
        print(types[i], s);
      }
      const double flow_len = seq["flow"]["mean_track_length_frames"];
      const double desc_len = seq["descriptor"]["mean_track_length_frames"];
      seq["track_length_ratio_flow_to_descriptor"] = desc_len > 0 ? flow_len / desc_len : 0.0;
      std::cout << "  track length flow / descriptor: " << std::setprecision(2)
                << seq["track_length_ratio_flow_to_descriptor"].get<double>() << "\n";
      report[fs::path(dir).lexically_normal().filename().string()] = seq;
    }
    if (args.isSet("json")) writeFileAtomically(args.get("json"), report.dump(2) + "\n");
    return 0;
  } catch (const Error& e) {
    std::cerr << "alvio_line_truth: error: " << e.what() << "\n";
    return 2;
  } catch (const cv::Exception& e) {
    std::cerr << "alvio_line_truth: OpenCV error: " << e.what() << "\n";
    return 2;
  }
}
