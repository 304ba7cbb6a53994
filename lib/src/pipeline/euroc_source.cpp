#include <opencv2/imgcodecs.hpp>

#include "alvio/io/euroc_dataset.h"
#include "alvio/pipeline/sensor_source.h"

namespace alvio {

EurocSource::EurocSource(const std::string& root) : root_(root) {
  EurocDataset ds(root, TimeOrderPolicy::kSortAndDedup);
  images_ = ds.images();
  imu_ = ds.imu();
  if (ds.groundTruth()) {
    Trajectory gt;
    for (const auto& s : *ds.groundTruth()) {
      StampedPose p;
      p.t = nsToSec(s.t_ns);
      p.p = s.p;
      p.q = s.q;
      gt.push_back(p);
    }
    ground_truth_ = std::move(gt);
  }
}

bool EurocSource::next(SensorMessage* m) {
  const bool have_image = next_image_ < images_.size();
  const bool have_imu = next_imu_ < imu_.size();
  if (!have_image && !have_imu) return false;
  // IMU first on equal stamps: the frame then sees the sample taken at its own time.
  if (have_imu && (!have_image || imu_[next_imu_].t_ns <= images_[next_image_].t_ns)) {
    m->kind = SensorMessage::Kind::kImu;
    m->imu = imu_[next_imu_++];
    m->t_ns = m->imu.t_ns;
    return true;
  }
  const ImageRecord record = images_[next_image_++];
  m->kind = SensorMessage::Kind::kImage;
  m->t_ns = record.t_ns;
  m->load_image = [record] { return cv::imread(record.path, cv::IMREAD_GRAYSCALE); };
  return true;
}

}  // namespace alvio
