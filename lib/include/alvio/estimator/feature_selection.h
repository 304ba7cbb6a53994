#pragma once
// Sensitivity-analysis-based feature selection and adaptive weighting (ALVIO,
// Sec. 3). A fitted surface gives the expected track length of a feature from
// its image position; features where it is below a level are left out of the
// optimisation. Points and lines are weighted by how many of each kind are tracked:
//   w_p = M_p / (a M_l + M_p),  w_l = a M_l / (a M_l + M_p),
// with a = alpha_more, alpha_similar or alpha_less when lines track more than,
// about as much as, or less than points (M by count, or by track length: trackMeasure).

#include <array>
#include <string>
#include <vector>

namespace alvio {

class YamlReader;

/// Expected track length over the image: a bivariate polynomial in
/// (u, v) = (x / width - 0.5, y / height - 0.5), monomials u^i v^j with i + j <= degree in
/// order of total degree, then increasing j (as scripts/analyze_sensitivity.py writes it).
struct TrackSurface {
  static constexpr int kMaxDegree = 8;
  int degree = 0;  ///< 0..kMaxDegree
  double width = 752, height = 480;
  std::vector<double> coefficients;
  double min_expected_track = 0;  ///< the selection level
  bool valid() const { return !coefficients.empty(); }
  double expected(double x, double y) const;
  bool keep(double x, double y) const { return !valid() || expected(x, y) >= min_expected_track; }
};

/// What the adaptive weights multiply: each visual residual (by 2w, so its cost by 4w^2), or
/// each visual cost term (by 2w, the residual by sqrt(2w)), as in weighted least squares.
enum class WeightTarget { kResiduals, kCosts };

struct FeatureSelectionOptions {
  bool select_points = false;  ///< leave points in low-value image regions out
  bool select_lines = false;
  /// Triangulate the points left out again every frame, so that they keep a depth fit for
  /// the outlier check and for the solve they join when their anchor moves.
  bool refresh_unselected = true;
  /// Fold the points and lines left out into the marginalisation prior when their first
  /// keyframe leaves.
  bool marginalize_unselected = true;
  std::string surfaces_file;  ///< selection_surfaces.yaml (alvio analyze); relative to the config
  TrackSurface point_surface, line_surface;  ///< loaded from surfaces_file
  bool adaptive_weighting = true;
  double alpha_more = 5.0;     ///< lines track more than points (M_l > M_p)
  double alpha_similar = 2.2;  ///< about as much
  double alpha_less = 1.0;     ///< less
  double similar_band = 0.2;   ///< |M_l - M_p| <= band * max(M_l, M_p) counts as "about as much"
  /// What M_p and M_l measure: true, each kind's mean number of tracks (tracked features per
  /// frame of the window: the paper's "number of tracking", which it says is much larger for
  /// points); false, its mean track length (observations per feature in the window).
  bool weights_by_count = true;
  /// Which measure picks alpha's case: false, the same M as the weights; true, the mean track
  /// length even when the weights count tracks. The paper's cases compare the trackers'
  /// "tracking capability", while its M_p is "much larger than M_l": by count, lines never
  /// track more than points, and alpha is always alpha_less.
  bool alpha_case_by_length = false;
  /// Scale the weighted residuals so that points and lines together carry as much
  /// information as unweighted: the weights then move trust between points and lines, not
  /// from the camera to the IMU. Off: the 2w of `weights_on` as it is (equal weights =
  /// unweighted).
  bool normalize_weights = true;
  WeightTarget weights_on = WeightTarget::kCosts;

  /// Reads `prefix` ("estimator.selection"); a relative surfaces_file is resolved against the
  /// directory of the config file and loaded (errors name that file and key).
  static FeatureSelectionOptions load(const YamlReader& yaml, const std::string& prefix);
};

/// Loads a selection_surfaces.yaml.
void loadTrackSurfaces(const std::string& path, TrackSurface* points, TrackSurface* lines);

struct FeatureWeights {
  double w_p = 0.5, w_l = 0.5, alpha = 1.0;
  double M_p = 0, M_l = 0;  ///< trackMeasure() of the points and lines in the window
};

/// M for one kind of feature: `observations` summed over its `features` in a window of
/// `frames`. By length, observations per feature; by count, tracked features per frame.
double trackMeasure(double observations, int features, int frames, bool by_count);

/// The ALVIO weights for the track measures M_p and M_l.
FeatureWeights adaptiveWeights(double M_p, double M_l, const FeatureSelectionOptions& options);
/// The same, with alpha's case decided by comparing `case_p` and `case_l` instead.
FeatureWeights adaptiveWeights(double M_p, double M_l, double case_p, double case_l,
                               const FeatureSelectionOptions& options);

/// Factors that multiply the point and line residuals for weights `w`, with
/// `point_residuals` and `line_residuals` residual blocks in the window (see
/// FeatureSelectionOptions::normalize_weights).
struct ResidualScales {
  double points = 1.0, lines = 1.0;
};
ResidualScales residualScales(const FeatureWeights& w, int point_residuals, int line_residuals,
                              bool normalize, WeightTarget target);

}  // namespace alvio
