#include "conversions.h"

#include <sensor_msgs/point_cloud2_iterator.h>

namespace alvio_ros {

ros::Time toRosTime(int64_t t_ns) {
  ros::Time t;
  t.fromNSec(static_cast<uint64_t>(t_ns));
  return t;
}

alvio::ImuSample fromMsg(const sensor_msgs::Imu& msg) {
  alvio::ImuSample s;
  s.t_ns = toNs(msg.header.stamp);
  s.acc = {msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z};
  s.gyr = {msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z};
  return s;
}

namespace {
template <typename Array>
void set2(Array& a, const Eigen::Vector2d& v) {
  a[0] = v.x();
  a[1] = v.y();
}
template <typename Array>
Eigen::Vector2d get2(const Array& a) {
  return {a[0], a[1]};
}
}  // namespace

void toMsg(const alvio::FeatureFrame& frame, const alvio::FrameTiming& timing,
           const std_msgs::Header& header, alvio::TrackedFeatures* msg) {
  msg->header = header;
  msg->header.stamp = toRosTime(frame.t_ns);
  msg->points.resize(frame.points.size());
  for (std::size_t i = 0; i < frame.points.size(); ++i) {
    const auto& p = frame.points[i];
    auto& m = msg->points[i];
    m.id = p.id;
    set2(m.px, p.px);
    set2(m.xy, p.xy);
    set2(m.velocity, p.velocity);
    m.track_count = p.track_count;
  }
  msg->lines.resize(frame.lines.size());
  for (std::size_t i = 0; i < frame.lines.size(); ++i) {
    const auto& l = frame.lines[i];
    auto& m = msg->lines[i];
    m.id = l.id;
    set2(m.start_px, l.start_px);
    set2(m.end_px, l.end_px);
    set2(m.start_norm, l.start_norm);
    set2(m.end_norm, l.end_norm);
    m.track_count = l.track_count;
    m.edge_checked = l.edge_checked;
    m.on_edge = l.on_edge;
    set2(m.edge_start_norm, l.edge_start_norm);
    set2(m.edge_end_norm, l.edge_end_norm);
  }
  auto& s = msg->stats;
  s.points = static_cast<int32_t>(frame.points.size());
  s.lines = static_cast<int32_t>(frame.lines.size());
  s.lines_detected = frame.line_stats.detected;
  s.lines_tracked = frame.line_stats.tracked;
  s.lines_new = frame.line_stats.new_lines;
  s.lines_merged = frame.line_stats.merged;
  s.lines_clipped = frame.line_stats.clipped;
  s.mean_intensity = frame.mean_intensity;
  s.total_ms = timing.total();
  s.stages.clear();
  s.stage_ms.clear();
  for (const auto& [stage, ms] : timing.stages_ms) {
    s.stages.push_back(stage);
    s.stage_ms.push_back(ms);
  }
}

alvio::FeatureFrame fromMsg(const alvio::TrackedFeatures& msg) {
  alvio::FeatureFrame f;
  f.t_ns = toNs(msg.header.stamp);
  f.points.resize(msg.points.size());
  for (std::size_t i = 0; i < msg.points.size(); ++i) {
    const auto& m = msg.points[i];
    auto& p = f.points[i];
    p.id = m.id;
    p.px = get2(m.px);
    p.xy = get2(m.xy);
    p.velocity = get2(m.velocity);
    p.track_count = m.track_count;
  }
  f.lines.resize(msg.lines.size());
  for (std::size_t i = 0; i < msg.lines.size(); ++i) {
    const auto& m = msg.lines[i];
    auto& l = f.lines[i];
    l.id = m.id;
    l.start_px = get2(m.start_px);
    l.end_px = get2(m.end_px);
    l.start_norm = get2(m.start_norm);
    l.end_norm = get2(m.end_norm);
    l.track_count = m.track_count;
    l.edge_checked = m.edge_checked;
    l.on_edge = m.on_edge;
    l.edge_start_norm = get2(m.edge_start_norm);
    l.edge_end_norm = get2(m.edge_end_norm);
  }
  const auto& s = msg.stats;
  f.line_stats.detected = s.lines_detected;
  f.line_stats.tracked = s.lines_tracked;
  f.line_stats.new_lines = s.lines_new;
  f.line_stats.merged = s.lines_merged;
  f.line_stats.clipped = s.lines_clipped;
  // The line stage times travel as stages (undistortion counts as detection there).
  for (std::size_t i = 0; i < s.stages.size() && i < s.stage_ms.size(); ++i) {
    if (s.stages[i] == "line_detection") f.line_stats.detect_ms = s.stage_ms[i];
    if (s.stages[i] == "line_tracking") f.line_stats.track_ms = s.stage_ms[i];
  }
  f.mean_intensity = s.mean_intensity;
  return f;
}

geometry_msgs::Pose toPose(const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
  geometry_msgs::Pose pose;
  pose.position.x = p.x();
  pose.position.y = p.y();
  pose.position.z = p.z();
  const Eigen::Quaterniond n = q.normalized();
  pose.orientation.x = n.x();
  pose.orientation.y = n.y();
  pose.orientation.z = n.z();
  pose.orientation.w = n.w();
  return pose;
}

geometry_msgs::Pose toPose(const Eigen::Isometry3d& T) {
  return toPose(T.translation(), Eigen::Quaterniond(T.rotation()));
}

Eigen::Isometry3d fromPose(const geometry_msgs::Pose& pose) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(pose.orientation.w, pose.orientation.x, pose.orientation.y,
                                  pose.orientation.z)
                   .normalized()
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  return T;
}

