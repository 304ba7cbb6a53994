#include "alvio/sim/bounding_volume_hierarchy.h"

#include <limits>

#include "alvio/common/error.h"

namespace alvio::sim {
namespace {

struct Bounds {
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
  Eigen::Vector3f hi = Eigen::Vector3f::Constant(-std::numeric_limits<float>::max());
  void grow(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
    lo = lo.cwiseMin(a);
    hi = hi.cwiseMax(b);
  }
  float area() const {
    if (lo.x() > hi.x()) return 0.0f;
    const Eigen::Vector3f d = hi - lo;
    return 2.0f * (d.x() * d.y() + d.y() * d.z() + d.z() * d.x());
  }
};

}  // namespace

void BoundingVolumeHierarchy::build(const std::vector<Eigen::Vector3f>& lo,
                                    const std::vector<Eigen::Vector3f>& hi, int max_leaf_size) {
  if (lo.size() != hi.size()) throw Error("BVH: lo/hi size mismatch");
  nodes_.clear();
  order_.resize(lo.size());
  lo_ = lo;
  hi_ = hi;
  centre_.resize(lo.size());
  for (std::size_t i = 0; i < lo.size(); ++i) {
    order_[i] = static_cast<int>(i);
    centre_[i] = 0.5f * (lo[i] + hi[i]);
  }
  if (lo.empty()) return;
  nodes_.reserve(2 * lo.size());
  nodes_.emplace_back();
  buildRecursive(0, 0, static_cast<int>(lo.size()), 0, std::max(1, max_leaf_size));
  lo_.clear();
  hi_.clear();
  centre_.clear();
}

// Fills the (already allocated) node `node_index` for order_[begin, end).
void BoundingVolumeHierarchy::buildRecursive(int node_index, int begin, int end, int depth,
                                             int max_leaf_size) {
  Bounds box, centres;
  for (int i = begin; i < end; ++i) {
    box.grow(lo_[order_[i]], hi_[order_[i]]);
    centres.grow(centre_[order_[i]], centre_[order_[i]]);
  }
  auto make_leaf = [&] {
    Node& n = nodes_[node_index];
    for (int k = 0; k < 3; ++k) {
      n.lo[k] = box.lo[k];
      n.hi[k] = box.hi[k];
    }
    n.first = begin;
    n.count = end - begin;
  };
  const int count = end - begin;
  if (count <= max_leaf_size || depth > 48) return make_leaf();

  // Binned surface-area heuristic over all three axes.
  constexpr int kBins = 16;
  float best_cost = std::numeric_limits<float>::max();
  int best_axis = -1, best_split = -1;
  for (int axis = 0; axis < 3; ++axis) {
    const float extent = centres.hi[axis] - centres.lo[axis];
    if (extent <= 1e-7f) continue;
    Bounds bins[kBins];
    int counts[kBins] = {};
    for (int i = begin; i < end; ++i) {
      const int p = order_[i];
      int b = static_cast<int>(kBins * (centre_[p][axis] - centres.lo[axis]) / extent);
      b = std::min(b, kBins - 1);
      bins[b].grow(lo_[p], hi_[p]);
      ++counts[b];
    }
    float right_area[kBins];
    int right_count[kBins];
    Bounds acc;
    int n = 0;
    for (int b = kBins - 1; b > 0; --b) {
      acc.grow(bins[b].lo, bins[b].hi);
      n += counts[b];
      right_area[b] = acc.area();
      right_count[b] = n;
    }
    acc = Bounds();
    n = 0;
    for (int b = 0; b < kBins - 1; ++b) {
      acc.grow(bins[b].lo, bins[b].hi);
      n += counts[b];
      if (n == 0 || right_count[b + 1] == 0) continue;
      const float cost = acc.area() * n + right_area[b + 1] * right_count[b + 1];
      if (cost < best_cost) {
        best_cost = cost;
        best_axis = axis;
        best_split = b;
      }
    }
  }
  // A leaf is cheaper than splitting when the split does not separate anything.
  if (best_axis < 0 || best_cost >= box.area() * count * 1.0f) {
    if (count <= 8 || best_axis < 0) return make_leaf();
  }
  int mid;
  if (best_axis >= 0) {
    const float extent = centres.hi[best_axis] - centres.lo[best_axis];
    const float lo_c = centres.lo[best_axis];
    mid = static_cast<int>(std::partition(order_.begin() + begin, order_.begin() + end,
                                          [&](int p) {
                                            int b = static_cast<int>(
                                                kBins * (centre_[p][best_axis] - lo_c) / extent);
                                            return std::min(b, kBins - 1) <= best_split;
                                          }) -
                           order_.begin());
  } else {
    mid = (begin + end) / 2;
  }
  if (mid == begin || mid == end) mid = (begin + end) / 2;

  const int left = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  nodes_.emplace_back();
  {
    Node& n = nodes_[node_index];
    for (int k = 0; k < 3; ++k) {
      n.lo[k] = box.lo[k];
      n.hi[k] = box.hi[k];
    }
    n.first = left;
    n.count = 0;
  }
  buildRecursive(left, begin, mid, depth + 1, max_leaf_size);
  buildRecursive(left + 1, mid, end, depth + 1, max_leaf_size);
}

}  // namespace alvio::sim
