#!/usr/bin/python3
"""How far alvio's odometry is from the truth, component by component, and the
`odometry_covariance:` sigmas that describe it.

    scripts/odometry_error.py RUN:DATASET [RUN:DATASET ...]
                              [--config YAML [--outages-only] [--plot DIR]]

RUN is an `alvio run --out` folder (trajectory.tum, states.csv, events.log); DATASET the
EuRoC/ASL folder it ran on, with mav0/state_groundtruth_estimate0/data.csv (position,
orientation, velocity) and mav0/imu0/data.csv. For every output pose the errors are those of
the estimator nodelet's odometry message:

- position and yaw relative to where the odometry started: both trajectories are put on the
  first output pose (position and yaw; roll and pitch are gravity's), so the error is the
  drift since then, against the path travelled (the truth's; the nodelet counts its own
  output's, which differs by the scale error, a few per cent) and the outages so far: pauses
  in the output longer than outage_min_s (0.3 s, or the --config's), bridged by the IMU's
  dead reckoning (images missing, tracking lost, a reset: events.log says which);
- tilt: the orientation's error about the world's x and y axes (gravity's direction);
- velocity in the body frame (R^T v), which no alignment changes;
- angular rate: the gyroscope interpolated at the frame's stamp less the estimated bias (what
  the nodelet publishes), against the truth's rate.

It prints each run's errors, then the sigmas fitted over all runs: the angular rate's RMS per
axis (a gyroscope on a vibrating body is noisier on some axes), velocity and tilt the largest
per-axis RMS, position and yaw the least-squares fits, all terms >= 0, of
e^2 = s0^2 + (k d)^2 + sum over the outages before the pose of (a T)^2 + (b T^2)^2 (yaw: (c T)^2),
d the path and T each outage's length (a, b, c are fitted only when the runs have an outage),
and per outage the error's jump across it. With
--config it also prints how often that configuration's model holds each error within 1 and 2
sigma (a Gaussian: 68 % and 95 %), to check sigmas on runs that did not set them. With
--outages-only it fits a, b and c alone, by Gaussian maximum likelihood, the configuration's
s0, k and yaw terms held: fit those on runs without faults first, then the outages on runs
with them (./alvio faults).
"""
import argparse
import sys
from pathlib import Path

import numpy as np
import yaml

import imu_noise  # scripts/, beside this one
from imu_noise import quat_to_matrix, rotation_log

KEYS = ("position_sigma_m", "position_drift", "tilt_sigma_deg", "yaw_sigma_deg",
        "yaw_drift_deg_per_m", "outage_min_s", "outage_position_sigma_mps",
        "outage_position_sigma_mps2", "outage_yaw_sigma_deg_per_s",
        "velocity_sigma_mps", "angular_rate_sigma_rps")
OUTAGE_KEYS = ("outage_position_sigma_mps", "outage_position_sigma_mps2",
               "outage_yaw_sigma_deg_per_s")
OUTAGE_MIN_S = 0.3  # alvio's default outage_min_s
# Keys of the sixty-sixth session's constant per reset, which alvio no longer reads.
REPLACED_KEYS = ("reset_position_sigma_m", "reset_yaw_sigma_deg")
# Sigmas of the body-frame twist: one number for all three axes or a list of three (x, y, z).
PER_AXIS_KEYS = ("velocity_sigma_mps", "angular_rate_sigma_rps")

# The columns read from each file (more may follow); imu_noise.py reads the same formats.
TUM_COLUMNS = imu_noise.TUM_COLUMNS
STATES_COLUMNS = ("t", "vx", "vy", "vz", "bax", "bay", "baz", "bgx", "bgy", "bgz")
TRUTH_COLUMNS = imu_noise.EUROC_GT_COLUMNS + ("v_RS_R_x", "v_RS_R_y", "v_RS_R_z")
IMU_COLUMNS = imu_noise.IMU_COLUMNS[:4]  # the gyroscope


def fail(message):
    sys.exit(f"odometry_error: {message}")


def load_table(path, columns, delimiter=None, header=0):
    return imu_noise.load_table(path, columns, delimiter, header, program="odometry_error")


