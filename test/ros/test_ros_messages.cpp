// The nodelets' message plumbing without a ROS master: the shared tracked frame
// serialises exactly as the generated alvio/TrackedFrame (so other processes,
// rosbag and rostopic understand it), and the conversions keep every field.
#include <gtest/gtest.h>
#include <ros/serialization.h>

#include "conversions.h"
#include "shared_tracked_frame.h"

using namespace alvio_ros;
namespace ser = ros::serialization;

namespace {

alvio::FeatureFrame sampleFrame() {
  alvio::FeatureFrame f;
  f.t_ns = 1600000001234567891;
  for (int i = 0; i < 3; ++i) {
    alvio::PointObservation p;
    p.id = 10 + i;
    p.px = {100.25 + i, 200.5};
    p.xy = {-0.125 * i, 0.0625};
    p.velocity = {0.01, -0.02 * i};
    p.track_count = i + 1;
    f.points.push_back(p);
  }
  alvio::LineObservation l;
  l.id = 7;
  l.start_px = {1, 2};
  l.end_px = {300, 400};
  l.start_norm = {-0.5, -0.25};
  l.end_norm = {0.25, 0.375};
  l.track_count = 4;
  l.edge_checked = true;
  l.on_edge = true;
  l.edge_start_norm = {-0.5, -0.25625};
  l.edge_end_norm = {0.25, 0.38125};
  f.lines.push_back(l);
  f.line_stats.detected = 40;
  f.line_stats.tracked = 30;
  f.line_stats.new_lines = 5;
  f.line_stats.merged = 2;
  f.line_stats.clipped = 1;
  f.mean_intensity = 97.5;
  return f;
}

template <typename M>
std::vector<uint8_t> serialize(const M& m) {
  std::vector<uint8_t> buffer(ser::serializationLength(m));
  ser::OStream out(buffer.data(), static_cast<uint32_t>(buffer.size()));
  ser::serialize(out, m);
  return buffer;
}

template <typename M>
M deserialize(std::vector<uint8_t>& buffer) {
  M m;
  ser::IStream in(buffer.data(), static_cast<uint32_t>(buffer.size()));
  ser::deserialize(in, m);
  return m;
}

SharedTrackedFrame sampleShared() {
  SharedTrackedFrame shared;
  std_msgs::Header header;
  header.stamp = toRosTime(sampleFrame().t_ns);
  header.frame_id = "cam0";
  alvio::FrameTiming timing;
  timing.add("point_tracking", 4.5);
  timing.add("line_detection", 6.25);
  toMsg(sampleFrame(), timing, header, &shared.features);
  auto image = boost::make_shared<sensor_msgs::Image>();
  image->header = header;
  image->width = 4;
  image->height = 2;
  image->step = 4;
  image->encoding = "mono8";
  image->data = {1, 2, 3, 4, 5, 6, 7, 8};
  shared.image = image;
  return shared;
}

}  // namespace

TEST(RosMessages, SharedTrackedFrameHasTheGeneratedMessagesIdentity) {
  namespace mt = ros::message_traits;
  EXPECT_STREQ(mt::md5sum<SharedTrackedFrame>(), mt::md5sum<alvio::TrackedFrame>());
  EXPECT_STREQ(mt::datatype<SharedTrackedFrame>(), "alvio/TrackedFrame");
  EXPECT_STREQ(mt::definition<SharedTrackedFrame>(), mt::definition<alvio::TrackedFrame>());
}

TEST(RosMessages, SharedTrackedFrameSerialisesAsTheGeneratedMessage) {
  const SharedTrackedFrame shared = sampleShared();
  alvio::TrackedFrame generated;
  generated.features = shared.features;
  generated.image = *shared.image;
  std::vector<uint8_t> a = serialize(shared), b = serialize(generated);
  EXPECT_EQ(a, b) << "same bytes on the wire";

  const auto back = deserialize<SharedTrackedFrame>(b);
  ASSERT_TRUE(back.image);
  EXPECT_NE(back.image.get(), shared.image.get()) << "a deserialised frame owns a new image";
  EXPECT_EQ(back.image->data, shared.image->data);
  EXPECT_EQ(back.features.points.size(), 3u);
  EXPECT_EQ(back.features.header.stamp, shared.features.header.stamp);

  SharedTrackedFrame empty;  // no image: serialised as an empty one
  std::vector<uint8_t> c = serialize(empty);
  EXPECT_EQ(deserialize<alvio::TrackedFrame>(c).image.data.size(), 0u);
}

