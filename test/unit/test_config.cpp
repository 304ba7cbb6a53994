#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "alvio/common/error.h"
#include "alvio/common/logging.h"
#include "alvio/common/resource_path.h"
#include "alvio/config/config.h"
#include "alvio/config/yaml_reader.h"
#include "alvio/io/euroc_dataset.h"
#include "test_support.h"

using namespace alvio;

namespace {
// Expect an alvio::Error whose message contains every fragment.
template <typename F>
void expectErrorMentioning(F&& f, std::initializer_list<std::string> fragments) {
  try {
    f();
    FAIL() << "expected alvio::Error";
  } catch (const Error& e) {
    for (const auto& frag : fragments)
      EXPECT_NE(std::string(e.what()).find(frag), std::string::npos)
          << "message '" << e.what() << "' lacks '" << frag << "'";
  }
}

std::string eurocYaml() {
  return test::readFile(test::sourcePath("config/euroc.yaml"));
}

std::string eurocYamlWithout(const std::string& key) {
  std::istringstream in(eurocYaml());
  std::string out, line;
  while (std::getline(in, line))
    if (line.find(key + ":") == std::string::npos) out += line + "\n";
  return out;
}

// The default config with the first occurrence of `from` replaced by `to`.
std::string eurocYamlReplacing(const std::string& from, const std::string& to) {
  std::string text = eurocYaml();
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  return text.replace(pos, from.size(), to);
}

// Loading the default config with the first `from` replaced by `to` fails, and the error
// mentions every fragment.
void expectReplacementRejected(const std::string& from, const std::string& to,
                               std::initializer_list<std::string> fragments) {
  const std::string path =
      test::writeFile(test::scratchDir() + "/replaced.yaml", eurocYamlReplacing(from, to));
  expectErrorMentioning([&] { Config::load(path); }, fragments);
}
}  // namespace

TEST(Config, DefaultEurocConfigLoadsWithEurocValues) {
  const Config c = Config::load(test::sourcePath("config/euroc.yaml"));
  EXPECT_EQ(c.camera.width, 752);
  EXPECT_EQ(c.camera.height, 480);
  EXPECT_DOUBLE_EQ(c.camera.intrinsics[0], 458.654);
  EXPECT_EQ(c.camera.distortion_model, "radial-tangential");
  EXPECT_NEAR(c.camera.T_b_c.translation().x(), -0.0216401454975, 1e-12);
  EXPECT_NEAR(c.camera.T_b_c.linear()(0, 1), -0.999880929698, 1e-6);
  EXPECT_DOUBLE_EQ(c.imu.accelerometer_noise_density, 2.0e-3);
  EXPECT_EQ(c.topics.image, "/cam0/image_raw");
  // Keyframes every 15 px of parallax (forty-ninth session), also for a config without the key.
  EXPECT_DOUBLE_EQ(c.estimator.keyframe_parallax_px, 15.0);
  EXPECT_DOUBLE_EQ(EstimatorOptions{}.keyframe_parallax_px, c.estimator.keyframe_parallax_px);
}

TEST(Config, MissingKeyNamesFileAndKey) {
  const std::string dir = test::scratchDir();
  const std::string path =
      test::writeFile(dir + "/bad.yaml", eurocYamlWithout("gyroscope_random_walk"));
  expectErrorMentioning([&] { Config::load(path); },
                        {path, "imu.gyroscope_random_walk", "missing"});
}

TEST(Config, MalformedValueNamesKeyAndValue) {
  expectReplacementRejected("gyroscope_noise_density: 1.6968e-04", "gyroscope_noise_density: fast",
                            {"imu.gyroscope_noise_density", "fast"});
}

TEST(Config, NegativeNoiseIsRejected) {
  expectReplacementRejected("accelerometer_random_walk: 3.0000e-3",
                            "accelerometer_random_walk: -3e-3",
                            {"accelerometer_random_walk", "positive"});
}

TEST(Config, NegativeSettlingIsRejected) {
  expectReplacementRejected("init_settle_change: 0.001", "init_settle_change: -1",
                            {"estimator.init_settle_change", "must not be negative"});
}

TEST(Config, BadWarmRestartSettingsAreRejected) {
  expectReplacementRejected("warm_restart_max_s: 3.0", "warm_restart_max_s: -1",
                            {"estimator.warm_restart_max_s", "must not be negative"});
  expectReplacementRejected("warm_restart_min_points: 10", "warm_restart_min_points: 0",
                            {"estimator.warm_restart_min_points", "must be at least 1"});
}

