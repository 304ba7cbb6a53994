"""Tests of scripts/odometry_error.py on a synthetic run: a tilted body flying a circle, an
"estimate" made from the truth with errors of known size (position and yaw drifting in
proportion to the path, tilt, body-frame velocity and gyroscope noise), written as alvio run
writes trajectory.tum, states.csv and events.log. The fitted sigmas must give those sizes back,
and a model with them must hold about 68 % and 95 % of Gaussian errors within 1 and 2 sigma.
A second run has outages (pauses in the output, most with a reset of the estimator), each of
which adds a variance of known growth with its length to position and yaw."""
import json
import os
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import numpy as np

from rotations import quaternion_xyzw  # test/scripts/, on the path
from script_failures import CleanFailureAssertions

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "odometry_error.py"
sys.path.insert(0, str(SCRIPT.parent))
from odometry_error import (KEYS, coverage as model_coverage, fit_growth, fit_outages,  # noqa: E402
                            load_model, normalised, plot_run, pooled, position_yaw_sigmas,
                            run_errors)
RATE_HZ, CAMERA_EVERY = 200, 10
DURATION_S = 200.0
SPEED, RADIUS = 1.0, 5.0              # m/s, m: a 200 m path
POSITION_DRIFT = 0.002                # m per m travelled, on each axis
YAW_DRIFT_DEG_PER_M = 0.004
TILT_SIGMA_DEG = 0.15
VELOCITY_SIGMA = 0.02                 # m/s, body frame, per axis
GYRO_SIGMA = np.array([0.002, 0.005, 0.003])  # rad/s per sample, per axis (as a vibrating body)
# The odometry's angular rate is the gyroscope interpolated at the camera's stamp, 1 ms before
# a sample at 200 Hz: weights 0.8 and 0.2 on the samples around it, so less noise than one.
# The sample after the stamp (what the nodelet published before) would give GYRO_SIGMA.
RATE_SIGMA = GYRO_SIGMA * np.hypot(0.8, 0.2)
# The run with outages: (when the output comes back, s after the start; the outage's length, s;
# whether the estimator reset in it).
OUTAGES = ((40.0, 1.0, True), (90.0, 3.0, True), (120.0, 2.0, False), (150.0, 6.0, True))
# Per outage of T s, added in quadrature: (a T)^2 + (b T^2)^2 per position axis, (c T)^2 on yaw.
OUTAGE_A, OUTAGE_B, OUTAGE_C = 0.01, 0.004, 0.05  # m/s, m/s^2, deg/s


def rot_z(a):
    c, s = np.cos(a), np.sin(a)
    R = np.zeros((len(a), 3, 3))
    R[:, 0, 0], R[:, 0, 1], R[:, 1, 0], R[:, 1, 1], R[:, 2, 2] = c, -s, s, c, 1
    return R


