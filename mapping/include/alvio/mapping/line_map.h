#pragma once
// The line map: 3D line segments accumulated in the world frame.
//
// - A segment reported again under the same landmark ID replaces that landmark's
//   estimate (latest wins); its extent is the union of the old extent (projected onto
//   the new line) and the new one, as long as the old estimate lies on the new line
//   within the merge distance (otherwise the old extent is dropped as stale).
// - Segments of different IDs that are collinear (angle and perpendicular distance
//   within tolerance) and overlapping are merged into one map line. A map line is the
//   length- and observation-weighted total-least-squares fit of its members' segments,
//   its extent the union of their projections; its observation count is their sum.
//   A short segment's direction is only known to about (2 x merge distance) / length:
//   for it the angle test allows that much, and lying inside the merge-distance tube
//   around the longer line decides.
// - A uniform hash grid over the segments finds merge candidates, so adding a segment
//   costs about the number of lines near it, not the size of the map.
// - Nothing is deleted while mapping: lines seen too rarely or looking like outliers
//   are left out when the map is read for saving (filteredLines()).

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "alvio/mapping/segment_geometry.h"

namespace alvio {

class YamlReader;

struct LineMapOptions {
  // Merging of different landmark IDs.
  double merge_angle_deg = 3.0;    ///< maximum angle between the two lines
  double merge_distance_m = 0.05;  ///< shorter segment's endpoints to the longer one's line
  double merge_min_overlap_m = 0;  ///< overlap of the extents along the longer line (>= 0)
  double index_cell_m = 0.5;       ///< cell size of the spatial hash grid
  /// A map line keeps at most this many member estimates; older ones are folded into
  /// one fixed member (their IDs are then forgotten), which bounds the memory of a
  /// line seen again and again.
  int max_members_per_line = 16;
  /// Lines still under min_observations that no keyframe has updated for this many
  /// keyframes are deleted while mapping (one-off outliers would otherwise pile up);
  /// 0 keeps them until saving.
  int prune_weak_after_keyframes = 30;
  // Filtering when the map is saved.
  int min_observations = 4;  ///< summed image observations of a kept line
  /// Landmark IDs (independent tracks) that a kept line must have merged. 2 keeps only lines
  /// that a second track, triangulated on its own, confirmed: on the simulator benchmark that
  /// raises precision from 56-67 % to 88-94 % but keeps only 11-26 % of the line length.
  int min_landmarks = 1;
  double min_length_m = 0.1;   ///< shorter lines are dropped
  double max_length_m = 30.0;  ///< longer lines are treated as triangulation outliers
  double max_depth_m = 20.0;   ///< lines never seen closer than this are outliers (<= 0: off)

  /// Read the keys under `prefix` ("mapping.lines"); throws alvio::Error naming the key.
  static LineMapOptions load(const YamlReader& yaml, const std::string& prefix);
};

/// One line of the map.
struct MapLine {
  int id = -1;  ///< the smallest landmark ID merged into it
  Eigen::Vector3d p0 = Eigen::Vector3d::Zero(), p1 = Eigen::Vector3d::Zero();
  int observations = 0;    ///< image observations, summed over its landmarks
  int landmarks = 0;       ///< landmark IDs merged into it
  double min_depth_m = 0;  ///< closest distance to a camera that reported it
  /// 1-sigma uncertainty of the midpoint across the line [m] of its best-placed landmark, as
  /// the estimator computed it at retirement; negative when unknown.
  double midpoint_std_m = -1;
  double length() const { return (p1 - p0).norm(); }
  Segment3 segment() const { return {p0, p1}; }
};

/// "midpoint uncertainty (1 sigma): median 6.9 mm; 58 of 108 lines (167.2 m of 226.2) under
/// 1 cm", for map summaries; empty when no line's uncertainty is known.
std::string describeLineUncertainty(const std::vector<MapLine>& lines);

class LineMap {
 public:
  explicit LineMap(const LineMapOptions& options = LineMapOptions());

