// Adaptive point/line weights (ALVIO Sec. 3) and the residual scales the estimator applies.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "alvio/config/yaml_reader.h"
#include "alvio/estimator/feature_selection.h"
#include "test_support.h"

using namespace alvio;

TEST(AdaptiveWeights, AlphaFollowsWhichKindTracksLonger) {
  const FeatureSelectionOptions o;                            // alpha 5.0 / 2.2 / 1.0, band 20 %
  EXPECT_DOUBLE_EQ(adaptiveWeights(4.0, 8.0, o).alpha, 5.0);  // lines track longer
  EXPECT_DOUBLE_EQ(adaptiveWeights(5.0, 4.5, o).alpha, 2.2);  // within the band
  EXPECT_DOUBLE_EQ(adaptiveWeights(8.0, 4.0, o).alpha, 1.0);  // lines track shorter
}

TEST(AdaptiveWeights, AreThePapersFractionsAndSumToOne) {
  const FeatureSelectionOptions o;
  const FeatureWeights w = adaptiveWeights(6.0, 3.0, o);  // alpha 1
  EXPECT_DOUBLE_EQ(w.w_p, 6.0 / 9.0);
  EXPECT_DOUBLE_EQ(w.w_l, 3.0 / 9.0);
  const FeatureWeights more = adaptiveWeights(3.0, 6.0, o);  // alpha 5
  EXPECT_DOUBLE_EQ(more.w_l, 30.0 / 33.0);
  EXPECT_DOUBLE_EQ(more.w_p + more.w_l, 1.0);
}

TEST(TrackMeasure, LengthIsPerFeatureAndCountIsPerFrame) {
  // 30 features seen 180 times in an 11-frame window: 6 frames each, 16.4 a frame.
  EXPECT_DOUBLE_EQ(trackMeasure(180, 30, 11, false), 6.0);
  EXPECT_DOUBLE_EQ(trackMeasure(180, 30, 11, true), 180.0 / 11);
  EXPECT_DOUBLE_EQ(trackMeasure(0, 0, 11, false), 0.0);  // no features: no division by zero
}

TEST(FeatureSelectionOptions, TrackMeasureIsLengthOrCountAndNamesTheKeyOtherwise) {
  auto load = [](const std::string& text) {
    return FeatureSelectionOptions::load(YamlReader::fromString(text, "test.yaml"), "selection");
  };
  EXPECT_TRUE(load("selection: {adaptive_weighting: true}\n").weights_by_count);  // default
  EXPECT_FALSE(load("selection: {track_measure: length}\n").weights_by_count);
  EXPECT_TRUE(load("selection: {track_measure: count}\n").weights_by_count);
  const std::string error = test::errorOf([&] { load("selection: {track_measure: number}\n"); });
  EXPECT_NE(error.find("selection.track_measure"), std::string::npos) << error;
}

// Counted, points outnumber lines (240 against 35 a frame) and alpha would stay 1; compared
// by track length (lines 8 frames, points 6) the lines' case is "more", while the weights
// still count.
TEST(AdaptiveWeights, AlphasCaseCanComeFromAnotherMeasure) {
  const FeatureSelectionOptions o;
  EXPECT_DOUBLE_EQ(adaptiveWeights(240.0, 35.0, o).alpha, 1.0);
  const FeatureWeights w = adaptiveWeights(240.0, 35.0, 6.0, 8.0, o);
  EXPECT_DOUBLE_EQ(w.alpha, 5.0);
  EXPECT_DOUBLE_EQ(w.w_l, 5.0 * 35.0 / (5.0 * 35.0 + 240.0));
  EXPECT_DOUBLE_EQ(w.M_l, 35.0);
  EXPECT_DOUBLE_EQ(adaptiveWeights(240.0, 35.0, 6.0, 6.5, o).alpha, 2.2);
}

TEST(FeatureSelectionOptions, AlphasCaseIsTheTrackMeasureOrLength) {
  auto load = [](const std::string& text) {
    return FeatureSelectionOptions::load(YamlReader::fromString(text, "test.yaml"), "selection");
  };
  EXPECT_FALSE(load("selection: {adaptive_weighting: true}\n").alpha_case_by_length);
  EXPECT_TRUE(load("selection: {alpha_case_by: length}\n").alpha_case_by_length);
  EXPECT_FALSE(load("selection: {alpha_case_by: track_measure}\n").alpha_case_by_length);
  const std::string error = test::errorOf([&] { load("selection: {alpha_case_by: count}\n"); });
  EXPECT_NE(error.find("selection.alpha_case_by"), std::string::npos) << error;
}