TEST(Config, TheWaitForMotionOffConstantVelocityIsReadAndANegativeOneIsRejected) {
  const Config c = Config::load(test::sourcePath("config/euroc.yaml"));
  EXPECT_DOUBLE_EQ(c.estimator.init_min_scale_motion_m, 0.005);
  EXPECT_DOUBLE_EQ(c.estimator.init_scale_motion_max_wait_s, 3.0);
  expectReplacementRejected("init_min_scale_motion_m: 0.005", "init_min_scale_motion_m: -0.005",
                            {"estimator.init_min_scale_motion_m", "must not be negative"});
}

TEST(Config, LineMapFilterIsReadAndANegativeParallaxIsRejected) {
  const Config c = Config::load(test::sourcePath("config/euroc.yaml"));
  EXPECT_DOUBLE_EQ(c.estimator.line_map_max_rms_px, 0.5);
  EXPECT_DOUBLE_EQ(c.estimator.line_map_min_parallax, 0.10);
  expectReplacementRejected("line_map_min_parallax: 0.10", "line_map_min_parallax: -0.1",
                            {"estimator.line_map_min_parallax", "must not be negative"});
}

TEST(Config, LineNoisesAreReadApartAndANonPositiveMapNoiseIsRejected) {
  const Config c = Config::load(test::sourcePath("config/euroc.yaml"));
  EXPECT_DOUBLE_EQ(c.estimator.line_sigma_px, 0.35);
  EXPECT_DOUBLE_EQ(c.estimator.line_map_sigma_px, 1.5);
  EXPECT_DOUBLE_EQ(c.estimator.line_map_max_midpoint_std_m, 0.03);
  expectReplacementRejected("line_map_sigma_px: 1.5", "line_map_sigma_px: 0",
                            {"estimator.line_map_sigma_px", "must be positive"});
}

TEST(Config, LineResidualsOnEdgesIsOffAndReadAsABoolean) {
  EXPECT_FALSE(
      Config::load(test::sourcePath("config/euroc.yaml")).estimator.line_residuals_on_edges);
  const std::string dir = test::scratchDir();
  const auto load = [&](const std::string& value) {
    return Config::load(test::writeFile(
        dir + "/edges.yaml",
        eurocYamlReplacing("line_residuals_on_edges: false", "line_residuals_on_edges: " + value)));
  };
  EXPECT_TRUE(load("true").estimator.line_residuals_on_edges);
  expectErrorMentioning([&] { load("maybe"); }, {"estimator.line_residuals_on_edges"});
}

TEST(Config, LineStepDampingIsReadAndANegativeOneIsRejected) {
  const Config c = Config::load(test::sourcePath("config/euroc.yaml"));
  EXPECT_EQ(c.estimator.line_step_damping, 10.0);
  expectReplacementRejected("line_step_damping: 10.0", "line_step_damping: -1.0",
                            {"estimator.line_step_damping", "must not be negative"});
}

TEST(Config, SolverIterationsAreReadAndZeroForTheFirstSolveIsRejected) {
  const Config c = Config::load(test::sourcePath("config/euroc.yaml"));
  EXPECT_EQ(c.estimator.max_iterations, 2);
  EXPECT_EQ(c.estimator.init_max_iterations, 24);
  expectReplacementRejected("init_max_iterations: 24", "init_max_iterations: 0",
                            {"estimator.init_max_iterations", "must be at least 1"});
}

TEST(Config, PointDriftIsReadAndANegativeDriftIsRejected) {
  const Config c = Config::load(test::sourcePath("config/euroc.yaml"));
  EXPECT_DOUBLE_EQ(c.estimator.point_drift_px2_per_s, 0.0);
  expectReplacementRejected("point_drift_px2_per_s: 0.0", "point_drift_px2_per_s: -1",
                            {"estimator.point_drift_px2_per_s", "must not be negative"});
}

TEST(Config, AnUnknownRobustLossIsRejectedByName) {
  expectReplacementRejected(
      "robust_loss: cauchy", "robust_loss: tukey",
      {"estimator.robust_loss", "must be cauchy, huber or none, not 'tukey'"});
}

