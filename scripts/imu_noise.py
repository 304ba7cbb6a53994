#!/usr/bin/python3
"""Measure an IMU's effective white-noise density against ground truth.

    scripts/imu_noise.py DATASET [--window-s 2.0]

DATASET is an EuRoC/ASL folder with mav0/imu0/data.csv and a ground truth (groundtruth.tum
at the IMU's stamps, as the simulator writes, or mav0/state_groundtruth_estimate0/data.csv).
The ground truth gives the true angular rate and specific force in the body frame; the
difference to the measurement, with its slowly moving bias removed (a moving average over
--window-s), is the noise. Integrated over an interval T, white noise of density s grows as
s*sqrt(T), so for each T the script prints sqrt(E[err(T)^2] / T). The moving average takes
part of the noise with the bias: white noise of density s reads s*sqrt(1 - T/W - T^2/(3 W^2))
for a window W >= 2T, flat only where T << W (0.99 s at T = 0.05 s, 0.85 s at 0.5 s, 0.65 s at
1 s with W = 2 s). For vibration it falls with T, and the value at the estimator's time scale
(the window's keyframe span, about 1 s) is what the estimator's noise density should be.

The ground truth's rotation must be smooth to second order (the simulator's spline fit is;
a raw motion-capture track is not, and then only the long intervals mean anything).
"""
import argparse
import sys
import warnings
from pathlib import Path

import numpy as np

GRAVITY = 9.81
INTERVALS_S = (0.05, 0.1, 0.25, 0.5, 1.0)
# The columns read from each file (further columns are ignored).
IMU_COLUMNS = ("timestamp", "w_RS_S_x", "w_RS_S_y", "w_RS_S_z", "a_RS_S_x", "a_RS_S_y", "a_RS_S_z")
TUM_COLUMNS = ("timestamp", "tx", "ty", "tz", "qx", "qy", "qz", "qw")
EUROC_GT_COLUMNS = ("timestamp", "p_RS_R_x", "p_RS_R_y", "p_RS_R_z", "q_RS_w", "q_RS_x", "q_RS_y",
                    "q_RS_z")


