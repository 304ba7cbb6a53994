#include "alvio/sim/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "alvio/common/error.h"

namespace alvio::sim {

Eigen::Vector3d SceneQuad::corner(int i) const {
  switch (i & 3) {
    case 0:
      return origin;
    case 1:
      return origin + edge_u;
    case 2:
      return origin + edge_u + edge_v;
    default:
      return origin + edge_v;
  }
}

int Scene::addObject(const std::string& object_name) {
  objects_.push_back(object_name);
  return static_cast<int>(objects_.size()) - 1;
}

int Scene::addMaterial(const SceneMaterial& material) {
  if (findMaterial(material.name) >= 0)
    throw Error("material '" + material.name + "' defined twice");
  materials_.push_back(material);
  return static_cast<int>(materials_.size()) - 1;
}

int Scene::findMaterial(const std::string& material_name) const {
  for (std::size_t i = 0; i < materials_.size(); ++i)
    if (materials_[i].name == material_name) return static_cast<int>(i);
  return -1;
}

void Scene::addEdge(const Eigen::Vector3d& a, const Eigen::Vector3d& b, int object) {
  SceneEdge e;
  e.a = a;
  e.b = b;
  e.object = object;
  edges_.push_back(e);
}

void Scene::addQuad(const SceneQuad& quad) {
  if (quad.edge_u.norm() < 1e-6 || quad.edge_v.norm() < 1e-6)
    throw Error("scene quad of object '" + objects_.at(quad.object) + "' has a zero-length edge");
  if (std::abs(quad.edge_u.normalized().dot(quad.edge_v.normalized())) > 1e-6)
    throw Error("scene quad of object '" + objects_.at(quad.object) +
                "' is not a rectangle (edges not orthogonal)");
  quads_.push_back(quad);
  for (int i = 0; i < 4; ++i) addEdge(quad.corner(i), quad.corner(i + 1), quad.object);
}

void Scene::addBox(const Eigen::Vector3d& center, const Eigen::Matrix3d& R,
                   const Eigen::Vector3d& size, int material, int object) {
  if ((size.array() <= 0).any())
    throw Error("box of object '" + objects_.at(object) + "' has a non-positive size");
  const Eigen::Vector3d h = 0.5 * size;
  const Eigen::Vector3d ax[3] = {R.col(0) * size.x(), R.col(1) * size.y(), R.col(2) * size.z()};
  const Eigen::Vector3d lo = center - R * h;  // corner at (-,-,-)
  // Each face: origin and two edges with edge_u x edge_v pointing outwards.
  auto face = [&](const Eigen::Vector3d& o, const Eigen::Vector3d& u, const Eigen::Vector3d& v) {
    SceneQuad q;
    q.origin = o;
    q.edge_u = u;
    q.edge_v = v;
    q.material = material;
    q.object = object;
    quads_.push_back(q);
  };
  face(lo, ax[2], ax[1]);          // -x
  face(lo + ax[0], ax[1], ax[2]);  // +x
  face(lo, ax[0], ax[2]);          // -y
  face(lo + ax[1], ax[2], ax[0]);  // +y
  face(lo, ax[1], ax[0]);          // -z
  face(lo + ax[2], ax[0], ax[1]);  // +z
  // The 12 edges: 4 along each axis.
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d& e1 = ax[(k + 1) % 3];
    const Eigen::Vector3d& e2 = ax[(k + 2) % 3];
    const Eigen::Vector3d starts[4] = {lo, lo + e1, lo + e2, lo + e1 + e2};
    for (const auto& s : starts) addEdge(s, s + ax[k], object);
  }
  SceneSolid solid;
  solid.center = center;
  solid.R = R;
  solid.half_size = h;
  solid.object = object;
  solids_.push_back(solid);
}