def interpolate_quaternions(t_query, t, q):
    """Normalised linear interpolation of quaternions (x, y, z, w) sampled densely."""
    q = q.copy()
    flip = np.sum(q[1:] * q[:-1], 1) < 0  # one hemisphere, so neighbours blend
    q[1:][np.cumsum(flip) % 2 == 1] *= -1
    out = np.stack([np.interp(t_query, t, q[:, k]) for k in range(4)], 1)
    return out / np.linalg.norm(out, axis=1, keepdims=True)


def run_errors(run, dataset, outage_min_s=OUTAGE_MIN_S):
    """The errors of one run's output poses (dict of arrays), and at each pose the path, the
    outages so far (count, sums of T^2 and T^4) and the resets so far."""
    run, dataset = Path(run), Path(dataset)
    est = load_table(run / "trajectory.tum", TUM_COLUMNS)
    states = load_table(run / "states.csv", STATES_COLUMNS, delimiter=",", header=1)
    gt = load_table(dataset / "mav0/state_groundtruth_estimate0/data.csv", TRUTH_COLUMNS,
                    delimiter=",")
    imu = load_table(dataset / "mav0/imu0/data.csv", IMU_COLUMNS, delimiter=",")
    if len(states) != len(est) or np.max(np.abs(states[:, 0] - est[:, 0])) > 1e-4:
        fail(f"{run}: states.csv and trajectory.tum do not have the same poses")
    # A reset before the first output pose (while initialising) re-anchors nothing.
    reset_times = load_reset_times(run / "events.log")
    reset_times = reset_times[reset_times > est[0, 0]]
    t_gt, t_imu = gt[:, 0] * 1e-9, imu[:, 0] * 1e-9
    inside = (est[:, 0] > t_gt[0] + 0.01) & (est[:, 0] < t_gt[-1] - 0.01)
    if inside.sum() < 2:
        fail(f"{run}: fewer than 2 poses inside the ground truth of {dataset}")
    est, states = est[inside], states[inside]
    t = est[:, 0]
    p_gt = np.stack([np.interp(t, t_gt, gt[:, k]) for k in (1, 2, 3)], 1)
    v_gt = np.stack([np.interp(t, t_gt, gt[:, k]) for k in (8, 9, 10)], 1)
    q_gt_all = gt[:, [5, 6, 7, 4]]  # EuRoC: w, x, y, z
    R_gt = quat_to_matrix(interpolate_quaternions(t, t_gt, q_gt_all))
    R_est = quat_to_matrix(est[:, 4:8])

    # Velocity in the body frame.
    v_body = np.einsum("nji,nj->ni", R_est, states[:, 1:4])
    v_body_gt = np.einsum("nji,nj->ni", R_gt, v_gt)
    # Position and orientation since the first output pose. The orientation's error is
    # a rotation about the world's axes, as the odometry's covariance has it: about x and y
    # it is tilt (gravity's), about z yaw.
    dyaw = -rotation_log(R_est[:1] @ R_gt[:1].transpose(0, 2, 1))[0, 2]
    c, s = np.cos(dyaw), np.sin(dyaw)
    Rz = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    p_est = (est[:, 1:4] - est[0, 1:4]) @ Rz.T + p_gt[0]
    rot_err = np.degrees(rotation_log(np.einsum("ij,njk,nlk->nil", Rz, R_est, R_gt)))
    path = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(p_gt, axis=0), axis=1))])
    resets = np.searchsorted(reset_times, t, side="right")  # resets at or before each pose
    gap = np.concatenate([[0.0], np.diff(t)])
    gap[gap <= outage_min_s] = 0.0
    outages, outage_s2, outage_s4 = np.cumsum(gap > 0), np.cumsum(gap ** 2), np.cumsum(gap ** 4)
    # Angular rate: the gyroscope interpolated at the frame's stamp, less the estimated bias
    # (Estimator::gyroAtLatestFrame; np.interp holds the last sample as the estimator does).
    gyro = np.stack([np.interp(t, t_imu, imu[:, 1 + k]) for k in range(3)], 1)
    h = 0.0025
    Rp = quat_to_matrix(interpolate_quaternions(np.clip(t + h, t_gt[0], t_gt[-1]), t_gt, q_gt_all))
    Rm = quat_to_matrix(interpolate_quaternions(np.clip(t - h, t_gt[0], t_gt[-1]), t_gt, q_gt_all))
    rate_gt = rotation_log(np.einsum("nji,njk->nik", Rm, Rp)) / (2 * h)
    rate_err = gyro - states[:, 7:10] - rate_gt
    return {"t": t, "path": path, "resets": resets, "outages": outages, "outage_s2": outage_s2,
            "outage_s4": outage_s4, "position": p_est - p_gt, "yaw": rot_err[:, 2],
            "tilt": rot_err[:, :2], "velocity": v_body - v_body_gt, "rate": rate_err}


