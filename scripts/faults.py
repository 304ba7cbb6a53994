#!/usr/bin/env python3
"""alvio faults: the fault-injection suite (issue 11).

Each fault is written into a copy of a clean bag (images and IMU), which is then run
both offline (alvio run) and through the nodelet pipeline (scripts/ros_demo.sh, the
bag played on simulated time). A markdown table says, per fault and mode, whether the
run completed (no crash, hang or NaN pose), how often the estimator reset, the ATE
before the fault and from the fault on (each SE(3)-aligned on its own), and how long
it took to track again after the fault ended.

  ./alvio faults [--dataset EUROC_DIR] [--config YAML] [--only a,b]
                 [--modes offline,nodelet] [--rate R] [--out DIR]

--only also takes gaps of any length: image_gap_3s, imu_gap_0.25s.

Default input: the demo sequence (30 s figure eight, rendered when missing). The fast
rotation is rendered by alvio_sim along the input's ground truth with a 360-degree yaw
spin inserted. Results: OUT/faults.md and OUT/faults.json; each run's files stay in
OUT/<fault>/<mode>/.
"""
import argparse
import copy
import json
import math
import os
import random
import shutil
import signal
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
IMAGE_TOPIC, IMU_TOPIC = "/cam0/image_raw", "/imu0"
GAP_S = 0.3  # a pause in the pose output longer than this is a loss of tracking


def log(msg):
    print(f"\033[1m[alvio faults]\033[0m {msg}", file=sys.stderr, flush=True)


# --- faults: each rewrites the message stream -------------------------------------------


@dataclass
class Fault:
    name: str
    what: str
    duration: float  # seconds of fault from the fault time (inf: to the end)
    mutate: object = None  # (FaultContext, topic, msg, bag_t) -> list of (topic, msg, bag_t)
    shift_after_s: float = 0.0  # stamps from the fault on were moved by this (evaluation undoes it)
    rendered: bool = False  # the input itself is re-rendered (fast rotation)


@dataclass
class FaultContext:
    t_fault: float
    t_end: float
    rng: random.Random = field(default_factory=lambda: random.Random(11))
    held: list = field(default_factory=list)
    count: int = 0
    duration: object = None  # seconds -> rospy.Duration (rospy comes with the ROS environment)

    def inside(self, t):
        return self.t_fault <= t < self.t_end


def stamp_s(msg):
    return msg.header.stamp.to_sec()


def image_array(msg):
    return np.frombuffer(msg.data, dtype=np.uint8).reshape(msg.height, msg.step)


def set_image(msg, arr):
    msg.data = np.ascontiguousarray(arr, dtype=np.uint8).tobytes()


def scaled(msg, gain):
    set_image(msg, np.clip(image_array(msg).astype(np.float32) * gain + 0.5, 0, 255))
    return msg


def drop_images(p):
    def mutate(ctx, topic, msg, t):
        if topic == IMAGE_TOPIC and ctx.inside(stamp_s(msg)) and ctx.rng.random() < p:
            return []
        return [(topic, msg, t)]
    return mutate


def drop_topic(which):
    def mutate(ctx, topic, msg, t):
        return [] if topic == which and ctx.inside(stamp_s(msg)) else [(topic, msg, t)]
    return mutate


def imu_out_of_order(ctx, topic, msg, t):
    # Pairs of IMU samples arrive swapped: the second one first.
    if topic != IMU_TOPIC or not ctx.inside(stamp_s(msg)):
        out = ctx.held + [(topic, msg, t)]
        ctx.held = []
        return out
    if not ctx.held:
        ctx.held = [(topic, msg, t)]
        return []
    (_, first, t_first) = ctx.held[0]
    ctx.held = []
    return [(topic, msg, t_first), (topic, first, t)]


