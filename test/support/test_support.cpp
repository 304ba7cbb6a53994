#include "test_support.h"

#include <unistd.h>
#include <algorithm>
#include <cstdlib>

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>

#include "alvio/common/error.h"

namespace fs = std::filesystem;

namespace alvio::test {

std::string sharedDataDir() {
  if (const char* env = std::getenv("ALVIO_SHARED_DATA")) return fs::is_directory(env) ? env : "";
  const fs::path p = fs::path(ALVIO_SOURCE_DIR) / ".." / "shared" / "data";
  return fs::is_directory(p) ? fs::canonical(p).string() : "";
}

std::vector<std::string> sharedEurocImages() {
  std::vector<std::string> files;
  const std::string shared = sharedDataDir();
  if (shared.empty()) return files;
  const fs::path dir =
      fs::path(shared) / "euroc_V1_01_easy_micro_kimera" / "mav0" / "cam0" / "data";
  if (!fs::is_directory(dir)) return files;
  for (const auto& e : fs::directory_iterator(dir)) files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

namespace {

fs::path programScratchRoot() {
  return fs::temp_directory_path() / ("alvio_test_" + std::to_string(::getpid()));
}

fs::path testScratchPath(const ::testing::TestInfo& info) {
  return programScratchRoot() / (std::string(info.test_suite_name()) + "." + info.name());
}

bool keepAllScratch() {
  const char* keep = std::getenv("ALVIO_KEEP_SCRATCH");
  return keep && *keep && std::string(keep) != "0";
}

// A passed test's scratch goes when it ends, so that repeated runs do not fill /tmp; a failed
// test's stays, and is named, for a look at what it wrote.
class ScratchCleanup : public ::testing::EmptyTestEventListener {
  void OnTestEnd(const ::testing::TestInfo& info) override {
    const fs::path dir = testScratchPath(info);
    std::error_code ec;
    if (!fs::exists(dir, ec)) return;
    if (info.result()->Failed()) {
      std::printf("scratch of the failed test kept: %s\n", dir.c_str());
    } else if (!keepAllScratch()) {
      fs::remove_all(dir, ec);
    }
  }
};

// The program's shared scratch folders go at exit, and then its root if nothing is left in it.
std::set<std::string>& sharedScratchDirs() {
  static auto* dirs = new std::set<std::string>;  // never destroyed: read at exit
  return *dirs;
}

void removeProgramScratch() {
  std::error_code ec;
  if (!keepAllScratch())
    for (const auto& dir : sharedScratchDirs()) fs::remove_all(dir, ec);
  fs::remove(programScratchRoot(), ec);  // only when empty
}

void registerScratchCleanupOnce() {
  static const bool registered = [] {
    ::testing::UnitTest::GetInstance()->listeners().Append(new ScratchCleanup);
    std::atexit(removeProgramScratch);
    return true;
  }();
  (void)registered;
}

}  // namespace

std::string scratchDir() {
  registerScratchCleanupOnce();
  const fs::path dir = testScratchPath(*::testing::UnitTest::GetInstance()->current_test_info());
  // Emptied on the first call of each test only, so helpers can share it.
  static std::set<std::string> prepared;
  if (prepared.insert(dir.string()).second) fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

std::string sharedScratchDir(const std::string& name) {
  registerScratchCleanupOnce();
  const fs::path dir = programScratchRoot() / name;
  if (sharedScratchDirs().insert(dir.string()).second) fs::remove_all(dir);  // a reused pid's
  fs::create_directories(dir);
  return dir.string();
}

std::string tool(const std::string& name) {
  return std::string(ALVIO_BIN_DIR) + "/" + name + " ";
}

std::string renderedSequence(const std::string& name, const std::string& sim_args) {
  static std::set<std::string> rendered;
  const std::string dir = sharedScratchDir(name);
  if (!rendered.insert(name).second) return dir;
  std::string out;
  if (runCommand(tool("alvio_sim") + sim_args + " --quiet --out " + dir, &out) != 0)
    ADD_FAILURE() << "alvio_sim " << sim_args << " failed:\n" << out;
  return dir;
}

std::string sourcePath(const std::string& relative) {
  return (fs::path(ALVIO_SOURCE_DIR) / relative).string();
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected alvio::Error";
  return "";
}

int runCommand(const std::string& command, std::string* out) {
  out->clear();
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return -1;
  char buf[4096];
  while (fgets(buf, sizeof buf, pipe)) *out += buf;
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::string writeFile(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

}  // namespace alvio::test
