// Bad rosbags give a clear error naming the file or topic, never a crash: missing topics,
// a topic of the wrong type, a truncated bag and a bag with damaged bytes.
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>

#include "alvio/common/error.h"
#include "rosbag_source.h"
#include "test_support.h"

using namespace alvio;
using test::errorOf;
namespace fs = std::filesystem;

namespace {

// A valid bag of `frames` 64x48 mono8 images (20 Hz) and IMU at 200 Hz. `image_topic` may
// be written as CompressedImage to get the wrong type.
std::string writeBag(const std::string& path, int frames, bool with_imu = true,
                     bool compressed_images = false) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  const ros::Time t0(100, 0);
  for (int i = 0; i < frames * 10; ++i) {
    const ros::Time t = t0 + ros::Duration(i * 0.005);
    if (with_imu) {
      sensor_msgs::Imu imu;
      imu.header.stamp = t;
      imu.linear_acceleration.z = 9.81;
      bag.write("/imu0", t, imu);
    }
    if (i % 10 != 0) continue;
    if (compressed_images) {
      sensor_msgs::CompressedImage image;
      image.header.stamp = t;
      image.format = "png";
      bag.write("/cam0/image_raw", t, image);
    } else {
      sensor_msgs::Image image;
      image.header.stamp = t;
      image.width = 64;
      image.height = 48;
      image.step = 64;
      image.encoding = "mono8";
      image.data.assign(64 * 48, static_cast<uint8_t>(i));
      bag.write("/cam0/image_raw", t, image);
    }
  }
  bag.close();
  return path;
}

std::size_t readAll(RosbagSource& source) {
  SensorMessage m;
  std::size_t n = 0;
  while (source.next(&m)) {
    if (m.kind == SensorMessage::Kind::kImage) m.load_image();
    ++n;
  }
  return n;
}

#define EXPECT_MENTIONS(message, fragment) \
  EXPECT_NE((message).find(fragment), std::string::npos) << "'" << (message) << "'"

}  // namespace

TEST(BadRosbag, GoodBagReadsEveryMessage) {
  const std::string bag = writeBag(test::scratchDir() + "/good.bag", 5);
  RosbagSource source(bag, TopicOptions{});
  EXPECT_EQ(source.imageCount(), 5u);
  EXPECT_EQ(readAll(source), 55u);
  EXPECT_EQ(source.badMessages(), 0u);
}

TEST(BadRosbag, MissingTopicIsNamed) {
  const std::string bag = writeBag(test::scratchDir() + "/no_imu.bag", 3, false);
  const std::string msg = errorOf([&] { RosbagSource s(bag, TopicOptions{}); });
  EXPECT_MENTIONS(msg, bag);
  EXPECT_MENTIONS(msg, "no topic '/imu0'");
  EXPECT_MENTIONS(msg, "/cam0/image_raw");  // what it does have
}

TEST(BadRosbag, WrongTopicTypeIsNamed) {
  const std::string bag = writeBag(test::scratchDir() + "/compressed.bag", 3, true, true);
  const std::string msg = errorOf([&] { RosbagSource s(bag, TopicOptions{}); });
  EXPECT_MENTIONS(msg, "'/cam0/image_raw'");
  EXPECT_MENTIONS(msg, "sensor_msgs/CompressedImage");
}

TEST(BadRosbag, MissingFileIsNamed) {
  const std::string bag = test::scratchDir() + "/none.bag";
  EXPECT_MENTIONS(errorOf([&] { RosbagSource s(bag, TopicOptions{}); }), bag);
}

TEST(BadRosbag, TruncatedBagGivesAClearError) {
  const std::string dir = test::scratchDir();
  const std::string bag = writeBag(dir + "/full.bag", 20);
  const auto size = fs::file_size(bag);
  for (const double keep : {0.9, 0.5, 0.1, 0.0}) {
    SCOPED_TRACE(keep);
    const std::string cut = dir + "/cut.bag";
    fs::copy_file(bag, cut, fs::copy_options::overwrite_existing);
    fs::resize_file(cut, static_cast<std::uintmax_t>(size * keep));
    // The index is at the end: a cut bag is refused when opened.
    const std::string msg = errorOf([&] {
      RosbagSource s(cut, TopicOptions{});
      readAll(s);
    });
    EXPECT_MENTIONS(msg, cut);
  }
}

// Bytes overwritten in the middle (a bad sector): an error or skipped messages, no crash.
TEST(BadRosbag, DamagedBytesGiveAnErrorOrSkippedMessages) {
  const std::string dir = test::scratchDir();
  const std::string bag = writeBag(dir + "/full.bag", 20);
  const auto size = fs::file_size(bag);
  std::mt19937 rng(3);
  int errors = 0, completed = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const std::string bad = dir + "/bad.bag";
    fs::copy_file(bag, bad, fs::copy_options::overwrite_existing);
    {
      std::fstream f(bad, std::ios::in | std::ios::out | std::ios::binary);
      const auto at = std::uniform_int_distribution<std::uintmax_t>(0, size - 64)(rng);
      f.seekp(static_cast<std::streamoff>(at));
      for (int i = 0; i < 32; ++i) f.put(static_cast<char>(rng()));
    }
    try {
      RosbagSource s(bad, TopicOptions{});
      readAll(s);
      ++completed;
    } catch (const Error& e) {
      EXPECT_MENTIONS(std::string(e.what()), bad);
      ++errors;
    }
  }
  EXPECT_EQ(errors + completed, 30);
  std::cout << errors << " damaged bags refused with an error, " << completed
            << " read to the end\n";
}
