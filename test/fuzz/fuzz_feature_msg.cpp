// libFuzzer target: the feature messages between the nodelets. The input drives the
// content of a TrackedFeatures or MapKeyframe message (any counts, ids, NaN/Inf values,
// stage strings), which is serialised and deserialised as ROS does between processes and
// decoded with the nodelets' fromMsg. The decoded frame must carry exactly what the
// message held. (Raw bytes are not fed to ROS's deserialiser: it resizes arrays to the
// declared length before checking the buffer, so that would only fuzz roscpp.)
#include <fuzzer/FuzzedDataProvider.h>
#include <ros/serialization.h>

#include <cstdlib>
#include <cstring>

#include "conversions.h"

namespace ser = ros::serialization;

namespace {

template <typename M>
M roundTrip(const M& msg) {
  const uint32_t length = ser::serializationLength(msg);
  std::vector<uint8_t> buffer(length);
  ser::OStream out(buffer.data(), length);
  ser::serialize(out, msg);
  M back;
  ser::IStream in(buffer.data(), length);
  ser::deserialize(in, back);
  return back;
}

// Bitwise equality, so that NaN payloads count as carried over.
bool same(double a, double b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

void check(bool ok) {
  if (!ok) std::abort();
}

void fuzzTrackedFeatures(FuzzedDataProvider& in) {
  alvio::TrackedFeatures msg;
  msg.header.stamp.sec = in.ConsumeIntegral<uint32_t>();
  msg.header.stamp.nsec = in.ConsumeIntegralInRange<uint32_t>(0, 999'999'999);
  msg.points.resize(in.ConsumeIntegralInRange<std::size_t>(0, 64));
  for (auto& p : msg.points) {
    p.id = in.ConsumeIntegral<int32_t>();
    for (double* v : {&p.px[0], &p.px[1], &p.xy[0], &p.xy[1], &p.velocity[0], &p.velocity[1]})
      *v = in.ConsumeFloatingPoint<double>();
    p.track_count = in.ConsumeIntegral<int32_t>();
  }
  msg.lines.resize(in.ConsumeIntegralInRange<std::size_t>(0, 32));
  for (auto& l : msg.lines) {
    l.id = in.ConsumeIntegral<int32_t>();
    for (auto* a : {&l.start_px, &l.end_px, &l.start_norm, &l.end_norm})
      for (double& v : *a) v = in.ConsumeFloatingPoint<double>();
    l.track_count = in.ConsumeIntegral<int32_t>();
  }
  auto& s = msg.stats;
  s.lines_detected = in.ConsumeIntegral<int32_t>();
  s.lines_tracked = in.ConsumeIntegral<int32_t>();
  s.mean_intensity = in.ConsumeFloatingPoint<double>();
  // Stage lists of different lengths, as a newer or older tracker might send.
  s.stages.resize(in.ConsumeIntegralInRange<std::size_t>(0, 6));
  for (auto& name : s.stages)
    name = in.ConsumeBool() ? (in.ConsumeBool() ? "line_detection" : "line_tracking")
                            : in.ConsumeRandomLengthString(24);
  s.stage_ms.resize(in.ConsumeIntegralInRange<std::size_t>(0, 6));
  for (double& v : s.stage_ms) v = in.ConsumeFloatingPoint<double>();

  const alvio::FeatureFrame f = alvio_ros::fromMsg(roundTrip(msg));
  check(f.t_ns == alvio_ros::toNs(msg.header.stamp));
  check(f.points.size() == msg.points.size() && f.lines.size() == msg.lines.size());
  for (std::size_t i = 0; i < f.points.size(); ++i) {
    const auto& m = msg.points[i];
    const auto& p = f.points[i];
    check(p.id == m.id && p.track_count == m.track_count);
    check(same(p.px.x(), m.px[0]) && same(p.px.y(), m.px[1]) && same(p.xy.x(), m.xy[0]) &&
          same(p.xy.y(), m.xy[1]) && same(p.velocity.y(), m.velocity[1]));
  }
  for (std::size_t i = 0; i < f.lines.size(); ++i) {
    const auto& m = msg.lines[i];
    const auto& l = f.lines[i];
    check(l.id == m.id && same(l.start_norm.x(), m.start_norm[0]) &&
          same(l.end_px.y(), m.end_px[1]));
  }
  check(f.line_stats.detected == s.lines_detected && same(f.mean_intensity, s.mean_intensity));
}

void fuzzMapKeyframe(FuzzedDataProvider& in) {
  alvio::MapKeyframe msg;
  msg.header.stamp.sec = in.ConsumeIntegral<uint32_t>();
  msg.kind = in.ConsumeIntegral<uint8_t>();
  for (double* v :
       {&msg.camera_pose.position.x, &msg.camera_pose.position.y, &msg.camera_pose.position.z,
        &msg.camera_pose.orientation.x, &msg.camera_pose.orientation.y,
        &msg.camera_pose.orientation.z, &msg.camera_pose.orientation.w})
    *v = in.ConsumeFloatingPoint<double>();
  msg.points.resize(in.ConsumeIntegralInRange<std::size_t>(0, 64));
  for (auto& p : msg.points) {
    p.id = in.ConsumeIntegral<int32_t>();
    p.position.x = in.ConsumeFloatingPoint<double>();
    p.position.z = in.ConsumeFloatingPoint<double>();
  }
  msg.lines.resize(in.ConsumeIntegralInRange<std::size_t>(0, 32));
  for (auto& l : msg.lines) {
    l.id = in.ConsumeIntegral<int32_t>();
    l.start.y = in.ConsumeFloatingPoint<double>();
    l.end.x = in.ConsumeFloatingPoint<double>();
    l.observations = in.ConsumeIntegral<int32_t>();
    l.direction_std_deg = in.ConsumeFloatingPoint<double>();
    l.midpoint_std_m = in.ConsumeFloatingPoint<double>();
  }
  const alvio::KeyframeLandmarks kf = alvio_ros::fromMsg(roundTrip(msg));
  check(kf.points.size() == msg.points.size());
  check(kf.lines.size() == msg.lines.size());
  for (std::size_t i = 0; i < msg.lines.size(); ++i) {
    const auto& l = msg.lines[i];
    check(kf.lines[i].id == l.id && kf.lines[i].observations == l.observations &&
          same(kf.lines[i].p0_w.y(), l.start.y) &&
          same(kf.lines[i].direction_std_deg, l.direction_std_deg) &&
          same(kf.lines[i].midpoint_std_m, l.midpoint_std_m));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  if (in.ConsumeBool())
    fuzzTrackedFeatures(in);
  else
    fuzzMapKeyframe(in);
  return 0;
}
