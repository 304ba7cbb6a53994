#include "alvio/mapping/synthetic_room.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>

namespace alvio {

double SyntheticRoom::surfaceDistance(const Eigen::Vector3d& p) const {
  // Distance to each of the six (finite) faces of the box.
  double best = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 3; ++axis)
    for (double plane : {0.0, size[axis]}) {
      Eigen::Vector3d q = p.cwiseMax(Eigen::Vector3d::Zero()).cwiseMin(size);
      q[axis] = plane;
      best = std::min(best, (p - q).norm());
    }
  return best;
}

namespace {

std::vector<Segment3> roomEdges(const Eigen::Vector3d& s) {
  std::vector<Segment3> e;
  // The 12 edges of the box.
  for (int axis = 0; axis < 3; ++axis) {
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    for (double va : {0.0, s[a]})
      for (double vb : {0.0, s[b]}) {
        Eigen::Vector3d p0 = Eigen::Vector3d::Zero();
        p0[a] = va;
        p0[b] = vb;
        Eigen::Vector3d p1 = p0;
        p1[axis] = s[axis];
        e.push_back({p0, p1});
      }
  }
  // A window frame in the middle of each wall: 40 % of its width, from 1.0 to 2.0 m high
  // (clipped to the room height).
  const double z0 = std::min(1.0, 0.3 * s.z()), z1 = std::min(2.0, 0.7 * s.z());
  for (int wall = 0; wall < 4; ++wall) {
    const int along = wall < 2 ? 0 : 1, across = 1 - along;
    const double at = (wall % 2 == 0) ? 0.0 : s[across];
    const double c = s[along] / 2, h = 0.2 * s[along];
    auto P = [&](double t, double z) {
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      p[along] = t;
      p[across] = at;
      p.z() = z;
      return p;
    };
    e.push_back({P(c - h, z0), P(c + h, z0)});
    e.push_back({P(c - h, z1), P(c + h, z1)});
    e.push_back({P(c - h, z0), P(c - h, z1)});
    e.push_back({P(c + h, z0), P(c + h, z1)});
  }
  return e;
}

// Camera looking along `forward` (horizontal), z forward, y down.
Eigen::Isometry3d cameraPose(const Eigen::Vector3d& position, const Eigen::Vector3d& forward) {
  const Eigen::Vector3d z = forward.normalized();
  const Eigen::Vector3d y(0, 0, -1);
  const Eigen::Vector3d x = y.cross(z);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = x;
  T.linear().col(1) = y;
  T.linear().col(2) = z;
  T.translation() = position;
  return T;
}

bool visible(const Eigen::Isometry3d& T_w_c, const Eigen::Vector3d& p_w, double range,
             double half_fov_tan) {
  const Eigen::Vector3d p_c = T_w_c.inverse() * p_w;
  return p_c.z() > 0.2 && p_c.norm() < range && std::abs(p_c.x()) < half_fov_tan * p_c.z() &&
         std::abs(p_c.y()) < half_fov_tan * p_c.z();
}

}  // namespace

