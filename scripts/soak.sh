#!/usr/bin/env bash
# alvio soak: a bag played over and over through the nodelet pipeline (launch/sim.launch,
# loop:=true) for a given time, on a private ROS master. Every 30 s it samples the nodelet
# manager's resident memory and the estimator's status (frames, resets), and checks that
# the manager is still the same process. Each loop sends time back to the bag's start,
# which the nodelets take as a new run.
#
#   scripts/soak.sh [--minutes 60] [--rate 0.5] [--bag FILE] [--out DIR]
#
# At the end the manager gets SIGTERM (as docker stop or systemd would send it) and must
# still write the latest run's trajectory and map into OUT/run. Default bag: the demo's
# (out/demo/demo.bag, written by ./alvio demo). Writes OUT/soak.csv and prints
# start/end/peak RSS; exit status 1 when the manager died, restarted or lost its files.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
BUILD="${ALVIO_BUILD_DIR:-$ROOT/build}"
minutes=60
rate=0.5
bag="$ROOT/out/demo/demo.bag"
out="$ROOT/out/soak"
while [[ $# -gt 0 ]]; do
  case "$1" in
    --minutes) minutes="$2"; shift 2 ;;
    --rate) rate="$2"; shift 2 ;;
    --bag) bag="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    -h|--help) sed -n '2,13p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "soak: unknown option $1" >&2; exit 2 ;;
  esac
done
log() { printf '\033[1m[alvio soak]\033[0m %s\n' "$*" >&2; }
die() { printf '[alvio soak] error: %s\n' "$*" >&2; exit 1; }

# shellcheck source=lib/ros_env.sh
source "$ROOT/scripts/lib/ros_env.sh"
source_ros_build "$BUILD"
[[ -f $bag ]] || die "no bag '$bag' (./alvio demo writes out/demo/demo.bag)"

mkdir -p "$out"
core_pid=""
trap 'kill $core_pid 2>/dev/null || true; wait 2>/dev/null || true' EXIT
start_private_master "$out" || die "roscore did not start (see $out/roscore.log)"

log "looping $(basename "$bag") at rate $rate for $minutes min (master $ROS_MASTER_URI)"
roslaunch "$ROOT/launch/sim.launch" bag:="$bag" rate:="$rate" loop:=true output_dir:="$out/run" \
  exit_at_end:=false >"$out/roslaunch.log" 2>&1 &
launch_pid=$!
trap 'kill -INT "$launch_pid" 2>/dev/null || true; wait "$launch_pid" 2>/dev/null || true; kill "$core_pid" 2>/dev/null || true; wait 2>/dev/null || true' EXIT

# Asked of this master, so that a manager of another run on the machine is never taken.
manager_pid() { timeout 10 rosnode info /alvio/alvio_manager 2>/dev/null | awk '/^Pid:/ { print $2 }' || true; }
for _ in $(seq 100); do [[ -n $(manager_pid) ]] && break; sleep 0.2; done
pid0=$(manager_pid)
[[ -n $pid0 ]] || die "no nodelet manager (see $out/roslaunch.log)"
status_field() {  # one field of the next status message ("" when none comes within 5 s)
  timeout 5 rostopic echo -n 1 "/alvio/estimator/status/$1" 2>/dev/null | head -1 || true
}

echo "elapsed_s,rss_mb,manager_pid,frames,reset_count,state" >"$out/soak.csv"
start=$(date +%s)
end=$((start + $(python3 -c "print(round(float(\"$minutes\") * 60))")))
restarts=0
while (($(date +%s) < end)); do
  sleep 30
  pid=$(manager_pid)
  rss=""
  [[ -n $pid ]] && rss=$(awk '/VmRSS/ { printf "%.1f", $2 / 1024 }' "/proc/$pid/status" 2>/dev/null || true)
  [[ $pid == "$pid0" ]] || { restarts=$((restarts + 1)); pid0=$pid; log "manager pid changed: now '${pid}'"; }
  line="$(($(date +%s) - start)),${rss},${pid},$(status_field frames),$(status_field reset_count),$(status_field state)"
  echo "$line" >>"$out/soak.csv"
  log "$line"
done
# While tracking, so that the current run has poses to write (a run the loop has just
# restarted has none yet, and an empty trajectory is not written).
for _ in $(seq 20); do [[ $(status_field state) == *tracking* ]] && break; sleep 2; done
log "SIGTERM to the nodelet manager ($pid0)"
rm -f "$out/run/"{trajectory.tum,octomap.bt,lines.csv,lines.ply,map.3Dscene}  # only what SIGTERM writes counts
kill -TERM "$pid0"
for _ in $(seq 60); do kill -0 "$pid0" 2>/dev/null || break; sleep 0.5; done
kill -0 "$pid0" 2>/dev/null && die "the manager did not exit within 30 s of SIGTERM"
missing=()
for f in trajectory.tum octomap.bt lines.csv lines.ply map.3Dscene; do
  [[ -s $out/run/$f ]] || missing+=("$f")
done
kill -INT "$launch_pid"
wait "$launch_pid" || true

python3 - "$out/soak.csv" "$restarts" <<'PY'
import csv, sys
rows = [r for r in csv.DictReader(open(sys.argv[1])) if r["rss_mb"]]
if not rows:
    sys.exit("soak: no memory samples")
rss = [float(r["rss_mb"]) for r in rows]
third = max(1, len(rss) // 3)
print(f"samples: {len(rows)} over {rows[-1]['elapsed_s']} s; manager restarts: {sys.argv[2]}")
print(f"RSS MB: first {rss[0]:.0f}, last {rss[-1]:.0f}, peak {max(rss):.0f}; "
      f"mean of the first third {sum(rss[:third]) / third:.0f}, "
      f"of the last third {sum(rss[-third:]) / third:.0f}")
PY
new_runs=$(grep -c "the estimator starts a new run" "$out/roslaunch.log" || true)
echo "runs restarted by the loop: $new_runs"
# Each finished run is kept once: the estimator's trajectory and the mapping nodelet's map.
kept_trajectories=$(find "$out/run" -maxdepth 1 -name 'trajectory_run*.tum' | wc -l)
kept_maps=$(find "$out/run" -mindepth 1 -maxdepth 1 -type d -name 'run[0-9]*' | wc -l)
echo "finished runs kept: $kept_trajectories trajectories, $kept_maps maps"
((restarts == 0)) || die "the nodelet manager restarted $restarts time(s)"
# The mapping nodelet hears of a new run from its first odometry, after initialisation: the
# run ended by SIGTERM may not have reached it (its map is then the top-level one).
((kept_maps == new_runs || kept_maps + 1 == new_runs)) ||
  die "$new_runs new runs but $kept_maps maps kept (run<N>/)"
((${#missing[@]} == 0)) || die "not written on SIGTERM: ${missing[*]}"
echo "written on SIGTERM into $out/run: trajectory.tum ($(wc -l <"$out/run/trajectory.tum") lines), octomap.bt, lines.csv, lines.ply, map.3Dscene"
