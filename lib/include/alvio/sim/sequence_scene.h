#pragma once
// The scene a rendered sequence was made from, for evaluations against its ground truth.
// sim_info.yaml names the scene file (`# scene: machine_hall.yaml <hash>` in its header);
// the scene is loaded from config/scenes/ and checked against the sequence's own
// scene_edges.csv, so that an edited scene file cannot silently score against a different
// world than the one rendered.

#include <string>

#include "alvio/sim/scene_file.h"

namespace alvio::sim {

/// The scene file named in `sim_info_path`; throws alvio::Error when it names none.
std::string sceneNameFromSimInfo(const std::string& sim_info_path);

/// The texture density the sequence was rendered with (`texture:` in sim_info.yaml's header,
/// as parseTextureDensity reads it); throws alvio::Error when the header has none.
double textureDensityFromSimInfo(const std::string& sim_info_path);

/// The IMU the sequence was rendered with (`imu:` in sim_info.yaml's header: synthetic, real,
/// or a data.csv path); throws alvio::Error when the header has none.
std::string imuModeFromSimInfo(const std::string& sim_info_path);

/// Throws alvio::Error unless the sequence in `sequence_dir` was rendered with the synthetic
/// IMU. With a real IMU, groundtruth.tum is the real EuRoC ground truth, not the spline the
/// images were rendered along (up to 1 degree apart): truth projected into the images from it
/// would be wrong.
void requireRenderedGroundTruth(const std::string& sequence_dir);

/// Load the scene of the sequence in `sequence_dir` (or `scene_override`, a name or path, when
/// not empty) and check that its edges are those of `sequence_dir`/scene_edges.csv (same IDs,
/// endpoints within 1e-5 m). Throws alvio::Error on any mismatch.
SceneFile loadSequenceScene(const std::string& sequence_dir,
                            const std::string& scene_override = "");

/// Rewrite `sequence_dir`/scene_edges.csv from its scene when the simulator now derives other
/// edges from it (the images do not depend on the edge list, only the truth does). Returns
/// whether the file changed. Throws alvio::Error when the scene file is not the one the
/// sequence was rendered from (its hash in sim_info.yaml differs).
bool refreshSceneEdges(const std::string& sequence_dir);

}  // namespace alvio::sim
