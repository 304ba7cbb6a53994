#include "alvio/sim/euroc_sequences.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>

namespace alvio::sim {
namespace fs = std::filesystem;

std::string findSharedDataDir() {
  if (const char* env = std::getenv("ALVIO_SHARED_DATA"))
    return fs::is_directory(env) ? std::string(env) : std::string();
  for (const fs::path& p : {fs::path(ALVIO_SOURCE_DIR) / ".." / "shared" / "data",
                            fs::current_path() / ".." / "shared" / "data"})
    if (fs::is_directory(p)) return fs::canonical(p).string();
  return "";
}

std::optional<EurocSequenceFiles> findEurocSequence(const std::string& name) {
  static const char* kFull[] = {"MH_01_easy",      "MH_02_easy",      "MH_03_medium",
                                "MH_04_difficult", "MH_05_difficult", "V1_01_easy",
                                "V1_02_medium",    "V1_03_difficult", "V2_01_easy",
                                "V2_02_medium",    "V2_03_difficult"};
  std::string key = name;
  std::transform(key.begin(), key.end(), key.begin(),
                 [](unsigned char c) { return std::toupper(c); });
  key.erase(std::remove(key.begin(), key.end(), '_'), key.end());  // "MH05" or "MH05DIFFICULT"
  const std::string data = findSharedDataDir();
  if (data.empty()) return std::nullopt;
  for (const char* full : kFull) {
    std::string k = full;
    std::transform(k.begin(), k.end(), k.begin(), [](unsigned char c) { return std::toupper(c); });
    k.erase(std::remove(k.begin(), k.end(), '_'), k.end());
    const std::string short_key = k.substr(0, 4);  // "MH05"
    if (key != k && key != short_key) continue;
    EurocSequenceFiles f;
    f.name = full;
    f.ground_truth = data + "/euroc_groundtruth/xygxgn_VINS-Fusion/output/" + f.name + ".txt";
    if (!fs::exists(f.ground_truth)) return std::nullopt;
    auto existing = [](const std::string& p) { return fs::exists(p) ? p : std::string(); };
    f.ground_truth_csv = existing(data +
                                  "/euroc_groundtruth/vins_mono_benchmark_publisher/"
                                  "benchmark_publisher/config/" +
                                  f.name + "/data.csv");
    const std::string orb = data + "/euroc_imu_only_orbslam3_format/Examples/Monocular-Inertial/";
    f.cam_timestamps = existing(orb + "EuRoC_TimeStamps/" + short_key + ".txt");
    f.imu = existing(orb + "EuRoC_IMU/" + short_key + ".txt");
    return f;
  }
  return std::nullopt;
}

}  // namespace alvio::sim
