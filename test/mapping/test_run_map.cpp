// alvio run writes the map files next to the trajectory, and alvio_map_info reads them
// (plumbing on the shared EuRoC slice, where the VIO does not initialise: an empty map).
#include <gtest/gtest.h>

#include <octomap/OcTree.h>
#include <cstdio>
#include <filesystem>

#include "alvio/mapping/map_files.h"
#include "test_support.h"

using namespace alvio;
namespace fs = std::filesystem;

using test::runCommand;

TEST(RunMap, OfflineRunnerWritesReadableMapFiles) {
  ALVIO_REQUIRE_SHARED_DATA(data);
  const std::string dataset = data + "/euroc_V1_01_easy_micro_kimera";
  if (!fs::exists(dataset + "/mav0")) GTEST_SKIP() << dataset << " missing";
  const std::string out = test::scratchDir() + "/run";
  std::string log;
  // Exit code 3: no poses (the slice is static); the files must be there all the same.
  const int rc =
      runCommand(std::string(ALVIO_BIN_DIR) + "/alvio_run --quiet --max-frames 30 --dataset '" +
                     dataset + "' --out '" + out + "'",
                 &log);
  ASSERT_TRUE(rc == 0 || rc == 3) << log;
  EXPECT_NE(log.find("map:"), std::string::npos) << log;
  for (const char* f : {kOctomapFileName, kLinesPlyFileName, kLinesCsvFileName, kSceneFileName})
    EXPECT_TRUE(fs::exists(fs::path(out) / f)) << f;
  octomap::OcTree tree(0.1);
  EXPECT_TRUE(tree.readBinary((fs::path(out) / kOctomapFileName).string()));
  EXPECT_TRUE(readLinesCsv((fs::path(out) / kLinesCsvFileName).string()).empty());

  std::string info;
  ASSERT_EQ(runCommand(std::string(ALVIO_BIN_DIR) + "/alvio_map_info '" + out + "'", &info), 0)
      << info;
  EXPECT_NE(info.find("lines: 0"), std::string::npos) << info;
  EXPECT_NE(info.find("voxels (0.050 m): 0 occupied"), std::string::npos) << info;
}
