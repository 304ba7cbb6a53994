#include "alvio/estimator/factors/marginalization.h"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "alvio/common/error.h"
#include "alvio/common/rotation.h"
#include "alvio/estimator/pose_manifold.h"

namespace alvio {
namespace {

// Tangent-space Jacobian of one block from its ambient (row-major) Jacobian, into `J`.
template <typename Columns>
void tangentJacobian(
    const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>& J_ambient,
    const double* x, int size, Columns&& J) {
  if (size != 7)
    J = J_ambient;
  else
    J.noalias() = J_ambient * posePlusJacobian(x);
}

// Inverse left Jacobian of SO(3) at rotation vector phi: d Log(Exp(e) R) / de at e = 0.
Eigen::Matrix3d inverseLeftJacobian(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  const Eigen::Matrix3d K = skew(phi);
  if (theta < 1e-6) return Eigen::Matrix3d::Identity() - 0.5 * K + K * K / 12.0;
  const double c = 1.0 / (theta * theta) - (1 + std::cos(theta)) / (2 * theta * std::sin(theta));
  return Eigen::Matrix3d::Identity() - 0.5 * K + c * K * K;
}

// Minus(x, x0) in the tangent space of a block.
Eigen::VectorXd tangentDifference(const double* x, const double* x0, int size) {
  Eigen::VectorXd d(tangentSizeOf(size));
  if (size != 7) {
    for (int i = 0; i < size; ++i) d[i] = x[i] - x0[i];
    return d;
  }
  // q and -q are the same rotation: take the difference along the shorter path, or a sign
  // flip of the parameter (from a matrix-to-quaternion conversion) reads as a 360 deg turn.
  double y[7];
  std::copy(x, x + 7, y);
  if (Eigen::Map<const Eigen::Vector4d>(x + 3).dot(Eigen::Map<const Eigen::Vector4d>(x0 + 3)) < 0)
    for (int i = 3; i < 7; ++i) y[i] = -y[i];
  PoseManifold().Minus(y, x0, d.data());
  return d;
}

// Robust-loss correction of residual and Jacobian, as Ceres' Corrector does.
void applyLoss(const ceres::LossFunction& loss, Eigen::VectorXd* r, Eigen::MatrixXd* J) {
  const double sq_norm = r->squaredNorm();
  double rho[3];
  loss.Evaluate(sq_norm, rho);
  const double sqrt_rho1 = std::sqrt(rho[1]);
  double residual_scaling, alpha_sq_norm;
  if (sq_norm == 0.0 || rho[2] <= 0.0) {
    residual_scaling = sqrt_rho1;
    alpha_sq_norm = 0.0;
  } else {
    const double D = 1.0 + 2.0 * sq_norm * rho[2] / rho[1];
    const double alpha = 1.0 - std::sqrt(D);
    residual_scaling = sqrt_rho1 / (1 - alpha);
    alpha_sq_norm = alpha / sq_norm;
  }
  *J = sqrt_rho1 * (*J - alpha_sq_norm * (*r) * (r->transpose() * (*J)));
  *r *= residual_scaling;
}

// Pseudo-inverse of a symmetric positive semi-definite matrix (eigenvalues up to 1e-8 count
// as zero).
Eigen::MatrixXd symmetricPseudoInverse(const Eigen::MatrixXd& A) {
  constexpr double kMinEigenvalue = 1e-8;
  if (A.rows() == 1)  // inverse depths: most of the landmarks
    return Eigen::MatrixXd::Constant(1, 1, A(0, 0) > kMinEigenvalue ? 1.0 / A(0, 0) : 0.0);
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (A + A.transpose()));
  const Eigen::VectorXd inv =
      (es.eigenvalues().array() > kMinEigenvalue).select(es.eigenvalues().array().inverse(), 0.0);
  return es.eigenvectors() * inv.asDiagonal() * es.eigenvectors().transpose();
}

// Linearises factors at the current values, in the tangent space.
class FactorLinearizer {
 public:
  /// The factor's tangent-space Jacobian (all blocks side by side, columns()[k] onwards for
  /// block k) and residual, robust loss applied.
  void evaluate(const ceres::CostFunction& cost, const ceres::LossFunction* loss,
                const std::vector<double*>& blocks) {
    const int num_residuals = cost.num_residuals();
    const auto& sizes = cost.parameter_block_sizes();
    r_.resize(num_residuals);
    Ja_.resize(blocks.size());
    jac_ptrs_.resize(blocks.size());
    column_.resize(blocks.size() + 1);
    column_[0] = 0;
    for (std::size_t k = 0; k < blocks.size(); ++k) {
      Ja_[k].resize(num_residuals, sizes[k]);
      jac_ptrs_[k] = Ja_[k].data();
      column_[k + 1] = column_[k] + tangentSizeOf(sizes[k]);
    }
    if (!cost.Evaluate(blocks.data(), r_.data(), jac_ptrs_.data()))
      throw Error("marginalisation: a factor failed to evaluate");
    J_.resize(num_residuals, column_.back());
    for (std::size_t k = 0; k < blocks.size(); ++k)
      tangentJacobian(Ja_[k], blocks[k], sizes[k],
                      J_.middleCols(column_[k], column_[k + 1] - column_[k]));
    if (loss) applyLoss(*loss, &r_, &J_);
  }
  const Eigen::MatrixXd& jacobian() const { return J_; }
  const Eigen::VectorXd& residual() const { return r_; }
  const std::vector<int>& columns() const { return column_; }

