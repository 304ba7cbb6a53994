// Nothing is lost: SIGINT/SIGTERM stop alvio_run cleanly with every output written, and a
// SIGKILL during a save leaves the previous map and log files intact and loadable.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <mrpt/obs/CObservationIMU.h>
#include <mrpt/obs/CRawlog.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <octomap/OcTree.h>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "alvio/io/trajectory_io.h"
#include "alvio/mapping/map_files.h"
#include "test_support.h"

using namespace alvio;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

// alvio_run in the background, its stdout and stderr in files.
pid_t startRun(const std::vector<std::string>& args, const std::string& log_prefix) {
  const pid_t pid = fork();
  if (pid == 0) {
    std::freopen((log_prefix + ".out").c_str(), "w", stdout);
    std::freopen((log_prefix + ".err").c_str(), "w", stderr);
    std::vector<std::string> argv_s = {std::string(ALVIO_BIN_DIR) + "/alvio_run"};
    argv_s.insert(argv_s.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : argv_s) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  return pid;
}

// Wait until `ready()` or the process ends or `timeout` passes; true when ready.
template <typename F>
bool waitUntil(pid_t pid, F&& ready, double timeout_s, bool* exited, int poll_us = 2000) {
  const auto end = Clock::now() + std::chrono::duration<double>(timeout_s);
  while (Clock::now() < end) {
    if (ready()) return true;
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) {
      *exited = true;
      return false;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(poll_us));
  }
  return false;
}

int waitExitCode(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 1000 + WTERMSIG(status);
}

// Every map and log file in `out` loads with its own library; returns whether the rawlog
// did (into *rawlog), so a caller that reads it on can stop when it did not.
bool expectSavedFilesLoad(const std::string& out, mrpt::obs::CRawlog* rawlog) {
  EXPECT_NO_THROW(readOctomapBinary(out + "/octomap.bt"));
  EXPECT_NO_THROW(readLinesCsv(out + "/lines.csv"));
  for (const char* scene : {"map.3Dscene", "alvio.3Dscene"}) {
    mrpt::opengl::COpenGLScene s;
    EXPECT_TRUE(s.loadFromFile(out + "/" + scene)) << scene;
  }
  return rawlog->loadFromRawLogFile(out + "/alvio.rawlog");
}

std::string microDataset() {
  const std::string shared = test::sharedDataDir();
  const std::string data = shared + "/euroc_V1_01_easy_micro_kimera";
  return !shared.empty() && fs::exists(data + "/mav0") ? data : "";
}

// Every file a run writes, read back with the library that reads it.
void expectCompleteOutputs(const std::string& out) {
  for (const char* f : {"trajectory.tum", "timing.csv", "events.log", "frame_stats.csv",
                        "states.csv", "summary.json", "octomap.bt", "lines.csv", "lines.ply",
                        "map.3Dscene", "alvio.rawlog", "alvio.3Dscene", "alvio.log"})
    EXPECT_TRUE(fs::exists(fs::path(out) / f)) << f;
  const auto summary = nlohmann::json::parse(test::readFile(out + "/summary.json"));
  const std::size_t frames = summary["frames"];
  // What the map filter did with the line tracks, one count per reason.
  for (const char* k : {"lines_retired", "lines_held_back_fit", "lines_held_back_parallax",
                        "lines_held_back_edge", "lines_held_back_uncertain"})
    EXPECT_TRUE(summary.contains(k)) << k;
  // timing.csv: a header and a row per processed frame.
  const std::string timing = test::readFile(out + "/timing.csv");
  EXPECT_EQ(static_cast<std::size_t>(std::count(timing.begin(), timing.end(), '\n')), frames + 1);
  const std::string trajectory = test::readFile(out + "/trajectory.tum");
  EXPECT_EQ(trajectory.rfind("# timestamp", 0), 0u);
  // states.csv: velocity, biases and time shift, a header and a row per pose of the trajectory.
  const std::string states = test::readFile(out + "/states.csv");
  EXPECT_EQ(states.rfind("t,vx,vy,vz,bax,bay,baz,bgx,bgy,bgz,time_shift_s\n", 0), 0u);
  EXPECT_EQ(std::count(states.begin(), states.end(), '\n'),
            std::count(trajectory.begin(), trajectory.end(), '\n'));
  mrpt::obs::CRawlog rawlog;
  ASSERT_TRUE(expectSavedFilesLoad(out, &rawlog));
  std::size_t imu = 0;
  for (std::size_t i = 0; i < rawlog.size(); ++i)
    imu += rawlog.getType(i) == mrpt::obs::CRawlog::etObservation &&
           IS_CLASS(*rawlog.getAsObservation(i), mrpt::obs::CObservationIMU);
  // 200 Hz IMU, 20 Hz frames: the IMU up to the stop is in the rawlog, and no more.
  EXPECT_GE(imu, 8 * frames);
  EXPECT_LE(imu, 10 * frames + 20);
  EXPECT_NE(test::readFile(out + "/alvio.log").find("logger closed"), std::string::npos);
  for (const auto& e : fs::directory_iterator(out)) {
    const std::string ext = e.path().extension().string();
    EXPECT_TRUE(ext != ".tmp" && ext != ".part") << "left over: " << e.path();
  }
}

}  // namespace

