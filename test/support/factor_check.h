#pragma once
// Checks an analytic Ceres cost function against central differences taken
// in the tangent space of each parameter block (poses through PoseManifold).

#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <vector>

namespace alvio::test {

struct JacobianCheck {
  double max_abs_error = 0;  ///< worst |analytic - numeric| over all entries
  double max_rel_error = 0;  ///< worst error relative to the block's largest entry
};

/// `blocks[k]` points at block k's values; `manifold_blocks[k]` true for pose blocks (size 7).
JacobianCheck checkJacobians(const ceres::CostFunction& cost, const std::vector<double*>& blocks,
                             double step = 1e-6);

}  // namespace alvio::test