  /// Evaluates the factor and adds its J^T J and J^T r to a system, at the blocks' offsets
  /// there.
  template <typename OffsetOf>
  void addTo(const ceres::CostFunction& cost, const ceres::LossFunction* loss,
             const std::vector<double*>& blocks, OffsetOf offset_of, Eigen::MatrixXd* H,
             Eigen::VectorXd* g) {
    evaluate(cost, loss, blocks);
    // One product gives every block pair's J_a^T J_b (per pair, Eigen's matrix product
    // set-up cost more than these few-column products). Even for two-row factors it beats a
    // product of depth fixed at 2 and a lazy one (fifty-second session).
    JtJ_.noalias() = J_.transpose() * J_;
    Jtr_.noalias() = J_.transpose() * r_;
    for (std::size_t a = 0; a < blocks.size(); ++a) {
      const int ia = offset_of(blocks[a]), ta = column_[a + 1] - column_[a];
      g->segment(ia, ta) += Jtr_.segment(column_[a], ta);
      for (std::size_t b = 0; b < blocks.size(); ++b) {
        const int tb = column_[b + 1] - column_[b];
        H->block(ia, offset_of(blocks[b]), ta, tb) += JtJ_.block(column_[a], column_[b], ta, tb);
      }
    }
  }

 private:
  // The matrices keep their storage from one factor to the next: most have the same shapes.
  Eigen::VectorXd r_, Jtr_;
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> Ja_;
  std::vector<double*> jac_ptrs_;
  std::vector<int> column_;
  Eigen::MatrixXd J_, JtJ_;
};

// The prior that one factor, linearised in `f`, leaves on its kept columns: a QR
// decomposition of [J_dropped | J_kept | r] (columns at `offset`: m dropped, then n kept)
// eliminates the dropped states; the rows they cannot explain are the prior.
void eliminateByQr(const FactorLinearizer& f, const std::vector<double*>& blocks,
                   const std::unordered_map<double*, int>& offset, int m, int n, Eigen::MatrixXd* J,
                   Eigen::VectorXd* r) {
  const int rows = static_cast<int>(f.residual().size());
  Eigen::MatrixXd A(rows, m + n + 1);
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const int c = f.columns()[k], t = f.columns()[k + 1] - c;
    A.middleCols(offset.at(blocks[k]), t) = f.jacobian().middleCols(c, t);
  }
  A.col(m + n) = f.residual();
  int used = 0;  // rows the dropped states take
  if (m > 0) {
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A.leftCols(m));
    used = static_cast<int>(qr.rank());
    A.rightCols(n + 1).applyOnTheLeft(qr.householderQ().adjoint());
  }
  *J = A.bottomRows(rows - used).middleCols(m, n);
  *r = A.bottomRows(rows - used).col(m + n);
}

// Pivots below this fraction of H's largest diagonal entry are rounding noise. In a window's
// prior the kept pivots were at least 3e-9 of it, the others at most 6e-12 (median 1e-14 and
// below; 800 frames each of sim_MH_05 and sim_MH_03_realimu).
constexpr double kPriorRankTolerance = 1e-10;

}  // namespace