namespace {
geometry_msgs::Point toPoint(const Eigen::Vector3d& p) {
  geometry_msgs::Point m;
  m.x = p.x();
  m.y = p.y();
  m.z = p.z();
  return m;
}
Eigen::Vector3d fromPoint(const geometry_msgs::Point& m) {
  return {m.x, m.y, m.z};
}
}  // namespace

void toMsg(const alvio::KeyframeLandmarks& keyframe, uint8_t kind, const std_msgs::Header& header,
           alvio::MapKeyframe* msg) {
  msg->header = header;
  msg->kind = kind;
  msg->camera_pose = toPose(keyframe.T_w_c);
  msg->points.resize(keyframe.points.size());
  for (std::size_t i = 0; i < keyframe.points.size(); ++i) {
    msg->points[i].id = keyframe.points[i].id;
    msg->points[i].position = toPoint(keyframe.points[i].p_w);
    msg->points[i].parallax_deg = keyframe.points[i].parallax_deg;
  }
  msg->lines.resize(keyframe.lines.size());
  for (std::size_t i = 0; i < keyframe.lines.size(); ++i) {
    const auto& l = keyframe.lines[i];
    auto& m = msg->lines[i];
    m.id = l.id;
    m.start = toPoint(l.p0_w);
    m.end = toPoint(l.p1_w);
    m.observations = l.observations;
    m.direction_std_deg = l.direction_std_deg;
    m.midpoint_std_m = l.midpoint_std_m;
  }
}

alvio::KeyframeLandmarks fromMsg(const alvio::MapKeyframe& msg) {
  alvio::KeyframeLandmarks kf;
  kf.t = msg.header.stamp.toSec();
  kf.T_w_c = fromPose(msg.camera_pose);
  for (const auto& p : msg.points)
    kf.points.push_back({p.id, fromPoint(p.position), p.parallax_deg});
  for (const auto& l : msg.lines)
    kf.lines.push_back({l.id, fromPoint(l.start), fromPoint(l.end), l.observations,
                        l.direction_std_deg, l.midpoint_std_m});
  return kf;
}

void toCloud(const std::vector<Eigen::Vector3d>& points, const std_msgs::Header& header,
             sensor_msgs::PointCloud2* cloud) {
  cloud->header = header;
  sensor_msgs::PointCloud2Modifier modifier(*cloud);
  modifier.setPointCloud2FieldsByString(1, "xyz");
  modifier.resize(points.size());
  cloud->height = 1;
  cloud->width = static_cast<uint32_t>(points.size());
  cloud->is_dense = true;
  sensor_msgs::PointCloud2Iterator<float> x(*cloud, "x"), y(*cloud, "y"), z(*cloud, "z");
  for (const auto& p : points) {
    *x = static_cast<float>(p.x());
    *y = static_cast<float>(p.y());
    *z = static_cast<float>(p.z());
    ++x;
    ++y;
    ++z;
  }
}

std::vector<Eigen::Vector3d> fromCloud(const sensor_msgs::PointCloud2& cloud) {
  std::vector<Eigen::Vector3d> out;
  if (cloud.width * cloud.height == 0) return out;
  sensor_msgs::PointCloud2ConstIterator<float> x(cloud, "x"), y(cloud, "y"), z(cloud, "z");
  for (; x != x.end(); ++x, ++y, ++z) out.emplace_back(*x, *y, *z);
  return out;
}

visualization_msgs::Marker lineListMarker(const Segments& segments, const std_msgs::Header& header,
                                          const std::string& ns, float r, float g, float b,
                                          double width_m) {
  visualization_msgs::Marker m;
  m.header = header;
  m.ns = ns;
  m.id = 0;
  m.type = visualization_msgs::Marker::LINE_LIST;
  m.action = visualization_msgs::Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.scale.x = width_m;
  m.color.r = r;
  m.color.g = g;
  m.color.b = b;
  m.color.a = 1.0f;
  m.points.reserve(2 * segments.size());
  for (const auto& [a, c] : segments) {
    m.points.push_back(toPoint(a));
    m.points.push_back(toPoint(c));
  }
  return m;
}

Segments fromLineList(const visualization_msgs::Marker& marker) {
  Segments out;
  for (std::size_t i = 0; i + 1 < marker.points.size(); i += 2)
    out.emplace_back(fromPoint(marker.points[i]), fromPoint(marker.points[i + 1]));
  return out;
}

}  // namespace alvio_ros
