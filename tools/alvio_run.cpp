// alvio_run: the offline runner. Reads an EuRoC folder or a rosbag, runs the
// whole pipeline on every frame and writes the trajectory and timing, and the map
// (octomap.bt, lines.ply, lines.csv, map.3Dscene) unless mapping.enabled is false.
#include <filesystem>
#include <iostream>
#include <memory>

#include "alvio/common/arg_parser.h"
#include "alvio/common/error.h"
#include "alvio/common/logging.h"
#include "alvio/config/config.h"
#include "alvio/config/yaml_reader.h"
#include "alvio/mapping/estimator_keyframe_feed.h"
#include "alvio/mapping/map_builder.h"
#include "alvio/pipeline/offline_runner.h"
#include "alvio/pipeline/vio_pipeline.h"
#include "rosbag_source.h"

using namespace alvio;

int main(int argc, char** argv) {
  ArgParser args("alvio run",
                 "Run alvio over a recorded dataset (EuRoC/ASL folder or rosbag), every frame,\n"
                 "deterministically and as fast as possible.");
  args.option("dataset", "EuRoC folder (containing mav0/) or .bag file", "", true);
  args.option("config", "YAML configuration", Config::defaultPath());
  args.option("out", "output folder", "", true);
  args.option("max-frames", "stop after this many images", "-1");
  args.flag("quiet", "no progress bar");
  try {
    if (!args.parse(argc, argv)) return 0;
    const Config config = Config::load(args.get("config"));
    std::unique_ptr<SensorSource> source;
    const std::string dataset = args.get("dataset");
    if (std::filesystem::path(dataset).extension() == ".bag")
      source = std::make_unique<RosbagSource>(dataset, config.topics);
    else
      source = std::make_unique<EurocSource>(dataset);
    RunOptions options;
    options.out_dir = args.get("out");
    options.max_frames = args.getInt("max-frames");
    options.progress = !args.isSet("quiet");

    // The map: keyframe landmarks from the estimator's window, body poses for the scene.
    const MappingOptions mapping = MappingOptions::load(YamlReader(args.get("config")), "mapping");
    std::unique_ptr<MapBuilder> map;
    EstimatorKeyframeFeed feed(config.camera.T_b_c);
    if (mapping.enabled) {
      map = std::make_unique<MapBuilder>(mapping);
      options.on_frame = [&](const PipelineOutput& out, const Estimator& estimator) {
        if (out.has_pose) map->addTrajectoryPose({out.state.t, out.state.p, out.state.q});
        if (auto keyframe = feed.poll(estimator)) map->addKeyframe(*keyframe);
      };
      options.on_finish = [&](const Estimator& estimator) {
        for (const KeyframeLandmarks& keyframe : feed.flush(estimator)) map->addKeyframe(keyframe);
      };
    }
    const RunResult r = runOffline(*source, config, options);
    if (map) {
      map->save(options.out_dir);
      std::cout << "map:\n" << map->summary().toString();
    }

    std::cout << "frames: " << r.frames << ", poses: " << r.poses << ", resets: " << r.resets
              << ", skipped images: " << r.skipped_images << "\n";
    if (r.initialization) {
      const auto& q = *r.initialization;
      std::cout << "initialised at " << std::fixed << q.time << " s (" << q.since_motion_s
                << " s after the first motion): scale error " << 100 * q.scale_error
                << " %, gravity error " << q.gravity_error_deg << " deg\n";
    }
    std::cout << r.timing.summaryTable();
    std::cout << "outputs in " << options.out_dir << "\n";
    if (r.evaluation) std::cout << "ATE_RMSE=" << r.evaluation->ate_translation_m.rmse << "\n";
    return r.poses > 0 ? 0 : 3;
  } catch (const Error& e) {
    std::cerr << "alvio run: error: " << e.what() << "\n";
    return 2;
  }
}
