#pragma once
// Numbers that say whether rendered images look like real ones to a VIO front
// end: KLT corners found as VINS-Mono finds them (goodFeaturesToTrack, 150
// corners, quality 0.01, 30 px apart), LSD segments longer than 6 % of the
// image diagonal, and grey-level statistics.

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace alvio::sim {

struct ImageStatistics {
  int corners = 0;           ///< as VINS-Mono: at most 150
  int corners_uncapped = 0;  ///< the same without the cap of 150 (how rich the image is)
  int segments = 0;
  double mean = 0.0;      ///< grey level
  double stddev = 0.0;    ///< grey-level contrast
  double gradient = 0.0;  ///< mean Sobel gradient magnitude (sharpness/texture)
};

ImageStatistics measureImage(const cv::Mat1b& image);

struct StatisticsSummary {
  int images = 0;
  double mean_corners = 0, mean_corners_uncapped = 0, mean_segments = 0, mean_grey = 0,
         mean_stddev = 0, mean_gradient = 0;
  int min_corners = 0, max_corners = 0, min_segments = 0, max_segments = 0;
  std::string format(const std::string& label) const;
};
StatisticsSummary summarize(const std::vector<ImageStatistics>& stats);

}  // namespace alvio::sim
