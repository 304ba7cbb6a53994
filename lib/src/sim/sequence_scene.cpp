#include "alvio/sim/sequence_scene.h"

#include <filesystem>
#include <fstream>
#include <regex>

#include "alvio/common/error.h"
#include "alvio/sim/edge_projection.h"
#include "alvio/sim/procedural_texture.h"
#include "alvio/sim/sequence_generator.h"

namespace alvio::sim {

namespace {
// The first capture of `pattern` in a header line of sim_info.yaml; `what` names it in errors.
std::string headerValue(const std::string& sim_info_path, const std::regex& pattern,
                        const std::string& what) {
  std::ifstream in(sim_info_path);
  if (!in) throw Error("cannot open " + sim_info_path);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] != '#') continue;
    std::smatch m;
    if (std::regex_search(line, m, pattern)) return m[1];
  }
  throw Error(sim_info_path + ": no " + what +
              " in its header (not written by the alvio simulator?)");
}
}  // namespace

std::string sceneNameFromSimInfo(const std::string& sim_info_path) {
  return headerValue(sim_info_path, std::regex(R"(^#\s+scene:\s+(\S+))"), "'# scene:' line");
}

double textureDensityFromSimInfo(const std::string& sim_info_path) {
  return parseTextureDensity(
      headerValue(sim_info_path, std::regex(R"(\stexture:\s+(\S+))"), "'texture:' value"));
}

std::string imuModeFromSimInfo(const std::string& sim_info_path) {
  return headerValue(sim_info_path, std::regex(R"(^#\s+imu:\s+(\S+))"), "'# imu:' line");
}

void requireRenderedGroundTruth(const std::string& sequence_dir) {
  const std::string info = (std::filesystem::path(sequence_dir) / "sim_info.yaml").string();
  const std::string imu = imuModeFromSimInfo(info);
  if (imu != "synthetic")
    throw Error(info + " says 'imu: " + imu +
                "': groundtruth.tum is then the real ground truth, not the trajectory the "
                "images were rendered along; use a sequence with the synthetic IMU");
}

namespace {
// Why `recorded` (read from `csv`) is not the edge list of `scene`, or "" when it is.
std::string edgeMismatch(const std::vector<SceneEdge>& recorded, const Scene& scene,
                         const std::string& name, const std::string& csv) {
  const std::vector<SceneEdge>& edges = scene.edges();
  if (recorded.size() != edges.size())
    return "scene '" + name + "' has " + std::to_string(edges.size()) + " edges but " + csv + " " +
           std::to_string(recorded.size());
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const bool same = recorded[i].id == edges[i].id && (recorded[i].a - edges[i].a).norm() < 1e-5 &&
                      (recorded[i].b - edges[i].b).norm() < 1e-5;
    if (!same)
      return "scene '" + name + "' edge " + std::to_string(edges[i].id) + " differs from " + csv;
  }
  return "";
}
}  // namespace

SceneFile loadSequenceScene(const std::string& sequence_dir, const std::string& scene_override) {
  const std::filesystem::path dir(sequence_dir);
  const std::string name = scene_override.empty()
                               ? sceneNameFromSimInfo((dir / "sim_info.yaml").string())
                               : scene_override;
  SceneFile file = loadSceneFile(name);
  const std::string csv = (dir / "scene_edges.csv").string();
  const std::string mismatch = edgeMismatch(readSceneEdgesCsv(csv), file.scene, name, csv);
  if (!mismatch.empty())
    throw Error(mismatch +
                ": not the scene the sequence was rendered in, or edges written by an older "
                "simulator (`alvio sim --benchmark DIR` refreshes a benchmark set's edges; "
                "otherwise render the sequence again)");
  return file;
}

bool refreshSceneEdges(const std::string& sequence_dir) {
  const std::filesystem::path dir(sequence_dir);
  const std::string info = (dir / "sim_info.yaml").string();
  const std::string name = sceneNameFromSimInfo(info);
  const std::string rendered_hash =
      headerValue(info, std::regex(R"(^#\s+scene:\s+\S+\s+(\S+))"), "'# scene:' hash");
  const std::string path = resolveScenePath(name);
  const std::string current_hash = fileHash(path);
  if (current_hash != rendered_hash)
    throw Error(info + " was rendered from another version of " + path + " (hash " + rendered_hash +
                ", now " + current_hash + "): render the sequence again");
  const SceneFile file = loadSceneFile(path);
  const std::string csv = (dir / "scene_edges.csv").string();
  if (std::filesystem::exists(csv) &&
      edgeMismatch(readSceneEdgesCsv(csv), file.scene, name, csv).empty())
    return false;
  writeSceneEdgesCsv(csv, file.scene);
  return true;
}

}  // namespace alvio::sim
