#!/usr/bin/env bash
# The ROS tests' input, made in OUT (the build tree), reused while still valid:
#   sim.bag            the first DURATION s of the simulated demo sequence (alvio_euroc_to_bag)
#   groundtruth.tum    its ground truth
#   reset.bag          the first RESET_DURATION s with a blackout RESET_AT s in (scripts/faults.py's
#                      black_then_saturated: 1 s black, 1 s saturated): the estimator resets
#   offline/           the offline runner (alvio_run) on sim.bag, OpenCV on one thread: the
#                      reference of the nodelet pipeline and of the in-process regression run
#                      (OpenCV's worker threads must not change the result); redone whenever
#                      the programs were rebuilt
# The demo sequence is the simulator's (alvio_sim --demo, deterministic): taken from
# $ALVIO_DEMO_DATA, <repo>/out/demo/sim, <repo>/../data/demo, else rendered with
# alvio_sim when it is built. Without any of them OUT/UNAVAILABLE says why and the
# tests skip.
#
# usage: make_test_data.sh OUT BIN_DIR SOURCE_DIR
set -euo pipefail
out="$1" bin="$2" src="$3"
duration="${ALVIO_ROS_TEST_DURATION:-16}"
reset_duration=20 reset_at=8
mkdir -p "$out"
rm -f "$out/UNAVAILABLE"

demo=""
for d in "${ALVIO_DEMO_DATA:-}" "$src/out/demo/sim" "$src/../data/demo" "$out/demo"; do
  if [[ -n $d && -f $d/mav0/cam0/data.csv ]]; then demo="$(cd "$d" && pwd)"; break; fi
done
if [[ -z $demo && -x $bin/alvio_sim ]]; then
  echo "rendering the demo sequence with alvio_sim into $out/demo"
  "$bin/alvio_sim" --demo "$out/demo" --quiet
  demo="$out/demo"
fi
if [[ -z $demo ]]; then
  echo "no simulated demo sequence (set ALVIO_DEMO_DATA, or build alvio_sim)" | tee "$out/UNAVAILABLE"
  exit 0
fi

# The bag: remade when the source or the window changes.
stamp="$demo $duration $(stat -c %Y "$demo/mav0/cam0/data.csv") $(stat -c %Y "$demo/mav0/imu0/data.csv")"
if [[ ! -f $out/sim.bag || ! -f $out/groundtruth.tum || "$(cat "$out/source.txt" 2>/dev/null)" != "$stamp" ]]; then
  "$bin/alvio_euroc_to_bag" --dataset "$demo" --out "$out/sim.bag" --duration "$duration" \
    --groundtruth "$out/groundtruth.tum"
  echo "$stamp" >"$out/source.txt"
  rm -rf "$out/offline"
fi

# The blackout bag: remade with the bag above, or when the fault's code changes.
reset_stamp="$stamp $reset_duration $reset_at $(stat -c %Y "$src/scripts/faults.py")"
if [[ ! -f $out/reset.bag || "$(cat "$out/reset_source.txt" 2>/dev/null)" != "$reset_stamp" ]]; then
  "$bin/alvio_euroc_to_bag" --dataset "$demo" --out "$out/reset_clean.bag" \
    --duration "$reset_duration"
  # Debian's python: rosbag and numpy (a pyenv python first on PATH has neither).
  /usr/bin/python3 "$src/test/ros/make_fault_bag.py" "$out/reset_clean.bag" \
    black_then_saturated "$reset_at" "$out/reset.bag"
  rm -f "$out/reset_clean.bag"
  echo "$reset_stamp" >"$out/reset_source.txt"
fi

# The offline reference: redone when the bag, alvio_run or a library it uses was rebuilt.
newest_build=$(find "$bin/alvio_run" "$bin/.."/libalvio_{core,mapping,logging}.so \
  -newer "$out/offline/trajectory.tum" 2>/dev/null | head -1 || true)
if [[ ! -f $out/offline/trajectory.tum || -n $newest_build ]]; then
  rm -rf "$out/offline"
  "$bin/alvio_run" --dataset "$out/sim.bag" --out "$out/offline" --quiet --no-log \
    --opencv-threads 1 >"$out/offline.txt" 2>&1 ||
    { cat "$out/offline.txt"; exit 1; }
fi
echo "test data in $out (from $demo, $duration s)"
