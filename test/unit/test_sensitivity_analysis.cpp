// The sensitivity-analysis chain (issue 6): `alvio run --analysis` writes the records
// (AnalysisWriter), `alvio analyze` (scripts/analyze_sensitivity.py) fits track-length
// surfaces to them, and the estimator evaluates those surfaces (TrackSurface). The script and
// the estimator must agree on the monomial order and on the image size the positions are
// normalised by, or selection silently drops the wrong features.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>

#include "alvio/config/config.h"
#include "alvio/config/yaml_reader.h"
#include "alvio/estimator/feature_selection.h"
#include "alvio/pipeline/analysis_writer.h"
#include "alvio/pipeline/offline_runner.h"
#include "test_support.h"

using namespace alvio;
namespace fs = std::filesystem;

namespace {

bool pythonWithNumpy() {
  std::string out;
  return test::runCommand("/usr/bin/python3 -c 'import numpy, matplotlib, yaml'", &out) == 0;
}

std::string analyze(const std::string& args, int* rc) {
  std::string out;
  *rc = test::runCommand(
      "/usr/bin/python3 '" + test::sourcePath("scripts/analyze_sensitivity.py") + "' " + args,
      &out);
  return out;
}

// A cubic track-length surface over normalised image positions (u, v) in [-0.5, 0.5]:
// long tracks in the middle, short ones at the sides and at the bottom, as in the paper.
double pointTrack(double u, double v) {
  return 8 + 1.5 * u - 3 * v - 12 * u * u + 2 * u * v - 6 * v * v + 4 * u * u * u - 5 * v * v * v;
}
double lineTrack(double u, double v) {
  return 6 - 2 * u + 1 * v - 8 * u * u - 10 * v * v;
}

struct Records {
  std::vector<double> point_tracks;  ///< the true expected track length at each point record
};

// Records of `features` features per kind on a width x height camera, with a little noise
// on the track length (the fit must average it out). No image_size.yaml when size_file is
// false (records written before alvio saved it).
Records writeRecords(const std::string& dir, int width, int height, bool size_file = true,
                     int features = 600) {
  fs::create_directories(dir);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ux(0, width), uy(0, height), noise(-0.02, 0.02);
  Records r;
  for (const char* kind : {"points", "lines"}) {
    std::ofstream f(dir + "/" + kind + ".csv");
    f << "window_t,id,x_px,y_px,tracked_frames\n";
    for (int i = 0; i < features; ++i) {
      const double x = ux(rng), y = uy(rng);
      const double u = x / width - 0.5, v = y / height - 0.5;
      const double truth = std::string(kind) == "points" ? pointTrack(u, v) : lineTrack(u, v);
      if (std::string(kind) == "points") r.point_tracks.push_back(truth);
      f << 100 + i / 50 << "," << i << "," << x << "," << y << "," << truth + noise(rng) << "\n";
    }
  }
  std::ofstream w(dir + "/windows.csv");
  w << "window_t,frames,mean_intensity,motion_m,points,lines,mean_point_track,mean_line_track\n";
  for (int i = 0; i < 40; ++i)
    w << 100 + i << ",10," << 60 + i << "," << 0.1 * i << ",50,20,6.5,4.2\n";
  if (size_file)
    std::ofstream(dir + "/image_size.yaml") << "width: " << width << "\nheight: " << height << "\n";
  return r;
}

// numpy.quantile's default (linear interpolation between order statistics).
double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  const double pos = q * (v.size() - 1);
  const std::size_t lo = static_cast<std::size_t>(pos);
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - lo) * (v[hi] - v[lo]);
}

}  // namespace

TEST(SensitivityAnalysis, WriterRecordsTheImageSizeBesideTheCsvFiles) {
  const std::string dir = test::scratchDir() + "/analysis";
  {
    AnalysisWriter writer(dir, 640, 360);
    writer.onFinish(RunResult{});
  }
  const YamlReader size(dir + "/image_size.yaml");
  EXPECT_EQ(size.getInt("width"), 640);
  EXPECT_EQ(size.getInt("height"), 360);
  EXPECT_EQ(test::readFile(dir + "/points.csv"), "window_t,id,x_px,y_px,tracked_frames\n");
  EXPECT_EQ(test::readFile(dir + "/lines.csv"), "window_t,id,x_px,y_px,tracked_frames\n");
  EXPECT_EQ(test::readFile(dir + "/windows.csv").substr(0, 17), "window_t,frames,m");
}

