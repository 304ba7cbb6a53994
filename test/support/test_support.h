#pragma once
// Where tests find the project's shared EuRoC data (../shared/data next to the
// repository, or $ALVIO_SHARED_DATA). Tests that need it skip with a message
// when it is absent.

#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

namespace alvio::test {

/// The shared data folder, or "" when it does not exist.
std::string sharedDataDir();
/// The real EuRoC camera images in the shared data (V1_01, cam0), sorted by name; empty when
/// the shared data or that folder is missing.
std::vector<std::string> sharedEurocImages();
/// A scratch folder unique to the running test, emptied on its first use in the test. It is
/// removed when the test passes and kept (its path printed) when it fails; ALVIO_KEEP_SCRATCH=1
/// keeps them all.
std::string scratchDir();
/// A scratch folder named `name` shared by the tests of this program, emptied on its first
/// use and removed when the program exits.
std::string sharedScratchDir(const std::string& name);
/// The path of one of alvio's programs followed by a space, to start a command line.
std::string tool(const std::string& name);
/// A sequence rendered by alvio_sim with `sim_args` into the shared scratch folder `name`, once
/// per program: the first call renders (a failure is a test failure), later calls return it.
std::string renderedSequence(const std::string& name, const std::string& sim_args);
/// Path of a file inside the source tree.
std::string sourcePath(const std::string& relative);
/// The message of the alvio::Error that `f` throws ("" and a test failure when it throws none).
std::string errorOf(const std::function<void()>& f);
/// Run a shell command; its stdout and stderr together go to `out`. Returns the exit code,
/// or -1 when it could not run or did not exit normally.
int runCommand(const std::string& command, std::string* out);
/// A file's bytes ("" when it cannot be read).
std::string readFile(const std::string& path);
/// Write text to path (binary) and return the path.
std::string writeFile(const std::string& path, const std::string& text);

}  // namespace alvio::test

/// Skip the current test when the shared data is missing; sets `var` to its path.
#define ALVIO_REQUIRE_SHARED_DATA(var)                                \
  const std::string var = ::alvio::test::sharedDataDir();             \
  if (var.empty())                                                    \
    GTEST_SKIP() << "shared EuRoC data not found (../shared/data or " \
                    "$ALVIO_SHARED_DATA): skipping";
