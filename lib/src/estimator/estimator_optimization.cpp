// The per-frame optimisation of the sliding window and the marginalisation
// that follows it.
#include <ceres/loss_function.h>
#include <ceres/ordered_groups.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "alvio/common/logging.h"
#include "alvio/common/rotation.h"
#include "alvio/estimator/estimator.h"
#include "alvio/estimator/factors/bias_prior_factor.h"
#include "alvio/estimator/factors/imu_factor.h"
#include "alvio/estimator/factors/line_step_damping_factor.h"
#include "alvio/estimator/factors/marginalization.h"
#include "alvio/estimator/factors/point_projection_factor.h"
#include "alvio/estimator/point_noise.h"
#include "alvio/estimator/pose_manifold.h"
#include "alvio/geometry/line_projection_factor.h"
#include "alvio/geometry/line_quality.h"
#include "alvio/geometry/line_triangulation.h"
#include "alvio/geometry/orthonormal_line.h"
#include "alvio/geometry/orthonormal_line_manifold.h"

namespace alvio {
namespace {

// IMU factors over longer gaps are meaningless (the preintegration drifts).
constexpr double kMaxImuFactorSpan = 10.0;

ceres::LossFunction* makeLoss(const EstimatorOptions& o) {
  if (o.robust_loss == "huber") return new ceres::HuberLoss(o.robust_loss_scale);
  if (o.robust_loss == "cauchy") return new ceres::CauchyLoss(o.robust_loss_scale);
  return nullptr;
}

}  // namespace

bool Estimator::pointSelected(const PointLandmark& l) const {
  const FeatureSelectionOptions& o = options_.selection;
  if (!o.select_points) return true;
  const Eigen::Vector2d& px = l.sightings.front().px;
  return o.point_surface.keep(px.x(), px.y());
}

bool Estimator::lineSelected(const LineLandmark& l) const {
  const FeatureSelectionOptions& o = options_.selection;
  if (!o.select_lines) return true;
  // Midpoint of the first observation in the window, in the undistorted image.
  const auto& first = l.observations.begin()->second;
  const Eigen::Vector2d mid = 0.5 * (first.start_norm + first.end_norm);
  return o.line_surface.keep(camera_.intrinsics[0] * mid.x() + camera_.intrinsics[2],
                             camera_.intrinsics[1] * mid.y() + camera_.intrinsics[3]);
}

void Estimator::updateWeights() {
  stats_ = OptimizationStats();
  double track_p = 0, track_l = 0;
  // Residuals of the selected features: what optimize() adds.
  int& point_residuals = stats_.point_residuals;
  int& line_residuals = stats_.line_residuals;
  for (const auto& [id, l] : points_.landmarks()) {
    if (!l.usable(W_)) continue;
    ++stats_.points_tracked;
    track_p += l.sightings.size();
    if (!pointSelected(l)) continue;
    ++stats_.points_used;
    point_residuals += static_cast<int>(l.sightings.size()) - 1;
  }
  for (const auto& [id, l] : lines_.landmarks()) {
    if (!options_.use_lines || !lines_.usable(l)) continue;
    ++stats_.lines_tracked;
    track_l += l.observations.size();
    if (!lineSelected(l)) continue;
    ++stats_.lines_used;
    line_residuals += static_cast<int>(l.observations.size());
  }
  const FeatureSelectionOptions& o = options_.selection;
  const double M_p = trackMeasure(track_p, stats_.points_tracked, W_ + 1, o.weights_by_count);
  const double M_l = trackMeasure(track_l, stats_.lines_tracked, W_ + 1, o.weights_by_count);
  // By length, alpha's case; with track_measure: length that is M itself.
  const FeatureWeights w =
      o.alpha_case_by_length
          ? adaptiveWeights(M_p, M_l, trackMeasure(track_p, stats_.points_tracked, W_ + 1, false),
                            trackMeasure(track_l, stats_.lines_tracked, W_ + 1, false), o)
          : adaptiveWeights(M_p, M_l, o);
  stats_.w_p = w.w_p;
  stats_.w_l = w.w_l;
  stats_.alpha = w.alpha;
  stats_.M_p = M_p;
  stats_.M_l = M_l;
  ResidualScales scales;  // unweighted
  if (o.adaptive_weighting && options_.use_lines)
    scales = residualScales(w, point_residuals, line_residuals, o.normalize_weights, o.weights_on);
  point_scale_ = scales.points;
  line_scale_ = scales.lines;
}

void Estimator::statesToParameters() {
  for (int i = 0; i <= W_; ++i) {
    Eigen::Map<Eigen::Vector3d>{para_pose_[i].data()} = Ps_[i];
    Eigen::Map<Eigen::Quaterniond>{para_pose_[i].data() + 3} =
        Eigen::Quaterniond(Rs_[i]).normalized();
    Eigen::Map<Eigen::Matrix<double, 9, 1>> sb(para_speed_bias_[i].data());
    sb << Vs_[i], Bas_[i], Bgs_[i];
  }
  const Eigen::VectorXd inv = points_.inverseDepths();
  para_landmarks_.assign(inv.data(), inv.data() + inv.size());
  num_point_params_ = para_landmarks_.size();
  for (const auto& [id, l] : lines_.landmarks()) {
    if (!lines_.usable(l)) continue;
    const std::size_t at = para_landmarks_.size();
    para_landmarks_.resize(at + OrthonormalLine::kParameterSize);
    OrthonormalLine::fromPlucker(l.line_w).toParameters(&para_landmarks_[at]);
  }
  para_time_shift_[0] = time_shift_;
}

double Estimator::windowTurnRate() const {
  double sum = 0;
  std::size_t n = 0;
  for (int i = 1; i <= frame_count_; ++i)
    for (const Eigen::Vector3d& w : gyr_buf_[i]) {
      sum += (w - Bgs_[i]).squaredNorm();
      ++n;
    }
  return n > 0 ? std::sqrt(sum / static_cast<double>(n)) : 0.0;
}

bool Estimator::timeShiftEstimated() const {
  return options_.estimate_time_shift && status_ == EstimatorStatus::kTracking;
}

double* Estimator::lineBlock(std::size_t k) {
  return &para_landmarks_[num_point_params_ + OrthonormalLine::kParameterSize * k];
}

PointProjectionFactor* Estimator::newPointFactor(const PointSighting& obs_i,
                                                 const PointSighting& obs_j, int i, int j) const {
  const double dt = 1e-9 * static_cast<double>(header_ns_[j] - header_ns_[i]);
  const double sigma =
      pointObservationSigmaPx(options_.point_sigma_px, options_.point_drift_px2_per_s, dt);
  const double sqrt_info = point_scale_ * camera_.intrinsics[0] / sigma;
  auto* factor =
      new PointProjectionFactor(obs_i.xy1.head<2>(), obs_j.xy1.head<2>(), T_b_c_, sqrt_info);
  if (timeShiftEstimated()) factor->estimateTimeShift(obs_i.velocity, obs_j.velocity);
  return factor;
}

LineProjectionFactor* Estimator::newLineFactor(const LineLandmarkObservation& obs) const {
  const double sqrt_info = line_scale_ * camera_.intrinsics[0] / options_.line_sigma_px;
  auto* factor = new LineProjectionFactor(obs.start_norm, obs.end_norm, T_b_c_, sqrt_info);
  if (timeShiftEstimated()) factor->estimateTimeShift(obs.start_velocity, obs.end_velocity);
  return factor;
}

std::map<int64_t, int> Estimator::windowSlots() const {
  std::map<int64_t, int> slot;
  for (int i = 0; i <= frame_count_; ++i) slot[header_ns_[i]] = i;
  return slot;
}

void Estimator::parametersToStates() {
  // The window is only constrained up to a yaw and a translation (plus the prior): keep the
  // oldest keyframe's yaw and position where they were, so the output does not wander.
  const Eigen::Vector3d origin_P0 = Ps_[0];
  const Eigen::Matrix3d R0_new =
      Eigen::Quaterniond(para_pose_[0][6], para_pose_[0][3], para_pose_[0][4], para_pose_[0][5])
          .normalized()
          .toRotationMatrix();
  const Eigen::Matrix3d rot_diff =
      Eigen::AngleAxisd(yawAlignment(Rs_[0], R0_new), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d P0_new(para_pose_[0][0], para_pose_[0][1], para_pose_[0][2]);
  for (int i = 0; i <= W_; ++i) {
    const Eigen::Quaterniond q(para_pose_[i][6], para_pose_[i][3], para_pose_[i][4],
                               para_pose_[i][5]);
    Rs_[i] = rot_diff * q.normalized().toRotationMatrix();
    const Eigen::Vector3d p(para_pose_[i][0], para_pose_[i][1], para_pose_[i][2]);
    Ps_[i] = rot_diff * (p - P0_new) + origin_P0;
    const Eigen::Map<const Eigen::Matrix<double, 9, 1>> sb(para_speed_bias_[i].data());
    Vs_[i] = rot_diff * sb.segment<3>(0);
    Bas_[i] = sb.segment<3>(3);
    Bgs_[i] = sb.segment<3>(6);
  }
  points_.setInverseDepths(
      Eigen::Map<const Eigen::VectorXd>(para_landmarks_.data(), num_point_params_));
  if (timeShiftEstimated()) time_shift_ = para_time_shift_[0];
  // The lines' optimised parameters are not kept: each solve restarts them from the
  // triangulation. Keeping them was measured worse, in ATE and in the map
  // (docs/benchmarks.md, seventh session).
}

void Estimator::optimize(FrameTiming* timing, int max_iterations, bool triangulate_lines) {
  {
    ScopedStage stage(timing, "triangulation");
    std::vector<Eigen::Vector3d> P(Ps_.begin(), Ps_.end());
    std::vector<Eigen::Matrix3d> R(Rs_.begin(), Rs_.end());
    points_.triangulate(P, R, T_b_c_);
    const FeatureSelectionOptions& sel = options_.selection;
    if (sel.select_points && sel.refresh_unselected)
      points_.retriangulate(P, R, T_b_c_,
                            [this](const PointLandmark& l) { return !pointSelected(l); });
    if (options_.use_lines && triangulate_lines)
      lines_.triangulate([this](int64_t ns) { return cameraPose(ns); });
  }
  ScopedStage stage(timing, "optimization");
  updateWeights();
  statesToParameters();
  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
#ifdef NDEBUG
  // Ceres' checks (no block passed twice to a residual, none overlapping another) sort and
  // look up every residual's blocks on each solve. The window's blocks are separate fixed
  // arrays; builds without NDEBUG still check them.
  problem_options.disable_all_safety_checks = true;
#endif
  ceres::Problem problem(problem_options);
  // Landmarks are eliminated first, states form the reduced system. Left to itself Ceres also
  // eliminates every other speed-bias block, whose 15-row IMU residuals then force its slowest
  // (all-dynamic) Schur eliminator. A group of its own for each state fixes their order, which
  // Ceres would otherwise take from their addresses.
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  std::unique_ptr<ceres::LossFunction> loss(makeLoss(options_));
  auto* pose_manifold = new PoseManifold();  // shared by all pose blocks, owned by the problem
  for (int i = 0; i <= frame_count_; ++i) {
    problem.AddParameterBlock(para_pose_[i].data(), kPoseSize, pose_manifold);
    problem.AddParameterBlock(para_speed_bias_[i].data(), kSpeedBiasSize);
    ordering->AddElementToGroup(para_pose_[i].data(), 1 + 2 * i);
    ordering->AddElementToGroup(para_speed_bias_[i].data(), 2 + 2 * i);
  }
  // The visual factors' blocks after the landmark's: the time shift's, when estimated.
  std::vector<double*> time_shift_block;
  if (timeShiftEstimated()) {
    problem.AddParameterBlock(para_time_shift_.data(), 1);
    ordering->AddElementToGroup(para_time_shift_.data(), 3 + 2 * W_);
    time_shift_block.push_back(para_time_shift_.data());
    if (windowTurnRate() < options_.time_shift_min_turn_rate)
      problem.SetParameterBlockConstant(para_time_shift_.data());
  }
  const auto with_time_shift = [&time_shift_block](std::vector<double*> blocks) {
    blocks.insert(blocks.end(), time_shift_block.begin(), time_shift_block.end());
    return blocks;
  };
  if (last_marginalization_)
    problem.AddResidualBlock(new MarginalizationFactor(last_marginalization_), nullptr,
                             last_marginalization_blocks_);
  if (bias_prior_pending_)
    problem.AddResidualBlock(
        new BiasPriorFactor(bias_prior_ba_, bias_prior_bg_, options_.init_accel_bias_sigma,
                            options_.init_gyro_bias_sigma),
        nullptr, para_speed_bias_[0].data());
  for (int i = 0; i < frame_count_; ++i) {
    const int j = i + 1;
    if (preintegrations_[j]->sumDt() > kMaxImuFactorSpan) continue;
    problem.AddResidualBlock(new ImuFactor(preintegrations_[j].get(), gravity_), nullptr,
                             para_pose_[i].data(), para_speed_bias_[i].data(), para_pose_[j].data(),
                             para_speed_bias_[j].data());
  }
  int index = -1;
  for (const auto& [id, l] : points_.landmarks()) {
    if (!l.usable(W_)) continue;
    ++index;
    if (!pointSelected(l)) continue;
    const int i = l.start_frame;
    if (l.sightings.size() > 1) ordering->AddElementToGroup(inverseDepthBlock(index), 0);
    for (std::size_t k = 1; k < l.sightings.size(); ++k) {
      const int j = i + static_cast<int>(k);
      problem.AddResidualBlock(
          newPointFactor(l.sightings.front(), l.sightings[k], i, j), loss.get(),
          with_time_shift({para_pose_[i].data(), para_pose_[j].data(), inverseDepthBlock(index)}));
    }
  }
  // Lines: one factor per window observation, on the observing frame's pose.
  if (options_.use_lines) {
    auto* line_manifold = new OrthonormalLineManifold();  // owned by the problem
    const std::map<int64_t, int> slot = windowSlots();
    std::size_t k = 0;
    for (const auto& [id, l] : lines_.landmarks()) {
      if (!lines_.usable(l)) continue;
      double* line_block = lineBlock(k++);
      if (!lineSelected(l)) continue;
      problem.AddParameterBlock(line_block, OrthonormalLine::kParameterSize, line_manifold);
      ordering->AddElementToGroup(line_block, 0);
      for (const auto& [ns, obs] : l.observations)
        problem.AddResidualBlock(newLineFactor(obs), loss.get(),
                                 with_time_shift({para_pose_[slot.at(ns)].data(), line_block}));
      if (options_.line_step_damping > 0)
        for (int half : {0, 1})
          problem.AddResidualBlock(
              new LineStepDampingHalfFactor(line_block, options_.line_step_damping, half), nullptr,
              line_block);
    }
  }

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_SCHUR;
  options.linear_solver_ordering = ordering;
  options.trust_region_strategy_type = ceres::DOGLEG;
  options.max_num_iterations = max_iterations;
  options.num_threads = options_.num_threads;
  // Ceres formats a log line every iteration unless silent, even when nothing prints it.
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  stats_.iterations = static_cast<int>(summary.iterations.size());
  stats_.unsuccessful_steps = summary.num_unsuccessful_steps;
  // Ceres counts the starting point as a successful iteration 0.
  stats_.accepted_steps = std::max(0, summary.num_successful_steps - 1);
  stats_.solver_ms = 1e3 * summary.total_time_in_seconds;
  stats_.linear_solver_ms = 1e3 * summary.linear_solver_time_in_seconds;
  stats_.jacobian_ms = 1e3 * summary.jacobian_evaluation_time_in_seconds;
  stats_.schur_structure = summary.schur_structure_used;
  parametersToStates();
  removeReprojectionOutliers();
  if (options_.use_lines) {
    removeLineOutliers();
    lines_.updateExtents([this](int64_t ns) { return cameraPose(ns); });
    updateLineUncertainty();
  }
}

void Estimator::removeReprojectionOutliers() {
  // Mean reprojection error of each landmark over the window, in pixels.
  const double f = camera_.intrinsics[0];
  const Eigen::Isometry3d T_c_b = T_b_c_.inverse();
  std::vector<int> outliers;
  for (const auto& [id, l] : points_.landmarks()) {
    if (!l.usable(W_) || l.depth <= 0) continue;
    const int i = l.start_frame;
    const Eigen::Vector3d p_w = Rs_[i] * (T_b_c_ * (l.sightings.front().xy1 * l.depth)) + Ps_[i];
    double err = 0;
    int n = 0;
    for (std::size_t k = 1; k < l.sightings.size(); ++k) {
      const int j = i + static_cast<int>(k);
      const Eigen::Vector3d p_c = T_c_b * (Rs_[j].transpose() * (p_w - Ps_[j]));
      err += (p_c.head<2>() / p_c.z() - l.sightings[k].xy1.head<2>()).norm() * f;
      ++n;
    }
    if (n > 0 && err / n > options_.outlier_reprojection_px) outliers.push_back(id);
  }
  points_.removeIds(outliers);
}

void Estimator::marginalize() {
  statesToParameters();
  std::vector<double*> time_shift_block;
  if (timeShiftEstimated()) time_shift_block.push_back(para_time_shift_.data());
  const auto with_time_shift = [&time_shift_block](std::vector<double*> blocks) {
    blocks.insert(blocks.end(), time_shift_block.begin(), time_shift_block.end());
    return blocks;
  };
  if (marginalization_ == Marginalization::kOld) {
    auto info = std::make_shared<MarginalizationInfo>();
    if (last_marginalization_) {
      std::vector<int> drop;
      for (std::size_t k = 0; k < last_marginalization_blocks_.size(); ++k)
        if (last_marginalization_blocks_[k] == para_pose_[0].data() ||
            last_marginalization_blocks_[k] == para_speed_bias_[0].data())
          drop.push_back(static_cast<int>(k));
      info->addResidualBlock(new MarginalizationFactor(last_marginalization_), nullptr,
                             last_marginalization_blocks_, drop);
    }
    if (bias_prior_pending_) {
      // The prior leaves the window with the oldest keyframe: into the marginalisation prior.
      info->addResidualBlock(
          new BiasPriorFactor(bias_prior_ba_, bias_prior_bg_, options_.init_accel_bias_sigma,
                              options_.init_gyro_bias_sigma),
          nullptr, {para_speed_bias_[0].data()}, {0});
      bias_prior_pending_ = false;
    }
    if (preintegrations_[1]->sumDt() < kMaxImuFactorSpan)
      info->addResidualBlock(new ImuFactor(preintegrations_[1].get(), gravity_), nullptr,
                             {para_pose_[0].data(), para_speed_bias_[0].data(),
                              para_pose_[1].data(), para_speed_bias_[1].data()},
                             {0, 1});
    int index = -1;
    for (const auto& [id, l] : points_.landmarks()) {
      if (!l.usable(W_)) continue;
      ++index;
      if (l.start_frame != 0) continue;
      if (!options_.selection.marginalize_unselected && !pointSelected(l)) continue;
      for (std::size_t k = 1; k < l.sightings.size(); ++k)
        info->addResidualBlock(
            newPointFactor(l.sightings.front(), l.sightings[k], 0, static_cast<int>(k)),
            makeLoss(options_),
            with_time_shift({para_pose_[0].data(), para_pose_[k].data(), inverseDepthBlock(index)}),
            {0, 2});
    }
    if (options_.use_lines) {
      // Lines first seen in the oldest frame leave the state with it, like points anchored
      // there: all their window observations go into the prior.
      const std::map<int64_t, int> slot = windowSlots();
      std::size_t k = 0;
      for (const auto& [id, l] : lines_.landmarks()) {
        if (!lines_.usable(l)) continue;
        double* line_block = lineBlock(k++);
        if (l.observations.begin()->first != header_ns_[0]) continue;
        if (!options_.selection.marginalize_unselected && !lineSelected(l)) continue;
        for (const auto& [ns, obs] : l.observations)
          info->addResidualBlock(newLineFactor(obs), makeLoss(options_),
                                 with_time_shift({para_pose_[slot.at(ns)].data(), line_block}),
                                 {1});
      }
    }
    // The shift drifts: what the prior knows of it fades over the oldest keyframe's span.
    if (timeShiftEstimated())
      info->addRandomWalk(para_time_shift_.data(), options_.time_shift_random_walk *
                                                       options_.time_shift_random_walk *
                                                       (headers_[1] - headers_[0]));
    if (!info->marginalize()) {
      last_marginalization_.reset();
      last_marginalization_blocks_.clear();
      return;
    }
    std::map<double*, double*> shift;
    for (int i = 1; i <= W_; ++i) {
      shift[para_pose_[i].data()] = para_pose_[i - 1].data();
      shift[para_speed_bias_[i].data()] = para_speed_bias_[i - 1].data();
    }
    shift[para_time_shift_.data()] = para_time_shift_.data();
    last_marginalization_blocks_ = info->keptBlocks(shift);
    last_marginalization_ = info;
    return;
  }
  // Dropping the second-newest frame: only the prior can involve it.
  if (!last_marginalization_) return;
  std::vector<int> drop;
  for (std::size_t k = 0; k < last_marginalization_blocks_.size(); ++k)
    if (last_marginalization_blocks_[k] == para_pose_[W_ - 1].data())
      drop.push_back(static_cast<int>(k));
  if (drop.empty()) return;
  auto info = std::make_shared<MarginalizationInfo>();
  info->addResidualBlock(new MarginalizationFactor(last_marginalization_), nullptr,
                         last_marginalization_blocks_, drop);
  if (!info->marginalize()) {
    last_marginalization_.reset();
    last_marginalization_blocks_.clear();
    return;
  }
  std::map<double*, double*> shift;
  for (int i = 0; i <= W_; ++i) {
    if (i == W_ - 1) continue;
    double* to_pose = i == W_ ? para_pose_[W_ - 1].data() : para_pose_[i].data();
    double* to_sb = i == W_ ? para_speed_bias_[W_ - 1].data() : para_speed_bias_[i].data();
    shift[para_pose_[i].data()] = to_pose;
    shift[para_speed_bias_[i].data()] = to_sb;
  }
  shift[para_speed_bias_[W_ - 1].data()] = para_speed_bias_[W_ - 1].data();
  shift[para_time_shift_.data()] = para_time_shift_.data();
  last_marginalization_blocks_ = info->keptBlocks(shift);
  last_marginalization_ = info;
}

void Estimator::removeLineOutliers() {
  // Mean endpoint-to-line distance over the window, in pixels; lines that the observed
  // endpoints' rays meet behind a camera go too.
  const double f = camera_.intrinsics[0];
  std::vector<int> outliers;
  for (const auto& [id, l] : lines_.landmarks()) {
    if (!lines_.usable(l)) continue;
    double err = 0;
    bool behind = false;
    for (const auto& [ns, obs] : l.observations) {
      const PluckerLine lc = l.line_w.transformed(cameraPose(ns).inverse());
      double d_start = 0, d_end = 0;
      if (!imageLineEndpointDistances(lc, obs.start_norm, obs.end_norm, &d_start, &d_end)) {
        behind = true;  // seen end-on
        break;
      }
      err += 0.5 * d_start * f;
      err += 0.5 * d_end * f;
      for (const Eigen::Vector2d& e : {obs.start_norm, obs.end_norm}) {
        double s_line = 0, t_ray = 0;
        if (closestPointOnLineToRay(lc, Eigen::Vector3d::Zero(), Eigen::Vector3d(e.x(), e.y(), 1),
                                    &s_line, &t_ray))
          behind |= t_ray < options_.line_triangulation.min_depth;
      }
    }
    if (behind || err / l.observations.size() > options_.line_outlier_px) outliers.push_back(id);
  }
  lines_.removeIds(outliers);
}

void Estimator::updateLineUncertainty() {
  const double sigma = options_.line_map_sigma_px / camera_.intrinsics[0];
  for (auto& [id, l] : lines_.landmarks()) {
    if (!lines_.usable(l)) continue;
    LineViews views;
    for (const auto& [ns, obs] : l.observations) {
      LineView v;
      v.T_w_c = cameraPose(ns);
      v.start_norm = obs.start_norm;
      v.end_norm = obs.end_norm;
      views.push_back(v);
    }
    l.direction_std_deg = lineDirectionStdDeg(l.line_w, views, sigma);
  }
}

}  // namespace alvio
