#!/usr/bin/env bash
# SE(3) ATE of every estimated trajectory in ../shared/data/euroc_trajectories
# against the EuRoC body-frame ground truth, as a markdown table.
# Usage: scripts/eval_shared_trajectories.sh [SHARED_DATA_DIR]
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
DATA="${1:-$ROOT/../shared/data}"
EVAL="${ALVIO_BUILD_DIR:-$ROOT/build}/devel/lib/alvio/alvio_eval"
[[ -x $EVAL ]] || { echo "build first: ./alvio build" >&2; exit 1; }
GT="$DATA/euroc_groundtruth/xygxgn_VINS-Fusion/output"

seq_of() {  # map a trajectory path to its ground-truth file
  local p="$1"
  case "$p" in
    *Yixin-F*) echo "$GT/MH_05_difficult.txt" ;;
    *kavehsgh*) echo "$GT/MH_01_easy.txt" ;;
    *V1_01*) echo "$DATA/euroc_groundtruth/plvio/benchmark_publisher/config/V1_01_easy/v101_gt_tum.txt" ;;
    *V102.txt) echo "$GT/V1_02_medium.txt" ;;
    *)
      for s in MH_01:MH_01_easy MH_02:MH_02_easy MH_03:MH_03_medium MH_04:MH_04_difficult \
               MH_05:MH_05_difficult V1_02:V1_02_medium V1_03:V1_03_difficult \
               V2_01:V2_01_easy V2_02:V2_02_medium V2_03:V2_03_difficult; do
        local key="${s%%:*}"
        if [[ $p == *"$key"* || $p == *"${key/_/-}"* ]]; then echo "$GT/${s#*:}.txt"; return; fi
      done ;;
  esac
}

echo "| estimated trajectory | ground truth | matched | ATE RMSE SE(3) [m] |"
echo "|---|---|---:|---:|"
find "$DATA/euroc_trajectories" -type f \( -name 'vins_result*.csv' -o -name 'stamped_*.txt' \
  -o -name V102.txt -o -name vins_tum.txt \) | sort | while read -r est; do
  gt="$(seq_of "$est")"
  [[ -n $gt ]] || continue
  out="$("$EVAL" --gt "$gt" --est "$est" 2>/dev/null)" || { echo "| ${est#$DATA/} | $(basename "$gt") | - | failed |"; continue; }
  matched="$(sed -n 's/.* \([0-9]*\) matched.*/\1/p' <<<"$out")"
  echo "| ${est#$DATA/euroc_trajectories/} | $(basename "$gt" .txt) | $matched | ${out##*ATE_RMSE=} |"
done