TEST(ResidualScales, EqualWeightsLeaveResidualsUnscaled) {
  FeatureWeights equal;  // 0.5 / 0.5
  for (bool normalize : {false, true})
    for (WeightTarget target : {WeightTarget::kResiduals, WeightTarget::kCosts}) {
      const ResidualScales s = residualScales(equal, 1200, 300, normalize, target);
      EXPECT_DOUBLE_EQ(s.points, 1.0);
      EXPECT_DOUBLE_EQ(s.lines, 1.0);
    }
}

TEST(ResidualScales, NormalizedKeepTheTotalVisualInformation) {
  FeatureWeights w;
  w.w_p = 0.3;
  w.w_l = 0.7;
  const int n_p = 1300, n_l = 280;
  const ResidualScales raw = residualScales(w, n_p, n_l, false, WeightTarget::kResiduals);
  EXPECT_DOUBLE_EQ(raw.points, 0.6);
  EXPECT_DOUBLE_EQ(raw.lines, 1.4);
  const ResidualScales s = residualScales(w, n_p, n_l, true, WeightTarget::kResiduals);
  // Information is the square of the scale, summed over the residuals.
  EXPECT_NEAR(s.points * s.points * n_p + s.lines * s.lines * n_l, n_p + n_l, 1e-9);
  EXPECT_NEAR(s.lines / s.points, w.w_l / w.w_p, 1e-12);
  // Without the normalisation these weights leave 64 % of it (0.36 * 1300 + 1.96 * 280).
  EXPECT_NEAR((raw.points * raw.points * n_p + raw.lines * raw.lines * n_l) / (n_p + n_l), 0.6435,
              1e-4);
}

TEST(ResidualScales, NoResidualsGiveUnitScales) {
  FeatureWeights w;
  w.w_p = 0.2;
  w.w_l = 0.8;
  const ResidualScales s = residualScales(w, 0, 0, true, WeightTarget::kCosts);
  EXPECT_DOUBLE_EQ(s.points, 1.0);
  EXPECT_DOUBLE_EQ(s.lines, 1.0);
}

TEST(ResidualScales, WeightsOnTheCostsScaleResidualsByTheirRoot) {
  FeatureWeights w;
  w.w_p = 0.3;
  w.w_l = 0.7;
  const ResidualScales raw = residualScales(w, 1300, 280, false, WeightTarget::kCosts);
  EXPECT_DOUBLE_EQ(raw.points, std::sqrt(0.6));
  EXPECT_DOUBLE_EQ(raw.lines, std::sqrt(1.4));
  const ResidualScales s = residualScales(w, 1300, 280, true, WeightTarget::kCosts);
  // Lines get w_l / w_p times the information of points, not its square.
  EXPECT_NEAR(s.lines * s.lines / (s.points * s.points), w.w_l / w.w_p, 1e-12);
  EXPECT_NEAR(s.points * s.points * 1300 + s.lines * s.lines * 280, 1300 + 280, 1e-9);
}

TEST(FeatureSelectionOptions, WeightsOnNamesTheKeyWhenItIsNeitherResidualsNorCosts) {
  const FeatureSelectionOptions costs = FeatureSelectionOptions::load(
      YamlReader::fromString("selection: {weights_on: costs}\n", "test.yaml"), "selection");
  EXPECT_EQ(costs.weights_on, WeightTarget::kCosts);
  const FeatureSelectionOptions residuals = FeatureSelectionOptions::load(
      YamlReader::fromString("selection: {weights_on: residuals}\n", "test.yaml"), "selection");
  EXPECT_EQ(residuals.weights_on, WeightTarget::kResiduals);
  const FeatureSelectionOptions unset = FeatureSelectionOptions::load(
      YamlReader::fromString("selection: {adaptive_weighting: true}\n", "test.yaml"), "selection");
  EXPECT_EQ(unset.weights_on, FeatureSelectionOptions().weights_on);
  const std::string error = test::errorOf([] {
    FeatureSelectionOptions::load(
        YamlReader::fromString("selection: {weights_on: cost}\n", "test.yaml"), "selection");
  });
  EXPECT_NE(error.find("selection.weights_on"), std::string::npos) << error;
}