void factorPrior(const Eigen::MatrixXd& H, const Eigen::VectorXd& g, Eigen::MatrixXd* J,
                 Eigen::VectorXd* r) {
  const int n = static_cast<int>(H.rows());
  // Outer-product LDL^T with complete diagonal pivoting (LAPACK's dpstrf): each step takes
  // the largest diagonal entry of what is left, so the factorisation stops at H's rank.
  // (Eigen's LDLT pivots on the original diagonal, which does not reveal the rank.)
  Eigen::MatrixXd A = H;
  std::vector<int> perm(n);
  for (int i = 0; i < n; ++i) perm[i] = i;
  const double tol = std::max(1e-8, kPriorRankTolerance * A.diagonal().maxCoeff());
  int rank = 0;
  for (; rank < n; ++rank) {
    int p;
    if (A.diagonal().tail(n - rank).maxCoeff(&p) <= tol) break;
    p += rank;
    if (p != rank) {
      A.row(rank).swap(A.row(p));
      A.col(rank).swap(A.col(p));
      std::swap(perm[rank], perm[p]);
    }
    const int rest = n - rank - 1;
    const double d = A(rank, rank);
    A.col(rank).tail(rest) /= d;
    A.bottomRightCorner(rest, rest).noalias() -=
        d * A.col(rank).tail(rest) * A.col(rank).tail(rest).transpose();
  }
  // H = P^T L D L^T P with L (n x rank) unit lower triangular: J = D^1/2 L^T P.
  const Eigen::VectorXd sqrt_d = A.diagonal().head(rank).cwiseSqrt();
  J->setZero(rank, n);
  Eigen::VectorXd pg(n);
  for (int i = 0; i < n; ++i) {
    pg[i] = g[perm[i]];
    for (int k = 0; k < std::min(i, rank); ++k) (*J)(k, perm[i]) = A(i, k) * sqrt_d[k];
    if (i < rank) (*J)(i, perm[i]) = sqrt_d[i];
  }
  // r = D^-1/2 L^-1 P g (g lies in H's range).
  *r = A.topLeftCorner(rank, rank)
           .triangularView<Eigen::UnitLower>()
           .solve(pg.head(rank))
           .cwiseQuotient(sqrt_d);
}

void MarginalizationInfo::addResidualBlock(ceres::CostFunction* cost, ceres::LossFunction* loss,
                                           std::vector<double*> blocks, std::vector<int> drop) {
  Block b;
  b.cost.reset(cost);
  b.loss.reset(loss);
  b.blocks = std::move(blocks);
  b.drop = std::move(drop);
  factors_.push_back(std::move(b));
}

MarginalizationInfo::Layout MarginalizationInfo::planLayout() const {
  Layout layout;
  std::unordered_map<double*, int>& size_of = layout.size_of;
  std::unordered_map<double*, bool> is_dropped;
  for (const auto& f : factors_) {
    const auto& sizes = f.cost->parameter_block_sizes();
    for (std::size_t k = 0; k < f.blocks.size(); ++k) size_of[f.blocks[k]] = sizes[k];
    for (int d : f.drop) is_dropped[f.blocks[d]] = true;
  }
  // Dropped landmarks (inverse depths, lines: size 1 or 4) couple only with the states, never
  // with each other: each is eliminated in a small system of its own factors and the states
  // they touch. The states (dropped first, then kept) form one dense system.
  auto isLandmark = [&](double* b) {
    return is_dropped.count(b) && (size_of[b] == 1 || size_of[b] == 4);
  };
  for (std::size_t i = 0; i < factors_.size(); ++i) {
    double* landmark = nullptr;
    for (double* b : factors_[i].blocks) {
      if (isLandmark(b)) {
        if (landmark && landmark != b)
          throw Error("marginalisation: a factor couples two landmarks");
        landmark = b;
        continue;
      }
      auto& list = is_dropped.count(b) ? layout.dropped : layout.kept;
      if (std::find(list.begin(), list.end(), b) == list.end()) list.push_back(b);
    }
    if (!landmark) {
      layout.state_factors.push_back(i);
      continue;
    }
    auto& of = layout.factors_of[landmark];
    if (of.empty()) layout.landmarks.push_back(landmark);
    of.push_back(i);
  }
  int& m = layout.m;
  int& n = layout.n;
  for (double* b : layout.dropped) layout.offset[b] = m, m += tangentSizeOf(size_of[b]);
  for (double* b : layout.kept) layout.offset[b] = m + n, n += tangentSizeOf(size_of[b]);
  return layout;
}

