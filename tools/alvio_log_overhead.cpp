// alvio_log_overhead: what the MRPT logger costs. Runs the offline pipeline on the
// same dataset with and without the logger, interleaved (off/on, then on/off, ...)
// so that machine load and file-cache effects hit both alike, and reports the
// median wall time of each and their ratio.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <vector>

#include "alvio/common/arg_parser.h"
#include "alvio/common/error.h"
#include "alvio/common/timing.h"
#include "alvio/config/config.h"
#include "alvio/io/trajectory_io.h"
#include "alvio/logging/run_logger.h"
#include "alvio/pipeline/offline_runner.h"
#include "rosbag_source.h"

using namespace alvio;

namespace {

struct Measurement {
  double wall_ms = 0, observer_ms = 0;
  std::size_t frames = 0;
};

Measurement runOnce(const std::string& dataset, const Config& config, const std::string& out,
                    int max_frames, bool with_logger) {
  std::unique_ptr<SensorSource> source;
  if (std::filesystem::path(dataset).extension() == ".bag")
    source = std::make_unique<RosbagSource>(dataset, config.topics);
  else
    source = std::make_unique<EurocSource>(dataset);
  RunOptions options;
  options.out_dir = out;
  options.max_frames = max_frames;
  options.progress = false;
  std::unique_ptr<RunLogger> logger;
  if (with_logger) {
    logger = std::make_unique<RunLogger>(config.logger);
    options.observers.push_back(logger.get());
  }
  const auto start = std::chrono::steady_clock::now();
  const RunResult r = runOffline(*source, config, options);
  logger.reset();  // closing the files is part of the cost
  Measurement m;
  m.wall_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  m.observer_ms = r.observer_ms;
  m.frames = r.frames;
  return m;
}

double median(std::vector<double> v) {
  return percentile(std::move(v), 50);
}

std::uintmax_t folderBytes(const std::filesystem::path& dir) {
  std::uintmax_t bytes = 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir))
    if (e.is_regular_file()) bytes += e.file_size();
  return bytes;
}

}  // namespace

int main(int argc, char** argv) {
  ArgParser args("alvio_log_overhead",
                 "Measure the MRPT logger's cost: the offline pipeline with and without it on\n"
                 "the same dataset, interleaved, median wall times and their ratio.");
  args.option("dataset", "EuRoC folder (containing mav0/) or .bag file", "", true);
  args.option("config", "YAML configuration (its logger section is used)", Config::defaultPath());
  args.option("out", "scratch output folder", "", true);
  args.option("reps", "runs per mode", "3");
  args.option("max-frames", "stop after this many images", "-1");
  args.option("json", "also write the result here", "");
  try {
    if (!args.parse(argc, argv)) return 0;
    Config config = Config::load(args.get("config"));
    config.logger.out_dir.clear();  // each run logs into its own folder
    const int reps = args.getInt("reps");
    if (reps < 1) throw Error("--reps must be at least 1");
    const std::string out = args.get("out");
    std::vector<double> off_ms, on_ms, observer_ms;
    std::size_t frames = 0;
    for (int i = 0; i < reps; ++i) {
      // Alternate which mode goes first, so neither always runs on a warm cache.
      for (const bool with_logger : {i % 2 == 1, i % 2 == 0}) {
        const std::string dir =
            out + "/rep" + std::to_string(i) + (with_logger ? "_log" : "_nolog");
        const Measurement m =
            runOnce(args.get("dataset"), config, dir, args.getInt("max-frames"), with_logger);
        (with_logger ? on_ms : off_ms).push_back(m.wall_ms);
        if (with_logger) observer_ms.push_back(m.observer_ms);
        frames = m.frames;
        std::cerr << "rep " << i << (with_logger ? " with" : " without")
                  << " logger: " << std::fixed << std::setprecision(1) << m.wall_ms << " ms\n";
      }
    }
    const double off = median(off_ms), on = median(on_ms), obs = median(observer_ms);
    const std::uintmax_t log_bytes =
        folderBytes(out + "/rep0_log") - folderBytes(out + "/rep0_nolog");
    std::cout << std::fixed << std::setprecision(1) << "frames: " << frames << ", reps: " << reps
              << "\nwithout logger: " << off << " ms (median)\nwith logger:    " << on
              << " ms (median; " << obs << " ms inside the logger's callbacks)\n"
              << "log files: " << log_bytes / 1024 << " KiB\n"
              << std::setprecision(3) << "OVERHEAD_RATIO=" << on / off << "\n";
    if (!args.get("json").empty()) {
      nlohmann::json j;
      j["frames"] = frames;
      j["reps"] = reps;
      j["without_logger_ms"] = off_ms;
      j["with_logger_ms"] = on_ms;
      j["logger_callbacks_ms"] = observer_ms;
      j["ratio"] = on / off;
      j["log_bytes"] = log_bytes;
      writeFileAtomically(args.get("json"), j.dump(2) + "\n");
    }
    return 0;
  } catch (const Error& e) {
    std::cerr << "alvio_log_overhead: error: " << e.what() << "\n";
    return 2;
  }
}