def load_reset_times(path):
    """The times of the estimator's resets: events.log's lines "<t> reset <why>"."""
    try:
        lines = Path(path).read_text().splitlines()
    except OSError as e:
        fail(f"{path}: cannot read: {e} (alvio run writes it beside trajectory.tum)")
    times = []
    for number, line in enumerate(lines, 1):
        fields = line.split(maxsplit=2)
        if len(fields) >= 2 and fields[1] == "reset":
            try:
                times.append(float(fields[0]))
            except ValueError:
                fail(f"{path}:{number}: a reset without a time: {line!r}")
    return np.sort(np.array(times))


def outage_ends(errors):
    """The index of the first pose after each outage."""
    return np.flatnonzero(np.diff(errors["outages"]) > 0) + 1


def outage_jumps(errors):
    """Per outage: (s after the first pose, its length: s from the last pose before it to the
    first after, resets in it, the position error's jump (m), the yaw error's (deg))."""
    t = errors["t"]
    return [(t[i] - t[0], t[i] - t[i - 1], int(errors["resets"][i] - errors["resets"][i - 1]),
             float(np.linalg.norm(errors["position"][i] - errors["position"][i - 1])),
             float(errors["yaw"][i] - errors["yaw"][i - 1])) for i in outage_ends(errors)]


def pooled(all_errors):
    """The runs' errors end to end: one array per quantity."""
    return {k: np.concatenate([r[k] for r in all_errors]) for k in all_errors[0]}


def rms(x, axis=0):
    return np.sqrt(np.mean(np.square(x), axis=axis))


def nonnegative_lstsq(A, b):
    """min |A x - b| with x >= 0. With a few unknowns the constrained optimum is the best
    unconstrained fit, over the subsets of the terms, whose coefficients are all >= 0."""
    m = A.shape[1]
    best = (np.sum(np.square(b)), np.zeros(m))  # no term at all
    for subset in range(1, 2 ** m):
        cols = [j for j in range(m) if subset >> j & 1]
        coef, *_ = np.linalg.lstsq(A[:, cols], b, rcond=None)
        if np.any(coef < 0):
            continue
        full = np.zeros(m)
        full[cols] = coef
        residual = np.sum(np.square(A @ full - b))
        if residual < best[0]:
            best = (residual, full)
    return best[1]


def fit_growth(errors_sq, *columns, offset=None, weighted=False, iterations=50):
    """The sigmas s of e^2 = offset + sum s_j^2 x_j (x_j the columns), all >= 0, by least
    squares on the squares; weighted, by Gaussian maximum likelihood: each square weighted by
    1 / variance^2 (the spread of e^2 grows with its variance), iterated from the unweighted
    fit.

    The outages' terms are fitted weighted: unweighted, the few largest errors (after the
    longest outages) set them, too narrow for the many smaller ones. The path's terms are not:
    the output is anchored at its first pose, so the errors near it are about 0 by
    construction, and weighted they pull the floor (s0) to 0 (sixty-eighth session)."""
    A = np.stack(columns, 1)
    offset = np.zeros_like(errors_sq) if offset is None else offset
    b = errors_sq - offset
    coef = nonnegative_lstsq(A, b)
    floor = 1e-12 + 1e-9 * np.mean(errors_sq)  # no infinite weight where the model says 0
    for _ in range(iterations if weighted else 0):
        w = 1.0 / np.maximum(offset + A @ coef, floor)
        new = nonnegative_lstsq(A * w[:, None], b * w)
        done = np.allclose(new, coef, rtol=1e-7, atol=1e-15)
        coef = new
        if done:
            break
    return tuple(float(np.sqrt(c)) for c in coef)