def imu_duplicates(ctx, topic, msg, t):
    if topic != IMU_TOPIC or not ctx.inside(stamp_s(msg)):
        return [(topic, msg, t)]
    twin = copy.deepcopy(msg)
    twin.linear_acceleration.x += 0.05  # same stamp, different reading
    return [(topic, msg, t), (topic, twin, t + ctx.duration(1e-6))]


def time_jump_back(seconds):
    def mutate(ctx, topic, msg, t):
        if stamp_s(msg) >= ctx.t_fault:
            msg.header.stamp = msg.header.stamp - ctx.duration(seconds)
        return [(topic, msg, t)]
    return mutate


def black_then_saturated(ctx, topic, msg, t):
    if topic == IMAGE_TOPIC and ctx.inside(stamp_s(msg)):
        value = 0 if stamp_s(msg) < ctx.t_fault + 1.0 else 255
        set_image(msg, np.full((msg.height, msg.step), value, np.uint8))
    return [(topic, msg, t)]


def illumination(gain):
    def mutate(ctx, topic, msg, t):
        if topic == IMAGE_TOPIC and ctx.inside(stamp_s(msg)):
            scaled(msg, gain)
        return [(topic, msg, t)]
    return mutate


def fade(gain, seconds):
    # A slow change passes the exposure compensation (a few tenths of a percent a frame), so
    # both trackers see the dark frames as they are.
    def mutate(ctx, topic, msg, t):
        if topic == IMAGE_TOPIC and ctx.inside(stamp_s(msg)):
            done = min(1.0, (stamp_s(msg) - ctx.t_fault) / seconds)
            scaled(msg, 1.0 - (1.0 - gain) * done)
        return [(topic, msg, t)]
    return mutate


def flicker(ctx, topic, msg, t):
    # Mains flicker aliased by the camera: the gain swings between 0.4 and 1.0 at 6 Hz.
    if topic == IMAGE_TOPIC and ctx.inside(stamp_s(msg)):
        scaled(msg, 0.7 + 0.3 * math.sin(2 * math.pi * 6.0 * (stamp_s(msg) - ctx.t_fault)))
    return [(topic, msg, t)]


def imu_nan_inf(ctx, topic, msg, t):
    if topic == IMU_TOPIC and ctx.inside(stamp_s(msg)):
        ctx.count += 1
        if ctx.count % 5 == 0:
            msg.linear_acceleration.x = float("nan")
        elif ctx.count % 7 == 0:
            msg.angular_velocity.z = float("inf")
    return [(topic, msg, t)]


