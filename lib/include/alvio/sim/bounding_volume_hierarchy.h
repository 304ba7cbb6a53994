#pragma once
// A binary BVH over axis-aligned boxes (binned SAH build), in single precision
// for cache efficiency. The renderer casts one ray per pixel through it; the
// traversal is a header template so the primitive test inlines.

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <vector>

namespace alvio::sim {

struct BvhRay {
  Eigen::Vector3f origin;
  Eigen::Vector3f direction;
  Eigen::Vector3f inv_direction;
  int sign[3];
  BvhRay(const Eigen::Vector3f& o, const Eigen::Vector3f& d) : origin(o), direction(d) {
    for (int k = 0; k < 3; ++k) {
      // A zero component gives +-inf, which the slab test handles.
      inv_direction[k] = 1.0f / d[k];
      sign[k] = inv_direction[k] < 0 ? 1 : 0;
    }
  }
};

class BoundingVolumeHierarchy {
 public:
  struct Node {
    float lo[3], hi[3];
    int32_t first;  ///< leaf: first index into primitiveOrder(); inner: index of the left child
    int32_t count;  ///< leaf: number of primitives (> 0); inner: 0 (right child = left + 1)
  };

  /// Build over boxes given as (lo, hi) pairs.
  void build(const std::vector<Eigen::Vector3f>& lo, const std::vector<Eigen::Vector3f>& hi,
             int max_leaf_size = 2);

  bool empty() const { return nodes_.empty(); }
  const std::vector<Node>& nodes() const { return nodes_; }
  const std::vector<int>& primitiveOrder() const { return order_; }

  /// Visit every primitive in every node whose box passes `accept(lo, hi)` (e.g. a
  /// frustum test), calling `visit(prim)`; children of rejected nodes are skipped.
  template <typename AcceptFn, typename VisitFn>
  void traverseIf(AcceptFn&& accept, VisitFn&& visit) const {
    if (nodes_.empty()) return;
    int stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& n = nodes_[stack[--top]];
      if (!accept(n.lo, n.hi)) continue;
      if (n.count > 0) {
        for (int i = 0; i < n.count; ++i) visit(order_[n.first + i]);
        continue;
      }
      stack[top++] = n.first + 1;
      stack[top++] = n.first;
    }
  }

  /// Visit, near to far, every primitive whose box the ray enters before `*t_max`.
  /// `hit(prim, t_max)` tests the primitive and lowers *t_max on a closer hit.
  template <typename HitFn>
  void traverse(const BvhRay& ray, float* t_max, HitFn&& hit) const {
    if (nodes_.empty()) return;
    int stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& n = nodes_[stack[--top]];
      if (!enters(n, ray, *t_max)) continue;
      if (n.count > 0) {
        for (int i = 0; i < n.count; ++i) hit(order_[n.first + i], t_max);
        continue;
      }
      // Push the far child first so the near one is visited first.
      const int left = n.first, right = n.first + 1;
      const Node& l = nodes_[left];
      const Node& r = nodes_[right];
      const int axis = splitAxis(l, r);
      if (ray.sign[axis]) {
        stack[top++] = left;
        stack[top++] = right;
      } else {
        stack[top++] = right;
        stack[top++] = left;
      }
    }
  }

 private:
  static bool enters(const Node& n, const BvhRay& ray, float t_max) {
    float t0 = 0.0f, t1 = t_max;
    for (int k = 0; k < 3; ++k) {
      const float a = ((ray.sign[k] ? n.hi[k] : n.lo[k]) - ray.origin[k]) * ray.inv_direction[k];
      const float b = ((ray.sign[k] ? n.lo[k] : n.hi[k]) - ray.origin[k]) * ray.inv_direction[k];
      // max/min written so that NaN (0 * inf) never widens the interval.
      t0 = a > t0 ? a : t0;
      t1 = b < t1 ? b : t1;
    }
    return t0 <= t1;
  }
  static int splitAxis(const Node& a, const Node& b) {
    float best = -1;
    int axis = 0;
    for (int k = 0; k < 3; ++k) {
      const float d = std::abs((a.lo[k] + a.hi[k]) - (b.lo[k] + b.hi[k]));
      if (d > best) {
        best = d;
        axis = k;
      }
    }
    return axis;
  }
  void buildRecursive(int node_index, int begin, int end, int depth, int max_leaf_size);

  std::vector<Node> nodes_;
  std::vector<int> order_;
  std::vector<Eigen::Vector3f> lo_, hi_, centre_;
};

}  // namespace alvio::sim