  /// Add or update landmark `id` with the segment [p0_w, p1_w] supported by `observations`
  /// image observations (cumulative for the ID), reported by a camera at `camera_w`, with
  /// the landmark's midpoint uncertainty (negative: unknown). Degenerate or non-finite
  /// segments are ignored (returns false).
  bool addSegment(int id, const Eigen::Vector3d& p0_w, const Eigen::Vector3d& p1_w,
                  int observations, const Eigen::Vector3d& camera_w, double midpoint_std_m = -1);
  /// Start a new keyframe (the clock of prune_weak_after_keyframes); prunes stale weak
  /// lines every few keyframes. Returns the number of lines deleted.
  std::size_t beginKeyframe();

  /// Lines in the map (after merging), before filtering.
  std::size_t size() const { return lines_.size(); }
  /// Landmark IDs whose latest estimate is remembered.
  std::size_t landmarkCount() const { return line_of_id_.size(); }
  /// How many times two lines were merged into one (a landmark merging back into its own
  /// line after an update does not count).
  std::size_t mergeCount() const { return merges_; }
  /// Weak lines deleted while mapping (prune_weak_after_keyframes).
  std::size_t prunedCount() const { return pruned_; }
  /// All lines, ordered by id.
  std::vector<MapLine> lines() const;
  /// The lines kept when saving: enough observations, plausible length and depth.
  std::vector<MapLine> filteredLines() const;
  /// The map line a landmark ID currently belongs to.
  std::optional<MapLine> lineOf(int landmark_id) const;
  /// Approximate heap memory of the map and its index (bytes).
  std::size_t memoryBytes() const;
  const LineMapOptions& options() const { return options_; }

 private:
  struct Member {
    int id = -1;  ///< -1: folded older members
    Eigen::Vector3d p0 = Eigen::Vector3d::Zero(), p1 = Eigen::Vector3d::Zero();
    int observations = 1;
    int landmarks = 1;
    double min_depth = 0;
    double midpoint_std_m = -1;
    uint64_t stamp = 0;  ///< update counter, for folding the oldest
  };
  struct Line {
    int id = -1;
    std::vector<Member> members;
    /// Fitted line: centroid and unit direction.
    Eigen::Vector3d c = Eigen::Vector3d::Zero(), u = Eigen::Vector3d::Zero();
    double t0 = 0, t1 = 0;  ///< extent along u from c
    int observations = 0, landmarks = 0;
    double min_depth = 0;
    double midpoint_std_m = -1;  ///< the smallest known of its members'
    int64_t last_keyframe = 0;   ///< keyframe of the last update
    std::vector<int64_t> cells;  ///< grid cells it is registered in
    Eigen::Vector3d p0() const { return c + t0 * u; }
    Eigen::Vector3d p1() const { return c + t1 * u; }
  };

  static void fit(Line* line);
  void foldOldMembers(Line* line);
  bool compatible(const Line& a, const Line& b) const;
  /// Merge `key` with every compatible neighbour; returns the surviving key. Merging into
  /// `home` (the line a re-reported landmark came from) is not counted as a merge.
  int mergeNeighbours(int key, int home = -1);
  void registerCells(int key);
  void unregisterCells(int key);
  int newLine(Member member);
  void removeMember(int id);
  int64_t cellKey(const Eigen::Vector3d& p) const;
  MapLine toMapLine(const Line& line) const;

  LineMapOptions options_;
  double cos_merge_angle_ = 1;
  std::unordered_map<int, Line> lines_;                 // by internal key
  std::unordered_map<int, int> line_of_id_;             // landmark id -> line key
  std::unordered_map<int64_t, std::vector<int>> grid_;  // cell -> line keys
  int next_key_ = 0;
  uint64_t stamp_ = 0;
  std::size_t merges_ = 0, pruned_ = 0;
  int64_t keyframe_ = 0;
};

}  // namespace alvio