def bad_images(ctx, topic, msg, t):
    # In turn: half the size, an encoding nobody knows, data shorter than height x step.
    if topic != IMAGE_TOPIC or not ctx.inside(stamp_s(msg)):
        return [(topic, msg, t)]
    ctx.count += 1
    kind = ctx.count % 3
    if kind == 0:
        half = image_array(msg)[::2, : msg.width : 2]
        msg.height, msg.width = half.shape
        msg.step = msg.width
        set_image(msg, half)
    elif kind == 1:
        msg.encoding = "bayer_unknown16"
    else:
        msg.data = msg.data[: len(msg.data) // 3]
    return [(topic, msg, t)]


FAULTS = [
    Fault("none", "no fault (the reference)", 0.0, None),
    Fault("drop_10pct", "10 % of the frames dropped at random, from the fault on", math.inf,
          drop_images(0.10)),
    Fault("image_gap_1s", "no images for 1 s", 1.0, drop_topic(IMAGE_TOPIC)),
    Fault("imu_gap_0.5s", "no IMU for 0.5 s", 0.5, drop_topic(IMU_TOPIC)),
    Fault("imu_out_of_order", "IMU samples arrive in swapped pairs for 1 s", 1.0, imu_out_of_order),
    Fault("imu_duplicate_stamps", "every IMU sample sent twice (second reading differs) for 1 s",
          1.0, imu_duplicates),
    Fault("stamp_jump_back", "all stamps jump 0.5 s back (a clock reset) from the fault on",
          math.inf, time_jump_back(0.5), shift_after_s=-0.5),
    Fault("black_then_saturated", "1 s of black frames, then 1 s of saturated frames", 2.0,
          black_then_saturated),
    Fault("illumination_x0.3", "the light drops to 30 % for good", math.inf, illumination(0.3)),
    Fault("fade_to_0.3", "the light fades to 30 % over 5 s and stays there", math.inf,
          fade(0.3, 5.0)),
    Fault("flicker", "3 s of flicker (gain 0.4 to 1.0 at 6 Hz)", 3.0, flicker),
    Fault("fast_rotation", "a 360-degree yaw spin in 1 s (peak 540 deg/s), rendered", 1.0, None,
          rendered=True),
    Fault("imu_nan_inf", "NaN or Inf in one IMU sample in three for 1 s", 1.0, imu_nan_inf),
    Fault("bad_images", "wrong size, unknown encoding or truncated data in every image for 1 s",
          1.0, bad_images),
]

# Gaps of any length, by name (image_gap_3s, imu_gap_0.25s): outages of several lengths are
# what scripts/odometry_error.py fits the odometry's outage sigmas on.
GAP_TOPICS = {"image_gap": (IMAGE_TOPIC, "images"), "imu_gap": (IMU_TOPIC, "IMU")}
MAX_GAP_S = 60.0


def fault_named(name):
    """The fault of this name: one of FAULTS, or a gap of any length; None when unknown."""
    for f in FAULTS:
        if f.name == name:
            return f
    kind, _, length = name.rpartition("_")
    if kind not in GAP_TOPICS or not length.endswith("s"):
        return None
    try:
        seconds = float(length[:-1])
    except ValueError:
        return None
    if not 0 < seconds <= MAX_GAP_S:
        return None
    topic, what = GAP_TOPICS[kind]
    return Fault(name, f"no {what} for {seconds:g} s", seconds, drop_topic(topic))


def faults_named(names):
    """The faults of a comma-separated list, in its order; exits naming any unknown one."""
    found = [(n, fault_named(n)) for n in dict.fromkeys(names.split(","))]  # once each
    unknown = [n for n, f in found if f is None]
    if unknown:
        sys.exit(f"faults: unknown fault(s) {unknown}; known: {[f.name for f in FAULTS]}, and "
                 f"image_gap_<S>s or imu_gap_<S>s for a gap of S seconds (0 < S <= {MAX_GAP_S:g})")
    return [f for _, f in found]


# --- inputs ------------------------------------------------------------------------------


def ros_env(build):
    """The environment with the catkin devel space sourced (rosbag, roslaunch, messages)."""
    cmd = f"source '{build}/devel/setup.bash' && env -0"
    env = dict(os.environ)
    env["PATH"] = "/usr/bin:/bin:/usr/sbin:/sbin:" + env.get("PATH", "")
    env.pop("PYTHONPATH", None)
    out = subprocess.run(["bash", "-c", cmd], env=env, check=True, capture_output=True).stdout
    return dict(item.split("=", 1) for item in out.decode().split("\0") if "=" in item)


def read_tum(path):
    rows = []
    if not Path(path).exists():
        return np.zeros((0, 8))
    for line in Path(path).read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            rows.append([float(v) for v in line.split()[:8]])
    return np.array(rows) if rows else np.zeros((0, 8))


def write_tum(path, rows):
    with open(path, "w") as f:
        f.write("# timestamp tx ty tz qx qy qz qw\n")
        for r in rows:
            f.write(f"{r[0]:.9f} " + " ".join(f"{v:.9f}" for v in r[1:8]) + "\n")


def prepare_input(args, env, out):
    """The clean bag and its ground truth (TUM)."""
    bin_dir = Path(args.build) / "devel/lib/alvio"
    if args.dataset:
        src = Path(args.dataset).resolve()
    else:
        src = ROOT / "out/demo/sim"
        if not (src / "mav0/cam0/data.csv").exists():
            log(f"rendering the demo sequence into {src}")
            subprocess.run([str(bin_dir / "alvio_sim"), "--demo", str(src)], env=env, check=True)
    bag, gt = out / "input/clean.bag", out / "input/groundtruth.tum"
    bag.parent.mkdir(parents=True, exist_ok=True)
    if not bag.exists() or (src / "mav0/cam0/data.csv").stat().st_mtime > bag.stat().st_mtime:
        log(f"writing {bag} from {src}")
        subprocess.run([str(bin_dir / "alvio_euroc_to_bag"), "--dataset", str(src), "--out",
                        str(bag), "--groundtruth", str(gt)], env=env, check=True)
    return bag, gt


def yaw_spin_trajectory(gt_rows, t_fault, seconds):
    """The ground truth with a full turn about the world z axis inserted at t_fault
    (smoothstep profile: back to the original orientation after `seconds`)."""
    out = gt_rows.copy()
    for r in out:
        u = (r[0] - t_fault) / seconds
        if not 0.0 < u < 1.0:
            continue
        theta = 2 * math.pi * (3 * u * u - 2 * u * u * u)
        qz = np.array([0.0, 0.0, math.sin(theta / 2), math.cos(theta / 2)])  # x y z w
        r[4:8] = quat_mul(qz, r[4:8])
    return out


def quat_mul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return np.array([aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw,
                     aw * bw - ax * bx - ay * by - az * bz])


def render_fast_rotation(args, env, gt, t_fault, out):
    """A bag along the input's ground truth with the spin inserted, and its ground truth."""
    bin_dir = Path(args.build) / "devel/lib/alvio"
    folder = out / "input/fast_rotation"
    bag = folder / "fast_rotation.bag"
    if bag.exists():
        return bag, folder / "groundtruth.tum"
    traj = out / "input/fast_rotation_trajectory.tum"
    write_tum(traj, yaw_spin_trajectory(read_tum(gt), t_fault, 1.0))
    log("rendering the fast-rotation sequence (alvio_sim along the spun ground truth)")
    subprocess.run([str(bin_dir / "alvio_sim"), "--trajectory", str(traj), "--still", "0",
                    "--config", args.config, "--out", str(folder), "--bag", "--quiet"],
                   env=env, check=True)
    subprocess.run([str(bin_dir / "alvio_euroc_to_bag"), "--dataset", str(folder), "--out",
                    str(folder / "unused.bag"), "--groundtruth", str(folder / "groundtruth.tum")],
                   env=env, check=True, stdout=subprocess.DEVNULL)
    (folder / "unused.bag").unlink()
    return bag, folder / "groundtruth.tum"


def write_faulted_bag(clean, fault, t_fault, path):
    import rosbag  # from the sourced ROS environment
    import rospy
    t_end = t_fault + fault.duration
    ctx = FaultContext(t_fault, t_end, duration=rospy.Duration.from_sec)
    with rosbag.Bag(str(clean)) as src, rosbag.Bag(str(path) + ".tmp", "w") as dst:
        for topic, msg, t in src.read_messages(topics=[IMAGE_TOPIC, IMU_TOPIC]):
            for o_topic, o_msg, o_t in fault.mutate(ctx, topic, msg, t):
                dst.write(o_topic, o_msg, o_t)
        for o_topic, o_msg, o_t in ctx.held:
            dst.write(o_topic, o_msg, o_t)
    os.replace(str(path) + ".tmp", path)


# --- runs and their evaluation -------------------------------------------------------------


def ate(bin_dir, env, gt, rows, path):
    """SE(3)-aligned ATE RMSE of these poses (None when fewer than 3)."""
    if len(rows) < 3:
        return None
    write_tum(path, rows)
    js = path.with_suffix(".json")
    r = subprocess.run([str(bin_dir / "alvio_eval"), "--gt", str(gt), "--est", str(path),
                        "--align", "se3", "--json", str(js)], env=env, capture_output=True)
    if r.returncode != 0 or not js.exists():
        return None
    return json.loads(js.read_text())["ate_translation_m"]["rmse"]


def read_runs(traj_path):
    """The poses in the order they were estimated: first the runs that a clock jump ended
    (the nodelets keep each as trajectory_run<N>.tum), then the current one."""
    runs = sorted(traj_path.parent.glob("trajectory_run*.tum"),
                  key=lambda p: int(p.stem[len("trajectory_run"):]))
    return np.vstack([read_tum(p) for p in runs] + [read_tum(traj_path)])


def evaluate(bin_dir, env, gt, traj_path, fault, t_fault, run_dir):
    rows = read_runs(traj_path)
    res = {"poses": int(len(rows)), "nan_poses": int((~np.isfinite(rows)).any(axis=1).sum())}
    rows = rows[np.isfinite(rows).all(axis=1)]
    if fault.shift_after_s and len(rows):
        rows = rows.copy()
        # Back onto the true clock. The old clock's stamps all lie before the fault, so in
        # estimation order the new clock starts at the first stamp that is past the fault or
        # goes back.
        t = rows[:, 0]
        new_clock = (t >= t_fault) | np.concatenate([[False], np.diff(t) < 0])
        first = int(np.argmax(new_clock)) if new_clock.any() else len(rows)
        rows[first:, 0] -= fault.shift_after_s
    before, after = rows[rows[:, 0] < t_fault], rows[rows[:, 0] >= t_fault]
    res["ate_before_m"] = ate(bin_dir, env, gt, before, run_dir / "eval_before.tum")
    res["ate_after_m"] = ate(bin_dir, env, gt, after, run_dir / "eval_after.tum")
    # Recovery: when the final unbroken stretch of poses began, after the fault's end (a
    # lasting change, such as darker light, from its start).
    fault_end = t_fault + (fault.duration if math.isfinite(fault.duration) else 0.0)
    if len(after) == 0:
        res["recovery_s"] = None
    else:
        t = rows[:, 0]
        gaps = np.where(np.diff(t) > GAP_S)[0]
        stretch_start = t[gaps[-1] + 1] if len(gaps) else t[0]
        res["tracking_lost"] = bool(stretch_start >= t_fault)
        res["recovery_s"] = max(0.0, stretch_start - fault_end) if stretch_start >= t_fault else 0.0
    return res


def run_offline(args, env, bag, run_dir, timeout):
    bin_dir = Path(args.build) / "devel/lib/alvio"
    cmd = [str(bin_dir / "alvio_run"), "--dataset", str(bag), "--out", str(run_dir),
           "--config", args.config, "--quiet"]
    with open(run_dir / "run.log", "w") as logf:
        try:
            r = subprocess.run(cmd, env=env, stdout=logf, stderr=subprocess.STDOUT, timeout=timeout)
            code = r.returncode
        except subprocess.TimeoutExpired:
            return {"completed": False, "why": f"hang (no exit in {timeout:.0f} s)"}
    summary_path = run_dir / "summary.json"
    if code != 0 or not summary_path.exists():
        return {"completed": False, "why": f"exit status {code}"}
    s = json.loads(summary_path.read_text())
    return {"completed": True, "resets": s.get("resets", 0), "frames": s.get("frames"),
            "dropped_images": s.get("dropped_images", 0) + s.get("skipped_images", 0),
            "dropped_imu": s.get("dropped_imu", 0)}


def read_recorded(path):
    """The estimator's status messages, and how many odometry messages hold a NaN or Inf (pose
    or twist: what a robot's controller would read)."""
    import rosbag
    statuses, bad_odometry = [], 0
    if not path.exists():
        return statuses, bad_odometry
    with rosbag.Bag(str(path)) as b:
        for topic, msg, _ in b.read_messages():
            if topic.endswith("/odometry"):
                p, q, tw = msg.pose.pose.position, msg.pose.pose.orientation, msg.twist.twist
                values = [p.x, p.y, p.z, q.x, q.y, q.z, q.w, tw.linear.x, tw.linear.y,
                          tw.linear.z, tw.angular.x, tw.angular.y, tw.angular.z]
                bad_odometry += not all(math.isfinite(v) for v in values)
            else:
                statuses.append(msg)
    return statuses, bad_odometry


def run_nodelet(args, env, bag, run_dir, timeout):
    cmd = ["bash", str(ROOT / "scripts/ros_demo.sh"), "--bag", str(bag), "--out", str(run_dir),
           "--rate", str(args.rate), "--config", args.config, "--record-status"]
    with open(run_dir / "demo.log", "w") as logf:
        try:
            p = subprocess.Popen(cmd, env=env, stdout=logf, stderr=subprocess.STDOUT,
                                 start_new_session=True)
            code = p.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            return {"completed": False, "why": f"hang (no exit in {timeout:.0f} s)"}
    launch_log = (run_dir / "roslaunch.log").read_text(errors="replace") \
        if (run_dir / "roslaunch.log").exists() else ""
    died = [l for l in launch_log.splitlines() if "process has died" in l]
    if code != 0 or died:
        return {"completed": False, "why": died[0] if died else f"exit status {code}"}
    statuses, bad_odometry = read_recorded(run_dir / "run/status.bag")
    res = {"completed": True, "status_messages": len(statuses), "nan_odometry": bad_odometry}
    if statuses:
        last = statuses[-1]
        res.update(resets=int(last.reset_count), frames=int(last.frames),
                   dropped_images=int(last.dropped_frames), dropped_imu=int(last.dropped_imu),
                   reset_statuses=sum(1 for m in statuses if m.state == m.RESET))
    return res


def fmt(v, spec="{:.3f}"):
    return "—" if v is None else spec.format(v)


def table(results):
    lines = ["| fault | mode | completed | frames | resets | ATE before (m) | ATE from fault (m) | "
             "tracking lost | recovery (s) | dropped img / IMU | NaN poses (odometry) |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        done = "yes" if r.get("completed") else f"**no**: {r.get('why', '')}"
        lost = "—" if "tracking_lost" not in r else ("yes" if r["tracking_lost"] else "no")
        dropped = "—" if "dropped_images" not in r else \
            f"{r['dropped_images']} / {r.get('dropped_imu', 0)}"
        lines.append(f"| {r['fault']} | {r['mode']} | {done} | {r.get('frames', '—')} | "
                     f"{r.get('resets', '—')} | "
                     f"{fmt(r.get('ate_before_m'))} | {fmt(r.get('ate_after_m'))} | {lost} | "
                     f"{fmt(r.get('recovery_s'), '{:.2f}')} | {dropped} | "
                     f"{r.get('nan_poses', '—')}"
                     + (f" ({r['nan_odometry']})" if "nan_odometry" in r else "") + " |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="faults: " + ", ".join(f.name for f in FAULTS) +
                                 "; also image_gap_<S>s and imu_gap_<S>s of any length")
    ap.add_argument("--dataset", help="EuRoC folder with ground truth (default: the demo sequence)")
    # Given to the offline and the nodelet runs alike (ros_demo.sh does not read ALVIO_CONFIG);
    # a real IMU's sequence wants config/euroc_real.yaml.
    ap.add_argument("--config",
                    default=os.environ.get("ALVIO_CONFIG", str(ROOT / "config/euroc.yaml")),
                    help="alvio configuration of every run (default: $ALVIO_CONFIG, else "
                         "config/euroc.yaml)")
    ap.add_argument("--only", help="comma-separated fault names; image_gap_<S>s and "
                                   "imu_gap_<S>s take any length S in seconds (image_gap_3s)")
    ap.add_argument("--modes", default="offline,nodelet")
    ap.add_argument("--rate", type=float, default=0.5, help="nodelet playback rate")
    ap.add_argument("--fault-at", type=float, default=0.4,
                    help="fault time as a fraction of the sequence (default 0.4)")
    ap.add_argument("--out", default=str(ROOT / "out/faults"))
    ap.add_argument("--keep-bags", action="store_true", help="keep each faulted bag")
    ap.add_argument("--build", default=os.environ.get("ALVIO_BUILD_DIR", str(ROOT / "build")))
    args = ap.parse_args()
    if not Path(args.config).is_file():
        sys.exit(f"faults: --config {args.config}: no such file")
    args.config = str(Path(args.config).resolve())
    modes = args.modes.split(",")
    for m in modes:
        if m not in ("offline", "nodelet"):
            sys.exit(f"faults: unknown mode '{m}' (offline, nodelet)")
    faults = faults_named(args.only) if args.only else FAULTS

    env = ros_env(args.build)
    sys.path[:0] = [p for p in env.get("PYTHONPATH", "").split(":") if p]
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    bin_dir = Path(args.build) / "devel/lib/alvio"
    clean, gt = prepare_input(args, env, out)
    gt_rows = read_tum(gt)
    t0, t1 = gt_rows[0, 0], gt_rows[-1, 0]
    t_fault = t0 + args.fault_at * (t1 - t0)
    log(f"input {clean} ({t1 - t0:.1f} s); faults at {t_fault - t0:.1f} s")

    results = []
    started = time.time()
    for i, fault in enumerate(faults):
        log(f"[{i + 1}/{len(faults)}] {fault.name}: {fault.what}")
        fault_dir = out / fault.name
        shutil.rmtree(fault_dir, ignore_errors=True)
        fault_dir.mkdir(parents=True)
        fault_gt = gt
        if fault.rendered:
            bag, fault_gt = render_fast_rotation(args, env, gt, t_fault, out)
        elif fault.mutate is None:
            bag = clean
        else:
            bag = fault_dir / f"{fault.name}.bag"
            write_faulted_bag(clean, fault, t_fault, bag)
        for mode in modes:
            run_dir = fault_dir / mode
            run_dir.mkdir()
            seconds = t1 - t0
            if mode == "offline":
                res = run_offline(args, env, bag, run_dir, timeout=60 + 10 * seconds)
                traj = run_dir / "trajectory.tum"
            else:
                res = run_nodelet(args, env, bag, run_dir,
                                  timeout=120 + 3 * seconds / args.rate)
                traj = run_dir / "run/trajectory.tum"
            if res.get("completed"):
                res.update(evaluate(bin_dir, env, fault_gt, traj, fault, t_fault, run_dir))
                if res["nan_poses"] or res.get("nan_odometry"):
                    res["completed"] = False
                    res["why"] = (f"{res['nan_poses']} NaN pose(s), "
                                  f"{res.get('nan_odometry', 0)} odometry message(s) with NaN "
                                  f"or Inf")
            res.update(fault=fault.name, mode=mode, what=fault.what)
            results.append(res)
            log(f"    {mode}: " + ", ".join(f"{k}={v}" for k, v in res.items()
                                            if k not in ("fault", "mode", "what")))
        if bag != clean and not fault.rendered and not args.keep_bags:
            bag.unlink()

    md = (f"Input: {clean} ({t1 - t0:.1f} s), faults at {t_fault - t0:.1f} s; nodelets at "
          f"rate {args.rate}. ATE: SE(3)-aligned RMSE of the poses before the fault and of "
          f"those from the fault on, each aligned on its own. Recovery: from the fault's end "
          f"to the start of the final unbroken stretch of poses (0 when tracking never "
          f"stopped for over {GAP_S} s).\n\n" + table(results) + "\n\nFaults:\n\n" +
          "\n".join(f"- `{f.name}`: {f.what}" for f in faults) + "\n")
    (out / "faults.md").write_text(md)
    (out / "faults.json").write_text(json.dumps(results, indent=2) + "\n")
    print(md)
    log(f"done in {time.time() - started:.0f} s: {out / 'faults.md'}")
    failed = [r for r in results if not r.get("completed")]
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