// SIGINT (and SIGTERM) once a third of the frames are done: the run stops early and
// still writes the trajectory, timing, summary, maps and logs.
TEST(NothingLost, StopSignalMidRunWritesEverything) {
  const std::string data = microDataset();
  if (data.empty()) GTEST_SKIP() << "shared EuRoC data not found (../shared/data): skipping";
  for (const int signo : {SIGINT, SIGTERM}) {
    SCOPED_TRACE(signo == SIGINT ? "SIGINT" : "SIGTERM");
    const std::string dir = test::scratchDir() + "/" + std::to_string(signo);
    fs::create_directories(dir);
    const std::string out = dir + "/out";
    const pid_t pid = startRun({"--dataset", data, "--out", out}, dir + "/run");
    // The progress lines (stderr is not a terminal) say how far it got.
    bool exited = false;
    const bool third = waitUntil(
        pid, [&] { return test::readFile(dir + "/run.err").find(" 30% ") != std::string::npos; },
        300, &exited);
    ASSERT_TRUE(third) << "never reached 30 %: " << test::readFile(dir + "/run.err");
    kill(pid, signo);
    EXPECT_EQ(waitExitCode(pid), 128 + signo) << test::readFile(dir + "/run.err");
    EXPECT_NE(test::readFile(dir + "/run.out").find("interrupted by signal"), std::string::npos);
    const auto summary = nlohmann::json::parse(test::readFile(out + "/summary.json"));
    EXPECT_TRUE(summary["interrupted"].get<bool>());
    EXPECT_GE(summary["frames"].get<int>(), 28);
    EXPECT_LT(summary["frames"].get<int>(), 95) << "the signal did not stop the run early";
    expectCompleteOutputs(out);
  }
}

// A child overwriting a map file with a large new version is killed as soon as its save
// is under way (the .tmp exists): the file under the final name must still be the old
// one, byte for byte, or (had the rename already happened) a complete new one.
TEST(NothingLost, SigkillDuringSaveKeepsPreviousFile) {
  const std::string dir = test::scratchDir();
  struct Writer {
    std::string name;
    std::function<void(const std::string&, int)> save;  // version 0: small, 1: large
    std::function<void(const std::string&)> load;       // throws or fails the test
  };
  const std::vector<Writer> writers = {
      {"octomap.bt",
       [](const std::string& path, int version) {
         octomap::OcTree tree(0.01);
         const int n = version == 0 ? 10 : 110;
         for (int x = 0; x < n; ++x)
           for (int y = 0; y < n; ++y)
             for (int z = 0; z < n; ++z) tree.updateNode(x * 0.02, y * 0.02, z * 0.02, true);
         writeOctomapBinary(path, tree);
       },
       [](const std::string& path) { readOctomapBinary(path); }},
      {"map.3Dscene",
       [](const std::string& path, int version) {
         SceneContent c;
         for (int i = 0; i < (version == 0 ? 10 : 2000000); ++i)
           c.points.emplace_back(i * 1e-3, std::sin(i), std::cos(i));
         writeScene(path, c);
       },
       [](const std::string& path) {
         mrpt::opengl::COpenGLScene s;
         EXPECT_TRUE(s.loadFromFile(path)) << path;
       }},
      {"lines.csv",
       [](const std::string& path, int version) {
         std::vector<MapLine> lines(version == 0 ? 3 : 1000000);
         for (std::size_t i = 0; i < lines.size(); ++i) lines[i].id = static_cast<int>(i);
         writeFileAtomically(path, linesToCsv(lines));
       },
       [](const std::string& path) { readLinesCsv(path); }},
  };
  for (const Writer& w : writers) {
    SCOPED_TRACE(w.name);
    const std::string path = dir + "/" + w.name;
    int mid_save_kills = 0;
    for (int trial = 0; trial < 3; ++trial) {
      w.save(path, 0);
      const std::string before = test::readFile(path);
      const pid_t pid = fork();
      if (pid == 0) {
        w.save(path, 1);
        std::_Exit(0);
      }
      bool exited = false;
      // The octomap's write itself takes about a millisecond: poll fast.
      waitUntil(
          pid, [&] { return fs::exists(path + ".tmp"); }, 120, &exited, 50);
      if (!exited) {
        kill(pid, SIGKILL);
        waitExitCode(pid);
      }
      // Killed while writing: the old file is untouched.
      if (fs::exists(path + ".tmp")) {
        ++mid_save_kills;
        EXPECT_EQ(test::readFile(path), before) << "trial " << trial;
      }
      EXPECT_NO_THROW(w.load(path));
      fs::remove(path + ".tmp");
    }
    EXPECT_GT(mid_save_kills, 0) << "no kill landed during a save";
  }
}

