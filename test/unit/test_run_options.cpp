// alvio run's command line: a bad option value stops the run before any input is read, with
// an error that names the option.
#include <gtest/gtest.h>

#include <string>

#include "test_support.h"

namespace {

struct Outcome {
  int rc = -1;
  std::string output;
};

Outcome runWith(const std::string& args) {
  Outcome o;
  o.rc = alvio::test::runCommand(std::string(ALVIO_BIN_DIR) + "/alvio_run --dataset /nowhere " +
                                     "--out " + alvio::test::scratchDir() + "/run " + args,
                                 &o.output);
  return o;
}

}  // namespace

TEST(RunOptions, OpenCvThreadsBelowOneIsRefusedByName) {
  for (const char* value : {"0", "-2"}) {
    const Outcome o = runWith(std::string("--opencv-threads ") + value);
    EXPECT_NE(o.rc, 0) << value;
    EXPECT_NE(o.output.find("--opencv-threads must be at least 1"), std::string::npos) << o.output;
  }
}

TEST(RunOptions, UnknownLineTrackerIsRefusedByName) {
  const Outcome o = runWith("--line-tracker lbd");
  EXPECT_NE(o.rc, 0);
  EXPECT_NE(o.output.find("--line-tracker must be flow or descriptor, got 'lbd'"),
            std::string::npos)
      << o.output;
}

TEST(RunOptions, OneOpenCvThreadStillReachesTheInput) {
  // The option is taken; the run then fails on the missing dataset, which it names.
  const Outcome o = runWith("--opencv-threads 1");
  EXPECT_NE(o.rc, 0);
  EXPECT_EQ(o.output.find("--opencv-threads"), std::string::npos) << o.output;
  EXPECT_NE(o.output.find("/nowhere"), std::string::npos) << o.output;
}

TEST(RunOptions, TheAllocatorInUseIsTheOneBuiltIn) {
  // Checked on a live allocation: a linker that dropped mimalloc would leave glibc's malloc.
  const Outcome o = runWith("--verbose");
#ifdef ALVIO_EXPECT_MIMALLOC
  EXPECT_NE(o.output.find("memory allocator: mimalloc"), std::string::npos) << o.output;
#else
  EXPECT_NE(o.output.find("memory allocator: glibc malloc"), std::string::npos) << o.output;
#endif
}