namespace {
// Signed distance from p to an oriented box (negative inside).
double boxDistance(const SceneSolid& s, const Eigen::Vector3d& p) {
  const Eigen::Vector3d local = s.R.transpose() * (p - s.center);
  const Eigen::Vector3d q = local.cwiseAbs() - s.half_size;
  const double outside = q.cwiseMax(0.0).norm();
  const double inside = std::min(q.maxCoeff(), 0.0);
  return outside + inside;
}

double quadDistance(const SceneQuad& q, const Eigen::Vector3d& p) {
  const Eigen::Vector3d d = p - q.origin;
  const double lu = q.edge_u.norm(), lv = q.edge_v.norm();
  const double a = std::clamp(d.dot(q.edge_u) / lu, 0.0, lu);
  const double b = std::clamp(d.dot(q.edge_v) / lv, 0.0, lv);
  const Eigen::Vector3d closest = q.origin + q.edge_u * (a / lu) + q.edge_v * (b / lv);
  return (p - closest).norm();
}

// The slab test in the box's frame: the interval of t in [0, 1] where a + t (b - a) lies
// inside the box grown by `grow` (negative: shrunk), if any.
std::optional<std::pair<double, double>> slabInterval(const SceneSolid& s, const Eigen::Vector3d& a,
                                                      const Eigen::Vector3d& b, double grow) {
  const Eigen::Vector3d o = s.R.transpose() * (a - s.center);
  const Eigen::Vector3d d = s.R.transpose() * (b - a);
  double t0 = 0.0, t1 = 1.0;
  for (int i = 0; i < 3; ++i) {
    const double h = s.half_size[i] + grow;
    if (h <= 0) return std::nullopt;
    if (std::abs(d[i]) < 1e-12) {
      if (std::abs(o[i]) >= h) return std::nullopt;
      continue;
    }
    double lo = (-h - o[i]) / d[i], hi = (h - o[i]) / d[i];
    if (lo > hi) std::swap(lo, hi);
    t0 = std::max(t0, lo);
    t1 = std::min(t1, hi);
    if (t0 >= t1) return std::nullopt;
  }
  return std::make_pair(t0, t1);
}

// Where the edge a -> b runs inside the box: deeper than `margin` somewhere (an edge on the
// box's face is not inside it), then cut at the box's true faces.
std::optional<std::pair<double, double>> insideInterval(const SceneSolid& s,
                                                        const Eigen::Vector3d& a,
                                                        const Eigen::Vector3d& b, double margin) {
  if (!slabInterval(s, a, b, -margin)) return std::nullopt;
  return slabInterval(s, a, b, 0.0);
}

// `pieces` (sorted, disjoint) minus the interval `cut`.
std::vector<std::pair<double, double>> subtractInterval(
    const std::vector<std::pair<double, double>>& pieces, const std::pair<double, double>& cut) {
  std::vector<std::pair<double, double>> out;
  for (const auto& [t0, t1] : pieces) {
    if (cut.second <= t0 || cut.first >= t1) {
      out.emplace_back(t0, t1);
      continue;
    }
    if (cut.first > t0) out.emplace_back(t0, cut.first);
    if (cut.second < t1) out.emplace_back(cut.second, t1);
  }
  return out;
}

// Slivers of a clipped edge shorter than this (a few millimetres poking out of a neighbour)
// are no line anyone could detect.
constexpr double kMinEdgePieceM = 0.01;
}  // namespace

