#include "alvio/mapping/map_builder.h"

#include <filesystem>
#include <iomanip>
#include <limits>
#include <sstream>

#include "alvio/common/error.h"
#include "alvio/common/logging.h"
#include "alvio/config/yaml_reader.h"
#include "alvio/io/trajectory_io.h"
#include "alvio/mapping/map_files.h"

namespace alvio {

MappingOptions MappingOptions::load(const YamlReader& yaml, const std::string& prefix) {
  MappingOptions o;
  o.enabled = yaml.getBool(prefix + ".enabled", o.enabled);
  o.write_scene = yaml.getBool(prefix + ".write_scene", o.write_scene);
  o.max_line_direction_std_deg =
      yaml.getDouble(prefix + ".max_line_direction_std_deg", o.max_line_direction_std_deg);
  o.min_point_parallax_deg =
      yaml.getDouble(prefix + ".min_point_parallax_deg", o.min_point_parallax_deg);
  if (!(o.min_point_parallax_deg >= 0 && o.min_point_parallax_deg < 90))
    throw Error(yaml.path() + ": " + prefix + ".min_point_parallax_deg must be in [0, 90)");
  o.lines = LineMapOptions::load(yaml, prefix + ".lines");
  o.octomap = OccupancyMapOptions::load(yaml, prefix + ".octomap");
  for (const std::string& key : yaml.unknownKeys())
    if (key.rfind(prefix + ".", 0) == 0) logWarn(yaml.path(), ": unknown key '", key, "' ignored");
  return o;
}

std::string MapSummary::toString() const {
  std::ostringstream os;
  os << std::fixed << std::setprecision(2);
  os << "keyframes: " << keyframes << ", poses: " << poses << ", points: " << points << "\n";
  os << "lines: " << lines_kept << " kept of " << lines << " (" << merges << " merges, "
     << line_landmarks << " landmark IDs), total length " << lines_kept_length_m << " m\n";
  os << "voxels (" << resolution << " m): " << voxels.occupied << " occupied, " << voxels.free
     << " free, " << voxels.leaf_nodes << " leaf nodes\n";
  if (has_extent)
    os << "extent: [" << extent_min.x() << ", " << extent_min.y() << ", " << extent_min.z()
       << "] .. [" << extent_max.x() << ", " << extent_max.y() << ", " << extent_max.z() << "] m\n";
  os << "memory: " << std::setprecision(1) << memoryTotal() / 1024.0 << " KiB (lines "
     << memory_lines / 1024.0 << ", octree " << memory_octree / 1024.0 << ", points "
     << memory_points / 1024.0 << ", trajectory " << memory_trajectory / 1024.0 << ")\n";
  return os.str();
}

MapBuilder::MapBuilder(const MappingOptions& options)
    : options_(options), lines_(options.lines), occupancy_(options.octomap) {}

void MapBuilder::addKeyframe(const KeyframeLandmarks& keyframe) {
  KeyframeLandmarks kept;  // what passes the filters below
  kept.t = keyframe.t;
  kept.T_w_c = keyframe.T_w_c;
  for (const LandmarkSegment& l : keyframe.lines)
    if (l.direction_std_deg >= 0 && l.direction_std_deg <= options_.max_line_direction_std_deg)
      kept.lines.push_back(l);
  // A report of retiring lines none of which is certain enough brings nothing.
  if (keyframe.points.empty() && kept.lines.empty()) return;
  ++keyframes_;
  lines_.beginKeyframe();
  const Eigen::Vector3d camera = keyframe.T_w_c.translation();
  for (const LandmarkPoint& p : keyframe.points) {
    if (!p.p_w.allFinite()) continue;
    if (p.parallax_deg >= 0 && p.parallax_deg < options_.min_point_parallax_deg) continue;
    points_[p.id] = p.p_w;
    kept.points.push_back(p);
  }
  for (const LandmarkSegment& l : kept.lines)
    lines_.addSegment(l.id, l.p0_w, l.p1_w, l.observations, camera, l.midpoint_std_m);
  occupancy_.insertKeyframe(kept);
}

void MapBuilder::addTrajectoryPose(const StampedPose& T_w_b) {
  trajectory_.push_back(T_w_b);
}

MapFilePaths MapBuilder::save(const std::string& dir) const {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error(dir + ": cannot create the map folder: " + ec.message());
  MapFilePaths paths;
  paths.octomap = (fs::path(dir) / kOctomapFileName).string();
  paths.lines_ply = (fs::path(dir) / kLinesPlyFileName).string();
  paths.lines_csv = (fs::path(dir) / kLinesCsvFileName).string();
  const std::vector<MapLine> kept = lines_.filteredLines();
  writeOctomapBinary(paths.octomap, occupancy_.tree());
  writeFileAtomically(paths.lines_ply, linesToPly(kept));
  writeFileAtomically(paths.lines_csv, linesToCsv(kept));
  if (options_.write_scene) {
    paths.scene = (fs::path(dir) / kSceneFileName).string();
    SceneContent content;
    content.trajectory = trajectory_;
    content.points.reserve(points_.size());
    for (const auto& [id, p] : points_) content.points.push_back(p);
    content.lines = kept;
    content.voxel_centres = occupiedVoxelCentres(occupancy_.tree());
    writeScene(paths.scene, content);
  }
  return paths;
}

MapSummary MapBuilder::summary() const {
  MapSummary s;
  s.keyframes = keyframes_;
  s.poses = trajectory_.size();
  s.points = points_.size();
  s.lines = lines_.size();
  s.line_landmarks = lines_.landmarkCount();
  s.merges = lines_.mergeCount();
  s.resolution = occupancy_.options().resolution;
  s.voxels = occupancy_.counts();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  if (!s.voxels.empty()) {
    lo = s.voxels.occupied_min;
    hi = s.voxels.occupied_max;
  }
  for (const MapLine& l : lines_.filteredLines()) {
    ++s.lines_kept;
    s.lines_kept_length_m += l.length();
    lo = lo.cwiseMin(l.p0).cwiseMin(l.p1);
    hi = hi.cwiseMax(l.p0).cwiseMax(l.p1);
  }
  s.has_extent = lo.allFinite() && hi.allFinite();
  if (s.has_extent) {
    s.extent_min = lo;
    s.extent_max = hi;
  }
  s.memory_lines = lines_.memoryBytes();
  s.memory_octree = occupancy_.memoryBytes();
  // std::map nodes: three pointers and a colour besides the value.
  s.memory_points = points_.size() * (sizeof(std::pair<const int, Eigen::Vector3d>) + 32);
  s.memory_trajectory = trajectory_.capacity() * sizeof(StampedPose);
  return s;
}

}  // namespace alvio