TEST(Config, GyroscopeFlowSettingsAreReadAndNegativeLevelsRejectedByName) {
  const Config c = Config::load(test::sourcePath("config/euroc.yaml"));
  EXPECT_TRUE(c.points.gyro_flow);
  EXPECT_TRUE(c.lines.flow.gyro_flow);
  EXPECT_EQ(c.points.gyro_klt_levels, 3);
  EXPECT_EQ(c.lines.flow.gyro_klt_levels, 1);
  expectReplacementRejected("  gyro_klt_levels: 3\n", "  gyro_klt_levels: -1\n",
                            {"points.gyro_klt_levels", "must not be negative"});
  expectReplacementRejected("    gyro_klt_levels: 1", "    gyro_klt_levels: -2",
                            {"gyro_klt_levels", "non-negative", "-2"});
}

TEST(Config, ClaheSettingsAreReadAndNonPositiveOnesAreRejected) {
  const Config c = Config::load(test::sourcePath("config/euroc.yaml"));
  EXPECT_DOUBLE_EQ(c.points.clahe_clip_limit, 3.0);
  EXPECT_EQ(c.points.clahe_tiles, 8);
  expectReplacementRejected("clahe_clip_limit: 3.0", "clahe_clip_limit: 0",
                            {"points.clahe_clip_limit", "must be positive"});
  expectReplacementRejected("clahe_tiles: 8", "clahe_tiles: 0",
                            {"points.clahe_tiles", "at least 1"});
  expectReplacementRejected("min_new_features: 20", "min_new_features: 151",
                            {"points.min_new_features", "[1, max_features]"});
}

TEST(Config, PatchAnchorSettingsAreReadAndBadOnesAreRejected) {
  const Config c = Config::load(test::sourcePath("config/euroc.yaml"));
  EXPECT_EQ(c.points.anchors.window, 21);
  EXPECT_DOUBLE_EQ(c.points.anchors.max_shift_px, 1.0);
  EXPECT_TRUE(c.points.anchors.enabled);
  EXPECT_EQ(c.points.anchors.reanchor_frames, 0);
  EXPECT_DOUBLE_EQ(c.points.anchors.min_zncc, 0.7);
  EXPECT_EQ(c.points.anchors.warp, "affine");
  EXPECT_TRUE(c.points.anchors.end_mismatched);
  EXPECT_FALSE(c.points.anchors.skip_backward_when_aligned);
  const std::string dir = test::scratchDir();
  const std::string skip = test::writeFile(
      dir + "/skip.yaml",
      eurocYamlReplacing("skip_backward_when_aligned: false", "skip_backward_when_aligned: true"));
  EXPECT_TRUE(Config::load(skip).points.anchors.skip_backward_when_aligned);
  EXPECT_TRUE(c.points.anchors.end_mismatched_before_init);
  const std::string keep = test::writeFile(
      dir + "/keep.yaml",
      eurocYamlReplacing("end_mismatched_before_init: true", "end_mismatched_before_init: false"));
  EXPECT_FALSE(Config::load(keep).points.anchors.end_mismatched_before_init);
  expectReplacementRejected("    window: 21", "    window: 20", {"points.anchors.window", "odd"});
  expectReplacementRejected("max_shift_px: 1.0", "max_shift_px: 0",
                            {"points.anchors.max_shift_px", "must be positive"});
  expectReplacementRejected("min_zncc: 0.7", "min_zncc: 1.5",
                            {"points.anchors.min_zncc", "[-1, 1]"});
  expectReplacementRejected("warp: affine", "warp: projective",
                            {"points.anchors.warp", "projective"});
}

TEST(Config, NonRotationExtrinsicIsRejected) {
  expectReplacementRejected("0.0148655429818", "2.0", {"camera.T_BS", "not a rotation"});
}

TEST(Config, WrongListSizeIsRejected) {
  const auto yaml = YamlReader::fromString("a: [1, 2, 3]\n", "mem.yaml");
  expectErrorMentioning([&] { yaml.getDoubles("a", 4); }, {"mem.yaml", "'a'", "4 values"});
}

