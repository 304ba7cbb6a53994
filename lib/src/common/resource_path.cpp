#include "alvio/common/resource_path.h"

#include <cstdlib>
#include <filesystem>
#include <vector>

#include "alvio/common/error.h"

namespace alvio {

std::string findPackageFile(const std::string& relative, const std::string& executable) {
  namespace fs = std::filesystem;
  std::vector<fs::path> candidates;
  if (const char* env = std::getenv("ALVIO_ROOT")) candidates.push_back(fs::path(env) / relative);
  // Installed catkin layout: tools in <prefix>/lib/alvio/, data in <prefix>/share/alvio/. It
  // comes before the source tree, so an installed program reads the files installed with it
  // even while the checkout it was built from still exists (and may have changed). A devel
  // space's share/alvio holds no config, so programs there read the source tree.
  const fs::path exe_dir = fs::path(executable).parent_path();
  if (!executable.empty())
    candidates.push_back(exe_dir.parent_path().parent_path() / "share" / "alvio" / relative);
  candidates.push_back(fs::path(ALVIO_SOURCE_DIR) / relative);
  if (!executable.empty()) candidates.push_back(exe_dir / fs::path(relative).filename());
  for (const auto& p : candidates)
    if (fs::exists(p)) return p.string();
  throw Error("cannot find package file '" + relative +
              "' (set ALVIO_ROOT to the alvio source folder)");
}

std::string findPackageFile(const std::string& relative) {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return findPackageFile(relative, ec ? std::string() : exe.string());
}

}  // namespace alvio
