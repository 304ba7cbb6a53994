#pragma once
// The C++ type the tracker publishes on ~frame: its features and the image they
// were tracked in, held as the shared pointer the tracker received. Within one
// nodelet manager roscpp hands the published pointer to every subscriber of this
// type, so the estimator, the logger and anyone else see the very same image
// (zero-copy). Across processes it is serialised exactly like the generated
// alvio/TrackedFrame message (same MD5 sum and definition), so `rostopic echo`,
// rosbag and subscribers of alvio::TrackedFrame in other processes work too.

#include <alvio/TrackedFeatures.h>
#include <alvio/TrackedFrame.h>
#include <ros/message_traits.h>
#include <ros/serialization.h>
#include <sensor_msgs/Image.h>

#include <boost/make_shared.hpp>
#include <boost/shared_ptr.hpp>

namespace alvio_ros {

struct SharedTrackedFrame {
  alvio::TrackedFeatures features;
  sensor_msgs::ImageConstPtr image;  ///< never modified once published

  using Ptr = boost::shared_ptr<SharedTrackedFrame>;
  using ConstPtr = boost::shared_ptr<const SharedTrackedFrame>;
};

}  // namespace alvio_ros

namespace ros {
namespace message_traits {

template <>
struct MD5Sum<alvio_ros::SharedTrackedFrame> {
  static const char* value() { return MD5Sum<alvio::TrackedFrame>::value(); }
  static const char* value(const alvio_ros::SharedTrackedFrame&) { return value(); }
};

template <>
struct DataType<alvio_ros::SharedTrackedFrame> {
  static const char* value() { return DataType<alvio::TrackedFrame>::value(); }
  static const char* value(const alvio_ros::SharedTrackedFrame&) { return value(); }
};

template <>
struct Definition<alvio_ros::SharedTrackedFrame> {
  static const char* value() { return Definition<alvio::TrackedFrame>::value(); }
  static const char* value(const alvio_ros::SharedTrackedFrame&) { return value(); }
};

}  // namespace message_traits

namespace serialization {

// Field order and encoding of alvio/TrackedFrame: features, then image.
template <>
struct Serializer<alvio_ros::SharedTrackedFrame> {
  template <typename Stream>
  static void write(Stream& stream, const alvio_ros::SharedTrackedFrame& m) {
    stream.next(m.features);
    if (m.image)
      stream.next(*m.image);
    else
      stream.next(sensor_msgs::Image());
  }

  template <typename Stream>
  static void read(Stream& stream, alvio_ros::SharedTrackedFrame& m) {
    stream.next(m.features);
    auto image = boost::make_shared<sensor_msgs::Image>();
    stream.next(*image);
    m.image = image;
  }

  static uint32_t serializedLength(const alvio_ros::SharedTrackedFrame& m) {
    return serializationLength(m.features) +
           (m.image ? serializationLength(*m.image) : serializationLength(sensor_msgs::Image()));
  }
};

}  // namespace serialization
}  // namespace ros
