// The tests' scratch folders: a passed test's goes when it ends, a failed test's stays and is
// named, and the program's shared folders go at exit, so that repeated test runs do not fill
// /tmp. The program runs itself as the child whose folders are checked: the ScratchProbe tests
// only do something there.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <string>

#include "test_support.h"

namespace fs = std::filesystem;

namespace alvio {
namespace {

constexpr const char* kProbeEnv = "ALVIO_SCRATCH_PROBE";

bool inProbe() {
  return std::getenv(kProbeEnv) != nullptr;
}

void writeMarker(const std::string& dir, const std::string& label) {
  std::ofstream(fs::path(dir) / "marker.txt") << label << "\n";
  std::printf("probe %s: %s\n", label.c_str(), dir.c_str());
}

TEST(ScratchProbe, Passes) {
  if (!inProbe()) GTEST_SKIP() << "runs only as the child of the ScratchDir tests";
  writeMarker(test::scratchDir(), "passed");
  writeMarker(test::sharedScratchDir("probe_shared"), "shared");
}

TEST(ScratchProbe, Fails) {
  if (!inProbe()) GTEST_SKIP() << "runs only as the child of the ScratchDir tests";
  writeMarker(test::scratchDir(), "failed");
  ADD_FAILURE() << "this probe fails on purpose";
}

struct ProbeRun {
  int exit_code = 0;
  std::string output;
  std::map<std::string, std::string> dirs;  // label -> folder
};

ProbeRun runProbe(const std::string& filter, const std::string& extra_env = "") {
  ProbeRun run;
  run.exit_code = test::runCommand(std::string(kProbeEnv) + "=1 " + extra_env + " " +
                                       fs::read_symlink("/proc/self/exe").string() +
                                       " --gtest_filter='" + filter + "'",
                                   &run.output);
  static const std::regex kLine(R"(probe (\w+): (\S+))");
  for (std::sregex_iterator it(run.output.begin(), run.output.end(), kLine), end; it != end; ++it)
    run.dirs[(*it)[1]] = (*it)[2];
  return run;
}

TEST(ScratchDir, APassedTestsFolderGoesAndAFailedTestsStaysNamed) {
  const ProbeRun run = runProbe("ScratchProbe.*");
  ASSERT_EQ(run.exit_code, 1) << run.output;
  ASSERT_EQ(run.dirs.size(), 3u) << run.output;

  EXPECT_FALSE(fs::exists(run.dirs.at("passed"))) << run.output;
  EXPECT_FALSE(fs::exists(run.dirs.at("shared"))) << run.output;
  const fs::path failed = run.dirs.at("failed");
  EXPECT_TRUE(fs::exists(failed / "marker.txt")) << run.output;
  EXPECT_NE(run.output.find("scratch of the failed test kept: " + failed.string()),
            std::string::npos)
      << run.output;
  fs::remove_all(failed.parent_path());  // the child's root, kept because of its failure
}

TEST(ScratchDir, AllPassedLeavesNothingBehind) {
  const ProbeRun run = runProbe("ScratchProbe.Passes");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  ASSERT_EQ(run.dirs.count("passed"), 1u) << run.output;
  // Not even the child's own root folder.
  EXPECT_FALSE(fs::exists(fs::path(run.dirs.at("passed")).parent_path())) << run.output;
}

TEST(ScratchDir, KeepScratchKeepsAPassedTestsFolder) {
  const ProbeRun run = runProbe("ScratchProbe.Passes", "ALVIO_KEEP_SCRATCH=1");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  ASSERT_EQ(run.dirs.count("passed"), 1u) << run.output;
  const fs::path passed = run.dirs.at("passed");
  EXPECT_TRUE(fs::exists(passed / "marker.txt")) << run.output;
  EXPECT_TRUE(fs::exists(fs::path(run.dirs.at("shared")) / "marker.txt")) << run.output;
  fs::remove_all(passed.parent_path());
}

}  // namespace
}  // namespace alvio
