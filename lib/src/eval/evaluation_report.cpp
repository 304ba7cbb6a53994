#include "alvio/eval/evaluation_report.h"

#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "alvio/io/trajectory_io.h"

namespace alvio {
namespace {
nlohmann::json statsJson(const ErrorStats& s) {
  return {{"count", s.count}, {"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median},
          {"std", s.std},     {"min", s.min},   {"max", s.max}};
}
}  // namespace

std::string formatEvaluationText(const EvaluationResult& r, const EvaluationOptions& o) {
  std::ostringstream os;
  char buf[256];
  os << "poses: " << r.est_poses << " estimated, " << r.gt_poses << " ground truth, " << r.matched
     << " matched (max dt " << o.max_dt << " s)\n";
  std::snprintf(buf, sizeof(buf), "alignment: %s, scale %.6f, path length %.2f m\n",
                alignmentModeName(o.alignment), r.alignment.s, r.path_length_m);
  os << buf;
  const auto& a = r.ate_translation_m;
  std::snprintf(buf, sizeof(buf),
                "ATE translation [m]: rmse %.4f  mean %.4f  median %.4f  std %.4f  max %.4f\n",
                a.rmse, a.mean, a.median, a.std, a.max);
  os << buf;
  const auto& b = r.ate_rotation_deg;
  std::snprintf(buf, sizeof(buf),
                "ATE rotation [deg]:  rmse %.3f  mean %.3f  median %.3f  max %.3f\n", b.rmse,
                b.mean, b.median, b.max);
  os << buf << "RPE over sub-trajectories:\n"
     << "  length [m] (fraction)  pairs  trans mean [%]  trans median [%]  rot mean [deg/m]\n";
  for (const auto& s : r.rpe) {
    std::snprintf(buf, sizeof(buf), "  %8.2f (%3.0f%%)      %6zu  %14.3f  %16.3f  %16.4f\n",
                  s.length_m, 100 * s.fraction, s.translation_percent.count,
                  s.translation_percent.mean, s.translation_percent.median,
                  s.rotation_deg_per_m.mean);
    os << buf;
  }
  std::snprintf(buf, sizeof(buf), "ATE_RMSE=%.6f\n", a.rmse);
  os << buf;
  return os.str();
}

std::string evaluationToJson(const EvaluationResult& r, const EvaluationOptions& o,
                             const std::string& gt_path, const std::string& est_path,
                             const SharedError* shared, const std::string& against_path) {
  nlohmann::json j;
  j["ground_truth"] = gt_path;
  j["estimate"] = est_path;
  j["alignment"] = alignmentModeName(o.alignment);
  j["max_dt"] = o.max_dt;
  j["poses"] = {{"estimated", r.est_poses}, {"ground_truth", r.gt_poses}, {"matched", r.matched}};
  j["path_length_m"] = r.path_length_m;
  j["transform"] = {{"scale", r.alignment.s},
                    {"rotation",
                     {{r.alignment.R(0, 0), r.alignment.R(0, 1), r.alignment.R(0, 2)},
                      {r.alignment.R(1, 0), r.alignment.R(1, 1), r.alignment.R(1, 2)},
                      {r.alignment.R(2, 0), r.alignment.R(2, 1), r.alignment.R(2, 2)}}},
                    {"translation", {r.alignment.t.x(), r.alignment.t.y(), r.alignment.t.z()}}};
  j["ate_translation_m"] = statsJson(r.ate_translation_m);
  j["ate_rotation_deg"] = statsJson(r.ate_rotation_deg);
  nlohmann::json rpe = nlohmann::json::array();
  for (const auto& s : r.rpe)
    rpe.push_back({{"fraction", s.fraction},
                   {"length_m", s.length_m},
                   {"translation_percent", statsJson(s.translation_percent)},
                   {"rotation_deg_per_m", statsJson(s.rotation_deg_per_m)}});
  j["rpe"] = rpe;
  if (shared)
    j["shared_error"] = {{"against", against_path},
                         {"matched", shared->matched},
                         {"rms_m", shared->rms_a},
                         {"against_rms_m", shared->rms_b},
                         {"difference_rms_m", shared->rms_difference},
                         {"shared_rms_m", shared->rms_shared},
                         {"shared_fraction", shared->shared_fraction},
                         {"axis_correlation",
                          {shared->axis_correlation.x(), shared->axis_correlation.y(),
                           shared->axis_correlation.z()}}};
  return j.dump(2) + "\n";
}

void writeEvaluationCsv(const std::string& path, const EvaluationResult& r) {
  std::string text = "t,est_x,est_y,est_z,gt_x,gt_y,gt_z,error_m\n";
  char buf[256];
  for (std::size_t k = 0; k < r.t.size(); ++k) {
    const auto& e = r.est_aligned[k];
    const auto& g = r.gt_matched[k];
    std::snprintf(buf, sizeof(buf), "%.9f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f\n", r.t[k], e.x(),
                  e.y(), e.z(), g.x(), g.y(), g.z(), r.translation_error_m[k]);
    text += buf;
  }
  writeFileAtomically(path, text);
}

std::string formatSharedErrorText(const SharedError& s, const std::string& against_path) {
  char buf[512];
  std::snprintf(buf, sizeof(buf),
                "against %s, %zu poses at the same times:\n"
                "  ATE [m]: this run %.4f, the other %.4f; their errors differ by %.4f (rms)\n"
                "  shared error %.4f m rms, %.1f %% of the two runs' squared error; "
                "correlation along x / y / z %.2f / %.2f / %.2f\n",
                against_path.c_str(), s.matched, s.rms_a, s.rms_b, s.rms_difference, s.rms_shared,
                100 * s.shared_fraction, s.axis_correlation.x(), s.axis_correlation.y(),
                s.axis_correlation.z());
  return buf;
}

}  // namespace alvio
