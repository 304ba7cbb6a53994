// alvio_image_stats: KLT-corner and LSD-segment counts (as a VIO front end sees
// them) and grey-level statistics over image folders, to compare rendered
// sequences with real EuRoC images.
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>

#include "alvio/common/arg_parser.h"
#include "alvio/common/error.h"
#include "alvio/sim/image_statistics.h"

using namespace alvio;
namespace fs = std::filesystem;

int main(int argc, char** argv) {
  ArgParser args("alvio_image_stats",
                 "Per-image KLT corners (goodFeaturesToTrack 150/0.01/30) and LSD segments\n"
                 "(>= 6% of the diagonal), averaged over each folder given (PNG/JPG, or an\n"
                 "EuRoC mav0 folder: its cam0/data is used).");
  args.option("every", "use every n-th image", "1");
  args.option("max", "at most this many images per folder", "1000000");
  try {
    if (!args.parse(argc, argv)) return 0;
    if (args.positional().empty()) throw Error("give one or more image folders");
    const int every = std::max(1, args.getInt("every"));
    const int max_images = std::max(1, args.getInt("max"));
    for (std::string dir : args.positional()) {
      for (const char* sub : {"/mav0/cam0/data", "/cam0/data"})
        if (fs::is_directory(dir + sub)) {
          dir += sub;
          break;
        }
      if (!fs::is_directory(dir)) throw Error("not a folder: " + dir);
      std::vector<std::string> files;
      for (const auto& e : fs::directory_iterator(dir)) {
        const std::string ext = e.path().extension().string();
        if (ext == ".png" || ext == ".jpg" || ext == ".jpeg") files.push_back(e.path().string());
      }
      std::sort(files.begin(), files.end());
      std::vector<sim::ImageStatistics> stats;
      for (std::size_t i = 0; i < files.size() && static_cast<int>(stats.size()) < max_images;
           i += every) {
        const cv::Mat1b img = cv::imread(files[i], cv::IMREAD_GRAYSCALE);
        if (img.empty()) throw Error("cannot read image " + files[i]);
        stats.push_back(sim::measureImage(img));
      }
      std::cout << sim::summarize(stats).format(dir) << "\n";
    }
    return 0;
  } catch (const Error& e) {
    std::cerr << "alvio_image_stats: error: " << e.what() << "\n";
    return 2;
  }
}
