#include "alvio/estimator/factors/marginalization.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "alvio/common/error.h"
#include "alvio/common/rotation.h"
#include "alvio/estimator/pose_manifold.h"

namespace alvio {
namespace {

// Tangent-space Jacobian of one block from its ambient (row-major) Jacobian, into `J`
// (whose storage is reused).
void tangentJacobian(
    const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>& J_ambient,
    const double* x, int size, Eigen::MatrixXd* J) {
  if (size != 7)
    *J = J_ambient;
  else
    J->noalias() = J_ambient * posePlusJacobian(x);
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

// Robust-loss correction of residual and Jacobians, as Ceres' Corrector does.
void applyLoss(const ceres::LossFunction& loss, Eigen::VectorXd* r,
               std::vector<Eigen::MatrixXd>* jacobians) {
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
  for (auto& J : *jacobians) J = sqrt_rho1 * (J - alpha_sq_norm * (*r) * (r->transpose() * J));
  *r *= residual_scaling;
}

}  // namespace

void MarginalizationInfo::addResidualBlock(ceres::CostFunction* cost, ceres::LossFunction* loss,
                                           std::vector<double*> blocks, std::vector<int> drop) {
  Block b;
  b.cost.reset(cost);
  b.loss.reset(loss);
  b.blocks = std::move(blocks);
  b.drop = std::move(drop);
  factors_.push_back(std::move(b));
}

bool MarginalizationInfo::marginalize() {
  // Order the blocks: dropped first, then kept, each with a tangent offset.
  std::unordered_map<double*, int> size_of;
  std::vector<double*> dropped, kept;
  std::unordered_map<double*, bool> is_dropped;
  for (const auto& f : factors_) {
    const auto& sizes = f.cost->parameter_block_sizes();
    for (std::size_t k = 0; k < f.blocks.size(); ++k) size_of[f.blocks[k]] = sizes[k];
    for (int d : f.drop) is_dropped[f.blocks[d]] = true;
  }
  for (const auto& f : factors_)
    for (double* b : f.blocks) {
      auto& list = is_dropped.count(b) ? dropped : kept;
      if (std::find(list.begin(), list.end(), b) == list.end()) list.push_back(b);
    }
  // Landmark blocks (inverse depths, lines: size 1 or 4) first: they couple only with the
  // states, never with each other, so they are eliminated one by one below.
  std::stable_partition(dropped.begin(), dropped.end(),
                        [&](double* b) { return size_of[b] == 1 || size_of[b] == 4; });
  std::unordered_map<double*, int> offset;
  int m = 0, n = 0, m_landmarks = 0;
  for (double* b : dropped) {
    offset[b] = m;
    m += tangentSizeOf(size_of[b]);
    if (size_of[b] == 1 || size_of[b] == 4) m_landmarks = m;
  }
  for (double* b : kept) offset[b] = m + n, n += tangentSizeOf(size_of[b]);
  if (n == 0) return false;

  // Gauss-Newton system of all factors at the current values. The per-factor matrices keep
  // their storage from one factor to the next: most factors have the same shapes.
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(m + n, m + n);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(m + n);
  Eigen::VectorXd r;
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> Ja;
  std::vector<double*> jac_ptrs;
  std::vector<Eigen::MatrixXd> Jt;
  Eigen::MatrixXd Hab;
  for (const auto& f : factors_) {
    const int num_residuals = f.cost->num_residuals();
    const auto& sizes = f.cost->parameter_block_sizes();
    r.resize(num_residuals);
    Ja.resize(f.blocks.size());
    jac_ptrs.resize(f.blocks.size());
    Jt.resize(f.blocks.size());
    for (std::size_t k = 0; k < f.blocks.size(); ++k) {
      Ja[k].resize(num_residuals, sizes[k]);
      jac_ptrs[k] = Ja[k].data();
    }
    if (!f.cost->Evaluate(f.blocks.data(), r.data(), jac_ptrs.data()))
      throw Error("marginalisation: a factor failed to evaluate");
    for (std::size_t k = 0; k < f.blocks.size(); ++k)
      tangentJacobian(Ja[k], f.blocks[k], sizes[k], &Jt[k]);
    if (f.loss) applyLoss(*f.loss, &r, &Jt);
    for (std::size_t a = 0; a < f.blocks.size(); ++a) {
      const int ia = offset[f.blocks[a]];
      g.segment(ia, Jt[a].cols()) += Jt[a].transpose() * r;
      for (std::size_t b = a; b < f.blocks.size(); ++b) {
        const int ib = offset[f.blocks[b]];
        Hab.noalias() = Jt[a].transpose() * Jt[b];
        H.block(ia, ib, Hab.rows(), Hab.cols()) += Hab;
        if (a != b) H.block(ib, ia, Hab.cols(), Hab.rows()) += Hab.transpose();
      }
    }
  }

  // Schur complement onto the kept states. Landmarks go first, block by block (their blocks
  // are tiny and mutually independent), then the remaining dropped states densely; both
  // with pseudo-inverses, as a landmark can be unconstrained in some direction.
  auto pseudoInverse = [](const Eigen::MatrixXd& A) {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (A + A.transpose()));
    const Eigen::VectorXd inv =
        (es.eigenvalues().array() > 1e-8).select(es.eigenvalues().array().inverse(), 0.0);
    return Eigen::MatrixXd(es.eigenvectors() * inv.asDiagonal() * es.eigenvectors().transpose());
  };
  const int total = m + n;
  for (double* b : dropped) {
    const int o = offset[b], t = tangentSizeOf(size_of[b]);
    if (o >= m_landmarks) break;
    const Eigen::MatrixXd inv = pseudoInverse(H.block(o, o, t, t));
    const int rest = total - m_landmarks;  // eliminate into the states and kept blocks only
    const Eigen::MatrixXd Hxl = H.block(m_landmarks, o, rest, t);
    const Eigen::MatrixXd K = Hxl * inv;
    H.bottomRightCorner(rest, rest).noalias() -= K * Hxl.transpose();
    g.tail(rest).noalias() -= K * g.segment(o, t);
  }
  Eigen::MatrixXd Hrr = H.bottomRightCorner(n, n);
  Eigen::VectorXd gr = g.tail(n);
  const int m_states = m - m_landmarks;
  if (m_states > 0) {
    const Eigen::MatrixXd Hmm_inv =
        pseudoInverse(H.block(m_landmarks, m_landmarks, m_states, m_states));
    const Eigen::MatrixXd Hrm = H.block(m, m_landmarks, n, m_states);
    Hrr -= Hrm * Hmm_inv * Hrm.transpose();
    gr -= Hrm * Hmm_inv * g.segment(m_landmarks, m_states);
  }

