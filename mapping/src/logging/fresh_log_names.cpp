#include "alvio/logging/fresh_log_names.h"

#include <filesystem>

namespace alvio {

LoggerOptions freshLogNames(LoggerOptions options, const std::string& dir) {
  namespace fs = std::filesystem;
  const fs::path folder(options.out_dir.empty() ? dir : options.out_dir);
  const std::string name = options.name;
  const fs::path text(options.text_file);
  for (int n = 1;; ++n) {
    // .rawlog.part: a rawlog still being written (another logger in the same folder).
    if (!fs::exists(folder / (options.name + ".rawlog")) &&
        !fs::exists(folder / (options.name + ".rawlog.part")) &&
        !fs::exists(folder / (options.name + ".3Dscene")) &&
        !fs::exists(folder / options.text_file))
      return options;
    const std::string suffix = "_" + std::to_string(n);
    options.name = name + suffix;
    options.text_file =
        (text.parent_path() / (text.stem().string() + suffix + text.extension().string())).string();
  }
}

}  // namespace alvio
