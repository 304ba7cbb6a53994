"""Tests of scripts/imu_noise.py on synthetic EuRoC/ASL folders: a smooth, rotating and
accelerating trajectory, an IMU made from it with a slowly drifting bias and white noise of a
known density, and the ground truth at the IMU's stamps (groundtruth.tum, or the EuRoC csv).
The script's table must give back the density, scaled by what its bias window takes out of
white noise, and twice the density must read twice as high."""
import math
import os
import subprocess
import tempfile
import unittest
from pathlib import Path

import numpy as np

from rotations import quaternion_xyzw  # test/scripts/, on the path
from script_failures import CleanFailureAssertions

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "imu_noise.py"
INTERVALS_S = np.array([0.05, 0.1, 0.25, 0.5, 1.0])  # the script's columns
RATE_HZ = 200.0
DURATION_S = 120.0
GYRO_DENSITY = 5e-4   # rad/s/sqrt(Hz)
ACCEL_DENSITY = 3e-3  # m/s^2/sqrt(Hz)


def rotation(axis, angle):
    """Rotation matrices about one axis, Rodrigues' formula, shape (N, 3, 3)."""
    u = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
    angle = np.atleast_1d(angle)[:, None, None]
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * (K @ K)


def make_dataset(folder, gyro_density, accel_density, seed, tum=True, duration_s=DURATION_S):
    rng = np.random.default_rng(seed)
    n = int(duration_s * RATE_HZ) + 1
    t_ns = 1_600_000_000_000_000_000 + np.arange(n, dtype=np.int64) * int(1e9 / RATE_HZ)
    t = np.arange(n) / RATE_HZ
    # Motion fast enough (0.35-0.6 Hz) that the 2 s bias window cannot hide a frame error.
    amp, omega = np.array([0.3, 0.2, 0.1]), 2 * np.pi * np.array([0.5, 0.35, 0.6])
    p = amp * np.sin(omega * t[:, None])
    a_world = -amp * omega ** 2 * np.sin(omega * t[:, None])
    # Body-to-world rotation: a fixed tilt, then a swing about a fixed body axis u, so the
    # body rate is exactly u * d(angle)/dt.
    u, wf = np.array([1.0, 2.0, 2.0]) / 3, 2 * np.pi * 0.4
    R = rotation([1, 0, 0], 0.4) @ rotation(u, 0.5 * np.sin(wf * t))
    rate = (0.5 * wf * np.cos(wf * t))[:, None] * u
    gyro_bias = np.array([0.01, -0.02, 0.005]) + 1e-4 * t[:, None]
    accel_bias = np.array([0.1, -0.05, 0.2]) - 2e-4 * t[:, None]
    # White noise of density s, sampled at rate f: standard deviation s * sqrt(f).
    gyro = rate + gyro_bias + rng.normal(0, gyro_density * math.sqrt(RATE_HZ), (n, 3))
    accel = (np.einsum("nji,nj->ni", R, a_world + [0, 0, 9.81]) + accel_bias
             + rng.normal(0, accel_density * math.sqrt(RATE_HZ), (n, 3)))

    imu = folder / "mav0" / "imu0"
    imu.mkdir(parents=True)
    with open(imu / "data.csv", "w") as f:
        f.write("#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
                "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n")
        for k in range(n):
            f.write(f"{t_ns[k]}," + ",".join(f"{v:.12g}" for v in (*gyro[k], *accel[k])) + "\n")
    q = quaternion_xyzw(R)
    if tum:  # as the simulator writes it
        with open(folder / "groundtruth.tum", "w") as f:
            f.write("# timestamp tx ty tz qx qy qz qw\n")
            for k in range(n):
                f.write(f"{t_ns[k] // 10**9}.{t_ns[k] % 10**9:09d} "
                        + " ".join(f"{v:.10f}" for v in (*p[k], *q[k])) + "\n")
    else:  # EuRoC: nanoseconds, quaternion w first, then velocity and biases
        gt = folder / "mav0" / "state_groundtruth_estimate0"
        gt.mkdir()
        with open(gt / "data.csv", "w") as f:
            f.write("#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], "
                    "q_RS_y [], q_RS_z [], v_x, v_y, v_z, bw_x, bw_y, bw_z, ba_x, ba_y, ba_z\n")
            for k in range(n):
                f.write(f"{t_ns[k]}," + ",".join(f"{v:.10f}" for v in (*p[k], q[k, 3], *q[k, :3]))
                        + ",0,0,0,0,0,0,0,0,0\n")