  // Factor the prior as |J dx + r|^2: Hrr = J^T J, gr = J^T r.
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(0.5 * (Hrr + Hrr.transpose()));
  const Eigen::VectorXd S = (es.eigenvalues().array() > 1e-8).select(es.eigenvalues().array(), 0.0);
  const Eigen::VectorXd S_inv =
      (es.eigenvalues().array() > 1e-8).select(es.eigenvalues().array().inverse(), 0.0);
  linearized_jacobian_ = S.cwiseSqrt().asDiagonal() * es.eigenvectors().transpose();
  linearized_residual_ = S_inv.cwiseSqrt().asDiagonal() * es.eigenvectors().transpose() * gr;

  kept_addresses_ = kept;
  kept_sizes_.clear();
  kept_tangent_sizes_.clear();
  kept_values_.clear();
  for (double* b : kept) {
    kept_sizes_.push_back(size_of[b]);
    kept_tangent_sizes_.push_back(tangentSizeOf(size_of[b]));
    kept_values_.emplace_back(b, b + size_of[b]);
  }
  kept_tangent_size_ = n;
  factors_.clear();  // the evaluated factors are no longer needed
  return true;
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
  set_num_residuals(info_->keptTangentSize());
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
  Eigen::Map<Eigen::VectorXd> r(residuals, n);
  r = info_->linearizedResidual() + info_->linearizedJacobian() * dx;
  if (!jacobians) return true;
  offset = 0;
  for (std::size_t k = 0; k < sizes.size(); ++k) {
    const int t = tangentSizeOf(sizes[k]);
    if (jacobians[k]) {
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J(
          jacobians[k], n, sizes[k]);
      const Eigen::MatrixXd Jt = info_->linearizedJacobian().middleCols(offset, t);
      if (sizes[k] != 7) {
        J = Jt;
      } else {
        // d Minus(x, x0)/d delta at x is I for the position and the inverse left Jacobian of
        // the rotation difference (in Ceres' half-angle units, phi = 2 delta); mapped to the
        // ambient space with P^T, since P^T P = I.
        const Eigen::Vector3d half_angle = dx.segment<3>(offset + 3);
        Eigen::Matrix<double, 6, 6> D = Eigen::Matrix<double, 6, 6>::Identity();
        D.bottomRightCorner<3, 3>() = inverseLeftJacobian(2.0 * half_angle);
        J = Jt * D * posePlusJacobian(parameters[k]).transpose();
      }
    }
    offset += t;
  }
  return true;
}

}  // namespace alvio
