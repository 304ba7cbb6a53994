#pragma once
// A weak pull of a line landmark back to where the solve started it. A line seen from nearly
// one viewpoint is barely constrained along some directions (it may slide and turn inside its
// interpretation plane), and the Gauss-Newton step sends it far that way, often hundreds of
// radians: the cost rises, the step is rejected and the trust region shrinks. On sim_MH_05
// that took 2.3 of 5 iterations a solve; with every line block held constant none was
// rejected (docs/benchmarks.md, forty-first session). This term bounds those steps like
// Levenberg-Marquardt damping on the line blocks alone, and is re-anchored every solve, so it
// does not bias where a line settles across frames. A well-observed line has information of
// 1e4-1e6 per rad^2 and barely feels a weight of 10 (information 100).
//
// Parameter block: the line's orthonormal parameters [theta (3), phi] (OrthonormalLine).
// Residual (4): weight * Minus(x, x0), the manifold's own difference, so a rotation near pi
// whose log flips sign is still a small residual.

#include <ceres/sized_cost_function.h>

namespace alvio {

class LineStepDampingFactor final : public ceres::SizedCostFunction<4, 4> {
 public:
  /// @param start the line block's 4 parameters when the solve begins.
  /// @param weight square root of the damping information, per radian (> 0).
  LineStepDampingFactor(const double* start, double weight);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  double start_[4];
  double weight_;
};

/// The same term as two residual blocks of two rows each (`half` 0: rows 0-1, 1: rows 2-3),
/// which together cost exactly what the 4-row block costs. Ceres picks a Schur eliminator
/// specialised on the residuals' row count only when every residual on an eliminated block has
/// the same count. The point and line factors have 2 rows; with a 4-row damping block on the
/// lines the solve fell back to its all-dynamic kernels.
class LineStepDampingHalfFactor final : public ceres::SizedCostFunction<2, 4> {
 public:
  LineStepDampingHalfFactor(const double* start, double weight, int half);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  LineStepDampingFactor full_;
  int first_row_;
};

}  // namespace alvio