def fit(e):
    """Every sigma, fitted on the pooled errors of the runs."""
    ones = np.ones_like(e["path"])
    s0 = fit_growth(np.square(e["position"]).reshape(-1),
                    *(np.repeat(x, 3) for x in (ones, e["path"] ** 2, e["outage_s2"],
                                                e["outage_s4"])))
    y0 = fit_growth(np.square(e["yaw"]), ones, e["path"] ** 2, e["outage_s2"])
    return {
        "position_sigma_m": s0[0], "position_drift": s0[1],
        "tilt_sigma_deg": float(np.max(rms(e["tilt"]))),
        "yaw_sigma_deg": y0[0], "yaw_drift_deg_per_m": y0[1],
        "outage_position_sigma_mps": s0[2], "outage_position_sigma_mps2": s0[3],
        "outage_yaw_sigma_deg_per_s": y0[2],
        "velocity_sigma_mps": float(np.max(rms(e["velocity"]))),
        "angular_rate_sigma_rps": [float(x) for x in rms(e["rate"])],
    }


def fit_outages(e, model):
    """The outage sigmas alone on the pooled errors, the model's path terms held: for runs with
    faults, once the path terms were fitted on runs without."""
    d = e["path"]
    position_held = model["position_sigma_m"] ** 2 + (model["position_drift"] * d) ** 2
    yaw_held = model["yaw_sigma_deg"] ** 2 + (model["yaw_drift_deg_per_m"] * d) ** 2
    a, b = fit_growth(np.square(e["position"]).reshape(-1), np.repeat(e["outage_s2"], 3),
                      np.repeat(e["outage_s4"], 3), offset=np.repeat(position_held, 3),
                      weighted=True)
    c, = fit_growth(np.square(e["yaw"]), e["outage_s2"], offset=yaw_held, weighted=True)
    return {"outage_position_sigma_mps": a, "outage_position_sigma_mps2": b,
            "outage_yaw_sigma_deg_per_s": c}


def load_model(path):
    """The odometry_covariance section of a configuration, its base: files merged in."""
    def read(p, seen):
        p = Path(p).resolve()
        if p in seen:
            fail(f"{p}: 'base' cycle")
        try:
            data = yaml.safe_load(p.read_text()) or {}
        except (OSError, yaml.YAMLError) as e:
            fail(f"{p}: cannot read: {e}")
        section = {}
        if "base" in data:
            section = read(p.parent / data["base"], seen | {p})
        section.update(data.get("odometry_covariance") or {})
        return section
    section = read(path, frozenset())
    replaced = [k for k in REPLACED_KEYS if k in section]
    if replaced:
        fail(f"{path}: odometry_covariance.{replaced[0]} was replaced by {', '.join(OUTAGE_KEYS)} "
             "(an outage's error grows with its length; fit them with this script)")
    unknown = sorted(set(section) - set(KEYS))
    if unknown:
        fail(f"{path}: unknown key odometry_covariance.{unknown[0]}")
    # A configuration from before the outage keys widens nothing after one, as in alvio.
    section = {**{k: 0.0 for k in OUTAGE_KEYS}, "outage_min_s": OUTAGE_MIN_S, **section}
    missing = [k for k in KEYS if k not in section]
    if missing:
        fail(f"{path}: odometry_covariance.{missing[0]} is not set (give every key to check it)")
    return {k: model_value(path, k, section[k]) for k in KEYS}


def model_value(path, key, value):
    """A sigma from the file: a number, or for the twist's keys a list of three per axis."""
    per_axis = key in PER_AXIS_KEYS
    try:
        if per_axis and isinstance(value, list):
            if len(value) != 3:
                raise ValueError
            return np.array([float(v) for v in value])
        return float(value)
    except (TypeError, ValueError):
        wanted = "a number or a list of 3 numbers (x, y, z)" if per_axis else "a number"
        fail(f"{path}: odometry_covariance.{key} must be {wanted}, got {value!r}")


def normalised(e, sigma):
    """|e| / sigma; where sigma is 0 (a model without a floor, at the first pose), 0 for no
    error and infinity for any."""
    e, sigma = np.broadcast_arrays(np.abs(e), sigma)
    return np.divide(e, sigma, out=np.where(e > 0, np.inf, 0.0), where=sigma > 0)


