#include "alvio/mapping/line_map.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

#include "alvio/common/angles.h"
#include "alvio/common/error.h"
#include "alvio/config/yaml_reader.h"

namespace alvio {

LineMapOptions LineMapOptions::load(const YamlReader& yaml, const std::string& prefix) {
  LineMapOptions o;
  const std::string p = prefix + ".";
  o.merge_angle_deg = yaml.getDouble(p + "merge_angle_deg", o.merge_angle_deg);
  o.merge_distance_m = yaml.getDouble(p + "merge_distance_m", o.merge_distance_m);
  o.merge_min_overlap_m = yaml.getDouble(p + "merge_min_overlap_m", o.merge_min_overlap_m);
  o.index_cell_m = yaml.getDouble(p + "index_cell_m", o.index_cell_m);
  o.max_members_per_line = yaml.getInt(p + "max_members_per_line", o.max_members_per_line);
  o.prune_weak_after_keyframes =
      yaml.getInt(p + "prune_weak_after_keyframes", o.prune_weak_after_keyframes);
  o.min_observations = yaml.getInt(p + "min_observations", o.min_observations);
  o.min_landmarks = yaml.getInt(p + "min_landmarks", o.min_landmarks);
  o.min_length_m = yaml.getDouble(p + "min_length_m", o.min_length_m);
  o.max_length_m = yaml.getDouble(p + "max_length_m", o.max_length_m);
  o.max_depth_m = yaml.getDouble(p + "max_depth_m", o.max_depth_m);
  auto check = [&](bool ok, const std::string& key, const std::string& what) {
    if (!ok) throw Error(yaml.where(p + key) + " " + what);
  };
  check(o.merge_angle_deg >= 0 && o.merge_angle_deg < 90, "merge_angle_deg", "must be in [0, 90)");
  check(o.merge_distance_m >= 0, "merge_distance_m", "must be >= 0");
  check(o.merge_min_overlap_m >= 0, "merge_min_overlap_m", "must be >= 0");
  check(o.index_cell_m > 0, "index_cell_m", "must be > 0");
  check(o.max_members_per_line >= 2, "max_members_per_line", "must be at least 2");
  check(o.prune_weak_after_keyframes >= 0, "prune_weak_after_keyframes", "must be >= 0");
  check(o.min_landmarks >= 1, "min_landmarks", "must be at least 1");
  check(o.min_length_m >= 0, "min_length_m", "must be >= 0");
  check(o.max_length_m > o.min_length_m, "max_length_m", "must be greater than min_length_m");
  return o;
}

LineMap::LineMap(const LineMapOptions& options)
    : options_(options), cos_merge_angle_(std::cos(options.merge_angle_deg * kDegToRad)) {}

bool LineMap::addSegment(int id, const Eigen::Vector3d& p0_w, const Eigen::Vector3d& p1_w,
                         int observations, const Eigen::Vector3d& camera_w, double midpoint_std_m) {
  const double len = (p1_w - p0_w).norm();
  if (!p0_w.allFinite() || !p1_w.allFinite() || !(len > 1e-9)) return false;
  Member m;
  m.id = id;
  m.p0 = p0_w;
  m.p1 = p1_w;
  m.observations = std::max(1, observations);
  m.min_depth = camera_w.allFinite() ? pointSegmentDistance(camera_w, p0_w, p1_w)
                                     : std::numeric_limits<double>::infinity();
  m.midpoint_std_m = midpoint_std_m;
  m.stamp = ++stamp_;

  int key = -1, home = -1;
  auto known = line_of_id_.find(id);
  if (known != line_of_id_.end()) {
    Line& line = lines_.at(known->second);
    auto old = std::find_if(line.members.begin(), line.members.end(),
                            [&](const Member& x) { return x.id == id; });
    if (old != line.members.end()) {
      // Latest estimate wins; the extent grows by the old one when it still fits the line.
      const Eigen::Vector3d u = (p1_w - p0_w) / len;
      if (pointLineDistance(old->p0, p0_w, u) <= options_.merge_distance_m &&
          pointLineDistance(old->p1, p0_w, u) <= options_.merge_distance_m) {
        const double ta = (old->p0 - p0_w).dot(u), tb = (old->p1 - p0_w).dot(u);
        const double t0 = std::min({0.0, ta, tb}), t1 = std::max({len, ta, tb});
        m.p0 = p0_w + t0 * u;
        m.p1 = p0_w + t1 * u;
      }
      m.observations = std::max(m.observations, old->observations);
      m.min_depth = std::min(m.min_depth, old->min_depth);
      if (line.members.size() == 1) {
        // Update in place: the map line keeps its ID.
        key = known->second;
        unregisterCells(key);
        line.members.front() = m;
        fit(&line);
        registerCells(key);
      } else {
        home = known->second;
        unregisterCells(home);
        line.members.erase(old);
        fit(&line);
        registerCells(home);
      }
    }
  }
  if (key < 0) key = newLine(m);
  key = mergeNeighbours(key, home);
  Line& line = lines_.at(key);
  line.last_keyframe = keyframe_;
  if (static_cast<int>(line.members.size()) > options_.max_members_per_line) {
    unregisterCells(key);
    foldOldMembers(&line);
    registerCells(key);
  }
  return true;
}

std::size_t LineMap::beginKeyframe() {
  ++keyframe_;
  const int after = options_.prune_weak_after_keyframes;
  if (after <= 0 || keyframe_ % 10 != 0) return 0;
  std::vector<int> stale;
  for (const auto& [key, line] : lines_)
    if (line.observations < options_.min_observations && keyframe_ - line.last_keyframe > after)
      stale.push_back(key);
  for (int key : stale) {
    unregisterCells(key);
    for (const Member& m : lines_.at(key).members)
      if (m.id >= 0) line_of_id_.erase(m.id);
    lines_.erase(key);
  }
  pruned_ += stale.size();
  return stale.size();
}

int LineMap::newLine(Member member) {
  const int key = next_key_++;
  Line& line = lines_[key];
  line.id = key;
  line.last_keyframe = keyframe_;
  line.members.push_back(std::move(member));
  line_of_id_[line.members.front().id] = key;
  fit(&line);
  registerCells(key);
  return key;
}

void LineMap::fit(Line* line) {
  // Total least squares on the members seen as uniform mass along each segment, mass =
  // observations x length: centroid of the masses, direction = principal axis of
  // (segment spreads d d^T / 12 + spread of the midpoints).
  double mass = 0;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const Member& m : line->members) {
    const double w = m.observations * (m.p1 - m.p0).norm();
    c += w * 0.5 * (m.p0 + m.p1);
    mass += w;
  }
  c /= mass;
  Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
  for (const Member& m : line->members) {
    const double w = m.observations * (m.p1 - m.p0).norm();
    const Eigen::Vector3d d = m.p1 - m.p0, e = 0.5 * (m.p0 + m.p1) - c;
    S += w * (d * d.transpose() / 12.0 + e * e.transpose());
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(S);
  Eigen::Vector3d u = eig.eigenvectors().col(2).normalized();
  // Keep the orientation stable: along the previous fit, or the first member.
  const bool had_fit = line->u.allFinite() && line->u.squaredNorm() > 0.5;
  const Eigen::Vector3d ref =
      had_fit ? line->u : Eigen::Vector3d(line->members.front().p1 - line->members.front().p0);
  if (u.dot(ref) < 0) u = -u;
  double t0 = std::numeric_limits<double>::infinity(), t1 = -t0;
  line->observations = 0;
  line->landmarks = 0;
  line->min_depth = std::numeric_limits<double>::infinity();
  line->midpoint_std_m = -1;
  for (const Member& m : line->members) {
    for (const Eigen::Vector3d& p : {m.p0, m.p1}) {
      t0 = std::min(t0, (p - c).dot(u));
      t1 = std::max(t1, (p - c).dot(u));
    }
    line->observations += m.observations;
    line->landmarks += m.landmarks;
    line->min_depth = std::min(line->min_depth, m.min_depth);
    if (m.midpoint_std_m >= 0 &&
        (line->midpoint_std_m < 0 || m.midpoint_std_m < line->midpoint_std_m))
      line->midpoint_std_m = m.midpoint_std_m;
  }
  line->c = c;
  line->u = u;
  line->t0 = t0;
  line->t1 = t1;
}

void LineMap::foldOldMembers(Line* line) {
  // Fold the oldest members (all but the newest half of the budget) into one fixed member.
  auto& ms = line->members;
  std::sort(ms.begin(), ms.end(),
            [](const Member& a, const Member& b) { return a.stamp < b.stamp; });
  const std::size_t keep = static_cast<std::size_t>(options_.max_members_per_line / 2);
  const std::size_t n_fold = ms.size() - keep;
  Line old;
  old.members.assign(ms.begin(), ms.begin() + n_fold);
  old.u = line->u;
  fit(&old);
  Member folded;
  folded.id = -1;
  folded.p0 = old.p0();
  folded.p1 = old.p1();
  folded.observations = old.observations;
  folded.landmarks = old.landmarks;
  folded.min_depth = old.min_depth;
  folded.midpoint_std_m = old.midpoint_std_m;
  folded.stamp = old.members.back().stamp;
  for (const Member& m : old.members)
    if (m.id >= 0) line_of_id_.erase(m.id);
  ms.erase(ms.begin(), ms.begin() + n_fold);
  ms.insert(ms.begin(), folded);
  fit(line);
}

bool LineMap::compatible(const Line& a, const Line& b) const {
  const bool a_longer = a.t1 - a.t0 >= b.t1 - b.t0;
  const Line& lo = a_longer ? a : b;
  const Line& sh = a_longer ? b : a;
  // The shorter segment's direction is known to about (2 x merge distance) / length.
  const double short_len = sh.t1 - sh.t0;
  const double cos_tol =
      short_len > 0 ? std::min(cos_merge_angle_,
                               std::cos(std::atan2(2 * options_.merge_distance_m, short_len)))
                    : cos_merge_angle_;
  if (std::abs(a.u.dot(b.u)) < cos_tol) return false;
  const Eigen::Vector3d s0 = sh.p0(), s1 = sh.p1();
  if (pointLineDistance(s0, lo.c, lo.u) > options_.merge_distance_m ||
      pointLineDistance(s1, lo.c, lo.u) > options_.merge_distance_m)
    return false;
  const double ta = (s0 - lo.c).dot(lo.u), tb = (s1 - lo.c).dot(lo.u);
  const double overlap = std::min(std::max(ta, tb), lo.t1) - std::max(std::min(ta, tb), lo.t0);
  return overlap >= options_.merge_min_overlap_m;
}

int LineMap::mergeNeighbours(int key, int home) {
  for (;;) {
    const Line& line = lines_.at(key);
    if (line.t1 - line.t0 > options_.max_length_m) return key;  // outlier: not indexed
    std::vector<int> candidates;
    const double step = options_.index_cell_m / 4;
    for (const Eigen::Vector3d& p : sampleSegment(line.p0(), line.p1(), step)) {
      auto cell = grid_.find(cellKey(p));
      if (cell == grid_.end()) continue;
      for (int k : cell->second)
        if (k != key) candidates.push_back(k);
    }
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    int other = -1;
    for (int k : candidates)
      if (compatible(line, lines_.at(k))) {
        other = k;
        break;
      }
    if (other < 0) return key;
    // The older line survives, so map line IDs stay stable.
    const int keep = std::min(key, other), drop = std::max(key, other);
    if (other != home) ++merges_;
    home = -1;
    unregisterCells(keep);
    unregisterCells(drop);
    Line& kept = lines_.at(keep);
    Line& dropped = lines_.at(drop);
    for (Member& m : dropped.members) {
      if (m.id >= 0) line_of_id_[m.id] = keep;
      kept.members.push_back(std::move(m));
    }
    kept.last_keyframe = std::max(kept.last_keyframe, dropped.last_keyframe);
    lines_.erase(drop);
    fit(&kept);
    registerCells(keep);
    key = keep;
  }
}

int64_t LineMap::cellKey(const Eigen::Vector3d& p) const {
  auto idx = [&](double v) {
    const int64_t i = static_cast<int64_t>(std::floor(v / options_.index_cell_m));
    return static_cast<int64_t>(std::clamp<int64_t>(i + (1 << 20), 0, (1 << 21) - 1));
  };
  return (idx(p.x()) << 42) | (idx(p.y()) << 21) | idx(p.z());
}

void LineMap::registerCells(int key) {
  Line& line = lines_.at(key);
  line.cells.clear();
  if (line.t1 - line.t0 > options_.max_length_m) return;  // outlier: not indexed
  // Samples every cell/4 along the line, each widened by the merge distance plus half a
  // step, so that any line within merge distance has a sample in one of these cells.
  const double step = options_.index_cell_m / 4;
  const double r = options_.merge_distance_m + step;
  for (const Eigen::Vector3d& p : sampleSegment(line.p0(), line.p1(), step))
    for (double dx : {-r, r})
      for (double dy : {-r, r})
        for (double dz : {-r, r}) line.cells.push_back(cellKey(p + Eigen::Vector3d(dx, dy, dz)));
  // A box of half-size r < cell spans at most two cells per axis: its corners cover them
  // all. Wider boxes also need the cells in between.
  if (2 * r >= options_.index_cell_m) {
    const std::vector<Eigen::Vector3d> samples = sampleSegment(line.p0(), line.p1(), step);
    const double h = options_.index_cell_m / 2;
    for (const Eigen::Vector3d& p : samples)
      for (double dx = -r; dx <= r + 1e-12; dx += h)
        for (double dy = -r; dy <= r + 1e-12; dy += h)
          for (double dz = -r; dz <= r + 1e-12; dz += h)
            line.cells.push_back(cellKey(p + Eigen::Vector3d(dx, dy, dz)));
  }
  std::sort(line.cells.begin(), line.cells.end());
  line.cells.erase(std::unique(line.cells.begin(), line.cells.end()), line.cells.end());
  line.cells.shrink_to_fit();
  for (int64_t c : line.cells) grid_[c].push_back(key);
}

void LineMap::unregisterCells(int key) {
  Line& line = lines_.at(key);
  for (int64_t c : line.cells) {
    auto it = grid_.find(c);
    if (it == grid_.end()) continue;
    auto& keys = it->second;
    keys.erase(std::remove(keys.begin(), keys.end(), key), keys.end());
    if (keys.empty()) grid_.erase(it);
  }
  line.cells.clear();
}

MapLine LineMap::toMapLine(const Line& line) const {
  MapLine out;
  out.id = line.id;
  out.p0 = line.p0();
  out.p1 = line.p1();
  out.observations = line.observations;
  out.landmarks = line.landmarks;
  out.min_depth_m = line.min_depth;
  out.midpoint_std_m = line.midpoint_std_m;
  return out;
}

std::vector<MapLine> LineMap::lines() const {
  std::vector<MapLine> out;
  out.reserve(lines_.size());
  for (const auto& [key, line] : lines_) out.push_back(toMapLine(line));
  std::sort(out.begin(), out.end(), [](const MapLine& a, const MapLine& b) { return a.id < b.id; });
  return out;
}

std::vector<MapLine> LineMap::filteredLines() const {
  std::vector<MapLine> out;
  for (const MapLine& l : lines()) {
    const double len = l.length();
    if (l.observations < options_.min_observations || l.landmarks < options_.min_landmarks)
      continue;
    if (!(len >= options_.min_length_m) || len > options_.max_length_m) continue;
    if (options_.max_depth_m > 0 && l.min_depth_m > options_.max_depth_m) continue;
    out.push_back(l);
  }
  return out;
}

std::optional<MapLine> LineMap::lineOf(int landmark_id) const {
  auto it = line_of_id_.find(landmark_id);
  if (it == line_of_id_.end()) return std::nullopt;
  return toMapLine(lines_.at(it->second));
}

std::size_t LineMap::memoryBytes() const {
  // Hash-map nodes carry a next pointer and a cached hash besides the value.
  constexpr std::size_t kNode = 2 * sizeof(void*);
  std::size_t bytes = 0;
  for (const auto& [key, line] : lines_)
    bytes += sizeof(std::pair<const int, Line>) + kNode + line.members.capacity() * sizeof(Member) +
             line.cells.capacity() * sizeof(int64_t);
  bytes += lines_.bucket_count() * sizeof(void*);
  bytes += line_of_id_.size() * (sizeof(std::pair<const int, int>) + kNode) +
           line_of_id_.bucket_count() * sizeof(void*);
  for (const auto& [cell, keys] : grid_)
    bytes +=
        sizeof(std::pair<const int64_t, std::vector<int>>) + kNode + keys.capacity() * sizeof(int);
  bytes += grid_.bucket_count() * sizeof(void*);
  return bytes;
}

std::string describeLineUncertainty(const std::vector<MapLine>& lines) {
  std::vector<double> known;
  double length = 0, length_under = 0;
  int under = 0;
  for (const MapLine& l : lines) {
    length += l.length();
    if (l.midpoint_std_m < 0) continue;
    known.push_back(l.midpoint_std_m);
    if (l.midpoint_std_m < 0.01) {
      ++under;
      length_under += l.length();
    }
  }
  if (known.empty()) return "";
  std::nth_element(known.begin(), known.begin() + known.size() / 2, known.end());
  std::ostringstream os;
  os << std::fixed << std::setprecision(1) << "midpoint uncertainty (1 sigma): median "
     << 1000 * known[known.size() / 2] << " mm; " << under << " of " << lines.size() << " lines ("
     << length_under << " m of " << length << ") under 1 cm";
  return os.str();
}

}  // namespace alvio
