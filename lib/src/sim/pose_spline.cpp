#include "alvio/sim/pose_spline.h"

#include <algorithm>
#include <cmath>

#include "alvio/common/error.h"
#include "alvio/common/types.h"
#include "alvio/sim/so3.h"

namespace alvio::sim {

Eigen::Isometry3d BodyState::T_w_b() const {
  return isometry(p_w, q_w_b);
}

void cubicBSplineWeights(double u, double w[4], double dw[4], double ddw[4]) {
  const double u2 = u * u, u3 = u2 * u;
  w[0] = (1 - 3 * u + 3 * u2 - u3) / 6;
  w[1] = (4 - 6 * u2 + 3 * u3) / 6;
  w[2] = (1 + 3 * u + 3 * u2 - 3 * u3) / 6;
  w[3] = u3 / 6;
  dw[0] = (-3 + 6 * u - 3 * u2) / 6;
  dw[1] = (-12 * u + 9 * u2) / 6;
  dw[2] = (3 + 6 * u - 9 * u2) / 6;
  dw[3] = 3 * u2 / 6;
  ddw[0] = (6 - 6 * u) / 6;
  ddw[1] = (-12 + 18 * u) / 6;
  ddw[2] = (6 - 18 * u) / 6;
  ddw[3] = u;
}

void cumulativeBSplineWeights(double u, double w[3], double dw[3]) {
  const double u2 = u * u, u3 = u2 * u;
  w[0] = (5 + 3 * u - 3 * u2 + u3) / 6;
  w[1] = (1 + 3 * u + 3 * u2 - 2 * u3) / 6;
  w[2] = u3 / 6;
  dw[0] = (3 - 6 * u + 3 * u2) / 6;
  dw[1] = (3 + 6 * u - 6 * u2) / 6;
  dw[2] = u2 / 2;
}

PoseSpline::PoseSpline(double t0, double dt, Vector3dList positions, QuaternionList rotations)
    : t0_(t0), dt_(dt), positions_(std::move(positions)), rotations_(std::move(rotations)) {
  if (positions_.size() < 4 || positions_.size() != rotations_.size())
    throw Error("PoseSpline needs at least 4 position and rotation controls, equally many");
  if (!(dt_ > 0)) throw Error("PoseSpline knot spacing must be positive");
  for (auto& q : rotations_) q.normalize();
  // The relative rotations between neighbouring controls are constant: cache their logs.
  log_deltas_.resize(rotations_.size());
  log_deltas_[0].setZero();
  for (std::size_t j = 1; j < rotations_.size(); ++j)
    log_deltas_[j] = so3Log(rotations_[j - 1].conjugate() * rotations_[j]);
}

void PoseSpline::locate(double t, int* segment, double* u) const {
  const double s = (t - t0_) / dt_;
  int i = static_cast<int>(std::floor(s));
  i = std::clamp(i, 0, segments() - 1);
  *segment = i;
  *u = std::clamp(s - i, 0.0, 1.0);
}

Eigen::Vector3d PoseSpline::position(double t) const {
  return state(t).p_w;
}

Eigen::Quaterniond PoseSpline::orientation(double t) const {
  int i;
  double u;
  locate(t, &i, &u);
  double w[3], dw[3];
  cumulativeBSplineWeights(u, w, dw);
  Eigen::Quaterniond q = rotations_[i];
  for (int j = 0; j < 3; ++j) q = q * so3Exp(w[j] * log_deltas_[i + j + 1]);
  return q.normalized();
}

Eigen::Isometry3d PoseSpline::pose(double t) const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = orientation(t).toRotationMatrix();
  T.translation() = state(t).p_w;
  return T;
}

BodyState PoseSpline::state(double t) const {
  int i;
  double u;
  locate(t, &i, &u);
  BodyState s;
  s.t = t;
  double w[4], dw[4], ddw[4];
  cubicBSplineWeights(u, w, dw, ddw);
  for (int j = 0; j < 4; ++j) {
    s.p_w += w[j] * positions_[i + j];
    s.v_w += dw[j] / dt_ * positions_[i + j];
    s.a_w += ddw[j] / (dt_ * dt_) * positions_[i + j];
  }
  // Orientation and body rate by the recursion of Sommer et al. (CVPR 2020):
  // omega_j = A_j^T omega_{j-1} + dlambda_j/dt * d_j.
  double cw[3], cdw[3];
  cumulativeBSplineWeights(u, cw, cdw);
  Eigen::Quaterniond q = rotations_[i];
  Eigen::Vector3d omega = Eigen::Vector3d::Zero();
  for (int j = 0; j < 3; ++j) {
    const Eigen::Vector3d& d = log_deltas_[i + j + 1];
    const Eigen::Quaterniond A = so3Exp(cw[j] * d);
    q = q * A;
    omega = A.conjugate() * omega + (cdw[j] / dt_) * d;
  }
  s.q_w_b = q.normalized();
  s.omega_b = omega;
  return s;
}

}  // namespace alvio::sim
