#include "alvio/common/resource_path.h"

#include <cstdlib>
#include <filesystem>
#include <vector>

#include "alvio/common/error.h"

namespace alvio {

std::string findPackageFile(const std::string& relative) {
  namespace fs = std::filesystem;
  std::vector<fs::path> candidates;
  if (const char* env = std::getenv("ALVIO_ROOT")) candidates.push_back(fs::path(env) / relative);
  candidates.push_back(fs::path(ALVIO_SOURCE_DIR) / relative);
  // Installed catkin layout: tools and scripts in <prefix>/lib/alvio/, data in
  // <prefix>/share/alvio/.
  std::error_code ec;
  const fs::path exe_dir = fs::read_symlink("/proc/self/exe", ec).parent_path();
  if (!ec) {
    candidates.push_back(exe_dir.parent_path().parent_path() / "share" / "alvio" / relative);
    candidates.push_back(exe_dir / fs::path(relative).filename());
  }
  for (const auto& p : candidates)
    if (fs::exists(p)) return p.string();
  throw Error("cannot find package file '" + relative +
              "' (set ALVIO_ROOT to the alvio source folder)");
}

}  // namespace alvio