void MarginalizationInfo::addRandomWalk(double* block, double variance) {
  if (variance > 0) random_walks_.emplace_back(block, variance);
}

bool MarginalizationInfo::marginalize() {
  const Layout layout = planLayout();
  if (layout.n == 0) return false;
  if (layout.landmarks.empty() && layout.state_factors.size() == 1 && random_walks_.empty()) {
    // The prior alone, when the second-newest frame leaves the window (every frame that is
    // not a keyframe): no information matrix needed.
    const Block& f = factors_[layout.state_factors[0]];
    FactorLinearizer linearize;
    linearize.evaluate(*f.cost, f.loss.get(), f.blocks);
    eliminateByQr(linearize, f.blocks, layout.offset, layout.m, layout.n, &linearized_jacobian_,
                  &linearized_residual_);
  } else {
    formPriorFromInformation(layout);
  }
  if (linearized_jacobian_.rows() == 0) return false;  // Ceres needs a residual

  kept_addresses_ = layout.kept;
  kept_sizes_.clear();
  kept_values_.clear();
  for (double* b : layout.kept) {
    const int size = layout.size_of.at(b);
    kept_sizes_.push_back(size);
    kept_values_.emplace_back(b, b + size);
  }
  kept_tangent_size_ = layout.n;
  factors_.clear();  // the evaluated factors are no longer needed
  return true;
}

void MarginalizationInfo::formPriorFromInformation(const Layout& layout) {
  const int m = layout.m, n = layout.n;
  FactorLinearizer linearize;
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(m + n, m + n);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(m + n);
  for (std::size_t i : layout.state_factors)
    linearize.addTo(
        *factors_[i].cost, factors_[i].loss.get(), factors_[i].blocks,
        [&](double* b) { return layout.offset.at(b); }, &H, &g);

  // Each landmark: [landmark, the states its factors touch], the landmark eliminated there.
  // A landmark touches a dozen blocks at most: a list finds them faster than a hash map.
  struct LocalBlock {
    double* address;
    int local_offset, offset, tangent_size;
  };
  // A stretch of blocks that are neighbours both in the landmark's system and in the states'.
  struct Run {
    int local_offset, offset, size;
  };
  std::vector<LocalBlock> local;
  std::vector<Run> runs;
  auto localOffset = [&](double* b) {
    for (const LocalBlock& l : local)
      if (l.address == b) return l.local_offset;
    return -1;
  };
  Eigen::MatrixXd Hl, K;
  Eigen::VectorXd gl;
  for (double* landmark : layout.landmarks) {
    const int t = tangentSizeOf(layout.size_of.at(landmark));
    local.assign(1, {landmark, 0, -1, t});
    int size = t;
    for (std::size_t i : layout.factors_of.at(landmark))
      for (double* b : factors_[i].blocks)
        if (localOffset(b) < 0) {
          const int tb = tangentSizeOf(layout.size_of.at(b));
          local.push_back({b, size, layout.offset.at(b), tb});
          size += tb;
        }
    Hl.setZero(size, size);
    gl.setZero(size);
    for (std::size_t i : layout.factors_of.at(landmark))
      linearize.addTo(*factors_[i].cost, factors_[i].loss.get(), factors_[i].blocks, localOffset,
                      &Hl, &gl);
    // Pseudo-inverse: a landmark can be unconstrained in some direction.
    const Eigen::MatrixXd inv = symmetricPseudoInverse(Hl.topLeftCorner(t, t));
    const int rest = size - t;
    K.noalias() = Hl.bottomLeftCorner(rest, t) * inv;
    // Column by column: outer products of vectors, cheaper than a matrix product this thin.
    for (int j = 0; j < t; ++j)
      Hl.bottomRightCorner(rest, rest).noalias() -= K.col(j) * Hl.row(j).tail(rest);
    gl.tail(rest).noalias() -= K * gl.head(t);
    // Scatter into the states' system by runs of blocks that are neighbours both here and
    // there (a landmark's poses mostly are): a few block sums instead of one per block pair,
    // each entry added once as before.
    runs.clear();
    for (std::size_t a = 1; a < local.size(); ++a) {
      const LocalBlock& la = local[a];
      if (!runs.empty() && runs.back().offset + runs.back().size == la.offset)
        runs.back().size += la.tangent_size;  // local offsets are consecutive already
      else
        runs.push_back({la.local_offset, la.offset, la.tangent_size});
    }
    for (const Run& ra : runs) {
      g.segment(ra.offset, ra.size) += gl.segment(ra.local_offset, ra.size);
      for (const Run& rb : runs)
        H.block(ra.offset, rb.offset, ra.size, rb.size) +=
            Hl.block(ra.local_offset, rb.local_offset, ra.size, rb.size);
    }
  }

  // Schur complement onto the kept states.
  Eigen::MatrixXd Hrr = H.bottomRightCorner(n, n);
  Eigen::VectorXd gr = g.tail(n);
  if (m > 0) {
    const Eigen::MatrixXd Hmm_inv = symmetricPseudoInverse(H.topLeftCorner(m, m));
    const Eigen::MatrixXd Hrm = H.bottomLeftCorner(n, m);
    Hrr -= Hrm * Hmm_inv * Hrm.transpose();
    gr -= Hrm * Hmm_inv * g.head(m);
  }
  // A random walk of variance q on kept coordinate k keeps the prior's mean and makes its
  // covariance P + q e_k e_k^T; by Woodbury the information becomes H - s H e_k e_k^T H with
  // s = 1 / (1/q + H_kk), which needs no inverse of a possibly singular H.
  for (const auto& [block, variance] : random_walks_) {
    const auto at = layout.offset.find(block);
    if (at == layout.offset.end() || at->second < m || layout.size_of.at(block) != 1) continue;
    const int k = at->second - m;
    const double s = 1.0 / (1.0 / variance + Hrr(k, k));
    const Eigen::VectorXd h = Hrr.col(k);
    gr -= s * gr(k) * h;
    Hrr -= s * h * h.transpose();
  }
  factorPrior(0.5 * (Hrr + Hrr.transpose()), gr, &linearized_jacobian_, &linearized_residual_);
}

