// The estimator end to end on feature-level synthetic data (no rendering):
// initialisation quality, tracking accuracy, robustness and determinism.
#include <gtest/gtest.h>

#include "alvio/common/logging.h"
#include "alvio/config/config.h"
#include "alvio/estimator/estimator.h"
#include "alvio/eval/trajectory_evaluation.h"
#include "alvio/pipeline/offline_runner.h"
#include "synthetic_scenario.h"
#include "test_support.h"

using namespace alvio;

namespace {
struct RunOutcome {
  Trajectory trajectory;
  int resets = 0;
  std::optional<InitializationQuality> init;
};

// `blackout` (seconds from start, [begin, end)) removes every feature from those frames.
RunOutcome runEstimator(const test::SyntheticScenario& s, const Config& c,
                        std::pair<double, double> blackout = {-1, -1}) {
  Estimator estimator(c.estimator, c.camera, c.imu);
  RunOutcome out;
  std::size_t next_imu = 0;
  const auto& imu = s.imu();
  const Trajectory gt = s.groundTruth();
  for (const auto& frame : s.frames()) {
    // IMU up to and one beyond the frame.
    while (next_imu < imu.size() && imu[next_imu].t_ns <= frame.t_ns)
      estimator.addImu(imu[next_imu++]);
    if (next_imu < imu.size()) estimator.addImu(imu[next_imu++]);
    const double t_rel = frame.t() - nsToSec(test::SyntheticScenario::kStartNs);
    FeatureFrame f = frame;
    if (t_rel >= blackout.first && t_rel < blackout.second) f.points.clear();
    if (estimator.addFrame(f)) {
      const BodyState st = estimator.latestState();
      StampedPose p;
      p.t = st.t;
      p.p = st.p;
      p.q = st.q;
      out.trajectory.push_back(p);
    }
    for (const auto& e : estimator.takeEvents())
      if (e.kind == EstimatorEvent::Kind::kInitialized && !out.init) {
        out.init = initializationQuality(e.window, gt);
        out.init->time = e.t - nsToSec(test::SyntheticScenario::kStartNs);
      }
  }
  out.resets = estimator.resetCount();
  return out;
}
}  // namespace

TEST(Estimator, InitialisesAndTracksSyntheticFeatures) {
  if (std::getenv("ALVIO_DEBUG")) setLogLevel(LogLevel::kDebug);
  const Config c = Config::load(test::sourcePath("config/euroc.yaml"));
  test::ScenarioOptions so;
  so.duration_s = 25;
  const test::SyntheticScenario scenario(so, c.camera, c.imu);
  const RunOutcome r = runEstimator(scenario, c);
  ASSERT_TRUE(r.init.has_value()) << "never initialised";
  EXPECT_LT(r.init->time, 3.0);
  EXPECT_LT(r.init->scale_error, 0.05);
  EXPECT_LT(r.init->gravity_error_deg, 1.0);
  EXPECT_EQ(r.resets, 0);
  ASSERT_GT(r.trajectory.size(), scenario.frames().size() * 8 / 10);
  const EvaluationResult e =
      evaluateTrajectory(r.trajectory, scenario.groundTruth(), EvaluationOptions());
  std::cout << "synthetic ATE " << e.ate_translation_m.rmse << " m over " << e.path_length_m
            << " m, init at " << r.init->time << " s, scale error " << r.init->scale_error
            << ", gravity error " << r.init->gravity_error_deg << " deg\n";
  EXPECT_LT(e.ate_translation_m.rmse, 0.05);
  EXPECT_LT(e.ate_rotation_deg.rmse, 1.0);
}

TEST(Estimator, IsDeterministic) {
  const Config c = Config::load(test::sourcePath("config/euroc.yaml"));
  test::ScenarioOptions so;
  so.duration_s = 8;
  const test::SyntheticScenario scenario(so, c.camera, c.imu);
  const RunOutcome a = runEstimator(scenario, c), b = runEstimator(scenario, c);
  ASSERT_EQ(a.trajectory.size(), b.trajectory.size());
  ASSERT_GT(a.trajectory.size(), 0u);
  for (std::size_t i = 0; i < a.trajectory.size(); ++i) {
    EXPECT_EQ(a.trajectory[i].p, b.trajectory[i].p);
    EXPECT_EQ(a.trajectory[i].q.coeffs(), b.trajectory[i].q.coeffs());
  }
}

// Losing every feature resets the estimator; it re-initialises and the output
// continues from the IMU-dead-reckoned pose (no jump to a new world frame).
TEST(Estimator, ResetsOnTrackingLossAndKeepsOutputContinuous) {
  const Config c = Config::load(test::sourcePath("config/euroc.yaml"));
  test::ScenarioOptions so;
  so.duration_s = 14;
  const test::SyntheticScenario scenario(so, c.camera, c.imu);
  const RunOutcome r = runEstimator(scenario, c, {6.0, 6.5});
  EXPECT_GE(r.resets, 1);
  // Poses exist before and after the blackout.
  const double t0 = nsToSec(test::SyntheticScenario::kStartNs);
  std::size_t before = 0, after = 0;
  for (const auto& p : r.trajectory)
    (p.t - t0 < 6.0 ? before : after) += p.t - t0 > 6.5 || p.t - t0 < 6.0;
  EXPECT_GT(before, 50u);
  EXPECT_GT(after, 50u);
  // Output continuity: across the gap the output moves as the true body moved, up to the
  // drift of 1.3 s of IMU dead reckoning (~0.1 m/s velocity error at the start).
  const test::SyntheticScenario& sc = scenario;
  for (std::size_t i = 1; i < r.trajectory.size(); ++i) {
    const auto& a = r.trajectory[i - 1];
    const auto& b = r.trajectory[i];
    if (b.t - a.t < 0.2) continue;  // only the gap
    const Eigen::Vector3d true_step = sc.position(b.t - t0) - sc.position(a.t - t0);
    EXPECT_LT(((b.p - a.p) - true_step).norm(), 0.35)
        << "gap " << a.t - t0 << ".." << b.t - t0 << " s, true step " << true_step.norm() << " m";
  }
  // And the whole run, aligned once, is still accurate to a few decimetres.
  const EvaluationResult e =
      evaluateTrajectory(r.trajectory, scenario.groundTruth(), EvaluationOptions());
  EXPECT_LT(e.ate_translation_m.rmse, 0.3);
}