def load_table(path, columns, delimiter=None, header=0, program="imu_noise"):
    """The numbers of a text file ('#' comments, `header` lines skipped), one row per line, at
    least len(columns) columns; exits with a message naming `program`, the file and the missing
    column if it cannot be read, is empty or is short."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # numpy warns about an empty file
            a = np.loadtxt(path, delimiter=delimiter, comments="#", ndmin=2, skiprows=header)
    except (OSError, ValueError) as e:
        sys.exit(f"{program}: {path}: cannot read: {e}")
    if len(a) == 0:
        sys.exit(f"{program}: {path} has no data rows")
    if a.shape[1] < len(columns):
        sys.exit(f"{program}: {path} has {a.shape[1]} columns, no {columns[a.shape[1]]} "
                 f"(column {a.shape[1] + 1} of {', '.join(columns)})")
    return a


def quat_to_matrix(q):
    """Rotation matrices from quaternions (x, y, z, w), shape (N, 3, 3)."""
    x, y, z, w = (q / np.linalg.norm(q, axis=1, keepdims=True)).T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], 1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], 1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], 1),
    ], 1)


def rotation_log(R):
    """Rotation vectors of rotation matrices (N, 3, 3)."""
    cos = np.clip((np.trace(R, axis1=1, axis2=2) - 1) / 2, -1, 1)
    angle = np.arccos(cos)
    axis = np.stack([R[:, 2, 1] - R[:, 1, 2], R[:, 0, 2] - R[:, 2, 0], R[:, 1, 0] - R[:, 0, 1]], 1)
    scale = np.where(angle > 1e-9, angle / (2 * np.sin(np.maximum(angle, 1e-9))), 0.5)
    return axis * scale[:, None]


def load_ground_truth(folder):
    """(t [s], p (N,3), q xyzw (N,4)) from groundtruth.tum or the EuRoC csv."""
    tum = folder / "groundtruth.tum"
    if tum.exists():
        a = load_table(tum, TUM_COLUMNS)
        return a[:, 0], a[:, 1:4], a[:, 4:8]
    csv = folder / "mav0" / "state_groundtruth_estimate0" / "data.csv"
    if not csv.exists():
        sys.exit(f"imu_noise: no ground truth in {folder} (groundtruth.tum or {csv})")
    a = load_table(csv, EUROC_GT_COLUMNS, delimiter=",")
    return a[:, 0] * 1e-9, a[:, 1:4], a[:, [5, 6, 7, 4]]  # EuRoC stores w first


def moving_average(x, n):
    k = np.ones(n) / n
    return np.stack([np.convolve(x[:, i], k, "same") for i in range(x.shape[1])], 1)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("dataset", type=Path)
    parser.add_argument("--window-s", type=float, default=2.0,
                        help="moving-average window that takes out the bias [2.0]")
    args = parser.parse_args()
    imu_csv = args.dataset / "mav0" / "imu0" / "data.csv"
    if not imu_csv.exists():
        sys.exit(f"imu_noise: {imu_csv} not found")
    imu = load_table(imu_csv, IMU_COLUMNS, delimiter=",")
    t_imu = imu[:, 0] * 1e-9
    t_gt, p_gt, q_gt = load_ground_truth(args.dataset)

    # Ground truth at the IMU's stamps: positions interpolated, then differentiated twice.
    inside = (t_imu >= t_gt[0]) & (t_imu <= t_gt[-1])
    t = t_imu[inside]
    gyro, accel = imu[inside, 1:4], imu[inside, 4:7]
    if len(t) < 1000:
        sys.exit(f"imu_noise: only {len(t)} IMU samples overlap the ground truth")
    dt = float(np.median(np.diff(t)))
    p = np.stack([np.interp(t, t_gt, p_gt[:, k]) for k in range(3)], 1)
    after = np.clip(np.searchsorted(t_gt, t), 1, len(t_gt) - 1)
    nearest = np.where(t - t_gt[after - 1] < t_gt[after] - t, after - 1, after)
    R = quat_to_matrix(q_gt[nearest])
    a_world = np.gradient(np.gradient(p, t, axis=0), t, axis=0)
    f_body = np.einsum("nji,nj->ni", R, a_world + np.array([0, 0, GRAVITY]))
    # Angular rate between consecutive samples, against the mean of their two gyro samples.
    w_body = rotation_log(np.einsum("nji,njk->nik", R[:-1], R[1:])) / np.diff(t)[:, None]
    errors = {"gyroscope [rad/s/sqrt(Hz)]": 0.5 * (gyro[:-1] + gyro[1:]) - w_body,
              "accelerometer [m/s^2/sqrt(Hz)]": accel - f_body}

    n_bias = max(3, int(round(args.window_s / dt)))
    print(f"{args.dataset.name}: {len(t)} IMU samples at {1 / dt:.0f} Hz, bias window "
          f"{args.window_s} s")
    print("| sensor | " + " | ".join(f"T = {T:g} s" for T in INTERVALS_S) + " |")
    print("|---|" + "---|" * len(INTERVALS_S))
    for name, err in errors.items():
        e = (err - moving_average(err, n_bias))[n_bias:-n_bias]  # edges: average incomplete
        integral = np.cumsum(e, axis=0) * dt
        cells = []
        for T in INTERVALS_S:
            n = int(round(T / dt))
            d = integral[n:] - integral[:-n]
            density = np.sqrt((d ** 2).mean(axis=0) / T)
            cells.append(" ".join(f"{v:.2g}" for v in density))
        print(f"| {name} | " + " | ".join(cells) + " |")
    print("(x y z per cell; white noise of density s gives s*sqrt(1 - T/W - T^2/(3 W^2)) for the "
          "bias window W >= 2T: s at short T, 0.65 s at T = 1 s with W = 2 s)")


if __name__ == "__main__":
    main()
