#pragma once
// Scenes described in YAML (config/scenes/*.yaml): materials with texture
// specs, lights, and objects. Primitive objects are `box` and `quad`; the
// composite ones (`room`, `pipe`, `frame`, `shelf`, `tray`) expand into boxes
// and quads, and any object can be `repeat`ed. Errors name the file and the
// object (objects[i]) and key at fault. See config/scenes/machine_hall.yaml.

#include <string>

#include "alvio/sim/procedural_trajectories.h"
#include "alvio/sim/scene.h"

namespace alvio::sim {

struct SceneFile {
  Scene scene;
  /// Where the built-in trajectories run in this scene (section `paths`).
  FigureEightOptions figure_eight;
  CorridorWalkOptions corridor;
};

/// Load and finalize a scene. `path` may also be a bare name ("corridor") of a
/// scene shipped in config/scenes/.
SceneFile loadSceneFile(const std::string& path);
/// Parse a scene held in memory (`name` stands for the file in messages).
SceneFile parseSceneText(const std::string& text, const std::string& name);

/// The file a scene name or path refers to (throws alvio::Error when absent).
std::string resolveScenePath(const std::string& name_or_path);
/// config/scenes/machine_hall.yaml, the built-in default.
std::string defaultScenePath();

}  // namespace alvio::sim
