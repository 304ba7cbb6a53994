#pragma once
// Marginalisation of old states into a Gaussian prior (Schur complement), and
// the factor that applies that prior in later windows.
//
// Blocks of ambient size 7 are poses (PoseManifold, tangent size 6); all other
// blocks are Euclidean. Jacobians are taken in the tangent space.

#include <ceres/cost_function.h>
#include <ceres/loss_function.h>

#include <Eigen/Core>
#include <map>
#include <memory>
#include <unordered_map>
#include <vector>

namespace alvio {

class MarginalizationInfo {
 public:
  /// A factor that touches the states being removed. Takes ownership of `cost` and `loss`.
  /// `drop` lists the indices (into `blocks`) of the parameter blocks to marginalise.
  void addResidualBlock(ceres::CostFunction* cost, ceres::LossFunction* loss,
                        std::vector<double*> blocks, std::vector<int> drop);

  /// A kept Euclidean block of size 1 that drifts: `variance` is added to its variance in the
  /// prior (a random walk since the last prior), so old information about it fades.
  void addRandomWalk(double* block, double variance);

  /// Evaluate all factors at the current parameter values and form the prior.
  /// Returns false when nothing is kept or the kept states learn nothing (no prior).
  bool marginalize();

  /// After the window shifted: the kept blocks' new addresses (old address -> new).
  /// Blocks absent from `shift` are dropped from the prior's parameter list (error).
  std::vector<double*> keptBlocks(const std::map<double*, double*>& shift) const;

  // The prior, for MarginalizationFactor.
  int keptTangentSize() const { return kept_tangent_size_; }
  const std::vector<int>& keptSizes() const { return kept_sizes_; }
  const std::vector<std::vector<double>>& keptLinearizationPoints() const { return kept_values_; }
  const Eigen::MatrixXd& linearizedJacobian() const { return linearized_jacobian_; }
  const Eigen::VectorXd& linearizedResidual() const { return linearized_residual_; }
  /// The kept blocks' addresses before the shift.
  const std::vector<double*>& keptAddresses() const { return kept_addresses_; }

 private:
  struct Block {
    std::unique_ptr<ceres::CostFunction> cost;
    std::unique_ptr<ceres::LossFunction> loss;
    std::vector<double*> blocks;
    std::vector<int> drop;
  };
  /// Where the blocks go: the states (dropped first, then kept) at tangent offsets in one
  /// dense system; each dropped landmark (inverse depth, line) with the factors that see it.
  struct Layout {
    std::unordered_map<double*, int> size_of, offset;
    std::vector<double*> dropped, kept, landmarks;
    std::unordered_map<double*, std::vector<std::size_t>> factors_of;
    std::vector<std::size_t> state_factors;  ///< factors without a landmark
    int m = 0, n = 0;                        ///< tangent sizes of the dropped and kept states
  };
  Layout planLayout() const;
  /// The prior from the factors' information, landmarks eliminated one by one.
  void formPriorFromInformation(const Layout& layout);

  std::vector<Block> factors_;
  std::vector<std::pair<double*, double>> random_walks_;
  std::vector<double*> kept_addresses_;
  std::vector<int> kept_sizes_;
  std::vector<std::vector<double>> kept_values_;
  int kept_tangent_size_ = 0;
  Eigen::MatrixXd linearized_jacobian_;
  Eigen::VectorXd linearized_residual_;
};

/// r = r0 + J * Minus(x, x0) over the kept blocks.
class MarginalizationFactor : public ceres::CostFunction {
 public:
  explicit MarginalizationFactor(std::shared_ptr<const MarginalizationInfo> info);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  std::shared_ptr<const MarginalizationInfo> info_;
};

/// Writes a Gaussian prior with information H (symmetric, positive semi-definite) and gradient
/// g (in H's range) as |J dx + r|^2: J^T J = H and J^T r = g. By an LDL^T with complete
/// diagonal pivoting, H = P^T L D L^T P: J = D^1/2 L^T P, r = D^-1/2 L^-1 P g (n^3 / 3
/// multiplications, where an eigendecomposition with its vectors takes about 9 n^3). The pivoting
/// leaves the directions H does not constrain (the window's position and yaw) last, where D is
/// rounding noise: J has one row per direction H constrains (rank x n), none for the others.
void factorPrior(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, Eigen::MatrixXd* J,
                 Eigen::VectorXd* r);

/// Tangent size of a block of ambient size `size` (7 -> 6, else unchanged).
inline int tangentSizeOf(int size) {
  return size == 7 ? 6 : size;
}

}  // namespace alvio
