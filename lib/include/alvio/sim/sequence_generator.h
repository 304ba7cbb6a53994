#pragma once
// A whole simulated sequence, written as an EuRoC ASL folder:
//   mav0/cam0/{data.csv, data/<ns>.png, sensor.yaml}, mav0/imu0/{data.csv, sensor.yaml},
//   mav0/state_groundtruth_estimate0/data.csv, plus groundtruth.tum, sim_info.yaml and
//   scene_edges.csv (the scene's true 3D edges, for line-tracker evaluation).
//
// Two IMU modes. Synthetic: the body trajectory is a spline fitted to the
// ground truth (or a built-in path); images, IMU and the written ground truth
// all come from that spline. Real: the images are rendered along the spline
// fitted to the real EuRoC ground truth, at the real cam0 time stamps, and are
// paired with the real EuRoC IMU; the written ground truth is then the real one.

#include <cstdint>
#include <string>

#include "alvio/config/config.h"
#include "alvio/sim/camera_simulator.h"
#include "alvio/sim/illumination.h"
#include "alvio/sim/pose_spline_fit.h"

namespace alvio::sim {

/// Bumped whenever the simulator's output for the same inputs changes, so that
/// cached benchmark sequences are rebuilt.
constexpr const char* kSimulatorVersion = "alvio-sim 4";

struct SequenceOptions {
  std::string scene;       ///< scene file or name; "" = the built-in machine hall
  std::string trajectory;  ///< GT file (TUM/EuRoC CSV), EuRoC name (MH_05), figure8, corridor
  std::string imu = "synthetic";  ///< synthetic | real (the EuRoC sequence's) | an imu0 data.csv
  std::string cam_timestamps;  ///< cam0 stamps [ns] file; "" = the EuRoC list if known, else 20 Hz
  double start_s = 0.0;        ///< skip this much of the trajectory
  double duration_s = 0.0;     ///< 0 = to its end (built-in paths: 30 s)
  /// Standstill prepended to a ground-truth trajectory that starts moving (synthetic
  /// IMU only), so that initialisation sees a rest phase as in the real sequences.
  /// < 0: automatic (2 s when the first second moves, else none).
  double still_s = -1.0;
  uint64_t seed = 1;
  std::string texture = "rich";  ///< rich | medium | poor | a density in [0, 1]
  IlluminationOptions illumination;
  CameraSimulationOptions camera;  ///< sensor, motion blur, anti-aliasing (threads: see below)
  int threads = 2;                 ///< frames rendered in parallel
  Config config;                   ///< camera and IMU calibration (EuRoC by default)
  SplineFitOptions fit;
  bool progress = true;
};

struct SequenceSummary {
  int frames = 0;
  int imu_samples = 0;
  double first_frame_s = 0, last_frame_s = 0;
  SplineFitReport fit;
  double render_seconds = 0;  ///< wall time of the frames (render + PNG)
  double total_seconds = 0;
  double exposure_dn = 0;
  std::string imu_mode;
  std::string summary() const;
};

/// Render and write the sequence into `out_dir` (created; an earlier simulator
/// output there is replaced, anything else is refused).
SequenceSummary generateSequence(const SequenceOptions& options, const std::string& out_dir);

/// A text that changes whenever the output would: every option, the simulator
/// version and the content of every input file. Its hash stamps cached sequences.
std::string describeSequenceInputs(const SequenceOptions& options);

/// 64-bit FNV-1a hash of a text, as 16 hex digits.
std::string hashText(const std::string& text);
/// hashText of a file's content: "-" for an empty path, "missing" for a file not readable.
std::string fileHash(const std::string& path);

}  // namespace alvio::sim
