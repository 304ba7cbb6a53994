#pragma once
// Presenting an evaluation: a human-readable table ending with the
// machine-readable "ATE_RMSE=<m>" line, a JSON document, and the per-pose CSV
// that scripts/plot_eval.py turns into PNG plots.

#include <string>

#include "alvio/eval/shared_error.h"
#include "alvio/eval/trajectory_evaluation.h"

namespace alvio {

std::string formatEvaluationText(const EvaluationResult& result, const EvaluationOptions& options);
/// With `shared` (`alvio eval --against against_path`), also a "shared_error" object.
std::string evaluationToJson(const EvaluationResult& result, const EvaluationOptions& options,
                             const std::string& gt_path, const std::string& est_path,
                             const SharedError* shared = nullptr,
                             const std::string& against_path = "");
/// The shared error of the estimate and a second run (`alvio eval --against`), in words.
std::string formatSharedErrorText(const SharedError& s, const std::string& against_path);
/// Columns: t, est_x, est_y, est_z, gt_x, gt_y, gt_z, error_m (aligned estimate).
void writeEvaluationCsv(const std::string& path, const EvaluationResult& result);

}  // namespace alvio
