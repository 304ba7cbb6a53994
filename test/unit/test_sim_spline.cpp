// The simulator's continuous-time trajectory: exact derivatives and a fit that
// smooths the steps of the EuRoC ground truth.
#include <gtest/gtest.h>

#include "alvio/io/trajectory_io.h"
#include "alvio/sim/pose_spline.h"
#include "alvio/sim/pose_spline_fit.h"
#include "alvio/sim/seeded_random.h"
#include "alvio/sim/so3.h"
#include "test_support.h"

using namespace alvio;
using namespace alvio::sim;

namespace {

PoseSpline randomSpline(int controls, double dt, uint64_t seed) {
  SeededRandom rng(seed);
  Vector3dList p;
  QuaternionList q;
  Eigen::Vector3d pos(1, 2, 3);
  Eigen::Quaterniond rot = Eigen::Quaterniond::Identity();
  for (int j = 0; j < controls; ++j) {
    pos += Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal()) * 0.1;
    rot = rot * so3Exp(Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal()) * 0.1);
    p.push_back(pos);
    q.push_back(rot);
  }
  return PoseSpline(100.0, dt, p, q);
}

}  // namespace

TEST(PoseSpline, DerivativesMatchFiniteDifferences) {
  const PoseSpline s = randomSpline(20, 0.1, 7);
  const double h = 1e-5;
  for (double t = s.startTime() + 0.013; t < s.endTime() - 0.01; t += 0.0371) {
    const BodyState st = s.state(t);
    const BodyState a = s.state(t - h), b = s.state(t + h);
    EXPECT_LT((st.v_w - (b.p_w - a.p_w) / (2 * h)).norm(), 1e-6) << t;
    EXPECT_LT((st.a_w - (b.v_w - a.v_w) / (2 * h)).norm(), 1e-5) << t;
    const Eigen::Vector3d omega_num =
        so3Log(Eigen::Quaterniond(a.q_w_b.conjugate() * b.q_w_b)) / (2 * h);
    EXPECT_LT((st.omega_b - omega_num).norm(), 1e-6) << t;
    EXPECT_NEAR(st.q_w_b.angularDistance(s.orientation(t)), 0.0, 1e-12);
  }
}

TEST(PoseSpline, IsContinuousAcrossKnots) {
  const PoseSpline s = randomSpline(12, 0.05, 3);
  for (int i = 1; i < s.segments(); ++i) {
    const double t = s.startTime() + i * s.knotSpacing();
    const BodyState a = s.state(t - 1e-9), b = s.state(t + 1e-9);
    EXPECT_LT((a.a_w - b.a_w).norm(), 1e-5);
    EXPECT_LT((a.omega_b - b.omega_b).norm(), 1e-5);
  }
}

TEST(PoseSplineFit, RecoversASplineFromNoisySamples) {
  const PoseSpline truth = randomSpline(60, 0.1, 11);
  Trajectory samples;
  SeededRandom rng(5);
  for (double t = truth.startTime(); t <= truth.endTime(); t += 0.005) {
    StampedPose p;
    p.t = t;
    p.p = truth.position(t) + Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal()) * 1e-4;
    p.q = truth.orientation(t);
    samples.push_back(p);
  }
  SplineFitOptions o;
  o.knot_spacing_s = 0.05;
  o.acceleration_sigma = 1e3;  // the truth moves briskly: do not smooth it away
  o.angular_acceleration_sigma = 1e3;
  SplineFitReport report;
  const PoseSpline fit = fitPoseSpline(samples, o, &report);
  EXPECT_EQ(report.samples, static_cast<int>(samples.size()));
  EXPECT_LT(report.position_rms_m, 2e-4) << report.summary();
  EXPECT_LT(report.rotation_rms_deg, 0.01) << report.summary();
  // Against the truth itself (not only the samples): velocity and rate agree too.
  for (double t = truth.startTime() + 0.5; t < truth.endTime() - 0.5; t += 0.1) {
    EXPECT_LT((fit.state(t).v_w - truth.state(t).v_w).norm(), 0.02) << t;
    EXPECT_LT((fit.state(t).omega_b - truth.state(t).omega_b).norm(), 0.02) << t;
  }
}

TEST(PoseSplineFit, SmoothsAStepInsteadOfFollowingIt) {
  // A hover with an 8 cm jump between two 5 ms samples, as in EuRoC MH_03/MH_05.
  Trajectory samples;
  for (int k = 0; k <= 2000; ++k) {
    StampedPose p;
    p.t = k * 0.005;
    p.p = Eigen::Vector3d(0.1 * std::sin(p.t), 0, 1) +
          (k > 1000 ? Eigen::Vector3d(0.08, 0, 0) : Eigen::Vector3d::Zero());
    samples.push_back(p);
  }
  SplineFitReport report;
  const PoseSpline fit = fitPoseSpline(samples, {}, &report);
  double max_acc = 0;
  for (double t = fit.startTime(); t <= fit.endTime(); t += 0.001)
    max_acc = std::max(max_acc, fit.state(t).a_w.norm());
  // Following the step within 5 ms would need ~3000 m/s^2.
  EXPECT_LT(max_acc, 40.0);
  // Away from the step the fit is tight; at the step it is off by about half the step.
  EXPECT_LT(report.position_rms_m, 0.01) << report.summary();
  EXPECT_NEAR(report.max_error_time, 5.0, 0.1) << report.summary();
}

TEST(PoseSplineFit, EurocMh03GroundTruthResidualIsSmall) {
  ALVIO_REQUIRE_SHARED_DATA(data);
  const Trajectory all =
      readTrajectory(data + "/euroc_groundtruth/xygxgn_VINS-Fusion/output/MH_03_medium.txt");
  // 25..45 s after the start: fast flight with the 4.6 cm and 8.5 cm steps at 29.8 s and 35.4 s.
  Trajectory part;
  for (const auto& p : all)
    if (p.t >= all.front().t + 25 && p.t <= all.front().t + 45) part.push_back(p);
  SplineFitReport report;
  fitPoseSpline(part, {}, &report);
  EXPECT_LT(report.position_rms_m, 0.01) << report.summary();
  EXPECT_LT(report.position_max_m, 0.06) << report.summary();
  EXPECT_LT(report.rotation_rms_deg, 0.3) << report.summary();
  std::cout << report.summary() << "\n";
}