TEST(Config, AChoiceOutsideItsWordsNamesThemAll) {
  const auto yaml = YamlReader::fromString("a: two\nb: tree\n", "mem.yaml");
  EXPECT_EQ(yaml.getChoice("a", "one", {"one", "two"}), "two");
  EXPECT_EQ(yaml.getChoice("missing", "one", {"one", "two"}), "one");
  expectErrorMentioning(
      [&] {
        yaml.getChoice("b", "one", {"one", "two", "three"});
      },
      {"mem.yaml", "'b'", "must be one, two or three, not 'tree'"});
  expectErrorMentioning(
      [&] {
        yaml.getChoice("b", "one", {"one", "two"});
      },
      {"must be one or two, not 'tree'"});
}

TEST(Config, UnknownKeysAreReported) {
  const std::string dir = test::scratchDir();
  const std::string path = test::writeFile(
      dir + "/unknown.yaml",
      eurocYamlReplacing("rate_hz: 200", "rate_hz: 200\n  gravty: 9.8") + "imu_typo:\n  rate: 3\n");
  std::vector<std::string> warnings;
  setLogSink([&](LogLevel level, const std::string& msg) {
    if (level == LogLevel::kWarn) warnings.push_back(msg);
  });
  Config::load(path);
  setLogSink(nullptr);
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_NE(warnings[0].find("imu.gravty"), std::string::npos);
  EXPECT_NE(warnings[1].find("imu_typo.rate"), std::string::npos);
}

TEST(Config, YamlSyntaxErrorGivesLine) {
  const std::string dir = test::scratchDir();
  const std::string path = test::writeFile(dir + "/syntax.yaml", "a: 1\nb: [1, 2\nc: 3\n");
  expectErrorMentioning([&] { YamlReader r(path); }, {path, "line"});
}

TEST(Config, EurocSensorYamlIsReadable) {
  ALVIO_REQUIRE_SHARED_DATA(shared);
  EurocDataset ds(shared + "/euroc_V1_01_easy_micro_kimera");
  const auto cam = ds.cameraCalibration();
  const auto imu = ds.imuCalibration();
  ASSERT_TRUE(cam && imu);
  const Config c = Config::load(test::sourcePath("config/euroc.yaml"));
  EXPECT_TRUE(cam->T_b_c.isApprox(c.camera.T_b_c, 1e-12));
  EXPECT_EQ(cam->intrinsics, c.camera.intrinsics);
  EXPECT_EQ(cam->distortion_coefficients, c.camera.distortion_coefficients);
  EXPECT_DOUBLE_EQ(imu->gyroscope_noise_density, c.imu.gyroscope_noise_density);
  EXPECT_DOUBLE_EQ(imu->accelerometer_random_walk, c.imu.accelerometer_random_walk);
}

// --- base: a configuration that overrides another ------------------------------------------

TEST(ConfigBase, OverridesTheBaseKeyByKeyAndInheritsTheRest) {
  const std::string dir = test::scratchDir();
  test::writeFile(dir + "/robot.yaml", eurocYaml());
  const std::string child =
      test::writeFile(dir + "/child.yaml",
                      "base: robot.yaml\n"
                      "estimator:\n  window_size: 7\n"
                      "  imu_noise:\n    accelerometer_noise_density: 0.08\n");
  const Config base = Config::load(dir + "/robot.yaml");
  const Config c = Config::load(child);
  EXPECT_EQ(c.estimator.window_size, 7);
  EXPECT_DOUBLE_EQ(c.estimator.imu_noise.accelerometer_noise_density, 0.08);
  EXPECT_DOUBLE_EQ(c.estimator.imu_noise.gyroscope_noise_density, 0.0);  // the sensor's
  EXPECT_EQ(c.estimator.max_iterations, base.estimator.max_iterations);
  EXPECT_EQ(c.camera.width, base.camera.width);
  EXPECT_DOUBLE_EQ(c.imu.accelerometer_noise_density, base.imu.accelerometer_noise_density);
  EXPECT_EQ(c.source, child);
}

TEST(ConfigBase, MissingBaseAndCyclesNameTheFile) {
  const std::string dir = test::scratchDir();
  const std::string orphan = test::writeFile(dir + "/orphan.yaml", "base: nowhere.yaml\n");
  expectErrorMentioning([&] { Config::load(orphan); }, {"orphan.yaml", "'base'", "nowhere.yaml"});
  test::writeFile(dir + "/a.yaml", "base: b.yaml\n");
  const std::string b = test::writeFile(dir + "/b.yaml", "base: a.yaml\n");
  expectErrorMentioning([&] { Config::load(b); }, {"'base'", "cycle"});
  const std::string bad = test::writeFile(dir + "/bad.yaml", "base: [1, 2]\n");
  expectErrorMentioning([&] { Config::load(bad); }, {"bad.yaml", "'base' must name"});
}