// End to end: later runs into the folder of a first one are SIGKILLed mid-run, and as
// soon as they start replacing a map or scene file. The previous rawlog is untouched
// while the new one is still .part, and every map file loads. The saves take milliseconds: a run
// that ends before one is caught is checked all the same, and run again (up to 5 times).
TEST(NothingLost, SigkillDuringRunSaveKeepsPreviousMaps) {
  const std::string data = microDataset();
  if (data.empty()) GTEST_SKIP() << "shared EuRoC data not found (../shared/data): skipping";
  const std::string dir = test::scratchDir();
  const std::string out = dir + "/out";
  const pid_t first = startRun({"--dataset", data, "--out", out, "--max-frames", "15"}, dir + "/1");
  ASSERT_EQ(waitExitCode(first), 3) << test::readFile(dir + "/1.err");  // 3: no poses (static)
  const auto saving = [&] {
    for (const char* f : {"octomap.bt", "lines.csv", "lines.ply", "map.3Dscene", "alvio.3Dscene"})
      if (fs::exists(out + "/" + f + ".tmp")) return true;
    return false;
  };
  // Killed mid-run: the rawlog being streamed is the .part, the first run's is intact.
  {
    const std::string rawlog_before = test::readFile(out + "/alvio.rawlog");
    const pid_t run = startRun({"--dataset", data, "--out", out}, dir + "/mid");
    bool exited = false;
    ASSERT_TRUE(waitUntil(
        run, [&] { return test::readFile(dir + "/mid.err").find(" 30% ") != std::string::npos; },
        300, &exited));
    kill(run, SIGKILL);
    EXPECT_EQ(waitExitCode(run), 1000 + SIGKILL);
    EXPECT_TRUE(fs::exists(out + "/alvio.rawlog.part"));
    EXPECT_EQ(test::readFile(out + "/alvio.rawlog"), rawlog_before);
    mrpt::obs::CRawlog rawlog;
    EXPECT_TRUE(rawlog.loadFromRawLogFile(out + "/alvio.rawlog"));
  }
  bool killed_mid_save = false;
  for (int attempt = 0; attempt < 5 && !killed_mid_save; ++attempt) {
    SCOPED_TRACE(attempt);
    const std::string rawlog_before = test::readFile(out + "/alvio.rawlog");
    ASSERT_FALSE(rawlog_before.empty());
    const pid_t run = startRun({"--dataset", data, "--out", out, "--max-frames", "30"}, dir + "/2");
    bool exited = false;
    killed_mid_save = waitUntil(run, saving, 300, &exited, 100);
    if (!exited) {
      kill(run, SIGKILL);
      waitExitCode(run);
    }
    // The logger finishes (renaming its rawlog) before the map is saved: either rawlog
    // is complete, and a leftover part means the old one is untouched.
    if (fs::exists(out + "/alvio.rawlog.part")) {
      EXPECT_EQ(test::readFile(out + "/alvio.rawlog"), rawlog_before);
    }
    mrpt::obs::CRawlog rawlog;
    EXPECT_TRUE(expectSavedFilesLoad(out, &rawlog));
  }
  EXPECT_TRUE(killed_mid_save) << "no run was caught during a save";
}
