#!/usr/bin/env bash
# alvio demo: the simulated demo sequence as a rosbag, played (--clock) through
# the nodelet pipeline (launch/sim.launch: tracker, estimator, mapping, logger in one
# manager) on a private ROS master; then the ATE of the trajectory the estimator
# wrote, and where every output file is.
#
#   scripts/ros_demo.sh [--rate R] [--out DIR]      (./alvio demo builds first)
#   scripts/ros_demo.sh --bag FILE [--groundtruth TUM] [--record-status] [--no-logging] ...
#   scripts/ros_demo.sh ... --allocator LIB   (preloaded into the manager; "" for glibc's malloc)
#   scripts/ros_demo.sh ... --config FILE     (the nodelets' configuration; default config/euroc.yaml)
#
# The demo sequence comes from $ALVIO_DEMO_DATA, out/demo/sim, ../data/demo, or is
# rendered with alvio_sim --demo when that tool is built. --bag plays another bag instead
# (the ATE needs --groundtruth); --record-status keeps the estimator's status and odometry
# messages in <out>/run/status.bag (the fault-injection suite reads them); --no-logging leaves the MRPT
# logger out, as the launch file's default does (latency measurements).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${ALVIO_BUILD_DIR:-$ROOT/build}"
BIN="$BUILD/devel/lib/alvio"
rate=0.5  # the front end needs ~45 ms per frame on 2 busy cores: real time is too tight
out="$ROOT/out/demo"
bag=""
gt=""
record_status=false
logging=true
allocator=libmimalloc.so.2
config="$ROOT/config/euroc.yaml"
while [[ $# -gt 0 ]]; do
  case "$1" in
    --rate) rate="$2"; shift 2 ;;
    # Absolute: roslaunch runs the player and the nodelets in another working directory.
    --out) out="$(realpath -m "$2")"; shift 2 ;;
    --bag) bag="$(realpath -m "$2")"; shift 2 ;;
    --groundtruth) gt="$(realpath -m "$2")"; shift 2 ;;
    --record-status) record_status=true; shift ;;
    --no-logging) logging=false; shift ;;
    --allocator) allocator="$2"; shift 2 ;;
    --config) config="$(realpath "$2")"; shift 2 ;;
    -h|--help) sed -n '2,16p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "demo: unknown option $1" >&2; exit 2 ;;
  esac
done

log() { printf '\033[1m[alvio demo]\033[0m %s\n' "$*" >&2; }
die() { printf '[alvio demo] error: %s\n' "$*" >&2; exit 1; }

# shellcheck source=lib/ros_env.sh
source "$ROOT/scripts/lib/ros_env.sh"
source_ros_build "$BUILD"

mkdir -p "$out"
if [[ -n $bag ]]; then
  [[ -f $bag ]] || die "no bag '$bag'"
else
  # The input: the simulator's demo folder, as a bag.
  demo=""
  for d in "${ALVIO_DEMO_DATA:-}" "$ROOT/out/demo/sim" "$ROOT/../data/demo"; do
    if [[ -n $d && -f $d/mav0/cam0/data.csv ]]; then demo="$(cd "$d" && pwd)"; break; fi
  done
  if [[ -z $demo ]]; then
    [[ -x $BIN/alvio_sim ]] || die "no demo sequence (set ALVIO_DEMO_DATA) and no alvio_sim to render one"
    log "rendering the demo sequence into $ROOT/out/demo/sim"
    "$BIN/alvio_sim" --demo "$ROOT/out/demo/sim"
    demo="$ROOT/out/demo/sim"
  fi
  bag="$out/demo.bag"
  gt="$out/groundtruth.tum"
  if [[ ! -f $bag || $demo/mav0/cam0/data.csv -nt $bag ]]; then
    log "writing $bag from $demo"
    "$BIN/alvio_euroc_to_bag" --dataset "$demo" --out "$bag" --groundtruth "$gt"
  fi
fi

run="$out/run"
rm -rf "$run"
mkdir -p "$run"
core_pid=""
trap 'kill $core_pid 2>/dev/null || true; wait 2>/dev/null || true' EXIT
start_private_master "$out" || die "roscore did not start (see $out/roscore.log)"

if $record_status; then
  rosbag record --quiet -O "$run/status.bag" /alvio/estimator/status /alvio/estimator/odometry \
    __name:=status_recorder \
    >"$out/status_record.log" 2>&1 &
  record_pid=$!
fi
log "playing $(basename "$bag") at rate $rate through the nodelet pipeline (master $ROS_MASTER_URI)"
start=$(date +%s)
roslaunch "$ROOT/launch/sim.launch" bag:="$bag" rate:="$rate" output_dir:="$run" logging:="$logging" \
  allocator:="$allocator" config_file:="$config" exit_at_end:=false >"$out/roslaunch.log" 2>&1 &
launch_pid=$!
trap 'kill -INT "$launch_pid" ${record_pid:-} 2>/dev/null || true; kill "$core_pid" 2>/dev/null || true; wait 2>/dev/null || true' EXIT
# The player appears, plays and leaves; then the estimator gets 1 s without frames to hand
# the window to the map (flush_after_s) before the pipeline shuts down and writes its files.
# (grep reads a captured list: under pipefail, `rosnode list | grep -q` fails at random when
# grep quits first and rosnode list dies of SIGPIPE.)
player_up() { local nodes; nodes=$(rosnode list 2>/dev/null || true); grep -q '^/player$' <<<"$nodes"; }
for _ in $(seq 150); do player_up && break; sleep 0.2; done
kill -0 "$launch_pid" 2>/dev/null || die "roslaunch ended early (see $out/roslaunch.log)"
while player_up; do
  kill -0 "$launch_pid" 2>/dev/null || die "roslaunch ended early (see $out/roslaunch.log)"
  sleep 1
done
sleep 3
kill -INT "$launch_pid"
wait "$launch_pid" || true
if $record_status; then rosnode kill /status_recorder >/dev/null 2>&1 || true; fi
log "pipeline finished in $(($(date +%s) - start)) s"

[[ -s $run/trajectory.tum ]] || die "no trajectory written (see $out/roslaunch.log)"
if [[ -z $gt ]]; then
  echo "trajectory: $run/trajectory.tum ($(wc -l <"$run/trajectory.tum") poses; no ground truth given)"
  exit 0
fi
"$BIN/alvio_eval" --gt "$gt" --est "$run/trajectory.tum" --align se3 \
  --json "$run/eval.json" --plot "$run" >"$run/eval.txt"
ate=$(python3 -c 'import json, sys; print("%.4f" % json.load(open(sys.argv[1]))["ate_translation_m"]["rmse"])' "$run/eval.json")
grep -h "dropped\|frames were lost" "$ROS_LOG_DIR"/*/*.log 2>/dev/null | tail -3 >&2 || true
echo "ATE_RMSE=$ate m (SE(3) alignment, $(wc -l <"$run/trajectory.tum") poses)"
echo "outputs in $run:"
for f in trajectory.tum eval.json octomap.bt lines.ply lines.csv map.3Dscene alvio.rawlog \
         alvio.3Dscene alvio.log; do
  [[ -e $run/$f ]] && echo "  $run/$f"
done
echo "  ROS logs: $ROS_LOG_DIR, launch output: $out/roslaunch.log"
