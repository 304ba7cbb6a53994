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

std::string scratchDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir = fs::temp_directory_path() / ("alvio_test_" + std::to_string(::getpid())) /
                       (std::string(info->test_suite_name()) + "." + info->name());
  // Emptied on the first call of each test only, so helpers can share it.
  static std::set<std::string> prepared;
  if (prepared.insert(dir.string()).second) fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
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
