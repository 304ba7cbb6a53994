// alvio_run: the offline runner. Reads an EuRoC folder or a rosbag, runs the
// whole pipeline on every frame and writes the trajectory and timing, and the map
// (octomap.bt, lines.ply, lines.csv, map.3Dscene) unless mapping.enabled is false.
// SIGINT/SIGTERM stop the run early; everything processed so far is still written.
#include <algorithm>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <memory>
#include <string>

#include <opencv2/core/utility.hpp>

#include "alvio/common/arg_parser.h"
#include "alvio/common/error.h"
#include "alvio/common/heap_retention.h"
#include "alvio/common/logging.h"
#include "alvio/common/stop_signal.h"
#include "alvio/config/config.h"
#include "alvio/config/yaml_overlay.h"
#include "alvio/config/yaml_reader.h"
#include "alvio/logging/run_logger.h"
#include "alvio/mapping/map_observer.h"
#include "alvio/pipeline/analysis_writer.h"
#include "alvio/pipeline/offline_runner.h"
#include "alvio/pipeline/vio_pipeline.h"
#include "dataset_source.h"

#ifdef ALVIO_WITH_MIMALLOC
#include <mimalloc.h>
#endif

using namespace alvio;

namespace {
// mimalloc, when linked, has replaced malloc for the whole process (it keeps freed pages for
// reuse by itself); else glibc's malloc is told to keep freed memory. Checked on a real
// allocation, so that a linker that dropped the library shows.
std::string useFastAllocator() {
#ifdef ALVIO_WITH_MIMALLOC
  void* probe = std::malloc(64);
  const bool replaced = mi_is_in_heap_region(probe);
  std::free(probe);
  if (replaced) return "mimalloc " + std::to_string(mi_version());
#endif
  alvio::retainFreedHeapMemory();  // per-frame image temporaries stay mapped
  return "glibc malloc, freed memory kept";
}
}  // namespace

