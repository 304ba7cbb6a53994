#include "alvio/sim/benchmark_set.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "alvio/common/error.h"
#include "alvio/common/logging.h"
#include "alvio/io/trajectory_io.h"
#include "alvio/sim/sequence_scene.h"

namespace alvio::sim {
namespace fs = std::filesystem;

namespace {
constexpr const char* kStampFile = "sim_stamp.txt";

std::string readFile(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
}  // namespace

std::vector<BenchmarkSequence> standardBenchmarkSet(const SequenceOptions& base) {
  std::vector<BenchmarkSequence> set;
  auto add = [&](const std::string& name, const std::string& description, auto&& change) {
    BenchmarkSequence s{name, description, base};
    change(s.options);
    set.push_back(s);
  };
  for (const char* seq : {"MH_01", "MH_02", "MH_03", "MH_05"})
    add(std::string("sim_") + seq, std::string(seq) + " trajectory, synthetic IMU",
        [&](SequenceOptions& o) {
          o.trajectory = seq;
          o.imu = "synthetic";
        });
  for (const char* seq : {"MH_03", "MH_05"})
    add(std::string("sim_") + seq + "_realimu",
        std::string(seq) + " trajectory, real EuRoC IMU and ground truth", [&](SequenceOptions& o) {
          o.trajectory = seq;
          o.imu = "real";
        });
  add("sim_MH_05_lowtex", "MH_05, poor texture (plain surfaces), synthetic IMU",
      [](SequenceOptions& o) {
        o.trajectory = "MH_05";
        o.texture = "poor";
      });
  add("sim_MH_05_dim", "MH_05, dim light (35 %) and the longer exposure it needs (motion blur)",
      [](SequenceOptions& o) {
        o.trajectory = "MH_05";
        o.illumination = parseIllumination("dim");
        o.camera.exposure_time_s = 0.008;
        o.camera.motion_blur_samples = 3;
      });
  // Where points are scarce and lines are not: plain walls, long straight edges, and a
  // turn on the spot in front of a wall at the far end.
  add("sim_corridor_lowtex", "corridor walk there and back (30 s), poor texture, synthetic IMU",
      [](SequenceOptions& o) {
        o.scene = "corridor";
        o.trajectory = "corridor";
        o.texture = "poor";
      });
  return set;
}

bool benchmarkSequenceIsCurrent(const std::string& dir, const BenchmarkSequence& s) {
  const fs::path folder = fs::path(dir) / s.name;
  if (!fs::exists(folder / kStampFile) || !fs::exists(folder / "mav0" / "cam0" / "data.csv"))
    return false;
  const std::string stamp = readFile(folder / kStampFile);
  return stamp.rfind(hashText(describeSequenceInputs(s.options)) + "\n", 0) == 0;
}

std::vector<BenchmarkBuildResult> buildBenchmark(const std::string& dir,
                                                 const SequenceOptions& base,
                                                 const std::vector<std::string>& only, bool force) {
  const std::vector<BenchmarkSequence> set = standardBenchmarkSet(base);
  for (const std::string& name : only) {
    bool known = false;
    for (const auto& s : set) known |= s.name == name;
    if (!known) {
      std::string names;
      for (const auto& s : set) names += (names.empty() ? "" : ", ") + s.name;
      throw Error("unknown benchmark sequence '" + name + "' (known: " + names + ")");
    }
  }
  std::vector<BenchmarkBuildResult> results;
  fs::create_directories(dir);
  for (const BenchmarkSequence& s : set) {
    if (!only.empty() && std::find(only.begin(), only.end(), s.name) == only.end()) continue;
    BenchmarkBuildResult r;
    r.name = s.name;
    if (!force && benchmarkSequenceIsCurrent(dir, s)) {
      if (refreshSceneEdges((fs::path(dir) / s.name).string()))
        logInfo(s.name, ": scene_edges.csv rewritten with this simulator's edge truth");
      logInfo(s.name, ": up to date, kept");
      results.push_back(r);
      continue;
    }
    logInfo(s.name, ": building (", s.description, ")");
    const fs::path folder = fs::path(dir) / s.name;
    // The stamp goes last: an interrupted build has none and is redone.
    fs::remove(folder / kStampFile);
    r.summary = generateSequence(s.options, folder.string());
    r.rebuilt = true;
    const std::string inputs = describeSequenceInputs(s.options);
    writeFileAtomically((folder / kStampFile).string(),
                        hashText(inputs) + "\n# " + s.description + "\n" + inputs);
    results.push_back(r);
  }
  return results;
}

}  // namespace alvio::sim
