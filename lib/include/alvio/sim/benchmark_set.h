#pragma once
// The standard simulated benchmark: the paper's EuRoC sequences rendered in the
// machine hall, with synthetic and with real IMU, plus low-texture and dim-light
// variants. Each sequence is cached in its folder with a stamp (hash of every
// input and option, and the simulator version) and rebuilt only when that changes.

#include <string>
#include <vector>

#include "alvio/sim/sequence_generator.h"

namespace alvio::sim {

struct BenchmarkSequence {
  std::string name;  ///< folder name, e.g. "sim_MH_05_dim"
  std::string description;
  SequenceOptions options;
};

/// sim_MH_01, sim_MH_02, sim_MH_03, sim_MH_05 (synthetic IMU), sim_MH_03_realimu,
/// sim_MH_05_realimu, sim_MH_05_lowtex, sim_MH_05_dim; built on `base` (scene,
/// seed, threads, calibration, progress).
std::vector<BenchmarkSequence> standardBenchmarkSet(const SequenceOptions& base);

struct BenchmarkBuildResult {
  std::string name;
  bool rebuilt = false;
  SequenceSummary summary;  ///< filled when rebuilt
};

/// Build the sequences named in `only` (all when empty) under `dir`; cached ones are
/// kept unless `force`. Throws alvio::Error on an unknown name.
std::vector<BenchmarkBuildResult> buildBenchmark(const std::string& dir,
                                                 const SequenceOptions& base,
                                                 const std::vector<std::string>& only = {},
                                                 bool force = false);

/// Whether `dir/name` holds a complete sequence built from exactly these inputs.
bool benchmarkSequenceIsCurrent(const std::string& dir, const BenchmarkSequence& sequence);

}  // namespace alvio::sim
