#include "alvio/sim/sequence_scene.h"

#include <filesystem>
#include <fstream>
#include <regex>

#include "alvio/common/error.h"
#include "alvio/sim/edge_projection.h"

namespace alvio::sim {

std::string sceneNameFromSimInfo(const std::string& sim_info_path) {
  std::ifstream in(sim_info_path);
  if (!in) throw Error("cannot open " + sim_info_path);
  const std::regex scene_line(R"(^#\s+scene:\s+(\S+))");
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (std::regex_search(line, m, scene_line)) return m[1];
  }
  throw Error(sim_info_path + ": no '# scene:' line (not written by the alvio simulator?)");
}

SceneFile loadSequenceScene(const std::string& sequence_dir, const std::string& scene_override) {
  const std::filesystem::path dir(sequence_dir);
  const std::string name = scene_override.empty()
                               ? sceneNameFromSimInfo((dir / "sim_info.yaml").string())
                               : scene_override;
  SceneFile file = loadSceneFile(name);
  const std::string csv = (dir / "scene_edges.csv").string();
  const std::vector<SceneEdge> recorded = readSceneEdgesCsv(csv);
  const std::vector<SceneEdge>& edges = file.scene.edges();
  if (recorded.size() != edges.size())
    throw Error("scene '" + name + "' has " + std::to_string(edges.size()) + " edges but " + csv +
                " " + std::to_string(recorded.size()) +
                ": not the scene the sequence was rendered in");
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const bool same = recorded[i].id == edges[i].id && (recorded[i].a - edges[i].a).norm() < 1e-5 &&
                      (recorded[i].b - edges[i].b).norm() < 1e-5;
    if (!same)
      throw Error("scene '" + name + "' edge " + std::to_string(edges[i].id) + " differs from " +
                  csv + ": not the scene the sequence was rendered in");
  }
  return file;
}

}  // namespace alvio::sim
