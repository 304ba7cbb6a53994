// The `alvio_point_truth` program end to end, on 8 s of a rendered figure eight: the tracked
// points against the scene, the estimator on their true positions (--oracle), and the files
// --out writes, the map included, which alvio_map_truth then scores.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>

#include "alvio/io/trajectory_io.h"
#include "test_support.h"

using namespace alvio;
namespace fs = std::filesystem;

namespace {

// Rendered once for all the tests here (about 8 s on two cores).
std::string sequence() {
  return test::renderedSequence("figure8", "--trajectory figure8 --duration 8");
}

struct TruthRun {
  std::string out_dir;  // --out, when given
  int rc = -1;
  std::string output;
  double ate = -1, point_error_px = -1;
};

TruthRun runPointTruth(const std::string& args,
                       const std::string& config = test::sourcePath("config/euroc.yaml")) {
  TruthRun r;
  r.rc = test::runCommand(
      test::tool("alvio_point_truth") + "--config " + config + " " + args + " " + sequence(),
      &r.output);
  std::smatch m;
  if (std::regex_search(r.output, m,
                        std::regex(R"(ATE ([0-9.]+) m; point error median ([0-9.]+) px)"))) {
    r.ate = std::stod(m[1]);
    r.point_error_px = std::stod(m[2]);
  }
  return r;
}

// The oracle, once, with its files written (the two tests below read it).
const TruthRun& oracleRun() {
  static const TruthRun r = [] {
    const std::string out = test::sharedScratchDir("oracle");
    TruthRun run = runPointTruth("--oracle --out " + out);
    run.out_dir = out;
    return run;
  }();
  return r;
}

}  // namespace

TEST(PointTruthTool, TheOracleFeedsTrueProjectionsWhoseNoiseTheEstimatorFeels) {
  const TruthRun tracked = runPointTruth("");
  const TruthRun& oracle = oracleRun();
  // 3 px of noise shrinks the aligned scale so much that the initialisation would wait for the
  // motion to change (estimator.init_min_scale_motion_m) past the 8 s: this compares the
  // estimates, so that wait is off.
  const std::string no_wait = test::writeFile(test::scratchDir() + "/no_scale_motion_wait.yaml",
                                              "base: " + test::sourcePath("config/euroc.yaml") +
                                                  "\nestimator:\n  init_min_scale_motion_m: 0\n");
  const TruthRun noisy = runPointTruth("--oracle --oracle-noise-px 3.0", no_wait);
  ASSERT_EQ(tracked.rc, 0) << tracked.output;
  ASSERT_EQ(oracle.rc, 0) << oracle.output;
  ASSERT_EQ(noisy.rc, 0) << noisy.output;
  ASSERT_GT(tracked.ate, 0) << tracked.output;
  ASSERT_GT(oracle.ate, 0) << oracle.output;
  // Tracked points lie within a pixel of their true projection (0.15 px median). On 8 s the ATE
  // of one run depends on where the initialisation happens to fall: over seven renderings
  // (seeds 1-7) tracked points score 0.0033-0.0145 m and true projections 0.0025-0.0082 m, while
  // 1 px of noise on the true projections (0.0046-0.0128 m) beat either on some of them. 3 px of
  // noise costs more on every one (0.022-0.27 m), so that is what shows the noise is felt.
  EXPECT_LT(tracked.point_error_px, 1.0);
  EXPECT_LT(tracked.ate, 0.05);
  EXPECT_LT(oracle.ate, noisy.ate);
  EXPECT_LT(tracked.ate, noisy.ate);
  // Both score the same tracks: the error statistic is of the tracked positions either way.
  EXPECT_DOUBLE_EQ(oracle.point_error_px, tracked.point_error_px);
}

TEST(PointTruthTool, OutWritesTheTrajectoryTheErrorsAndAMapThatMapTruthScores) {
  const TruthRun& r = oracleRun();
  const std::string& out = r.out_dir;
  ASSERT_EQ(r.rc, 0) << r.output;
  for (const char* f : {"trajectory.tum", "point_errors.csv", "point_observations.csv",
                        "octomap.bt", "lines.csv", "lines.ply", "map.3Dscene"})
    EXPECT_TRUE(fs::exists(fs::path(out) / f)) << f;
  EXPECT_GT(readTrajectory(out + "/trajectory.tum").size(), 50u);

  std::string scored;
  ASSERT_EQ(test::runCommand(test::tool("alvio_map_truth") + out + " " + sequence(), &scored), 0)
      << scored;
  std::smatch m;
  ASSERT_TRUE(
      std::regex_search(scored, m, std::regex(R"(octomap: ([0-9]+) occupied voxels, ([0-9.]+) %)")))
      << scored;
  EXPECT_GT(std::stoi(m[1]), 10) << scored;
  EXPECT_GT(std::stod(m[2]), 90.0) << scored;
}

TEST(PointTruthTool, ASequenceWithoutRenderedTruthIsRefusedByName) {
  const std::string empty = test::scratchDir() + "/not_a_sequence";
  fs::create_directories(empty);
  std::string out;
  EXPECT_NE(test::runCommand(test::tool("alvio_point_truth") + empty, &out), 0);
  EXPECT_NE(out.find("not_a_sequence"), std::string::npos) << out;
}
