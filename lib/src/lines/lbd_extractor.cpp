#include "alvio/lines/lbd_extractor.h"

#include <cmath>

namespace alvio {

LbdExtractor::LbdExtractor()
    : descriptor_(cv::line_descriptor::BinaryDescriptor::createBinaryDescriptor()) {}

cv::Mat LbdExtractor::compute(const cv::Mat& gray, const std::vector<LineSegment>& segments) const {
  if (segments.empty()) return cv::Mat();  // BinaryDescriptor prints an error on no lines
  std::vector<cv::line_descriptor::KeyLine> keylines(segments.size());
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const LineSegment& s = segments[i];
    cv::line_descriptor::KeyLine& kl = keylines[i];
    // BinaryDescriptor indexes its lines by class_id and reads the octave-0 coordinates.
    kl.class_id = static_cast<int>(i);
    kl.octave = 0;
    kl.startPointX = kl.sPointInOctaveX = static_cast<float>(s.start.x());
    kl.startPointY = kl.sPointInOctaveY = static_cast<float>(s.start.y());
    kl.endPointX = kl.ePointInOctaveX = static_cast<float>(s.end.x());
    kl.endPointY = kl.ePointInOctaveY = static_cast<float>(s.end.y());
    kl.lineLength = static_cast<float>(s.length());
    kl.numOfPixels = static_cast<int>(std::lround(s.length()));
    kl.angle = static_cast<float>(s.angle());
    kl.pt = cv::Point2f(static_cast<float>(s.midpoint().x()), static_cast<float>(s.midpoint().y()));
    kl.size = kl.lineLength;
    kl.response = 1.0f;
  }
  cv::Mat descriptors;
  descriptor_->compute(gray, keylines, descriptors);
  return descriptors;
}

}  // namespace alvio
