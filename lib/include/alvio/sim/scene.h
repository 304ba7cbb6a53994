#pragma once
// The simulated world: planar rectangles (quads) with a material each, grouped
// into named objects. Boxes are six quads plus a solid used for clearance
// checks. The scene knows its true 3D edges (what a line tracker should find)
// and answers ray casts and visibility queries exactly, through a BVH.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "alvio/sim/bounding_volume_hierarchy.h"
#include "alvio/sim/procedural_texture.h"

namespace alvio::sim {

/// A planar rectangle origin + a*edge_u + b*edge_v, a, b in [0, 1]; edge_u and
/// edge_v are orthogonal. The front side is where edge_u x edge_v points.
struct SceneQuad {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d edge_u = Eigen::Vector3d::UnitX();
  Eigen::Vector3d edge_v = Eigen::Vector3d::UnitY();
  int material = 0;
  int object = 0;
  /// Seen from both sides (thin panels, posters); box faces are one-sided.
  bool two_sided = false;
  /// Offset (m) into a shared, repeating texture so that surfaces do not look alike.
  Eigen::Vector2d texture_offset_m = Eigen::Vector2d::Zero();
  Eigen::Vector3d normal() const { return edge_u.cross(edge_v).normalized(); }
  Eigen::Vector3d corner(int i) const;  ///< 0: origin, 1: +u, 2: +u+v, 3: +v
};

/// A straight 3D edge of the geometry: a box edge or a quad's border.
struct SceneEdge {
  int id = 0;
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  int object = 0;
};

/// An oriented solid box, for clearance queries (is a trajectory inside something?).
struct SceneSolid {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  ///< box axes in the world
  Eigen::Vector3d half_size = Eigen::Vector3d::Zero();
  int object = 0;
};

struct SceneMaterial {
  std::string name;
  TextureSpec texture;
};

struct PointLight {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double intensity = 1.0;  ///< irradiance on a facing surface at 1 m
};

struct DirectionalLight {
  Eigen::Vector3d direction = -Eigen::Vector3d::UnitZ();  ///< where the light travels
  double intensity = 0.0;
};

struct SceneLighting {
  double ambient = 0.4;
  std::vector<DirectionalLight> directional;
  std::vector<PointLight> points;
  /// Point lights fall off as 1 / (1 + (d / falloff_m)^2), softer than 1/d^2 so that
  /// a few lamps light a hall without hot spots.
  double falloff_m = 4.0;
};

struct RayHit {
  double t = 0.0;  ///< distance along the (unit) direction
  int quad = -1;
  double a_m = 0.0, b_m = 0.0;  ///< hit position on the quad in metres along edge_u, edge_v
};

class Scene {
 public:
  std::string name;
  SceneLighting lighting;
  uint64_t texture_seed = 1;

  /// Register an object name; returns its index.
  int addObject(const std::string& object_name);
  int addMaterial(const SceneMaterial& material);
  /// Index of a material by name, or -1.
  int findMaterial(const std::string& material_name) const;

  /// A rectangle with its 4 border edges.
  void addQuad(const SceneQuad& quad);
  /// An oriented box: 6 one-sided faces, 12 edges and a solid.
  void addBox(const Eigen::Vector3d& center, const Eigen::Matrix3d& R, const Eigen::Vector3d& size,
              int material, int object);

  /// Build the acceleration structure and cut the parts of edges buried inside solids
  /// (an edge through a solid becomes the pieces either side of it). Must be
  /// called after the last add and before any query.
  void finalize();
  bool finalized() const { return !bvh_.empty() || quads_.empty(); }

  const std::vector<SceneQuad>& quads() const { return quads_; }
  const std::vector<SceneEdge>& edges() const { return edges_; }
  const std::vector<SceneSolid>& solids() const { return solids_; }
  const std::vector<SceneMaterial>& materials() const { return materials_; }
  const std::vector<std::string>& objectNames() const { return objects_; }
  /// Axis-aligned bounds of all geometry.
  Eigen::AlignedBox3d bounds() const;

  /// The nearest hit along origin + t * direction (direction need not be unit;
  /// t is then in its units), 0 < t < t_max.
  std::optional<RayHit> intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                  double t_max = 1e30) const;
  /// True if nothing lies between `from` and `point` (the point itself may sit on
  /// a surface or an edge; `tolerance_m` is the slack at the point's end).
  bool isVisible(const Eigen::Vector3d& point, const Eigen::Vector3d& from,
                 double tolerance_m = 1e-3) const;
  /// Distance from `p` to the nearest solid or two-sided quad (negative inside a
  /// solid); `object` (optional) receives the index of that object.
  double clearance(const Eigen::Vector3d& p, int* object = nullptr) const;

  // --- for the renderer: the precomputed single-precision quad data and the BVH.
  struct FastQuad {
    Eigen::Vector3f origin, normal;
    Eigen::Vector3f u_scaled, v_scaled;  ///< edge / |edge|^2, so a = (p - o) . u_scaled
    float length_u, length_v;
    int two_sided;
  };
  const std::vector<FastQuad>& fastQuads() const { return fast_; }
  const BoundingVolumeHierarchy& bvh() const { return bvh_; }

  /// Ray test against one quad (single precision). On a hit closer than *t_max it
  /// sets *t_max, *a and *b (fractions along the edges) and returns true.
  static inline bool intersectFast(const FastQuad& q, const BvhRay& ray, float* t_max, float* a,
                                   float* b) {
    return intersectFast(q, ray.origin, ray.direction, t_max, a, b);
  }
  static inline bool intersectFast(const FastQuad& q, const Eigen::Vector3f& origin,
                                   const Eigen::Vector3f& dir, float* t_max, float* a, float* b) {
    const float denom = q.normal.dot(dir);
    if (!q.two_sided && denom >= 0.0f) return false;  // back face of a solid
    if (denom == 0.0f) return false;
    const float t = q.normal.dot(q.origin - origin) / denom;
    if (!(t > 1e-5f) || t >= *t_max) return false;
    const Eigen::Vector3f d = origin + t * dir - q.origin;
    const float aa = d.dot(q.u_scaled);
    if (aa < 0.0f || aa > 1.0f) return false;
    const float bb = d.dot(q.v_scaled);
    if (bb < 0.0f || bb > 1.0f) return false;
    *t_max = t;
    *a = aa;
    *b = bb;
    return true;
  }

 private:
  void addEdge(const Eigen::Vector3d& a, const Eigen::Vector3d& b, int object);

  std::vector<std::string> objects_;
  std::vector<SceneMaterial> materials_;
  std::vector<SceneQuad> quads_;
  std::vector<SceneEdge> edges_;
  std::vector<SceneSolid> solids_;
  std::vector<FastQuad> fast_;
  BoundingVolumeHierarchy bvh_;
};

}  // namespace alvio::sim
