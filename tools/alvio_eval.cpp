// alvio_eval: accuracy of an estimated trajectory against ground truth (ATE, RPE).
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>

#include "alvio/common/arg_parser.h"
#include "alvio/common/error.h"
#include "alvio/common/logging.h"
#include "alvio/common/resource_path.h"
#include "alvio/eval/evaluation_report.h"
#include "alvio/io/trajectory_io.h"

using namespace alvio;

int main(int argc, char** argv) {
  ArgParser args("alvio eval",
                 "Absolute trajectory error (after alignment) and relative pose error of an\n"
                 "estimated trajectory. Files: TUM, EuRoC CSV or VINS-Mono CSV (auto-detected).");
  args.option("gt", "ground-truth trajectory file", "", true);
  args.option("est", "estimated trajectory file", "", true);
  args.option("align", "se3 | sim3 | posyaw | none", "se3");
  args.option("max-dt", "association window in seconds", "0.02");
  args.option("gt-format", "auto | tum | euroc | vins", "auto");
  args.option("est-format", "auto | tum | euroc | vins", "auto");
  args.option("against",
              "a second estimate of the same sequence: how much of the two runs' error is shared");
  args.option("json", "write all numbers to this JSON file");
  args.option("plot", "write PNG plots (and the per-pose CSV) into this folder");
  args.flag("strict", "fail on unsorted or duplicate timestamps instead of warning and dropping");
  try {
    if (!args.parse(argc, argv)) return 0;
    EvaluationOptions options;
    options.alignment = parseAlignmentMode(args.get("align"));
    options.max_dt = args.getDouble("max-dt");
    if (options.max_dt <= 0) throw Error("--max-dt must be positive");
    const TimeOrderPolicy order =
        args.isSet("strict") ? TimeOrderPolicy::kStrict : TimeOrderPolicy::kSortAndDedup;
    const Trajectory gt =
        readTrajectory(args.get("gt"), parseTrajectoryFormat(args.get("gt-format")), order);
    const Trajectory est =
        readTrajectory(args.get("est"), parseTrajectoryFormat(args.get("est-format")), order);
    const EvaluationResult result = evaluateTrajectory(est, gt, options);
    std::optional<SharedError> shared;
    if (args.isSet("against")) {
      const Trajectory other =
          readTrajectory(args.get("against"), parseTrajectoryFormat(args.get("est-format")), order);
      shared = sharedError(result, evaluateTrajectory(other, gt, options), options.max_dt);
    }
    if (args.isSet("json"))
      writeFileAtomically(args.get("json"),
                          evaluationToJson(result, options, args.get("gt"), args.get("est"),
                                           shared ? &*shared : nullptr, args.get("against")));
    if (args.isSet("plot")) {
      namespace fs = std::filesystem;
      const fs::path dir = args.get("plot");
      fs::create_directories(dir);
      writeEvaluationCsv((dir / "ate_pairs.csv").string(), result);
      const std::string script = findPackageFile("scripts/plot_eval.py");
      const std::string cmd = "/usr/bin/python3 '" + script + "' '" + dir.string() + "'";
      if (std::system(cmd.c_str()) != 0)
        logWarn("plotting failed (is python3-matplotlib installed?); data is in ",
                (dir / "ate_pairs.csv").string());
    }
    // The shared error first: the table ends with the machine-readable ATE_RMSE line.
    if (shared) std::cout << formatSharedErrorText(*shared, args.get("against"));
    std::cout << formatEvaluationText(result, options);
    return 0;
  } catch (const Error& e) {
    std::cerr << "alvio eval: error: " << e.what() << "\n";
    return 2;
  }
}