std::vector<double*> MarginalizationInfo::keptBlocks(
    const std::map<double*, double*>& shift) const {
  std::vector<double*> out;
  for (double* b : kept_addresses_) {
    const auto it = shift.find(b);
    if (it == shift.end())
      throw Error("marginalisation: a kept block has no place in the new window");
    out.push_back(it->second);
  }
  return out;
}

MarginalizationFactor::MarginalizationFactor(std::shared_ptr<const MarginalizationInfo> info)
    : info_(std::move(info)) {
  for (int size : info_->keptSizes()) mutable_parameter_block_sizes()->push_back(size);
  set_num_residuals(static_cast<int>(info_->linearizedJacobian().rows()));
}

bool MarginalizationFactor::Evaluate(double const* const* parameters, double* residuals,
                                     double** jacobians) const {
  const int n = info_->keptTangentSize();
  const auto& sizes = info_->keptSizes();
  Eigen::VectorXd dx(n);
  int offset = 0;
  for (std::size_t k = 0; k < sizes.size(); ++k) {
    const int t = tangentSizeOf(sizes[k]);
    dx.segment(offset, t) =
        tangentDifference(parameters[k], info_->keptLinearizationPoints()[k].data(), sizes[k]);
    offset += t;
  }
  const int rows = static_cast<int>(info_->linearizedJacobian().rows());
  Eigen::Map<Eigen::VectorXd> r(residuals, rows);
  r = info_->linearizedResidual() + info_->linearizedJacobian() * dx;
  if (!jacobians) return true;
  offset = 0;
  for (std::size_t k = 0; k < sizes.size(); ++k) {
    const int t = tangentSizeOf(sizes[k]);
    if (jacobians[k]) {
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J(
          jacobians[k], rows, sizes[k]);
      const auto Jt = info_->linearizedJacobian().middleCols(offset, t);
      if (sizes[k] != 7) {
        J = Jt;
      } else {
        // d Minus(x, x0)/d delta at x is I for the position and the inverse left Jacobian of
        // the rotation difference (in Ceres' half-angle units, phi = 2 delta); mapped to the
        // ambient space with P^T, since P^T P = I.
        const Eigen::Vector3d half_angle = dx.segment<3>(offset + 3);
        Eigen::Matrix<double, 6, 6> D = Eigen::Matrix<double, 6, 6>::Identity();
        D.bottomRightCorner<3, 3>() = inverseLeftJacobian(2.0 * half_angle);
        const Eigen::Matrix<double, 6, 7> to_ambient =
            D * posePlusJacobian(parameters[k]).transpose();
        J.noalias() = Jt * to_ambient;
      }
    }
    offset += t;
  }
  return true;
}

}  // namespace alvio
