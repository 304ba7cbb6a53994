#include "alvio/sim/image_statistics.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace alvio::sim {

ImageStatistics measureImage(const cv::Mat1b& image) {
  ImageStatistics s;
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(image, corners, 150, 0.01, 30);
  s.corners = static_cast<int>(corners.size());
  cv::goodFeaturesToTrack(image, corners, 2000, 0.01, 30);
  s.corners_uncapped = static_cast<int>(corners.size());

  const double min_length = 0.06 * std::hypot(image.cols, image.rows);
  cv::Ptr<cv::LineSegmentDetector> lsd = cv::createLineSegmentDetector(cv::LSD_REFINE_STD);
  std::vector<cv::Vec4f> lines;
  lsd->detect(image, lines);
  s.segments = static_cast<int>(std::count_if(lines.begin(), lines.end(), [&](const cv::Vec4f& l) {
    return std::hypot(l[2] - l[0], l[3] - l[1]) >= min_length;
  }));

  cv::Scalar mean, stddev;
  cv::meanStdDev(image, mean, stddev);
  s.mean = mean[0];
  s.stddev = stddev[0];
  cv::Mat1f gx, gy, mag;
  cv::Sobel(image, gx, CV_32F, 1, 0);
  cv::Sobel(image, gy, CV_32F, 0, 1);
  cv::magnitude(gx, gy, mag);
  s.gradient = cv::mean(mag)[0];
  return s;
}

StatisticsSummary summarize(const std::vector<ImageStatistics>& stats) {
  StatisticsSummary r;
  r.images = static_cast<int>(stats.size());
  if (stats.empty()) return r;
  r.min_corners = r.max_corners = stats[0].corners;
  r.min_segments = r.max_segments = stats[0].segments;
  for (const auto& s : stats) {
    r.mean_corners += s.corners;
    r.mean_corners_uncapped += s.corners_uncapped;
    r.mean_segments += s.segments;
    r.mean_grey += s.mean;
    r.mean_stddev += s.stddev;
    r.mean_gradient += s.gradient;
    r.min_corners = std::min(r.min_corners, s.corners);
    r.max_corners = std::max(r.max_corners, s.corners);
    r.min_segments = std::min(r.min_segments, s.segments);
    r.max_segments = std::max(r.max_segments, s.segments);
  }
  const double n = static_cast<double>(stats.size());
  r.mean_corners /= n;
  r.mean_corners_uncapped /= n;
  r.mean_segments /= n;
  r.mean_grey /= n;
  r.mean_stddev /= n;
  r.mean_gradient /= n;
  return r;
}

std::string StatisticsSummary::format(const std::string& label) const {
  std::ostringstream os;
  os << std::fixed << std::setprecision(1) << label << ": " << images << " images, KLT corners "
     << mean_corners << " (" << min_corners << ".." << max_corners << "; uncapped "
     << mean_corners_uncapped << "), LSD segments " << mean_segments << " (" << min_segments << ".."
     << max_segments << "), grey " << mean_grey << " +- " << mean_stddev << ", gradient "
     << mean_gradient;
  return os.str();
}

}  // namespace alvio::sim