void Scene::finalize() {
  // The parts of edges inside another solid can never be seen. Clip each edge against every
  // solid instead of testing its middle alone: a long rail runs through its posts, and the
  // post that holds its middle must not delete the whole rail from the truth.
  std::vector<SceneEdge> kept;
  for (const SceneEdge& e : edges_) {
    std::vector<std::pair<double, double>> pieces{{0.0, 1.0}};
    for (const SceneSolid& s : solids_) {
      const auto inside = insideInterval(s, e.a, e.b, 1e-3);
      if (inside) pieces = subtractInterval(pieces, *inside);
      if (pieces.empty()) break;
    }
    const double length = (e.b - e.a).norm();
    for (const auto& [t0, t1] : pieces) {
      if ((t1 - t0) * length < kMinEdgePieceM) continue;
      SceneEdge piece = e;
      piece.a = e.a + t0 * (e.b - e.a);
      piece.b = e.a + t1 * (e.b - e.a);
      kept.push_back(piece);
    }
  }
  edges_ = std::move(kept);
  for (std::size_t i = 0; i < edges_.size(); ++i) edges_[i].id = static_cast<int>(i);

  fast_.clear();
  std::vector<Eigen::Vector3f> lo, hi;
  for (const SceneQuad& q : quads_) {
    FastQuad f;
    f.origin = q.origin.cast<float>();
    f.normal = q.normal().cast<float>();
    f.length_u = static_cast<float>(q.edge_u.norm());
    f.length_v = static_cast<float>(q.edge_v.norm());
    f.u_scaled = (q.edge_u / q.edge_u.squaredNorm()).cast<float>();
    f.v_scaled = (q.edge_v / q.edge_v.squaredNorm()).cast<float>();
    f.two_sided = q.two_sided ? 1 : 0;
    fast_.push_back(f);
    Eigen::Vector3d a = q.corner(0), b = q.corner(0);
    for (int i = 1; i < 4; ++i) {
      a = a.cwiseMin(q.corner(i));
      b = b.cwiseMax(q.corner(i));
    }
    // Pad flat boxes so that the slab test stays robust.
    lo.push_back((a.array() - 1e-4).matrix().cast<float>());
    hi.push_back((b.array() + 1e-4).matrix().cast<float>());
  }
  bvh_.build(lo, hi, 2);
}

Eigen::AlignedBox3d Scene::bounds() const {
  Eigen::AlignedBox3d box;
  for (const SceneQuad& q : quads_)
    for (int i = 0; i < 4; ++i) box.extend(q.corner(i));
  return box;
}

std::optional<RayHit> Scene::intersect(const Eigen::Vector3d& origin,
                                       const Eigen::Vector3d& direction, double t_max) const {
  if (!finalized()) throw Error("Scene::intersect called before finalize()");
  const double scale = direction.norm();
  if (scale <= 0) return std::nullopt;
  const Eigen::Vector3d dir = direction / scale;
  const BvhRay ray(origin.cast<float>(), dir.cast<float>());
  float t_best = static_cast<float>(std::min(t_max * scale, 1e30));
  int best = -1;
  bvh_.traverse(ray, &t_best, [&](int qi, float* t) {
    float a, b;
    if (intersectFast(fast_[qi], ray, t, &a, &b)) best = qi;
  });
  if (best < 0) return std::nullopt;
  // The winner is decided in single precision (ties at shared edges are a matter of
  // 1e-6 m); its hit point is then recomputed in double precision.
  const SceneQuad& q = quads_[best];
  const Eigen::Vector3d n = q.normal();
  const double t = n.dot(q.origin - origin) / n.dot(dir);
  const Eigen::Vector3d d = origin + t * dir - q.origin;
  RayHit hit;
  hit.quad = best;
  hit.t = t / scale;
  hit.a_m = std::clamp(d.dot(q.edge_u) / q.edge_u.norm(), 0.0, q.edge_u.norm());
  hit.b_m = std::clamp(d.dot(q.edge_v) / q.edge_v.norm(), 0.0, q.edge_v.norm());
  if (hit.t >= t_max) return std::nullopt;
  return hit;
}

bool Scene::isVisible(const Eigen::Vector3d& point, const Eigen::Vector3d& from,
                      double tolerance_m) const {
  const Eigen::Vector3d d = point - from;
  const double dist = d.norm();
  if (dist <= tolerance_m) return true;
  return !intersect(from, d / dist, dist - tolerance_m).has_value();
}

double Scene::clearance(const Eigen::Vector3d& p, int* object) const {
  double best = std::numeric_limits<double>::max();
  int nearest = -1;
  for (const SceneSolid& s : solids_) {
    const double d = boxDistance(s, p);
    if (d < best) {
      best = d;
      nearest = s.object;
    }
  }
  for (const SceneQuad& q : quads_) {
    if (!q.two_sided) continue;
    const double d = quadDistance(q, p);
    if (d < best) {
      best = d;
      nearest = q.object;
    }
  }
  if (object) *object = nearest;
  return best;
}

}  // namespace alvio::sim