def small_rotation(v):
    """Rotation matrices of small rotation vectors (N, 3), Rodrigues' formula."""
    angle = np.linalg.norm(v, axis=1)
    u = v / np.maximum(angle, 1e-12)[:, None]
    K = np.zeros((len(v), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -u[:, 2], u[:, 1], -u[:, 0]
    K -= K.transpose(0, 2, 1)
    a = angle[:, None, None]
    return np.eye(3) + np.sin(a) * K + (1 - np.cos(a)) * (K @ K)


def make_run(folder, seed, outages=()):
    """A run in folder/run on the dataset folder/data, with these OUTAGES."""
    rng = np.random.default_rng(seed)
    n = int(DURATION_S * RATE_HZ) + 1
    t_ns = 1_600_000_000_000_000_000 + np.arange(n, dtype=np.int64) * (10**9 // RATE_HZ)
    t = np.arange(n) / RATE_HZ
    w = SPEED / RADIUS
    p = np.stack([RADIUS * np.cos(w * t), RADIUS * np.sin(w * t), 0.2 * np.sin(0.3 * t)], 1)
    v = np.stack([-SPEED * np.sin(w * t), SPEED * np.cos(w * t), 0.06 * np.cos(0.3 * t)], 1)
    # Heading along the circle, and a fixed tilt (a camera rig is rarely level): the body's
    # rate is then the heading's rate about the tilted body's own axis.
    tilt = small_rotation(np.array([[0.3, -0.2, 0.0]]))[0]
    R = rot_z(w * t + 1.0) @ tilt
    rate_body = tilt.T @ np.array([0, 0, w])
    gt = folder / "data" / "mav0" / "state_groundtruth_estimate0"
    gt.mkdir(parents=True)
    q = quaternion_xyzw(R)
    np.savetxt(gt / "data.csv", np.column_stack([t_ns.astype(float), p, q[:, [3, 0, 1, 2]], v,
                                                 np.zeros((n, 6))]),
               delimiter=",", fmt=["%d"] + ["%.12f"] * 16, header="timestamp,...")
    gyro = rate_body + rng.normal(0, GYRO_SIGMA, (n, 3)) + [0.01, -0.02, 0.005]
    imu = folder / "data" / "mav0" / "imu0"
    imu.mkdir(parents=True)
    np.savetxt(imu / "data.csv", np.column_stack([t_ns.astype(float), gyro, np.zeros((n, 3))]),
               delimiter=",", fmt=["%d"] + ["%.12f"] * 6, header="timestamp,...")
    # The estimate at the camera's stamps, 1 ms before an IMU sample (as the IMU runs ahead).
    k = np.arange(CAMERA_EVERY, n - CAMERA_EVERY, CAMERA_EVERY)
    k = k[[not any(end - length <= t[i] - 0.001 < end for end, length, _ in outages) for i in k]]
    tc = t[k] - 0.001
    stamps = t_ns[k] * 1e-9 - 0.001
    pk = np.stack([RADIUS * np.cos(w * tc), RADIUS * np.sin(w * tc), 0.2 * np.sin(0.3 * tc)], 1)
    # The path as the script measures it: through the output poses (across an outage, the
    # chord of the circle flown).
    path = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(pk, axis=0), axis=1))])
    # Position and yaw errors of exactly the model's size: the fit is least squares, so it must
    # give the terms back to the second-order effects of the noise. T: the pause as measured.
    gap = np.concatenate([[0.0], np.diff(tc)])
    gap[gap <= 0.3] = 0.0
    s2, s4 = np.cumsum(gap ** 2), np.cumsum(gap ** 4)
    position_error = np.sqrt((POSITION_DRIFT * path) ** 2 + OUTAGE_A ** 2 * s2 +
                             OUTAGE_B ** 2 * s4)
    yaw_error = np.sqrt((YAW_DRIFT_DEG_PER_M * path) ** 2 + OUTAGE_C ** 2 * s2)
    # The estimate's own frame: a yaw and an offset the script must take out at its start.
    frame_yaw, frame_offset = 0.7, np.array([3.0, -2.0, 0.5])
    vk = np.stack([-SPEED * np.sin(w * tc), SPEED * np.cos(w * tc), 0.06 * np.cos(0.3 * tc)], 1)
    Rk = rot_z(w * tc + 1.0) @ tilt
    err_rot = np.column_stack([rng.normal(0, np.radians(TILT_SIGMA_DEG), (len(k), 2)),
                               np.radians(yaw_error)])
    R_est = small_rotation(err_rot) @ Rk
    p_est = pk + position_error[:, None] * np.array([1.0, -1.0, 1.0])
    # The velocity's error in the estimate's own body frame, as the script measures it.
    v_body = np.einsum("nji,nj->ni", Rk, vk) + rng.normal(0, VELOCITY_SIGMA, (len(k), 3))
    v_est = np.einsum("nij,nj->ni", R_est, v_body)
    F = rot_z(np.array([frame_yaw]))[0]
    run = folder / "run"
    run.mkdir()
    np.savetxt(run / "trajectory.tum",
               np.column_stack([stamps, p_est @ F.T + frame_offset,
                                quaternion_xyzw(np.einsum("ij,njk->nik", F, R_est))]),
               fmt="%.9f", header="timestamp tx ty tz qx qy qz qw")
    bias = np.tile([0.01, -0.02, 0.005], (len(k), 1))
    np.savetxt(run / "states.csv",
               np.column_stack([stamps, v_est @ F.T, np.zeros((len(k), 3)), bias]),
               delimiter=",", fmt="%.9f", header="t,vx,vy,vz,bax,bay,baz,bgx,bgy,bgz",
               comments="")
    # As the offline runner logs them: "<t> <kind> <message>".
    start = t_ns[0] * 1e-9
    # A reset while initialising, before the first output pose, re-anchors nothing: the
    # script must not count it (nor does the nodelet).
    early = [f"{stamps[0] - 0.5:.6f} reset initialisation failed\n"] if outages else []
    events = early + [f"{stamps[0]:.6f} initialized estimator ready\n"] + [
        f"{start + end - length / 2:.6f} reset tracking lost: too few features\n"
        for end, length, reset in outages if reset]
    (run / "events.log").write_text("".join(events))
    return run, folder / "data"


