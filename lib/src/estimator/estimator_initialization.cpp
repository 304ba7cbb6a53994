// Initialisation of the estimator: up-to-scale visual structure from motion
// over the window, then alignment with the IMU for scale, gravity, velocities
// and gyroscope bias. Reasons for waiting are reported as events.
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "alvio/common/angles.h"
#include "alvio/common/logging.h"
#include "alvio/common/rotation.h"
#include "alvio/estimator/estimator.h"
#include "alvio/estimator/initialization/structure_from_motion.h"
#include "alvio/estimator/initialization/visual_inertial_alignment.h"

namespace alvio {

bool Estimator::initialize(double t) {
  warm_started_ = false;
  if (warm_restart_armed_ && warm_seeded_) {
    const double age = t - last_output_.t;
    if (age >= 0 && age <= options_.warm_restart_max_s) {
      if (warmStart(t)) {
        last_wait_reason_.clear();
        return true;
      }
    } else {
      warm_restart_armed_ = false;
      logInfo("warm restart given up: the last output is ", age, " s old; structure from motion");
    }
  }
  if (!initialStructure(t)) return false;
  if (!alignWithImu(t)) return false;
  last_wait_reason_.clear();
  return true;
}

namespace {
// Log a reason for waiting once, not on every attempt.
void waitFor(std::string* last, std::vector<EstimatorEvent>* events, double t,
             const std::string& why) {
  if (*last == why) return;
  *last = why;
  logInfo("initialisation waits: ", why);
  EstimatorEvent e;
  e.kind = EstimatorEvent::Kind::kWaiting;
  e.t = t;
  e.message = why;
  events->push_back(std::move(e));
}
}  // namespace

bool Estimator::initialStructure(double t) {
  // Enough accelerometer excitation to observe scale and gravity?
  {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    std::vector<Eigen::Vector3d> g;
    for (const auto& [stamp, f] : all_frames_) {
      if (!f.imu || f.imu->sumDt() <= 0) continue;
      g.push_back(f.imu->deltaV() / f.imu->sumDt());
      sum += g.back();
    }
    if (g.size() < 2) {
      waitFor(&last_wait_reason_, &events_, t, "not enough IMU data in the window");
      return false;
    }
    const Eigen::Vector3d mean = sum / g.size();
    double var = 0;
    for (const auto& x : g) var += (x - mean).squaredNorm();
    const double stddev = std::sqrt(var / g.size());
    // Below the threshold the sensor is essentially still: scale and gravity cannot be
    // separated. Smooth motion above it is tried; the post-refinement gate catches bad cases.
    if (stddev < options_.init_min_excitation) {
      std::ostringstream os;
      os << "IMU excitation too low (acceleration std " << stddev << " m/s^2 < "
         << options_.init_min_excitation << "): move the sensor";
      waitFor(&last_wait_reason_, &events_, t, os.str());
      return false;
    }
  }

  // A reference frame with enough correspondences and parallax to the newest frame.
  int ref = -1;
  Eigen::Matrix3d R_ref_last;
  Eigen::Vector3d t_ref_last;
  // Parallax is measured after removing the pair's rotation: rotation alone gives parallax
  // but no baseline, and the essential matrix of such a pair is unreliable. Both the
  // gyroscope's and the essential matrix's rotation are removed and the larger parallax
  // counts: before initialisation the gyroscope bias is unknown, and a real one (0.08 rad/s
  // on EuRoC MH_03) hides tens of pixels.
  // The relaxed threshold applies once the window has shown that much parallax for
  // init_relax_after_s without reaching the strict one (the clock starts at that sighting).
  const double relaxed_parallax =
      std::min(options_.init_relaxed_parallax_px, options_.init_min_parallax_px) /
      camera_.intrinsics[0];
  const bool relaxed =
      first_moving_attempt_ >= 0 && t - first_moving_attempt_ >= options_.init_relax_after_s;
  const double min_parallax =
      relaxed ? relaxed_parallax : options_.init_min_parallax_px / camera_.intrinsics[0];
  const Eigen::Matrix3d R_b_c = T_b_c_.linear();
  for (int i = 0; i < W_; ++i) {
    const auto corr = points_.correspondences(i, W_);
    if (static_cast<int>(corr.size()) < options_.init_min_correspondences) continue;
    // The pose of the first passing pair is the reference's; later pairs are not looked at.
    if (!relativePoseFromEssential(corr, &R_ref_last, &t_ref_last)) continue;
    Eigen::Quaterniond q_bi_bw = Eigen::Quaterniond::Identity();
    for (int k = i + 1; k <= W_; ++k) q_bi_bw = q_bi_bw * preintegrations_[k]->deltaQ();
    const Eigen::Matrix3d R_gyro = R_b_c.transpose() * q_bi_bw.toRotationMatrix() * R_b_c;
    // Mean image distance after rotating the newest frame's rays by R_i_last.
    const auto parallaxAfter = [&corr](const Eigen::Matrix3d& R_i_last) {
      double sum = 0;
      for (const auto& [a, b] : corr) {
        const Eigen::Vector3d b_in_i = R_i_last * b;
        sum += (a.head<2>() - b_in_i.head<2>() / b_in_i.z()).norm();
      }
      return sum / corr.size();
    };
    const double parallax = std::max(parallaxAfter(R_ref_last), parallaxAfter(R_gyro));
    if (parallax >= relaxed_parallax && first_moving_attempt_ < 0) first_moving_attempt_ = t;
    if (parallax < min_parallax) continue;
    ref = i;
    break;
  }
  if (ref < 0) {
    waitFor(&last_wait_reason_, &events_, t,
            "not enough parallax or correspondences between the window's frames");
    return false;
  }

  // Structure from motion over the keyframes of the window.
  std::vector<SfmTrack> tracks;
  for (const auto& [id, l] : points_.landmarks()) {
    SfmTrack track;
    track.id = id;
    for (std::size_t k = 0; k < l.sightings.size(); ++k)
      track.sightings.emplace_back(l.start_frame + static_cast<int>(k),
                                   l.sightings[k].xy1.head<2>());
    tracks.push_back(std::move(track));
  }
  SfmResult sfm;
  if (!reconstructStructure(frame_count_ + 1, ref, R_ref_last, t_ref_last, tracks, &sfm)) {
    waitFor(&last_wait_reason_, &events_, t, "visual structure from motion failed");
    marginalization_ = Marginalization::kOld;
    return false;
  }

  // Every frame since the oldest keyframe: keyframes from SfM, the others by PnP.
  const Eigen::Matrix3d R_c_b = T_b_c_.linear().transpose();
  int key = 0;
  for (auto& [stamp, f] : all_frames_) {
    if (key <= frame_count_ && std::abs(nsToSec(stamp) - headers_[key]) < 1e-6) {
      f.is_keyframe = true;
      f.R = sfm.q_ref_c[key].toRotationMatrix() * R_c_b;
      f.T = sfm.t_ref_c[key];
      ++key;
      continue;
    }
    f.is_keyframe = false;
    // Start from the pose of the next keyframe (the frame lies before it).
    const int guess = std::min(key, frame_count_);
    Eigen::Matrix3d R_ref_c = sfm.q_ref_c[guess].toRotationMatrix();
    Eigen::Vector3d t_ref_c = sfm.t_ref_c[guess];
    std::vector<Eigen::Vector3d> pts;
    std::vector<Eigen::Vector2d> obs;
    for (const auto& [id, xy1] : f.xy1) {
      const auto it = sfm.points.find(id);
      if (it == sfm.points.end()) continue;
      pts.push_back(it->second);
      obs.push_back(xy1.head<2>());
    }
    if (!cameraPoseFromPoints(pts, obs, &R_ref_c, &t_ref_c)) {
      waitFor(&last_wait_reason_, &events_, t, "PnP failed for a non-keyframe frame");
      return false;
    }
    f.R = R_ref_c * R_c_b;
    f.T = t_ref_c;
  }
  return true;
}

bool Estimator::alignWithImu(double t) {
  std::vector<AlignmentFrame> frames;
  for (auto& [stamp, f] : all_frames_) {
    AlignmentFrame a;
    a.R_c0_b = f.R;
    a.p_c0_c = f.T;
    a.imu = frames.empty() ? nullptr : f.imu.get();
    frames.push_back(a);
  }
  if (logLevel() <= LogLevel::kDebug) {
    for (std::size_t k = 1; k < frames.size(); ++k) {
      const Eigen::Quaterniond q_vis(frames[k - 1].R_c0_b.transpose() * frames[k].R_c0_b);
      logDebug("align: frame ", k, " dt ", frames[k].imu->sumDt(), " visual-vs-imu rotation ",
               q_vis.angularDistance(frames[k].imu->deltaQ()) * kRadToDeg, " deg, visual step ",
               (frames[k].p_c0_c - frames[k - 1].p_c0_c).norm());
    }
  }
  AlignmentResult result;
  if (!alignVisualInertial(frames, T_b_c_.translation(), imu_options_.gravity_magnitude, &result)) {
    waitFor(&last_wait_reason_, &events_, t, "visual-inertial alignment failed: " + result.failure);
    return false;
  }
  if (options_.init_min_scale_motion_m > 0 &&
      !(result.scale_motion_m >= options_.init_min_scale_motion_m)) {
    if (first_steady_alignment_ < 0) first_steady_alignment_ = t;
    // Noise in the visual positions shrinks the aligned scale, and the motion seen with it: a
    // front end that noisy would wait for ever.
    if (t - first_steady_alignment_ < options_.init_scale_motion_max_wait_s) {
      // The reason is logged once; each attempt's figure only at debug level.
      waitFor(&last_wait_reason_, &events_, t,
              "scale not yet observable: the window moved at nearly constant velocity");
      logDebug("scale motion ", 1000 * result.scale_motion_m, " mm < ",
               1000 * options_.init_min_scale_motion_m, " mm");
      return false;
    }
    logWarn("initialising after ", options_.init_scale_motion_max_wait_s, " s on ",
            1000 * result.scale_motion_m,
            " mm of motion off constant velocity: the scale may be off until the motion changes");
  }

  // Keyframe states in the c0 frame, metric, then rotated so gravity points down -z.
  for (int i = 0; i <= frame_count_; ++i) {
    const ImageFrame& f = all_frames_.lower_bound(secToNs(headers_[i]) - 1000)->second;
    Rs_[i] = f.R;
    Ps_[i] = f.T;
    Bgs_[i] = result.gyro_bias;
    Bas_[i].setZero();
  }
  for (int i = 0; i <= W_; ++i)
    if (preintegrations_[i]) preintegrations_[i]->repropagate(Eigen::Vector3d::Zero(), Bgs_[i]);
  const double s = result.scale;
  init_scale_ = s;
  bias_prior_pending_ = options_.init_accel_bias_sigma > 0;
  bias_prior_ba_.setZero();
  bias_prior_bg_ = result.gyro_bias;
  const Eigen::Vector3d t_b_c = T_b_c_.translation();
  for (int i = frame_count_; i >= 0; --i)
    Ps_[i] = s * Ps_[i] - Rs_[i] * t_b_c - (s * Ps_[0] - Rs_[0] * t_b_c);
  // Velocities: the alignment gives them in each frame's body frame, for every frame.
  int all_index = 0, key = 0;
  for (const auto& [stamp, f] : all_frames_) {
    if (key <= frame_count_ && f.is_keyframe) Vs_[key++] = f.R * result.velocities_body[all_index];
    ++all_index;
  }
  const Eigen::Matrix3d R0 = gravityAlignedRotation(result.gravity_c0);
  // World yaw: the first keyframe's orientation as close to identity as gravity allows.
  const double yaw = yawAlignment(Eigen::Matrix3d::Identity(), R0 * Rs_[0]);
  const Eigen::Matrix3d rot =
      Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R0;
  for (int i = 0; i <= frame_count_; ++i) {
    Ps_[i] = rot * Ps_[i];
    Rs_[i] = rot * Rs_[i];
    Vs_[i] = rot * Vs_[i];
  }
  // Depths: triangulate in the metric, gravity-aligned window.
  triangulatePointsAfresh();
  logInfo("initialised at t=", stampText(t), ": scale ", s, " (from ", 1000 * result.scale_motion_m,
          " mm of motion off constant velocity, residual rms ", result.residual_rms,
          "), gyroscope bias ", result.gyro_bias.transpose());
  return true;
}

void Estimator::triangulatePointsAfresh() {
  points_.clearDepths();
  std::vector<Eigen::Vector3d> P(Ps_.begin(), Ps_.end());
  std::vector<Eigen::Matrix3d> R(Rs_.begin(), Rs_.end());
  points_.triangulate(P, R, T_b_c_);
}

bool Estimator::warmStart(double t) {
  // The window's states are the IMU's propagation of the dead-reckoned state (gravity,
  // velocity and biases from before the reset): metric already, so no alignment. Depths
  // from these poses are the solve's start.
  triangulatePointsAfresh();
  // Every frame must see enough of them, or of lines with enough observations to be placed:
  // frames without (the black ones of a camera fault) would be held by the IMU alone, and the
  // new scale by a short stretch of images. Lines count as points do (two residuals a frame);
  // facing a plain wall they are most of what there is.
  std::vector<int> seen(W_ + 1, 0);
  for (const auto& [id, l] : points_.landmarks()) {
    if (!l.usable(W_) || l.depth <= 0) continue;
    for (int i = l.start_frame; i <= l.endFrame(); ++i) ++seen[i];
  }
  if (options_.use_lines) {
    const std::map<int64_t, int> slot = windowSlots();
    for (const auto& [id, l] : lines_.landmarks()) {
      if (!lines_.observedEnough(l)) continue;
      for (const auto& [ns, o] : l.observations) {
        const auto it = slot.find(ns);
        if (it != slot.end()) ++seen[it->second];
      }
    }
  }
  const int placed = *std::min_element(seen.begin(), seen.end());
  if (placed < options_.warm_restart_min_points) {
    // Structure from motion is tried next, and logs its own reason to wait.
    points_.clearDepths();
    logDebug("warm restart waits: a frame sees ", placed, " of ", options_.warm_restart_min_points,
             " points and lines");
    return false;
  }
  // Unlike after an alignment, the poses are metric: lines placed now carry no scale error.
  if (options_.use_lines) lines_.triangulate([this](int64_t ns) { return cameraPose(ns); });
  init_scale_ = 1.0;
  bias_prior_pending_ = options_.init_accel_bias_sigma > 0;
  bias_prior_ba_ = Bas_[0];
  bias_prior_bg_ = Bgs_[0];
  warm_restart_armed_ = false;
  warm_started_ = true;
  logInfo("initialised again at t=", stampText(t), " from ", t - last_output_.t,
          " s of IMU dead reckoning (", placed, " points and lines in every frame)");
  return true;
}

}  // namespace alvio