SyntheticRoom makeSyntheticRoom(const SyntheticRoomOptions& o) {
  SyntheticRoom room;
  room.size = o.size;
  room.edges = roomEdges(o.size);
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::poisson_distribution<int> outliers(std::max(1e-9, o.outliers_per_keyframe));
  const double half_fov_tan = std::tan(o.fov_deg * M_PI / 360);
  const Eigen::Vector3d centre(o.size.x() / 2, o.size.y() / 2, std::min(1.5, o.size.z() / 2));

  // A track's line estimate: the true edge with its ends displaced by fixed offsets (an
  // estimator's error is consistent over the track), plus a small jitter per keyframe.
  struct Track {
    int id = -1, age = 0, observations = 0, last_keyframe = -10;
    Eigen::Vector3d o0 = Eigen::Vector3d::Zero(), o1 = Eigen::Vector3d::Zero();
  };
  // (Explicit return types: an Eigen expression returned by `auto` would dangle.)
  auto gauss3 = [&](double sigma) -> Eigen::Vector3d {
    return Eigen::Vector3d(noise(rng), noise(rng), noise(rng)) * sigma;
  };
  std::vector<Track> tracks(room.edges.size());
  int next_line_id = 0, next_point_id = 0;
  const int n_kf = o.laps * o.keyframes_per_lap;
  for (int k = 0; k < n_kf; ++k) {
    const double phase = 2 * M_PI * k / o.keyframes_per_lap;
    // An ellipse around the centre, looking outwards and a little ahead.
    const Eigen::Vector3d pos =
        centre + Eigen::Vector3d(0.3 * o.size.x() * std::cos(phase),
                                 0.3 * o.size.y() * std::sin(phase), 0.1 * std::sin(3 * phase));
    const Eigen::Vector3d fwd(std::cos(phase + 0.4), std::sin(phase + 0.4), 0);
    KeyframeLandmarks kf;
    kf.t = k * 0.5;
    kf.T_w_c = cameraPose(pos, fwd);
    StampedPose pose;
    pose.t = kf.t;
    pose.p = pos;
    pose.q = Eigen::Quaterniond(kf.T_w_c.linear());
    room.trajectory.push_back(pose);

    // Lines: the longest visible run of each edge, sampled every 5 cm.
    for (std::size_t e = 0; e < room.edges.size(); ++e) {
      const Segment3& edge = room.edges[e];
      const auto samples = sampleSegment(edge.p0, edge.p1, 0.05);
      int best_begin = -1, best_len = 0, begin = -1;
      for (int i = 0; i <= static_cast<int>(samples.size()); ++i) {
        const bool vis = i < static_cast<int>(samples.size()) &&
                         visible(kf.T_w_c, samples[i], o.view_range_m, half_fov_tan);
        if (vis && begin < 0) begin = i;
        if (!vis && begin >= 0) {
          if (i - begin > best_len) best_len = i - begin, best_begin = begin;
          begin = -1;
        }
      }
      Track& tr = tracks[e];
      if (best_len < 5) continue;  // under 20 cm in view
      if (tr.last_keyframe != k - 1 || tr.age >= o.keyframes_per_track) {
        tr.id = next_line_id++;
        tr.age = 0;
        tr.observations = 0;
        tr.o0 = gauss3(o.endpoint_noise_m);
        tr.o1 = gauss3(o.endpoint_noise_m);
      }
      ++tr.age;
      tr.observations += o.frames_per_keyframe;
      tr.last_keyframe = k;
      // The detector finds a random 70-100 % of the visible run.
      const double n = static_cast<double>(samples.size() - 1);
      const double r0 = best_begin / n, r1 = (best_begin + best_len - 1) / n;
      const double s0 = r0 + 0.15 * uni(rng) * (r1 - r0), s1 = r1 - 0.15 * uni(rng) * (r1 - r0);
      auto estimate = [&](double r) -> Eigen::Vector3d {
        return edge.p0 + r * (edge.p1 - edge.p0) + (1 - r) * tr.o0 + r * tr.o1 +
               gauss3(o.endpoint_noise_m / 3);
      };
      LandmarkSegment seg;
      seg.id = tr.id;
      seg.observations = tr.observations;
      seg.p0_w = estimate(s0);
      seg.p1_w = estimate(s1);
      kf.lines.push_back(seg);
    }
    // Outliers: short random segments inside the room, reported once.
    const int n_out = o.outliers_per_keyframe > 0 ? outliers(rng) : 0;
    for (int i = 0; i < n_out; ++i) {
      LandmarkSegment seg;
      seg.id = next_line_id++;
      seg.observations = 1;
      seg.p0_w = Eigen::Vector3d(uni(rng), uni(rng), uni(rng)).cwiseProduct(o.size);
      seg.p1_w = seg.p0_w + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)) * 0.5;
      kf.lines.push_back(seg);
    }
    // Points: rays through the field of view to the walls.
    for (int i = 0; i < o.points_per_keyframe; ++i) {
      const Eigen::Vector3d ray_c((2 * uni(rng) - 1) * half_fov_tan,
                                  (2 * uni(rng) - 1) * half_fov_tan, 1.0);
      const Eigen::Vector3d ray_w = kf.T_w_c.linear() * ray_c;
      double t = std::numeric_limits<double>::infinity();
      for (int axis = 0; axis < 3; ++axis) {
        if (std::abs(ray_w[axis]) < 1e-9) continue;
        const double plane = ray_w[axis] > 0 ? o.size[axis] : 0.0;
        t = std::min(t, (plane - pos[axis]) / ray_w[axis]);
      }
      const Eigen::Vector3d p = pos + t * ray_w;
      if ((p - pos).norm() > o.view_range_m) continue;
      LandmarkPoint lp;
      lp.id = next_point_id++;
      lp.p_w = p + o.point_noise_m * Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
      kf.points.push_back(lp);
    }
    room.keyframes.push_back(std::move(kf));
  }
  return room;
}

}  // namespace alvio