def run_script(*args):
    return subprocess.run(["/usr/bin/python3", str(SCRIPT), *map(str, args)], capture_output=True,
                          text=True, timeout=120, env=dict(os.environ, PYTHONDONTWRITEBYTECODE="1"))


def fitted(stdout):
    values = {}
    section = stdout.split("odometry_covariance:", 1)[1]
    for line in section.splitlines():
        if line.startswith("  ") and ":" in line:
            key, value = line.split(":")
            values[key.strip()] = json.loads(value)  # a number or a per-axis list
    return values


def coverage(stdout):
    rows = {}
    for line in stdout.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 3 and cells[1].endswith("%"):
            rows[cells[0]] = (float(cells[1][:-1]), float(cells[2][:-1]))
    return rows


class FitGrowth(unittest.TestCase):
    """Independent Gaussian errors whose variance is s0^2 + (a T)^2 + (b T^2)^2: 1800 after
    short outages (1-1.5 s), 200 after long ones (12-12.5 s), as a run whose few poses after a
    long outage have errors 10x the others'."""
    S0, A, B = 0.01, 0.05, 0.004

    def outages(self, rng):
        """Each pose's outage length T (s), and the variance (a T)^2 + (b T^2)^2 it adds."""
        t = np.where(np.arange(2000) < 1800, 1.0, 12.0) + rng.uniform(0, 0.5, 2000)
        return t, (self.A * t) ** 2 + (self.B * t ** 2) ** 2

    def fits(self, weighted):
        out = []
        for seed in range(20):
            rng = np.random.default_rng(seed)
            t, outage_var = self.outages(rng)
            var = self.S0 ** 2 + outage_var
            e = rng.normal(0.0, np.sqrt(var))
            out.append(fit_growth(e ** 2, np.ones_like(t), t ** 2, t ** 4, weighted=weighted))
        return np.array(out)

    def test_maximum_likelihood_gives_the_sigmas_back_where_least_squares_scatters(self):
        ml, ls = self.fits(True), self.fits(False)
        truth = np.array([self.S0, self.A, self.B])
        ml_error, ls_error = (np.sqrt(np.mean(np.square(f - truth), 0)) for f in (ml, ls))
        # a and b, which the outages set: within 15 % (RMS over the seeds), and at least 3x
        # closer than the unweighted fit, which the long outages' few errors set.
        for j, name in ((1, "a"), (2, "b")):
            self.assertLess(ml_error[j], 0.15 * truth[j], name)
            self.assertLess(ml_error[j], ls_error[j] / 3, name)

    def test_the_outages_are_fitted_weighted_around_the_held_path_terms(self):
        model = {"position_sigma_m": self.S0, "position_drift": 0.002, "yaw_sigma_deg": 0.05,
                 "yaw_drift_deg_per_m": 0.003}
        c = 0.02  # deg/s
        errors = []
        for seed in range(20):
            rng = np.random.default_rng(100 + seed)
            t, outage_var = self.outages(rng)
            d = rng.uniform(0, 50, 2000)
            var = self.S0 ** 2 + (0.002 * d) ** 2 + outage_var
            yaw_var = 0.05 ** 2 + (0.003 * d) ** 2 + (c * t) ** 2
            errors.append({"path": d, "position": rng.normal(0.0, np.sqrt(var)[:, None],
                                                             (2000, 3)),
                           "yaw": rng.normal(0.0, np.sqrt(yaw_var)), "outage_s2": t ** 2,
                           "outage_s4": t ** 4})
        got = fit_outages(pooled(errors), model)
        for key, want in (("outage_position_sigma_mps", self.A),
                          ("outage_position_sigma_mps2", self.B),
                          ("outage_yaw_sigma_deg_per_s", c)):
            self.assertAlmostEqual(got[key], want, delta=0.05 * want, msg=key)

    def test_a_held_offset_is_not_fitted(self):
        t = np.linspace(1, 10, 500)
        e_sq = 0.02 ** 2 + (0.03 * t) ** 2
        for weighted in (False, True):
            a, = fit_growth(e_sq, t ** 2, offset=np.full_like(t, 0.02 ** 2), weighted=weighted)
            self.assertAlmostEqual(a, 0.03, places=6)
            # The offset says more than all the errors: nothing is left to the term.
            none, = fit_growth(e_sq, t ** 2, offset=e_sq * 2, weighted=weighted)
            self.assertEqual(none, 0.0)


