#include "alvio/lines/line_detector.h"

#include <algorithm>
#include <cmath>

#include "alvio/lines/edge_refinement.h"
#include "alvio/lines/linear_time_lsd.h"

namespace alvio {

LineDetector::LineDetector(const LineDetectorOptions& options, cv::Size image_size)
    : options_(options), last_quant_(options.lsd_quant) {
  options_.validate("line detector");
  min_length_ = options_.min_length_ratio * std::hypot(image_size.width, image_size.height);
  // OpenCV's LSD: its defaults apart from the scale, sigma, quant and refinement (angle
  // 22.5 deg, log_eps 0, density 0.7, 1024 bins); LinearTimeLsd has the same constants.
  if (options_.method == "fld")
    // Segments shorter than any we keep are not worth FLD's fitting; no merging (the tracker
    // merges split lines itself, as Type 3).
    fld_ = cv::ximgproc::createFastLineDetector(
        static_cast<int>(shortestLength() * options_.fld_scale), 1.41421356f, 50.0, 50.0, 3, false);
  else if (options_.method == "opencv_lsd")
    opencv_lsd_ = makeOpenCvLsd(options_.lsd_quant);
  else
    lsd_ = std::make_unique<LinearTimeLsd>(options_.lsd_scale, options_.lsd_sigma_scale,
                                           options_.lsd_quant, options_.lsd_pyramid_downscale);
}

namespace {
// A coordinate u_s of an image scaled by s, in pixel-centre convention, is u = (u_s + 0.5) / s
// - 0.5 in the full image: u_s / s plus this shift.
float scaleShift(double s) {
  return static_cast<float>(0.5 / s - 0.5);
}
void shift(std::vector<cv::Vec4f>* raw, float c) {
  for (cv::Vec4f& r : *raw) r += cv::Vec4f(c, c, c, c);
}
}  // namespace

cv::Ptr<cv::LineSegmentDetector> LineDetector::makeOpenCvLsd(double quant) const {
  return cv::createLineSegmentDetector(
      options_.lsd_refine ? cv::LSD_REFINE_STD : cv::LSD_REFINE_NONE, options_.lsd_scale,
      options_.lsd_sigma_scale, quant);
}

double LineDetector::quantFor(const cv::Mat& gray, const cv::Mat& valid_mask) const {
  // Gradients scale with the light: in a frame at a fraction of the reference brightness an
  // edge is that fraction as steep, so the threshold follows.
  const double mean = valid_mask.empty() ? cv::mean(gray)[0] : cv::mean(gray, valid_mask)[0];
  return options_.lsd_quant *
         std::clamp(mean / options_.lsd_reference_brightness, options_.lsd_min_quant_scale, 1.0);
}

std::vector<LineSegment> LineDetector::detect(const cv::Mat& gray, const cv::Mat& valid_mask) {
  std::vector<cv::Vec4f> raw;
  if (fld_ && options_.fld_scale < 1) {
    cv::resize(gray, scaled_, cv::Size(), options_.fld_scale, options_.fld_scale, cv::INTER_AREA);
    fld_->detect(scaled_, raw);
    const float k = static_cast<float>(1.0 / options_.fld_scale);
    for (cv::Vec4f& r : raw) r *= k;
    shift(&raw, scaleShift(options_.fld_scale));
  } else if (fld_) {
    fld_->detect(gray, raw);
  } else {
    // Both LSDs return u_s / s for a scaled run: without the shift every segment sat 0.5 px up
    // and left of its edge at lsd_scale 0.5 (test_line_tracker).
    if (options_.lsd_reference_brightness > 0) {
      const double quant = quantFor(gray, valid_mask);
      if (lsd_)
        lsd_->setQuant(quant);
      else if (quant != last_quant_)  // OpenCV's LSD takes its quant only when it is made
        opencv_lsd_ = makeOpenCvLsd(quant);
      last_quant_ = quant;
    }
    if (lsd_)
      lsd_->detect(gray, &raw);
    else
      opencv_lsd_->detect(gray, raw);
    if (options_.lsd_scale < 1) shift(&raw, scaleShift(options_.lsd_scale));
  }

  // The mask is the undistorter's, the same every frame: prepare it once.
  if (valid_mask.data != source_mask_.data) {
    source_mask_ = valid_mask;
    eroded_mask_.release();
    if (!valid_mask.empty() &&
        cv::countNonZero(valid_mask) < static_cast<int>(valid_mask.total())) {
      const int k = 2 * options_.border_margin_px + 1;
      cv::erode(valid_mask, eroded_mask_, cv::getStructuringElement(cv::MORPH_RECT, {k, k}));
    }
  }
  const cv::Mat* mask = eroded_mask_.empty() ? nullptr : &eroded_mask_;
  auto inside = [&](const Eigen::Vector2d& p) {
    const int u = static_cast<int>(std::lround(p.x())), v = static_cast<int>(std::lround(p.y()));
    return u >= 0 && v >= 0 && u < mask->cols && v < mask->rows && mask->at<uint8_t>(v, u) != 0;
  };

  std::vector<LineSegment> segments;
  segments.reserve(raw.size());
  for (const cv::Vec4f& r : raw) {
    const LineSegment s({r[0], r[1]}, {r[2], r[3]});
    if (s.length() < shortestLength()) continue;
    if (mask && !(inside(s.start) && inside(s.end) && inside(s.midpoint()))) continue;
    segments.push_back(s);
  }
  std::sort(segments.begin(), segments.end(),
            [](const LineSegment& a, const LineSegment& b) { return a.length() > b.length(); });
  const double scale = fld_ ? options_.fld_scale : options_.lsd_scale;
  if (options_.refine_edges && scale < 1) {
    // A segment whose edge is not found again is dropped, not kept where the scaled image put
    // it: tracks mixing both positions fitted their lines worse (docs/benchmarks.md).
    std::size_t kept = 0;
    for (std::size_t i = 0; i < segments.size() && static_cast<int>(kept) < options_.max_detections;
         ++i)
      if (refineSegmentToEdge(gray, EdgeRefinementOptions(), &segments[i]))
        segments[kept++] = segments[i];
    segments.resize(kept);
  }
  if (static_cast<int>(segments.size()) > options_.max_detections)
    segments.resize(options_.max_detections);
  return segments;
}

}  // namespace alvio
