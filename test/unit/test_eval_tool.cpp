// The `alvio_eval` program end to end: its last line, JSON and plots.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "alvio/io/trajectory_io.h"
#include "test_support.h"

using namespace alvio;

using test::runCommand;

TEST(EvalTool, PrintsMachineReadableLastLineAndWritesJsonAndPlots) {
  const std::string dir = test::scratchDir();
  Trajectory gt, est;
  for (int i = 0; i < 400; ++i) {
    StampedPose p;
    p.t = 10 + 0.05 * i;
    p.p = Eigen::Vector3d(std::cos(0.02 * i) * 3, std::sin(0.02 * i) * 3, 0.01 * i);
    gt.push_back(p);
    p.p.z() += (i % 2 ? 0.1 : -0.1);  // a known error of 0.1 m on every pose
    est.push_back(p);
  }
  writeTumTrajectory(dir + "/gt.tum", gt);
  writeTumTrajectory(dir + "/est.tum", est);
  std::string out;
  const std::string exe = std::string(ALVIO_BIN_DIR) + "/alvio_eval";
  ASSERT_EQ(runCommand(exe + " --gt " + dir + "/gt.tum --est " + dir + "/est.tum --json " + dir +
                           "/r.json --plot " + dir + "/plots",
                       &out),
            0)
      << out;
  const std::string last = out.substr(out.rfind("ATE_RMSE="));
  EXPECT_NEAR(std::stod(last.substr(9)), 0.1, 1e-3) << out;
  std::ifstream jf(dir + "/r.json");
  const auto j = nlohmann::json::parse(jf);
  EXPECT_NEAR(j["ate_translation_m"]["rmse"].get<double>(), 0.1, 1e-3);
  EXPECT_EQ(j["rpe"].size(), 5u);
  EXPECT_EQ(j["poses"]["matched"].get<int>(), 400);
  EXPECT_TRUE(std::filesystem::exists(dir + "/plots/trajectory_top.png"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/plots/ate_over_time.png"));

  // A second run with the same error: all of it shared, the last line still ATE_RMSE.
  ASSERT_EQ(runCommand(exe + " --gt " + dir + "/gt.tum --est " + dir + "/est.tum --against " + dir +
                           "/est.tum --json " + dir + "/s.json",
                       &out),
            0)
      << out;
  EXPECT_EQ(out.rfind("ATE_RMSE="), out.rfind('\n', out.size() - 2) + 1) << out;
  EXPECT_NE(out.find("100.0 % of the two runs' squared error"), std::string::npos) << out;
  std::ifstream sf(dir + "/s.json");
  const auto s = nlohmann::json::parse(sf);
  EXPECT_NEAR(s["shared_error"]["shared_fraction"].get<double>(), 1.0, 1e-9);
  EXPECT_EQ(s["shared_error"]["matched"].get<int>(), 400);
  EXPECT_NEAR(s["ate_translation_m"]["rmse"].get<double>(), 0.1, 1e-3);
}

TEST(EvalTool, BadInputGivesErrorAndNonZeroExit) {
  std::string out;
  const std::string exe = std::string(ALVIO_BIN_DIR) + "/alvio_eval";
  EXPECT_NE(runCommand(exe + " --gt /nonexistent.tum --est /nonexistent2.tum", &out), 0);
  EXPECT_NE(out.find("/nonexistent.tum"), std::string::npos) << out;
  EXPECT_NE(runCommand(exe + " --gt a --est b --align bogus", &out), 0);
  EXPECT_NE(out.find("bogus"), std::string::npos) << out;
  EXPECT_NE(runCommand(exe + " --est b", &out), 0);
  EXPECT_NE(out.find("--gt"), std::string::npos) << out;
  const std::string dir = test::scratchDir();
  Trajectory gt;
  for (int i = 0; i < 50; ++i) {
    StampedPose p;
    p.t = 10 + 0.05 * i;
    p.p = Eigen::Vector3d(std::cos(0.1 * i), std::sin(0.1 * i), 0.02 * i);
    gt.push_back(p);
  }
  writeTumTrajectory(dir + "/gt.tum", gt);
  EXPECT_NE(runCommand(exe + " --gt " + dir + "/gt.tum --est " + dir + "/gt.tum --against " + dir +
                           "/missing.tum",
                       &out),
            0);
  EXPECT_NE(out.find("missing.tum"), std::string::npos) << out;
}
