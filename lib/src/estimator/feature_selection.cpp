#include "alvio/estimator/feature_selection.h"

#include <cmath>
#include <filesystem>

#include "alvio/common/error.h"
#include "alvio/config/yaml_reader.h"

namespace alvio {

double TrackSurface::expected(double x, double y) const {
  const double u = x / width - 0.5, v = y / height - 0.5;
  // Each power once, by products: the estimator asks for every landmark several times a
  // frame (with std::pow this was 2.9 % of optimize() and marginalize() with selection on).
  double pu[kMaxDegree + 1], pv[kMaxDegree + 1];
  pu[0] = pv[0] = 1.0;
  for (int n = 1; n <= degree; ++n) {
    pu[n] = pu[n - 1] * u;
    pv[n] = pv[n - 1] * v;
  }
  double sum = 0;
  std::size_t k = 0;
  for (int total = 0; total <= degree; ++total)
    for (int j = 0; j <= total; ++j) sum += coefficients[k++] * pu[total - j] * pv[j];
  return sum;
}

void loadTrackSurfaces(const std::string& path, TrackSurface* points, TrackSurface* lines) {
  YamlReader yaml(path);
  const int degree = yaml.getInt("degree");
  if (degree < 0 || degree > TrackSurface::kMaxDegree)
    throw Error(yaml.where("degree") + " must be in 0.." +
                std::to_string(TrackSurface::kMaxDegree));
  const std::size_t n = static_cast<std::size_t>((degree + 1) * (degree + 2) / 2);
  for (const char* key : {"width", "height"})
    if (yaml.has(key) && yaml.getDouble(key) <= 0)
      throw Error(yaml.where(key) +
                  " must be positive (the image size the surfaces were fitted on)");
  for (auto [key, surface] : {std::make_pair("points", points), std::make_pair("lines", lines)}) {
    surface->coefficients.clear();
    if (!yaml.has(key)) continue;
    surface->degree = degree;
    surface->width = yaml.getDouble("width");
    surface->height = yaml.getDouble("height");
    surface->coefficients =
        yaml.getDoubles(std::string(key) + ".coefficients", static_cast<int>(n));
    surface->min_expected_track = yaml.getDouble(std::string(key) + ".min_expected_track");
  }
  yaml.warnUnknownKeys();
}

FeatureSelectionOptions FeatureSelectionOptions::load(const YamlReader& yaml,
                                                      const std::string& prefix) {
  FeatureSelectionOptions o;
  const std::string p = prefix + ".";
  o.select_points = yaml.getBool(p + "points", o.select_points);
  o.select_lines = yaml.getBool(p + "lines", o.select_lines);
  o.refresh_unselected = yaml.getBool(p + "refresh_unselected", o.refresh_unselected);
  o.marginalize_unselected = yaml.getBool(p + "marginalize_unselected", o.marginalize_unselected);
  o.surfaces_file = yaml.getString(p + "surfaces_file", o.surfaces_file);
  o.adaptive_weighting = yaml.getBool(p + "adaptive_weighting", o.adaptive_weighting);
  o.alpha_more = yaml.getDouble(p + "alpha_more", o.alpha_more);
  o.alpha_similar = yaml.getDouble(p + "alpha_similar", o.alpha_similar);
  o.alpha_less = yaml.getDouble(p + "alpha_less", o.alpha_less);
  o.similar_band = yaml.getDouble(p + "similar_band", o.similar_band);
  o.weights_by_count = yaml.getChoice(p + "track_measure", o.weights_by_count ? "count" : "length",
                                      {"length", "count"}) == "count";
  o.alpha_case_by_length =
      yaml.getChoice(p + "alpha_case_by", o.alpha_case_by_length ? "length" : "track_measure",
                     {"track_measure", "length"}) == "length";
  o.normalize_weights = yaml.getBool(p + "normalize_weights", o.normalize_weights);
  const bool costs = o.weights_on == WeightTarget::kCosts;
  const std::string weights_on =
      yaml.getChoice(p + "weights_on", costs ? "costs" : "residuals", {"residuals", "costs"});
  o.weights_on = weights_on == "costs" ? WeightTarget::kCosts : WeightTarget::kResiduals;
  for (const char* k : {"alpha_more", "alpha_similar", "alpha_less"})
    if (yaml.getDouble(p + k, 1.0) <= 0) throw Error(yaml.where(p + k) + " must be positive");
  if (o.similar_band < 0) throw Error(yaml.where(p + "similar_band") + " must not be negative");
  if (!o.surfaces_file.empty()) {
    namespace fs = std::filesystem;
    fs::path file(o.surfaces_file);
    if (file.is_relative()) file = fs::path(yaml.path()).parent_path() / file;
    if (!fs::exists(file))
      throw Error(yaml.where(p + "surfaces_file") + ": '" + file.string() + "' does not exist");
    o.surfaces_file = file.string();
    loadTrackSurfaces(o.surfaces_file, &o.point_surface, &o.line_surface);
  }
  if ((o.select_points && !o.point_surface.valid()) || (o.select_lines && !o.line_surface.valid()))
    throw Error(yaml.where(p + "surfaces_file") +
                " must name a selection_surfaces.yaml with the selected kinds (alvio analyze)");
  return o;
}

double trackMeasure(double observations, int features, int frames, bool by_count) {
  const int divisor = by_count ? frames : features;
  return divisor > 0 ? observations / divisor : 0.0;
}

FeatureWeights adaptiveWeights(double M_p, double M_l, const FeatureSelectionOptions& o) {
  return adaptiveWeights(M_p, M_l, M_p, M_l, o);
}

FeatureWeights adaptiveWeights(double M_p, double M_l, double case_p, double case_l,
                               const FeatureSelectionOptions& o) {
  FeatureWeights w;
  w.M_p = M_p;
  w.M_l = M_l;
  if (M_p <= 0 && M_l <= 0) return w;
  const double band = o.similar_band * std::max(case_p, case_l);
  w.alpha = std::abs(case_l - case_p) <= band ? o.alpha_similar
                                              : (case_l > case_p ? o.alpha_more : o.alpha_less);
  const double denominator = w.alpha * M_l + M_p;
  w.w_p = M_p / denominator;
  w.w_l = w.alpha * M_l / denominator;
  return w;
}

ResidualScales residualScales(const FeatureWeights& w, int point_residuals, int line_residuals,
                              bool normalize, WeightTarget target) {
  ResidualScales s{2 * w.w_p, 2 * w.w_l};
  if (target == WeightTarget::kCosts) s = {std::sqrt(s.points), std::sqrt(s.lines)};
  if (!normalize) return s;
  // Information goes with the square of the scale: keep its sum over all visual residuals.
  const double weighted =
      s.points * s.points * point_residuals + s.lines * s.lines * line_residuals;
  if (weighted <= 0) return ResidualScales();
  const double k = std::sqrt((point_residuals + line_residuals) / weighted);
  return {k * s.points, k * s.lines};
}

}  // namespace alvio
