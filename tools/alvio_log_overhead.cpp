// alvio_log_overhead: what the MRPT logger costs. Runs the offline pipeline on the
// same dataset with and without the logger, interleaved (off/on, then on/off, ...)
// so that machine load and file-cache effects hit both alike. Reports median wall
// and process CPU times and their ratios, and the time inside the logger's
// callbacks relative to the rest of the run. On a shared, loaded machine the wall
// ratio is noisy; the CPU ratio (OVERHEAD_RATIO) and the callback share less so.
#include <time.h>

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
#include "dataset_source.h"

using namespace alvio;

namespace {

struct Measurement {
  double wall_ms = 0, cpu_ms = 0, observer_ms = 0;
  std::size_t frames = 0;
};

// CPU time of this process (all threads), ms.
double cpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

Measurement runOnce(const std::string& dataset, const Config& config, const std::string& out,
                    int max_frames, bool with_logger) {
  const std::unique_ptr<SensorSource> source = openDataset(dataset, config.topics);
  RunOptions options;
  options.out_dir = out;
  options.max_frames = max_frames;
  options.progress = false;
  std::unique_ptr<RunLogger> logger;
  if (with_logger) {
    logger = std::make_unique<RunLogger>(config.logger);
    options.observers.push_back(logger.get());
  }
  const double cpu_start = cpuMs();
  const auto start = std::chrono::steady_clock::now();
  const RunResult r = runOffline(*source, config, options);
  logger.reset();  // closing the files is part of the cost
  Measurement m;
  m.wall_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  m.cpu_ms = cpuMs() - cpu_start;
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
    std::vector<double> off_ms, on_ms, off_cpu, on_cpu, observer_ms, observer_share;
    std::size_t frames = 0;
    for (int i = 0; i < reps; ++i) {
      // Alternate which mode goes first, so neither always runs on a warm cache.
      for (const bool with_logger : {i % 2 == 1, i % 2 == 0}) {
        const std::string dir =
            out + "/rep" + std::to_string(i) + (with_logger ? "_log" : "_nolog");
        const Measurement m =
            runOnce(args.get("dataset"), config, dir, args.getInt("max-frames"), with_logger);
        (with_logger ? on_ms : off_ms).push_back(m.wall_ms);
        (with_logger ? on_cpu : off_cpu).push_back(m.cpu_ms);
        if (with_logger) {
          observer_ms.push_back(m.observer_ms);
          observer_share.push_back(m.observer_ms / (m.wall_ms - m.observer_ms));
        }
        frames = m.frames;
        std::cerr << "rep " << i << (with_logger ? " with" : " without")
                  << " logger: " << std::fixed << std::setprecision(1) << m.wall_ms << " ms wall, "
                  << m.cpu_ms << " ms CPU\n";
      }
    }
    const double wall_ratio = median(on_ms) / median(off_ms);
    const double cpu_ratio = median(on_cpu) / median(off_cpu);
    const double share = median(observer_share);
    const std::uintmax_t log_bytes =
        folderBytes(out + "/rep0_log") - folderBytes(out + "/rep0_nolog");
    std::cout << std::fixed << std::setprecision(1) << "frames: " << frames << ", reps: " << reps
              << "\nwithout logger: " << median(off_ms) << " ms wall, " << median(off_cpu)
              << " ms CPU (medians)\nwith logger:    " << median(on_ms) << " ms wall, "
              << median(on_cpu) << " ms CPU (medians; " << median(observer_ms)
              << " ms inside the logger's callbacks)\nlog files: " << log_bytes / 1024 << " KiB\n"
              << std::setprecision(3) << "wall ratio " << wall_ratio << ", CPU ratio " << cpu_ratio
              << ", logger callbacks / rest of the run " << share << "\n"
              << "OVERHEAD_RATIO=" << cpu_ratio << "\n";
    if (!args.get("json").empty()) {
      nlohmann::json j;
      j["frames"] = frames;
      j["reps"] = reps;
      j["without_logger_wall_ms"] = off_ms;
      j["with_logger_wall_ms"] = on_ms;
      j["without_logger_cpu_ms"] = off_cpu;
      j["with_logger_cpu_ms"] = on_cpu;
      j["logger_callbacks_ms"] = observer_ms;
      j["wall_ratio"] = wall_ratio;
      j["cpu_ratio"] = cpu_ratio;
      j["callback_share"] = share;
      j["log_bytes"] = log_bytes;
      writeFileAtomically(args.get("json"), j.dump(2) + "\n");
    }
    return 0;
  } catch (const Error& e) {
    std::cerr << "alvio_log_overhead: error: " << e.what() << "\n";
    return 2;
  }
}