class Normalised(unittest.TestCase):
    def test_a_zero_sigma_holds_only_a_zero_error_and_warns_of_nothing(self):
        with np.errstate(all="raise"):  # a division by 0 would raise here
            z = normalised(np.array([[0.0, -1.0, 2.0], [0.5, 0.0, -0.3]]),
                           np.array([0.0, 0.0, 2.0]))
        np.testing.assert_array_equal(z, [[0.0, np.inf, 1.0], [np.inf, 0.0, 0.15]])


class OdometryErrorTest(CleanFailureAssertions, unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.run_dir, cls.data = make_run(Path(cls.tmp.name), seed=3)
        cls.reset_run, cls.reset_data = make_run(Path(cls.tmp.name) / "outages", seed=4,
                                                 outages=OUTAGES)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_fit_gives_back_the_errors_it_was_given(self):
        p = run_script(f"{self.run_dir}:{self.data}")
        self.assertEqual(p.returncode, 0, p.stderr)
        got = fitted(p.stdout)
        self.assertAlmostEqual(got["position_drift"], POSITION_DRIFT, delta=0.05 * POSITION_DRIFT)
        self.assertLess(got["position_sigma_m"], 0.01)
        self.assertAlmostEqual(got["yaw_drift_deg_per_m"], YAW_DRIFT_DEG_PER_M,
                               delta=0.05 * YAW_DRIFT_DEG_PER_M)
        self.assertLess(got["yaw_sigma_deg"], 0.02)
        # Random errors: about 2000 poses, a few % of scatter.
        for key, want in (("tilt_sigma_deg", TILT_SIGMA_DEG),
                          ("velocity_sigma_mps", VELOCITY_SIGMA)):
            self.assertAlmostEqual(got[key], want, delta=0.1 * want, msg=key)
        # The gyroscope's noise per axis.
        self.assertEqual(len(got["angular_rate_sigma_rps"]), 3)
        for axis, (value, want) in enumerate(zip(got["angular_rate_sigma_rps"], RATE_SIGMA)):
            self.assertAlmostEqual(value, want, delta=0.1 * want, msg=f"angular rate axis {axis}")
        # No outage to fit the outage sigmas on: they are left out, and the output says why.
        self.assertNotIn("outage_position_sigma_mps", got)
        self.assertIn("outage_yaw_sigma_deg_per_s: not fitted, as no run has an outage",
                      p.stdout)

    def test_each_outage_adds_its_sigma_and_the_fit_gives_it_back(self):
        p = run_script(f"{self.reset_run}:{self.reset_data}", f"{self.run_dir}:{self.data}")
        self.assertEqual(p.returncode, 0, p.stderr)
        row = p.stdout.split(f"| {self.reset_run} | ", 1)[1].split("\n", 1)[0].split(" | ")
        self.assertEqual(int(row[2]), len(OUTAGES))  # outages
        self.assertEqual(int(row[3]), sum(reset for *_, reset in OUTAGES))  # resets
        got = fitted(p.stdout)
        for key, want in (("outage_position_sigma_mps", OUTAGE_A),
                          ("outage_position_sigma_mps2", OUTAGE_B),
                          ("outage_yaw_sigma_deg_per_s", OUTAGE_C)):
            self.assertAlmostEqual(got[key], want, delta=0.05 * want, msg=key)
        # The path's drift is still the path's, not taken by the outages.
        self.assertAlmostEqual(got["position_drift"], POSITION_DRIFT, delta=0.05 * POSITION_DRIFT)
        self.assertAlmostEqual(got["yaw_drift_deg_per_m"], YAW_DRIFT_DEG_PER_M,
                               delta=0.05 * YAW_DRIFT_DEG_PER_M)

    def test_each_outages_jump_is_told_with_its_length(self):
        p = run_script(f"{self.reset_run}:{self.reset_data}")
        self.assertEqual(p.returncode, 0, p.stderr)
        table = p.stdout.split("| run | outage at (s after the first pose) |", 1)[1]
        rows = [line.split("|")[1:-1] for line in table.splitlines()
                if line.startswith(f"| {self.reset_run} |")]
        self.assertEqual(len(rows), len(OUTAGES))
        first_pose = CAMERA_EVERY / RATE_HZ - 0.001  # after the start
        frame = 1.01 * CAMERA_EVERY / RATE_HZ
        s2 = s4 = 0.0
        for n, (row, (end, length, reset)) in enumerate(zip(rows, OUTAGES), 1):
            at, measured, resets, dp, dyaw = (float(x) for x in row[1:])
            # The first pose after the outage: the camera's next stamp.
            self.assertAlmostEqual(at, end - first_pose, delta=frame)
            self.assertAlmostEqual(measured, length, delta=frame)
            self.assertEqual(resets, int(reset), f"outage {n}")
            # The error on each axis goes from sqrt((k d)^2 + sum ...) to the same with this
            # outage's (a T)^2 + (b T^2)^2 added; the path's part moves with the 1-6 m flown.
            before = np.sqrt((POSITION_DRIFT * SPEED * (end - measured - first_pose)) ** 2 +
                             OUTAGE_A ** 2 * s2 + OUTAGE_B ** 2 * s4)
            s2, s4 = s2 + measured ** 2, s4 + measured ** 4
            after = np.sqrt((POSITION_DRIFT * SPEED * (end - first_pose)) ** 2 +
                            OUTAGE_A ** 2 * s2 + OUTAGE_B ** 2 * s4)
            self.assertAlmostEqual(dp, np.sqrt(3) * (after - before), delta=0.002,
                                   msg=f"outage {n}")
            self.assertGreater(dyaw, 0.0, f"outage {n}")
        # A run without outages has no such table.
        p = run_script(f"{self.run_dir}:{self.data}")
        self.assertNotIn("outage at (s after the first pose)", p.stdout)

    def test_a_model_without_outage_sigmas_misses_the_poses_after_an_outage(self):
        rows = {}
        # Without: a configuration from before the outage keys, read as no widening.
        for name, scale in (("with", 1.0001), ("without", None)):
            config = self.true_model(f"{name}_outages.yaml", outage_scale=scale)
            p = run_script(f"{self.reset_run}:{self.reset_data}", "--config", config)
            self.assertEqual(p.returncode, 0, p.stderr)
            rows[name] = coverage(p.stdout)
        for part in ("position after an outage", "yaw after an outage"):
            self.assertGreater(rows["with"][part][0], 98.0, part)
            # Without them every pose after an outage is outside: its error is larger than the
            # path's alone.
            self.assertLess(rows["without"][part][0], 2.0, part)

    def test_outages_only_fits_them_with_the_configurations_path_terms_held(self):
        config = self.true_model("held.yaml", outage_scale=None)
        p = run_script(f"{self.reset_run}:{self.reset_data}", "--config", config,
                       "--outages-only")
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn("position and yaw terms held", p.stdout)
        got = fitted(p.stdout.split("'s sigmas: share of errors")[0])
        self.assertEqual(set(got), {"outage_position_sigma_mps", "outage_position_sigma_mps2",
                                    "outage_yaw_sigma_deg_per_s"})
        for key, want in (("outage_position_sigma_mps", OUTAGE_A),
                          ("outage_position_sigma_mps2", OUTAGE_B),
                          ("outage_yaw_sigma_deg_per_s", OUTAGE_C)):
            self.assertAlmostEqual(got[key], want, delta=0.05 * want, msg=key)
        # Held, not fitted: a configuration whose drift takes 3x the path's variance leaves
        # less to the outages.
        wide = Path(self.tmp.name) / "held_wide.yaml"
        wide.write_text(config.read_text().replace(
            f"position_drift: {POSITION_DRIFT * 1.0001}", f"position_drift: {POSITION_DRIFT * 3}"))
        p = run_script(f"{self.reset_run}:{self.reset_data}", "--config", wide, "--outages-only")
        self.assertEqual(p.returncode, 0, p.stderr)
        less = fitted(p.stdout.split("'s sigmas: share of errors")[0])
        self.assertLess(less["outage_position_sigma_mps"] ** 2 * 36 +
                        less["outage_position_sigma_mps2"] ** 2 * 36 ** 2,
                        0.9 * (OUTAGE_A ** 2 * 36 + OUTAGE_B ** 2 * 36 ** 2))

    def test_outages_only_needs_a_configuration_and_an_outage(self):
        self.assertFailsCleanly(run_script(f"{self.reset_run}:{self.reset_data}",
                                           "--outages-only"),
                                "--outages-only holds the path terms of a configuration")
        self.assertFailsCleanly(run_script(f"{self.run_dir}:{self.data}", "--config",
                                           self.true_model("held2.yaml"), "--outages-only"),
                                "--outages-only: no run has an outage")

    def test_the_plot_draws_each_error_in_its_bands_and_shades_each_outage(self):
        # Outage sigmas at half the truth: the errors after an outage lie between 1 and 2 sigma.
        config = self.true_model("plotted.yaml", outage_scale=0.5)
        out = Path(self.tmp.name) / "plots"
        p = run_script(f"{self.reset_run}:{self.reset_data}", f"{self.run_dir}:{self.data}",
                       "--config", config, "--plot", out)
        self.assertEqual(p.returncode, 0, p.stderr)
        pngs = sorted(out.glob("*.png"))
        self.assertEqual([png.name[:2] for png in pngs], ["1_", "2_"])
        for png in pngs:
            self.assertEqual(png.read_bytes()[:8], b"\x89PNG\r\n\x1a\n")
            self.assertGreater(png.stat().st_size, 30_000)
        # The figure itself: the errors drawn, the outages shaded, the share within 1 sigma.
        model = load_model(config)
        errors = run_errors(self.reset_run, self.reset_data)
        fig = plot_run(model, errors, "run")
        axes = fig.axes
        self.assertEqual(len(axes), 4)
        t = errors["t"] - errors["t"][0]
        shares = model_coverage(model, errors)
        self.assertLess(shares["position"][0], 0.9)  # the share within 1 sigma is not all
        sp, sy = position_yaw_sigmas(model, errors)
        for k, ax in enumerate(axes):
            drawn = ax.lines[0].get_ydata()
            want = errors["position"][:, k] if k < 3 else errors["yaw"]
            np.testing.assert_allclose(drawn, want)
            # The bands: 2 sigma, then 1 sigma, each reaching the model's largest sigma.
            sigma = sp if k < 3 else sy
            for band, scale in zip(ax.collections, (2, 1)):
                top = max(np.max(path.vertices[:, 1]) for path in band.get_paths())
                self.assertAlmostEqual(top, scale * np.max(sigma), places=9)
            # The axvspans, one per outage: from the last pose before it to the first after.
            spans = [(np.min(patch.get_xy()[:, 0]), np.max(patch.get_xy()[:, 0]))
                     for patch in ax.patches]
            self.assertEqual(len(spans), len(OUTAGES))
            first_pose = CAMERA_EVERY / RATE_HZ - 0.001  # after the start
            frame = 1.01 * CAMERA_EVERY / RATE_HZ
            for (x0, x1), (end, length, _) in zip(spans, OUTAGES):
                self.assertAlmostEqual(x1, end - first_pose, delta=frame)
                self.assertAlmostEqual(x1 - x0, length, delta=frame)
            self.assertLess(spans[-1][1], t[-1])
        # The position's axes together hold the check's share within 1 sigma.
        titles = [float(ax.get_title(loc="right").split(" %")[0]) for ax in axes[:3]]
        self.assertAlmostEqual(np.mean(titles), 100 * shares["position"][0], delta=1.0)
        self.assertAlmostEqual(float(axes[3].get_title(loc="right").split(" %")[0]),
                               100 * shares["yaw"][0], delta=0.5)

    def test_the_plot_needs_a_configuration(self):
        self.assertFailsCleanly(run_script(f"{self.run_dir}:{self.data}", "--plot",
                                           Path(self.tmp.name) / "p"),
                                "--plot draws a configuration's sigma bands")

    def test_the_replaced_reset_keys_are_named(self):
        config = Path(self.tmp.name) / "old_reset_keys.yaml"
        config.write_text(self.true_model("base.yaml").read_text() +
                          "  reset_position_sigma_m: 0.07\n")
        self.assertFailsCleanly(
            run_script(f"{self.run_dir}:{self.data}", "--config", config),
            "odometry_covariance.reset_position_sigma_m was replaced by outage_position_sigma_mps")

    def true_model(self, name, outage_scale=1.0001):
        """The sigmas the runs were made with, the drifts and outages just above them; with
        outage_scale None, no outage keys at all (a configuration from before them)."""
        config = Path(self.tmp.name) / name
        config.write_text(
            "odometry_covariance:\n"
            f"  position_sigma_m: 0.001\n  position_drift: {POSITION_DRIFT * 1.0001}\n"
            f"  tilt_sigma_deg: {TILT_SIGMA_DEG}\n  yaw_sigma_deg: 0.01\n"
            f"  yaw_drift_deg_per_m: {YAW_DRIFT_DEG_PER_M * 1.0001}\n"
            + ("" if outage_scale is None else
               f"  outage_position_sigma_mps: {OUTAGE_A * outage_scale}\n"
               f"  outage_position_sigma_mps2: {OUTAGE_B * outage_scale}\n"
               f"  outage_yaw_sigma_deg_per_s: {OUTAGE_C * outage_scale}\n")
            + f"  velocity_sigma_mps: {VELOCITY_SIGMA}\n"
            f"  angular_rate_sigma_rps: {json.dumps(RATE_SIGMA.tolist())}\n")
        return config

    def test_a_model_with_the_true_sigmas_holds_68_and_95_percent(self):
        config = self.true_model("model.yaml")
        p = run_script(f"{self.run_dir}:{self.data}", "--config", config)
        self.assertEqual(p.returncode, 0, p.stderr)
        rows = coverage(p.stdout)
        for name in ("tilt", "velocity", "angular rate", "angular rate x", "angular rate y",
                     "angular rate z", "velocity z"):
            one, two = rows[name]
            self.assertAlmostEqual(one, 68.3, delta=4, msg=name)
            self.assertAlmostEqual(two, 95.4, delta=2, msg=name)
        # The drifts are at the model's sigma, just inside it. The floors (1 mm, 0.01 deg) take
        # the second-order part of the tilt's noise in the yaw and the alignment.
        for name in ("position", "yaw"):
            self.assertGreater(rows[name][0], 98.0, name)
        self.assertNotIn("position after an outage", rows)  # no outage in this run

    def model_with_angular_rate(self, name, angular_rate):
        """A complete odometry_covariance section: 0.01 for every key but the angular rate."""
        config = Path(self.tmp.name) / name
        config.write_text("odometry_covariance:\n" + "".join(
            f"  {key}: 0.01\n" for key in KEYS if key != "angular_rate_sigma_rps")
            + f"  angular_rate_sigma_rps: {angular_rate}\n")
        return config

    def test_one_sigma_for_all_axes_shows_which_axis_it_misfits(self):
        config = self.model_with_angular_rate("one_sigma.yaml", RATE_SIGMA.max())
        p = run_script(f"{self.run_dir}:{self.data}", "--config", config)
        self.assertEqual(p.returncode, 0, p.stderr)
        rows = coverage(p.stdout)
        # The largest axis's sigma fits y (4.1 mrad/s) and holds x (1.6 mrad/s) far too often.
        self.assertAlmostEqual(rows["angular rate y"][0], 68.3, delta=4)
        self.assertGreater(rows["angular rate x"][0], 98.0)

    def test_bad_input_is_named(self):
        self.assertFailsCleanly(run_script(f"{self.run_dir}"), "RUN:DATASET")
        self.assertFailsCleanly(run_script(f"{self.run_dir}:{self.tmp.name}/nowhere"), "nowhere")
        config = Path(self.tmp.name) / "partial.yaml"
        config.write_text("odometry_covariance:\n  position_drift: 0.001\n")
        self.assertFailsCleanly(run_script(f"{self.run_dir}:{self.data}", "--config", config),
                                "odometry_covariance.position_sigma_m")
        two_axes = self.model_with_angular_rate("two_axes.yaml", "[0.01, 0.02]")
        self.assertFailsCleanly(run_script(f"{self.run_dir}:{self.data}", "--config", two_axes),
                                "odometry_covariance.angular_rate_sigma_rps must be a number or "
                                "a list of 3 numbers (x, y, z), got [0.01, 0.02]")

    def test_a_missing_or_bad_events_log_is_named(self):
        bare = Path(self.tmp.name) / "no_events"
        bare.mkdir(exist_ok=True)
        for name in ("states.csv", "trajectory.tum"):
            (bare / name).write_text((self.run_dir / name).read_text())
        self.assertFailsCleanly(run_script(f"{bare}:{self.data}"),
                                f"{bare / 'events.log'}: cannot read")
        (bare / "events.log").write_text("1.0 initialized ok\nsoon reset tracking lost\n")
        self.assertFailsCleanly(run_script(f"{bare}:{self.data}"),
                                f"{bare / 'events.log'}:2: a reset without a time")

    def test_a_short_file_names_its_missing_column(self):
        short = Path(self.tmp.name) / "short"
        short.mkdir(exist_ok=True)
        (short / "states.csv").write_text((self.run_dir / "states.csv").read_text())
        lines = (self.run_dir / "trajectory.tum").read_text().splitlines()
        (short / "trajectory.tum").write_text("".join(" ".join(line.split()[:5]) + "\n"
                                                      for line in lines))
        self.assertFailsCleanly(run_script(f"{short}:{self.data}"),
                                f"{short / 'trajectory.tum'} has 5 columns, no qy (column 6")


if __name__ == "__main__":
    unittest.main()
