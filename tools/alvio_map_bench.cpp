// alvio_map_bench: the mapping module on a synthetic box room observed lap after lap
// (mapping/synthetic_room.h): line count, merges and memory per lap, time per keyframe,
// line map precision/recall and occupancy accuracy against the true room, file sizes.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>

#include "alvio/common/angles.h"
#include "alvio/common/arg_parser.h"
#include "alvio/common/error.h"
#include "alvio/mapping/map_builder.h"
#include "alvio/mapping/map_evaluation.h"
#include "alvio/mapping/map_files.h"
#include "alvio/mapping/synthetic_room.h"

using namespace alvio;
namespace fs = std::filesystem;

namespace {
// Peak resident memory of this process (kB), from /proc.
long peakRssKb() {
  std::ifstream in("/proc/self/status");
  std::string key;
  while (in >> key) {
    if (key == "VmHWM:") {
      long kb = 0;
      in >> kb;
      return kb;
    }
    in.ignore(1 << 20, '\n');
  }
  return -1;
}
}  // namespace

int main(int argc, char** argv) {
  ArgParser args("alvio_map_bench",
                 "Mapping on a synthetic box room seen repeatedly with noise and new IDs.");
  args.option("laps", "laps around the room", "8");
  args.option("keyframes-per-lap", "keyframes per lap", "60");
  args.option("noise", "endpoint and point noise (m, std per axis)", "0.01");
  args.option("seed", "random seed", "1");
  args.option("out", "write the map files here and report their sizes");
  args.flag("no-merge", "disable merging of different IDs (for comparison)");
  try {
    if (!args.parse(argc, argv)) return 0;
    SyntheticRoomOptions ro;
    ro.laps = args.getInt("laps");
    ro.keyframes_per_lap = args.getInt("keyframes-per-lap");
    ro.endpoint_noise_m = ro.point_noise_m = args.getDouble("noise");
    ro.seed = static_cast<unsigned>(args.getInt("seed"));
    const SyntheticRoom room = makeSyntheticRoom(ro);

    MappingOptions mo;
    if (args.isSet("no-merge")) {
      mo.lines.merge_angle_deg = 0;
      mo.lines.merge_distance_m = 0;
    }
    MapBuilder builder(mo);
    std::cout << "room " << room.size.transpose() << " m, " << room.edges.size() << " true edges, "
              << room.keyframes.size() << " keyframes\n";
    std::cout << " lap  segments  line_ids  lines  kept  merges  mem_lines_KiB  mem_octree_KiB"
                 "  ms/keyframe\n";
    std::size_t segments = 0;
    double total_ms = 0;
    for (int lap = 0; lap < ro.laps; ++lap) {
      const auto t0 = std::chrono::steady_clock::now();
      for (int k = 0; k < ro.keyframes_per_lap; ++k) {
        const auto& kf = room.keyframes[lap * ro.keyframes_per_lap + k];
        segments += kf.lines.size();
        builder.addKeyframe(kf);
        builder.addTrajectoryPose(room.trajectory[lap * ro.keyframes_per_lap + k]);
      }
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      total_ms += ms;
      const MapSummary s = builder.summary();
      int max_id = -1;
      for (int i = 0; i <= lap; ++i)
        for (int k = 0; k < ro.keyframes_per_lap; ++k)
          for (const auto& l : room.keyframes[i * ro.keyframes_per_lap + k].lines)
            max_id = std::max(max_id, l.id);
      std::cout << std::setw(4) << lap + 1 << std::setw(10) << segments << std::setw(10)
                << max_id + 1 << std::setw(7) << s.lines << std::setw(6) << s.lines_kept
                << std::setw(8) << s.merges << std::fixed << std::setprecision(1) << std::setw(15)
                << s.memory_lines / 1024.0 << std::setw(16) << s.memory_octree / 1024.0
                << std::setprecision(2) << std::setw(13) << ms / ro.keyframes_per_lap << "\n";
    }
    const MapSummary s = builder.summary();
    std::cout << s.toString();
    std::cout << "mean time per keyframe: " << std::setprecision(2)
              << total_ms / room.keyframes.size() << " ms\n";

    std::vector<Segment3> kept;
    for (const MapLine& l : builder.lineMap().filteredLines()) kept.push_back(l.segment());
    const LineMapEvaluation le = evaluateLineMap(kept, room.edges, 0.10, 3.0 * kDegToRad);
    std::cout << std::setprecision(1) << "line map (10 cm, 3 deg): precision " << 100 * le.precision
              << " % of " << le.map_length_m << " m, recall " << 100 * le.recall << " % of "
              << le.true_length_m << " m true edges\n";
    const double res = builder.occupancyMap().options().resolution;
    const OccupancyEvaluation oe = evaluateOccupancy(
        builder.occupancyMap().tree(),
        [&](const Eigen::Vector3d& p) { return room.surfaceDistance(p); }, 2 * res);
    std::cout << "occupancy: " << 100 * oe.fraction << " % of " << oe.occupied_voxels
              << " occupied voxels within 2 voxels of a wall (mean " << std::setprecision(3)
              << oe.mean_distance_m << " m)\n";
    if (args.isSet("out")) {
      const MapFilePaths paths = builder.save(args.get("out"));
      std::cout << "files:";
      for (const std::string& p : {paths.octomap, paths.lines_ply, paths.lines_csv, paths.scene})
        if (!p.empty())
          std::cout << " " << fs::path(p).filename().string() << " " << std::setprecision(1)
                    << fs::file_size(p) / 1024.0 << " KiB";
      std::cout << "\n";
    }
    std::cout << "peak RSS of the process: " << peakRssKb() / 1024.0 << " MiB\n";
    return 0;
  } catch (const Error& e) {
    std::cerr << "alvio_map_bench: error: " << e.what() << "\n";
    return 2;
  }
}