TEST(ConfigBase, ReadYamlMergesTheBaseForOtherSections) {
  // The tools that also read `mapping:` take the YAML from Config::readYaml: the section
  // lives in the base file only.
  const YamlReader yaml = Config::readYaml(test::sourcePath("config/euroc_real.yaml"));
  EXPECT_TRUE(yaml.has("mapping.enabled"));
  EXPECT_TRUE(yaml.has("camera.distortion_model"));
  EXPECT_EQ(Config::load(yaml).camera.distortion_model, "radial-tangential");
}

TEST(ConfigBase, ShippedRealImuConfigIsEurocWithInFlightImuNoiseUndampedLinesAndTheirOwnNoise) {
  const Config euroc = Config::load(test::sourcePath("config/euroc.yaml"));
  const Config real = Config::load(test::sourcePath("config/euroc_real.yaml"));
  EXPECT_DOUBLE_EQ(real.estimator.imu_noise.accelerometer_noise_density, 0.06);
  EXPECT_DOUBLE_EQ(real.estimator.imu_noise.gyroscope_random_walk, 2.0e-6);
  // The sensor block (what the simulator uses) is euroc.yaml's.
  EXPECT_DOUBLE_EQ(real.imu.accelerometer_noise_density, euroc.imu.accelerometer_noise_density);
  EXPECT_EQ(real.estimator.window_size, euroc.estimator.window_size);
  EXPECT_DOUBLE_EQ(real.estimator.keyframe_parallax_px, euroc.estimator.keyframe_parallax_px);
  EXPECT_DOUBLE_EQ(euroc.estimator.imu_noise.accelerometer_noise_density, 0.0);
  // The lines' step damping helps with the synthetic IMU and costs accuracy with the real one.
  EXPECT_DOUBLE_EQ(euroc.estimator.line_step_damping, 10.0);
  EXPECT_DOUBLE_EQ(real.estimator.line_step_damping, 0.0);
  // So do a lower line noise and a tighter line outlier limit; the map lines' uncertainty is
  // computed alike in both.
  EXPECT_DOUBLE_EQ(euroc.estimator.line_sigma_px, 0.35);
  EXPECT_DOUBLE_EQ(real.estimator.line_sigma_px, 0.5);
  EXPECT_DOUBLE_EQ(euroc.estimator.line_outlier_px, 2.0);
  EXPECT_DOUBLE_EQ(real.estimator.line_outlier_px, 5.0);
  EXPECT_DOUBLE_EQ(real.estimator.line_map_sigma_px, euroc.estimator.line_map_sigma_px);
  EXPECT_DOUBLE_EQ(real.estimator.line_map_max_midpoint_std_m,
                   euroc.estimator.line_map_max_midpoint_std_m);
}

TEST(PackageFiles, AnInstalledProgramReadsItsInstalledConfigNotTheSourceTree) {
  namespace fs = std::filesystem;
  const fs::path prefix = test::scratchDir();
  const char* root = std::getenv("ALVIO_ROOT");  // it would come first
  const std::string saved_root = root ? root : "";
  unsetenv("ALVIO_ROOT");
  fs::create_directories(prefix / "share/alvio/config");
  fs::create_directories(prefix / "lib/alvio");
  const std::string installed =
      test::writeFile((prefix / "share/alvio/config/euroc.yaml").string(), "installed: true\n");
  const std::string exe = (prefix / "lib/alvio/alvio_run").string();
  EXPECT_EQ(findPackageFile("config/euroc.yaml", exe), installed);
  // A file the install lacks comes from the source tree, as for a devel-space program.
  EXPECT_EQ(fs::canonical(findPackageFile("config/euroc_real.yaml", exe)),
            fs::canonical(test::sourcePath("config/euroc_real.yaml")));
  EXPECT_EQ(fs::canonical(findPackageFile("config/euroc.yaml", "/nowhere/lib/alvio/alvio_run")),
            fs::canonical(test::sourcePath("config/euroc.yaml")));
  EXPECT_NE(test::errorOf([&] { findPackageFile("config/none.yaml", exe); }).find("none.yaml"),
            std::string::npos);
  if (!saved_root.empty()) setenv("ALVIO_ROOT", saved_root.c_str(), 1);
}