def position_yaw_sigmas(model, errors):
    """The model's sigma at each pose: position (per axis, m) and yaw (deg)."""
    d, s2, s4 = errors["path"], errors["outage_s2"], errors["outage_s4"]
    sp = np.sqrt(model["position_sigma_m"] ** 2 + (model["position_drift"] * d) ** 2 +
                 model["outage_position_sigma_mps"] ** 2 * s2 +
                 model["outage_position_sigma_mps2"] ** 2 * s4)
    sy = np.sqrt(model["yaw_sigma_deg"] ** 2 + (model["yaw_drift_deg_per_m"] * d) ** 2 +
                 model["outage_yaw_sigma_deg_per_s"] ** 2 * s2)
    return sp, sy


def coverage(model, errors):
    """Fraction of each component's errors within 1 and 2 of the model's sigmas."""
    n = errors["outages"]
    sp, sy = position_yaw_sigmas(model, errors)
    # Normalised errors, one per axis and pose.
    parts = {
        "position": normalised(errors["position"], sp[:, None]),
        "yaw": normalised(errors["yaw"], sy),
        "tilt": normalised(errors["tilt"], model["tilt_sigma_deg"]),
        "velocity": normalised(errors["velocity"], model["velocity_sigma_mps"]),
        "angular rate": normalised(errors["rate"], model["angular_rate_sigma_rps"]),
    }
    # The poses after an outage on their own: the few that the outage sigmas are for.
    if np.any(n > 0):
        parts["position after an outage"] = parts["position"][n > 0]
        parts["yaw after an outage"] = parts["yaw"][n > 0]
    # The twist per axis too: which axis a single sigma misfits, or a per-axis one still does.
    for name in ("velocity", "angular rate"):
        for axis, label in enumerate("xyz"):
            parts[f"{name} {label}"] = parts[name][:, axis]
    return {name: (float(np.mean(z <= 1)), float(np.mean(z <= 2))) for name, z in parts.items()}