int main(int argc, char** argv) {
  ArgParser args("alvio run",
                 "Run alvio over a recorded dataset (EuRoC/ASL folder or rosbag), every frame,\n"
                 "deterministically and as fast as possible.");
  args.option("dataset", "EuRoC folder (containing mav0/) or .bag file", "", true);
  args.option("config", "YAML configuration", Config::defaultPath());
  args.option("out", "output folder", "", true);
  args.option("max-frames", "stop after this many images", "-1");
  args.option("start",
              "skip this many seconds of data (IMU and images) from the first message: start "
              "mid-way, as a VIO started while the robot moves",
              "0");
  args.flag("no-lines", "points only (no line front end, no line landmarks)");
  args.option("line-tracker", "flow (ALVIO optical flow) | descriptor (PL-VIO LBD baseline)");
  args.flag("quiet", "no progress bar");
  args.flag("verbose", "debug messages on stderr (why initialisation waits, solver details)");
  args.option("analysis", "write sensitivity-analysis records (CSV) into this folder");
  args.listOption("set",
                  "override configuration keys: key=value[,key=value...], may be repeated "
                  "(e.g. estimator.selection.points=true)");
  args.flag("no-log", "no MRPT logs (rawlog, 3D scene, alvio.log); also config logger.enabled");
  args.option("opencv-threads",
              "threads OpenCV may use inside one call (KLT, CLAHE, resizing); 1 keeps the whole "
              "pipeline on one core [default: OpenCV's own, all cores]");
  try {
    if (!args.parse(argc, argv)) return 0;
    if (args.isSet("verbose")) setLogLevel(LogLevel::kDebug);
    const std::string allocator = useFastAllocator();
    logDebug("memory allocator: ", allocator);
    if (args.isSet("opencv-threads")) {
      const int threads = args.getInt("opencv-threads");
      if (threads < 1)
        throw Error("--opencv-threads must be at least 1, got " + std::to_string(threads));
      cv::setNumThreads(threads == 1 ? 0 : threads);  // OpenCV's 0 means: no worker threads
    }
    // The configuration file with the --set overrides laid over it; the reader keeps the
    // file's path, so relative paths in it still resolve next to the file.
    const std::string config_path = args.get("config");
    std::string config_text = readConfigText(config_path);
    std::vector<std::string> override_keys;
    if (args.isSet("set")) {
      for (const std::string& assignment : splitAssignments(args.get("set"))) {
        const std::string overlay = assignmentToYaml(assignment);
        config_text = overlayYaml(config_text, config_path, overlay, "--set " + assignment);
        const auto keys = yamlLeafKeys(overlay);
        override_keys.insert(override_keys.end(), keys.begin(), keys.end());
      }
    }
    const YamlReader config_yaml = YamlReader::fromString(config_text, config_path);
    Config config = Config::load(config_yaml);
    const MappingOptions mapping = MappingOptions::load(config_yaml, "mapping");
    for (const std::string& key : config_yaml.unknownKeys())
      if (std::find(override_keys.begin(), override_keys.end(), key) != override_keys.end())
        throw Error("--set: unknown configuration key '" + key + "' (misspelt?)");
    if (args.isSet("no-lines")) config.estimator.use_lines = false;
    if (args.isSet("analysis")) config.estimator.record_analysis = true;
    if (args.isSet("line-tracker")) {
      config.lines.tracker = args.get("line-tracker");
      if (config.lines.tracker != "flow" && config.lines.tracker != "descriptor")
        throw Error("--line-tracker must be flow or descriptor, got '" + config.lines.tracker +
                    "'");
    }
    const std::unique_ptr<SensorSource> source = openDataset(args.get("dataset"), config.topics);
    RunOptions options;
    options.out_dir = args.get("out");
    options.max_frames = args.getInt("max-frames");
    options.start_s = args.getDouble("start");
    options.progress = !args.isSet("quiet");
    options.stop = &installStopSignalHandlers();
    std::unique_ptr<RunLogger> logger;
    if (config.logger.enabled && !args.isSet("no-log")) {
      logger = std::make_unique<RunLogger>(config.logger);
      options.observers.push_back(logger.get());
    }
    std::unique_ptr<AnalysisWriter> analysis;
    if (args.isSet("analysis")) {
      analysis = std::make_unique<AnalysisWriter>(args.get("analysis"), config.camera.width,
                                                  config.camera.height);
      options.observers.push_back(analysis.get());
    }
    std::unique_ptr<MapObserver> map;
    if (mapping.enabled) {
      map = std::make_unique<MapObserver>(mapping, config.camera.T_b_c);
      options.observers.push_back(map.get());
    }
    const RunResult r = runOffline(*source, config, options);
    if (map) std::cout << "map:\n" << map->summary().toString();

    std::cout << "frames: " << r.frames << ", poses: " << r.poses << ", resets: " << r.resets
              << ", skipped images: " << r.skipped_images << "\n";
    if (r.dropped_images + r.dropped_imu > 0)
      std::cout << "dropped (out of order or not finite): " << r.dropped_images << " images, "
                << r.dropped_imu << " IMU samples\n";
    if (r.estimated_time_shift_s)
      std::cout << "camera time shift estimated: " << std::showpos << std::fixed
                << std::setprecision(2) << 1e3 * *r.estimated_time_shift_s << std::noshowpos
                << " ms on top of camera.timeshift_cam_imu (for the config: timeshift_cam_imu: "
                << std::setprecision(4)
                << config.camera.timeshift_cam_imu + *r.estimated_time_shift_s << ")\n";
    if (r.initialization) {
      const auto& q = *r.initialization;
      std::cout << "initialised at " << std::fixed << q.time << " s (" << q.since_motion_s
                << " s after the first motion): scale error " << 100 * q.scale_error
                << " %, gravity error " << q.gravity_error_deg << " deg\n";
    }
    const LineRetirementCounts& lr = r.line_retirement;
    if (lr.tracks() > 0)
      std::cout << "lines for the maps: "
                << describeLineRetirement(lr,
                                          lineMapLimits(config.estimator, config.lines.map_edges))
                << "\n";
    if (fitLimitLooksTooTight(lr)) std::cout << "note: " << kFitLimitHint << "\n";
    std::cout << r.timing.summaryTable();
    std::cout << "outputs in " << options.out_dir << "\n";
    if (logger && logger->logger()) {
      const LoggerPaths& p = logger->logger()->paths();
      std::cout << "MRPT logs:";
      for (const std::string* f : {&p.rawlog, &p.scene, &p.text})
        if (!f->empty()) std::cout << " " << *f;
      std::cout << " (observers " << r.observer_ms << " ms in all)\n";
    }
    if (r.evaluation) std::cout << "ATE_RMSE=" << r.evaluation->ate_translation_m.rmse << "\n";
    if (r.interrupted) {
      std::cout << "interrupted by signal " << stopSignalNumber() << ": outputs are complete up to "
                << "the last frame processed\n";
      return 128 + stopSignalNumber();  // the shell's convention for death by signal
    }
    return r.poses > 0 ? 0 : 3;
  } catch (const Error& e) {
    std::cerr << "alvio run: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    // Third-party failures (rosbag, OpenCV, MRPT) still end with a message, not an abort.
    std::cerr << "alvio run: error: " << e.what() << "\n";
    return 2;
  }
}
