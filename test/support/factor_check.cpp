#include "factor_check.h"

#include <algorithm>

#include "alvio/estimator/pose_manifold.h"

namespace alvio::test {

JacobianCheck checkJacobians(const ceres::CostFunction& cost, const std::vector<double*>& blocks,
                             double step) {
  const int nr = cost.num_residuals();
  const auto& sizes = cost.parameter_block_sizes();
  using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  std::vector<RowMat> J(blocks.size());
  std::vector<double*> jp(blocks.size());
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    J[k].resize(nr, sizes[k]);
    jp[k] = J[k].data();
  }
  Eigen::VectorXd r0(nr);
  cost.Evaluate(blocks.data(), r0.data(), jp.data());

  JacobianCheck out;
  PoseManifold pose_manifold;
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const int size = sizes[k];
    const bool is_pose = size == 7;
    const int tsize = is_pose ? 6 : size;
    const Eigen::MatrixXd analytic =
        is_pose ? Eigen::MatrixXd(J[k] * posePlusJacobian(blocks[k])) : Eigen::MatrixXd(J[k]);
    Eigen::MatrixXd numeric(nr, tsize);
    const std::vector<double> x0(blocks[k], blocks[k] + size);
    for (int d = 0; d < tsize; ++d) {
      Eigen::VectorXd rp(nr), rm(nr);
      for (int sign : {1, -1}) {
        Eigen::VectorXd delta = Eigen::VectorXd::Zero(tsize);
        delta[d] = sign * step;
        if (is_pose) {
          pose_manifold.Plus(x0.data(), delta.data(), blocks[k]);
        } else {
          for (int i = 0; i < size; ++i) blocks[k][i] = x0[i] + delta[i];
        }
        cost.Evaluate(blocks.data(), sign > 0 ? rp.data() : rm.data(), nullptr);
      }
      std::copy(x0.begin(), x0.end(), blocks[k]);
      numeric.col(d) = (rp - rm) / (2 * step);
    }
    const double err = (analytic - numeric).cwiseAbs().maxCoeff();
    const double scale = std::max(1e-9, numeric.cwiseAbs().maxCoeff());
    out.max_abs_error = std::max(out.max_abs_error, err);
    out.max_rel_error = std::max(out.max_rel_error, err / scale);
  }
  return out;
}

}  // namespace alvio::test