def plot_run(model, errors, title):
    """A figure of the run's position (per axis) and yaw errors over time inside the model's
    1 and 2 sigma bands, its outages shaded: where and after what the sigmas fall short."""
    import matplotlib
    matplotlib.use("Agg")  # no display needed
    import matplotlib.figure
    t = errors["t"] - errors["t"][0]
    sp, sy = position_yaw_sigmas(model, errors)
    fig = matplotlib.figure.Figure(figsize=(10, 8), dpi=100)
    axes = fig.subplots(4, 1, sharex=True)
    rows = [(f"position {axis} (m)", errors["position"][:, k], sp)
            for k, axis in enumerate("xyz")] + [("yaw (deg)", errors["yaw"], sy)]
    after = outage_ends(errors)
    for ax, (label, e, sigma) in zip(axes, rows):
        # Stepped: the sigma widens with the first pose after an outage, as it is published.
        ax.fill_between(t, -2 * sigma, 2 * sigma, step="post", color="tab:blue", alpha=0.12,
                        lw=0, label="2 sigma")
        ax.fill_between(t, -sigma, sigma, step="post", color="tab:blue", alpha=0.25, lw=0,
                        label="1 sigma")
        ax.plot(t, e, color="black", lw=0.8, label="error")
        for i in after:
            ax.axvspan(t[i - 1], t[i], color="tab:red", alpha=0.3, lw=0)
        within = 100 * np.mean(normalised(e, sigma) <= 1)
        ax.set_ylabel(label)
        ax.set_title(f"{within:.0f} % within 1 sigma", fontsize=8, loc="right")
        ax.grid(alpha=0.3)
    axes[0].legend(loc="upper left", fontsize=8)
    axes[-1].set_xlabel("s since the first output pose (red: an outage)")
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+", metavar="RUN:DATASET")
    ap.add_argument("--config", help="check this configuration's odometry_covariance sigmas "
                    "(its outage_min_s also says what an outage is)")
    ap.add_argument("--outages-only", action="store_true",
                    help="fit only the outage sigmas, holding --config's position and yaw "
                    "terms (fitted before on runs without outages)")
    ap.add_argument("--plot", metavar="DIR",
                    help="write DIR/<n>_<run>.png per run: its position and yaw errors over "
                    "time in --config's 1 and 2 sigma bands, its outages shaded")
    args = ap.parse_args()
    if args.outages_only and not args.config:
        fail("--outages-only holds the path terms of a configuration: give it with --config")
    if args.plot and not args.config:
        fail("--plot draws a configuration's sigma bands: give it with --config")
    model = load_model(args.config) if args.config else None
    outage_min_s = model["outage_min_s"] if model else OUTAGE_MIN_S
    runs = []
    for spec in args.runs:
        if ":" not in spec:
            fail(f"'{spec}' is not RUN:DATASET")
        runs.append(spec.split(":", 1))
    all_errors = []
    print("| run | poses | path (m) | outages | resets | position at the end (m) | "
          "yaw RMS (deg) | tilt RMS, larger axis (deg) | velocity RMS x/y/z (m/s) | "
          "angular rate RMS x/y/z (rad/s) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for run, dataset in runs:
        e = run_errors(run, dataset, outage_min_s)
        all_errors.append(e)
        velocity = " / ".join(f"{x:.4f}" for x in rms(e["velocity"]))
        rate = " / ".join(f"{x:.4f}" for x in rms(e["rate"]))
        print(f"| {run} | {len(e['path'])} | {e['path'][-1]:.1f} | {e['outages'][-1]} | "
              f"{e['resets'][-1]} | {np.linalg.norm(e['position'][-1]):.3f} | "
              f"{rms(e['yaw']):.3f} | {np.max(rms(e['tilt'])):.3f} | {velocity} | {rate} |")
    errors = pooled(all_errors)
    any_outage = any(e["outages"][-1] > 0 for e in all_errors)
    held = ""
    if args.outages_only:
        if not any_outage:
            fail("--outages-only: no run has an outage (a pause in the output over "
                 f"{outage_min_s:g} s) to fit them on")
        fitted = fit_outages(errors, model)
        held = f", {args.config}'s position and yaw terms held"
    else:
        fitted = fit(errors)
    print(f"\nFitted over {len(all_errors)} run(s), {len(errors['path'])} poses{held}:\n\n"
          "odometry_covariance:")
    for k in KEYS:
        if k == "outage_min_s" or (k in OUTAGE_KEYS and not any_outage):
            continue  # a setting, not fitted; nothing to fit them on: noted below
        if k not in fitted:
            continue  # held
        v = fitted[k]
        print(f"  {k}: " + (f"[{', '.join(f'{x:.4g}' for x in v)}]" if isinstance(v, list)
                            else f"{v:.4g}"))
    if any_outage:
        print(f"\nThe outages (pauses in the output over {outage_min_s:g} s): the error's jump "
              "across each\n\n| run | outage at (s after the first pose) | outage (s) | resets | "
              "position error's jump (m) | yaw error's jump (deg) |\n|---|---|---|---|---|---|")
        for (run, _), e in zip(runs, all_errors):
            for at, length, resets, dp, dyaw in outage_jumps(e):
                print(f"| {run} | {at:.2f} | {length:.2f} | {resets} | "
                      f"{dp:.4f} | {dyaw:+.3f} |")
    else:
        print(f"\n{', '.join(OUTAGE_KEYS)}: not fitted, as no run has an outage (a pause in the "
              f"output over {outage_min_s:g} s; keep your configuration's)")
    if model:
        print(f"\n{args.config}'s sigmas: share of errors within 1 and 2 sigma "
              "(a Gaussian: 68 % / 95 %)\n")
        print("| component | within 1 sigma | within 2 sigma |\n|---|---|---|")
        for name, (one, two) in coverage(model, errors).items():
            print(f"| {name} | {100 * one:.1f} % | {100 * two:.1f} % |")
    if args.plot:
        out = Path(args.plot)
        out.mkdir(parents=True, exist_ok=True)
        for number, ((run, _), e) in enumerate(zip(runs, all_errors), 1):
            name = "_".join(part for part in Path(run).parts if part not in ("/", ".", ".."))
            png = out / f"{number}_{name}.png"
            plot_run(model, e, f"{run} against {Path(args.config).name}").savefig(png)
            print(f"plot: {png}")


if __name__ == "__main__":
    main()