TEST(RosMessages, FeatureFrameSurvivesTheMessage) {
  const alvio::FeatureFrame in = sampleFrame();
  const SharedTrackedFrame shared = sampleShared();
  const alvio::FeatureFrame out = fromMsg(shared.features);
  EXPECT_EQ(out.t_ns, in.t_ns);
  ASSERT_EQ(out.points.size(), in.points.size());
  for (std::size_t i = 0; i < in.points.size(); ++i) {
    EXPECT_EQ(out.points[i].id, in.points[i].id);
    EXPECT_EQ(out.points[i].px, in.points[i].px);
    EXPECT_EQ(out.points[i].xy, in.points[i].xy);
    EXPECT_EQ(out.points[i].velocity, in.points[i].velocity);
    EXPECT_EQ(out.points[i].track_count, in.points[i].track_count);
  }
  ASSERT_EQ(out.lines.size(), 1u);
  EXPECT_EQ(out.lines[0].id, 7);
  EXPECT_EQ(out.lines[0].start_px, in.lines[0].start_px);
  EXPECT_EQ(out.lines[0].end_px, in.lines[0].end_px);
  EXPECT_EQ(out.lines[0].start_norm, in.lines[0].start_norm);
  EXPECT_EQ(out.lines[0].end_norm, in.lines[0].end_norm);
  EXPECT_EQ(out.lines[0].track_count, 4);
  EXPECT_TRUE(out.lines[0].edge_checked);
  EXPECT_TRUE(out.lines[0].on_edge);
  EXPECT_EQ(out.lines[0].edge_start_norm, in.lines[0].edge_start_norm);
  EXPECT_EQ(out.lines[0].edge_end_norm, in.lines[0].edge_end_norm);
  EXPECT_EQ(out.line_stats.detected, 40);
  EXPECT_EQ(out.line_stats.merged, 2);
  EXPECT_EQ(out.mean_intensity, 97.5);
  EXPECT_DOUBLE_EQ(out.line_stats.detect_ms, 6.25);
  EXPECT_DOUBLE_EQ(shared.features.stats.total_ms, 10.75);
}

TEST(RosMessages, MapKeyframeCarriesLineUncertainty) {
  alvio::KeyframeLandmarks kf;
  kf.t = 1600000002.5;
  kf.T_w_c = Eigen::Translation3d(1, 2, 3) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ());
  kf.points = {{1, {1, 1, 1}}, {2, {2, 2, 2}}};
  kf.lines = {{5, {0, 0, 0}, {1, 0, 0}, 6, 0.5, 0.012},
              {6, {0, 0, 1}, {0, 1, 1}, 9, 3.0, 0.25},
              {7, {0, 0, 2}, {1, 1, 2}, 3, -1.0, -1.0}};
  std_msgs::Header header;
  header.stamp.fromSec(kf.t);
  alvio::MapKeyframe msg;
  toMsg(kf, alvio::MapKeyframe::RETIRED_LINES, header, &msg);
  const alvio::KeyframeLandmarks back = fromMsg(msg);
  EXPECT_NEAR(back.t, kf.t, 1e-6);
  EXPECT_TRUE(back.T_w_c.isApprox(kf.T_w_c, 1e-12));
  ASSERT_EQ(back.points.size(), 2u);
  EXPECT_EQ(back.points[1].p_w, Eigen::Vector3d(2, 2, 2));
  ASSERT_EQ(back.lines.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back.lines[i].id, kf.lines[i].id);
    EXPECT_EQ(back.lines[i].observations, kf.lines[i].observations);
    EXPECT_EQ(back.lines[i].p1_w, kf.lines[i].p1_w);
    EXPECT_EQ(back.lines[i].direction_std_deg, kf.lines[i].direction_std_deg);
    EXPECT_EQ(back.lines[i].midpoint_std_m, kf.lines[i].midpoint_std_m);
  }
}

TEST(RosMessages, CloudsAndLineListsRoundTrip) {
  const std::vector<Eigen::Vector3d> points = {{1, 2, 3}, {-4, 5.5, 6}};
  sensor_msgs::PointCloud2 cloud;
  toCloud(points, std_msgs::Header(), &cloud);
  EXPECT_EQ(cloud.width, 2u);
  const auto back = fromCloud(cloud);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_TRUE(back[1].isApprox(points[1]));
  const Segments segments = {{{0, 0, 0}, {1, 0, 0}}, {{0, 1, 0}, {0, 1, 1}}};
  const auto marker = lineListMarker(segments, std_msgs::Header(), "ns", 1, 0, 0, 0.02);
  EXPECT_EQ(marker.points.size(), 4u);
  EXPECT_EQ(fromLineList(marker), segments);
}