TEST(SensitivityAnalysis, AnalyzedSurfacesEvaluateInTheEstimatorAsFitted) {
  if (!pythonWithNumpy()) GTEST_SKIP() << "/usr/bin/python3 with numpy, matplotlib, yaml missing";
  const std::string dir = test::scratchDir();
  // Not EuRoC's 752 x 480: a hard-coded size would put every position off.
  const Records records = writeRecords(dir + "/run", 640, 360);
  int rc = 0;
  const std::string log = analyze("'" + dir + "/run' --out '" + dir + "/out' --degree 3", &rc);
  ASSERT_EQ(rc, 0) << log;
  for (const char* png : {"points_track_surface.png", "lines_track_surface.png",
                          "track_vs_illumination.png", "track_vs_motion.png"})
    EXPECT_GT(fs::file_size(dir + "/out/" + png), 10000u) << png;

  TrackSurface points, lines;
  loadTrackSurfaces(dir + "/out/selection_surfaces.yaml", &points, &lines);
  ASSERT_TRUE(points.valid());
  ASSERT_TRUE(lines.valid());
  EXPECT_EQ(points.width, 640);
  EXPECT_EQ(points.height, 360);
  EXPECT_EQ(points.degree, 3);
  for (double x : {5.0, 160.0, 320.0, 500.0, 635.0})
    for (double y : {5.0, 90.0, 180.0, 300.0, 355.0}) {
      const double u = x / 640 - 0.5, v = y / 360 - 0.5;
      EXPECT_NEAR(points.expected(x, y), pointTrack(u, v), 0.02) << x << ", " << y;
      EXPECT_NEAR(lines.expected(x, y), lineTrack(u, v), 0.02) << x << ", " << y;
    }
  // The level is the quantile of the fitted values at the records' positions (0.5 for points).
  EXPECT_NEAR(points.min_expected_track, quantile(records.point_tracks, 0.5), 0.02);
  // The selection drops the short-track corners and keeps the centre.
  EXPECT_FALSE(points.keep(5, 355));
  EXPECT_TRUE(points.keep(320, 150));
}

TEST(SensitivityAnalysis, AnalyzeRefusesRecordsOfDifferentImageSizes) {
  if (!pythonWithNumpy()) GTEST_SKIP() << "/usr/bin/python3 with numpy, matplotlib, yaml missing";
  const std::string dir = test::scratchDir();
  writeRecords(dir + "/small", 640, 360, true, 100);
  writeRecords(dir + "/euroc", 752, 480, true, 100);
  int rc = 0;
  const std::string log =
      analyze("'" + dir + "/small' '" + dir + "/euroc' --out '" + dir + "/out'", &rc);
  EXPECT_NE(rc, 0) << log;
  EXPECT_NE(log.find("640x360"), std::string::npos) << log;
  EXPECT_NE(log.find("752x480"), std::string::npos) << log;
  EXPECT_FALSE(fs::exists(dir + "/out/selection_surfaces.yaml"));
}

TEST(SensitivityAnalysis, RecordsWithoutImageSizeAreTakenAsEuroc) {
  if (!pythonWithNumpy()) GTEST_SKIP() << "/usr/bin/python3 with numpy, matplotlib, yaml missing";
  const std::string dir = test::scratchDir();
  writeRecords(dir + "/old", 752, 480, /*size_file=*/false, 100);
  int rc = 0;
  const std::string log = analyze("'" + dir + "/old' --out '" + dir + "/out'", &rc);
  ASSERT_EQ(rc, 0) << log;
  EXPECT_NE(log.find("no image_size.yaml"), std::string::npos) << log;
  const YamlReader surfaces(dir + "/out/selection_surfaces.yaml");
  EXPECT_EQ(surfaces.getInt("width"), 752);
  EXPECT_EQ(surfaces.getInt("height"), 480);
}

TEST(SensitivityAnalysis, ConfigRefusesSurfacesFittedOnAnotherImageSize) {
  const std::string dir = test::scratchDir();
  std::ofstream(dir + "/surfaces.yaml") << "width: 640\nheight: 360\ndegree: 1\n"
                                        << "points:\n  min_expected_track: 5\n"
                                        << "  coefficients: [6, 1, -2]\n";
  std::string text = test::readFile(test::sourcePath("config/euroc.yaml"));
  const std::string from = "surfaces_file: \"\"";
  ASSERT_NE(text.find(from), std::string::npos) << "config/euroc.yaml changed";
  text.replace(text.find(from), from.size(), "surfaces_file: surfaces.yaml");
  const std::string config = dir + "/config.yaml";
  std::ofstream(config) << text;
  // EuRoC's camera is 752 x 480.
  const std::string error = test::errorOf([&] { Config::load(config); });
  EXPECT_NE(error.find("surfaces.yaml"), std::string::npos) << error;
  EXPECT_NE(error.find("640x360"), std::string::npos) << error;
  EXPECT_NE(error.find("[752, 480]"), std::string::npos) << error;

  // The same surface on a 640 x 360 camera loads, and evaluates u = x/640 - 0.5.
  const std::string res = "resolution: [752, 480]";
  ASSERT_NE(text.find(res), std::string::npos);
  text.replace(text.find(res), res.size(), "resolution: [640, 360]");
  std::ofstream(config) << text;
  const Config c = Config::load(config);
  EXPECT_NEAR(c.estimator.selection.point_surface.expected(320, 180), 6, 1e-12);
  EXPECT_NEAR(c.estimator.selection.point_surface.expected(640, 180), 6.5, 1e-12);
}

TEST(SensitivityAnalysis, SurfacesWithANonPositiveImageSizeAreRejected) {
  const std::string path = test::scratchDir() + "/surfaces.yaml";
  std::ofstream(path) << "width: 0\nheight: 480\ndegree: 0\npoints:\n  min_expected_track: 1\n"
                      << "  coefficients: [2]\n";
  TrackSurface points, lines;
  const std::string error = test::errorOf([&] { loadTrackSurfaces(path, &points, &lines); });
  EXPECT_NE(error.find("width"), std::string::npos) << error;
}