def expected(density, window_s):
    """What white noise of this density reads in each column. The residual after the moving
    average (box of W), integrated over T, is white noise through box_T - box_T * box_W/W, whose
    squared integral is T - T^2/W - T^3/(3 W^2) for T <= W/2 (derived by hand, not taken from
    the script)."""
    T = INTERVALS_S
    assert T.max() <= window_s / 2
    return density * np.sqrt(1 - T / window_s - T ** 2 / (3 * window_s ** 2))


def run(folder, *args):
    return subprocess.run(["/usr/bin/python3", str(SCRIPT), str(folder), *args],
                          capture_output=True, text=True, timeout=60,
                          env=dict(os.environ, PYTHONDONTWRITEBYTECODE="1"))


def table(stdout):
    """{"gyroscope": (5, 3) array, "accelerometer": (5, 3) array} from the markdown table."""
    rows = {}
    for line in stdout.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if cells[0].startswith(("gyroscope", "accelerometer")):
            rows[cells[0].split()[0]] = np.array([[float(v) for v in c.split()] for c in cells[1:]])
    return rows


class ImuNoiseTest(CleanFailureAssertions, unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.dir = Path(cls.tmp.name)
        make_dataset(cls.dir / "single", GYRO_DENSITY, ACCEL_DENSITY, seed=1)
        make_dataset(cls.dir / "double", 2 * GYRO_DENSITY, 2 * ACCEL_DENSITY, seed=2)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def measure(self, folder, *args):
        p = run(folder, *args)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.stdout = p.stdout
        rows = table(p.stdout)
        self.assertEqual(set(rows), {"gyroscope", "accelerometer"})
        for v in rows.values():
            self.assertEqual(v.shape, (len(INTERVALS_S), 3))
        return rows

    def assertDensity(self, rows, gyro, accel, window_s):
        # Cells (one axis, one interval) within 20 %, the mean of the three axes within 10 %:
        # 120 s give ~100 independent 1 s intervals, a few % of scatter per axis.
        for name, density in (("gyroscope", gyro), ("accelerometer", accel)):
            want = expected(density, window_s)
            np.testing.assert_allclose(rows[name], np.repeat(want[:, None], 3, 1), rtol=0.2,
                                       err_msg=name)
            np.testing.assert_allclose(rows[name].mean(axis=1), want, rtol=0.1, err_msg=name)

    def test_density_recovered(self):
        rows = self.measure(self.dir / "single")
        self.assertIn(f"{int(DURATION_S * RATE_HZ) + 1} IMU samples at 200 Hz", self.stdout)
        self.assertDensity(rows, GYRO_DENSITY, ACCEL_DENSITY, window_s=2.0)
        # The shortest interval is the density itself (the window takes ~1 %).
        np.testing.assert_allclose(rows["accelerometer"][0].mean(), ACCEL_DENSITY, rtol=0.1)
        np.testing.assert_allclose(rows["gyroscope"][0].mean(), GYRO_DENSITY, rtol=0.1)

    def test_doubled_density_reads_double(self):
        single = self.measure(self.dir / "single")
        double = self.measure(self.dir / "double")
        self.assertDensity(double, 2 * GYRO_DENSITY, 2 * ACCEL_DENSITY, window_s=2.0)
        for name in ("gyroscope", "accelerometer"):
            ratio = double[name].mean(axis=1) / single[name].mean(axis=1)
            np.testing.assert_allclose(ratio, 2.0, rtol=0.12, err_msg=name)

    def test_long_bias_window_reads_flat(self):
        # A 20 s window takes < 3 % of white noise over 1 s: every column near the density.
        rows = self.measure(self.dir / "single", "--window-s", "20")
        self.assertDensity(rows, GYRO_DENSITY, ACCEL_DENSITY, window_s=20.0)
        for name, density in (("gyroscope", GYRO_DENSITY), ("accelerometer", ACCEL_DENSITY)):
            np.testing.assert_allclose(rows[name].mean(axis=1), density, rtol=0.1, err_msg=name)

    def test_euroc_ground_truth_csv(self):
        # Quaternions stored w first; a wrong order would tilt gravity into the error.
        with tempfile.TemporaryDirectory() as tmp:
            make_dataset(Path(tmp), GYRO_DENSITY, ACCEL_DENSITY, seed=3, tum=False)
            rows = self.measure(Path(tmp))
        self.assertDensity(rows, GYRO_DENSITY, ACCEL_DENSITY, window_s=2.0)

    def test_missing_imu(self):
        with tempfile.TemporaryDirectory() as tmp:
            p = run(tmp)
        self.assertNotEqual(p.returncode, 0)
        self.assertIn(str(Path(tmp) / "mav0" / "imu0" / "data.csv") + " not found", p.stderr)

    def test_missing_ground_truth(self):
        with tempfile.TemporaryDirectory() as tmp:
            make_dataset(Path(tmp), GYRO_DENSITY, ACCEL_DENSITY, seed=4, duration_s=6)
            (Path(tmp) / "groundtruth.tum").unlink()
            p = run(tmp)
        self.assertNotEqual(p.returncode, 0)
        self.assertIn("no ground truth in " + tmp, p.stderr)
        csv = Path(tmp) / "mav0" / "state_groundtruth_estimate0" / "data.csv"
        self.assertIn(str(csv), p.stderr)

    def run_with(self, replace, tum=True):
        """imu_noise.py on a short dataset with the files of replace ({relative path: text})
        written over its own."""
        with tempfile.TemporaryDirectory() as tmp:
            make_dataset(Path(tmp), GYRO_DENSITY, ACCEL_DENSITY, seed=6, tum=tum, duration_s=6)
            for name, text in replace.items():
                (Path(tmp) / name).write_text(text)
            return run(tmp), Path(tmp)

    def test_empty_imu(self):
        imu = Path("mav0") / "imu0" / "data.csv"
        for text in ("", "#timestamp [ns],w_RS_S_x [rad s^-1]\n"):
            p, folder = self.run_with({imu: text})
            self.assertFailsCleanly(p, f"{folder / imu} has no data rows")

    def test_imu_missing_columns(self):
        imu = Path("mav0") / "imu0" / "data.csv"
        p, folder = self.run_with({imu: "".join(f"{1600000000000000000 + k * 5000000},0.1,0.2,0.3\n"
                                                for k in range(2000))})
        self.assertFailsCleanly(p, f"{folder / imu} has 4 columns, no a_RS_S_x (column 5")

    def test_empty_ground_truth(self):
        p, folder = self.run_with({"groundtruth.tum": "# timestamp tx ty tz qx qy qz qw\n"})
        self.assertFailsCleanly(p, f"{folder / 'groundtruth.tum'} has no data rows")

    def test_ground_truth_missing_columns(self):
        p, folder = self.run_with({"groundtruth.tum": "1600000000.0 0 0 0\n1600000001.0 0 0 0\n"})
        self.assertFailsCleanly(p, f"{folder / 'groundtruth.tum'} has 4 columns, no qx (column 5")
        gt = Path("mav0") / "state_groundtruth_estimate0" / "data.csv"
        p, folder = self.run_with({gt: "1600000000000000000,0,0,0,1,0,0\n"}, tum=False)
        self.assertFailsCleanly(p, f"{folder / gt} has 7 columns, no q_RS_z (column 8")

    def test_too_short_overlap(self):
        with tempfile.TemporaryDirectory() as tmp:
            make_dataset(Path(tmp), GYRO_DENSITY, ACCEL_DENSITY, seed=5, duration_s=3)
            p = run(tmp)
        self.assertNotEqual(p.returncode, 0)
        self.assertIn("only 601 IMU samples overlap the ground truth", p.stderr)


if __name__ == "__main__":
    unittest.main()
