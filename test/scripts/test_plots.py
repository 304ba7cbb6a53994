"""Tests of the plotting scripts (plot_eval.py, plot_weights.py, plot_map_truth.py) on small
synthetic inputs: the PNGs are written, are real PNGs of the size the figure asks for, carry
the input's data (read back from the figures and from the pixels), and a missing or bad input
ends the script with a non-zero exit and a message naming the file."""
import contextlib
import csv
import io
import math
import os
import struct
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path
from unittest import mock

import matplotlib

matplotlib.use("Agg")
import matplotlib.figure  # noqa: E402
import matplotlib.image  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from script_failures import CleanFailureAssertions  # noqa: E402 (test/scripts/, on the path)

SCRIPTS = Path(__file__).resolve().parents[2] / "scripts"
sys.dont_write_bytecode = True  # keep scripts/ free of __pycache__
sys.path.insert(0, str(SCRIPTS))
import plot_eval  # noqa: E402
import plot_map_truth  # noqa: E402
import plot_weights  # noqa: E402

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def png_size(path):
    """(width, height) from the IHDR chunk, after checking that the file is a PNG."""
    data = Path(path).read_bytes()
    if data[:8] != PNG_SIGNATURE or data[12:16] != b"IHDR":
        raise AssertionError(f"{path} is not a PNG")
    return struct.unpack(">II", data[16:24])


def run_script(name, *args):
    return subprocess.run(["/usr/bin/python3", str(SCRIPTS / name), *map(str, args)],
                          capture_output=True, text=True, timeout=60,
                          env=dict(os.environ, PYTHONDONTWRITEBYTECODE="1"))


def write_csv(path, header, rows):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)


class PlotTestCase(CleanFailureAssertions, unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = Path(self.tmp.name)

    def tearDown(self):
        plt.close("all")
        self.tmp.cleanup()

    def assertPng(self, path, width, height, min_bytes=10_000):
        self.assertTrue(Path(path).exists(), f"{path} not written")
        self.assertEqual(png_size(path), (width, height))
        # A plot with axes, text and curves is tens of kB; an empty canvas is a few.
        self.assertGreater(Path(path).stat().st_size, min_bytes)
        pixels = matplotlib.image.imread(path)
        self.assertEqual(pixels.shape[:2], (height, width))
        return pixels


class PlotEvalTest(PlotTestCase):
    HEADER = ["t", "est_x", "est_y", "est_z", "gt_x", "gt_y", "gt_z", "error_m"]

    def setUp(self):
        super().setUp()
        n = 120
        self.t = 1600000000.0 + 0.1 * np.arange(n)
        a = np.linspace(0, 2 * np.pi, n)
        self.gt = np.stack([3 * np.cos(a), 2 * np.sin(a), 0.1 * a], 1)
        self.est = self.gt + 0.05 * np.stack([np.sin(3 * a), np.cos(5 * a), 0 * a], 1)
        self.err = np.linalg.norm(self.est - self.gt, axis=1)
        rows = [[f"{self.t[k]:.9f}"] + [f"{v:.6f}" for v in (*self.est[k], *self.gt[k])]
                + [f"{self.err[k]:.6f}"] for k in range(n)]
        write_csv(self.dir / "ate_pairs.csv", self.HEADER, rows)

    def test_plots_written_with_the_data(self):
        figures = []
        stdout = io.StringIO()
        # Keep the figures open to read them back.
        with mock.patch.object(plot_eval.plt, "close", figures.append), \
                contextlib.redirect_stdout(stdout):
            plot_eval.main(str(self.dir))
        self.assertIn(f"plots written to {self.dir}", stdout.getvalue())
        self.assertPng(self.dir / "trajectory_top.png", 840, 720)  # 7 x 6 in at 120 dpi
        self.assertPng(self.dir / "ate_over_time.png", 960, 420)  # 8 x 3.5 in at 120 dpi

        # (pyplot may call close("all") itself when it sets up its backend.)
        top, over_time = [f for f in figures if isinstance(f, matplotlib.figure.Figure)]
        gt_line, est_line = top.axes[0].lines[:2]
        np.testing.assert_allclose(gt_line.get_xydata(), self.gt[:, :2], atol=1e-6)
        np.testing.assert_allclose(est_line.get_xydata(), self.est[:, :2], atol=1e-6)
        err_line, rmse_line = over_time.axes[0].lines
        np.testing.assert_allclose(err_line.get_xdata(), self.t - self.t[0], atol=1e-6)
        np.testing.assert_allclose(err_line.get_ydata(), self.err, atol=1e-6)
        rmse = math.sqrt(np.mean(self.err ** 2))
        np.testing.assert_allclose(rmse_line.get_ydata(), [rmse, rmse], atol=1e-6)
        self.assertEqual(rmse_line.get_label(), f"RMSE {rmse:.3f} m")

    def test_empty_csv(self):
        write_csv(self.dir / "ate_pairs.csv", self.HEADER, [])
        self.assertFailsCleanly(run_script("plot_eval.py", self.dir),
                                f"{self.dir / 'ate_pairs.csv'}: no rows")
        self.assertFalse((self.dir / "trajectory_top.png").exists())

    def test_missing_csv(self):
        (self.dir / "ate_pairs.csv").unlink()
        self.assertFailsCleanly(run_script("plot_eval.py", self.dir),
                                f"{self.dir / 'ate_pairs.csv'}: No such file or directory")

    def test_missing_column(self):
        header = [k for k in self.HEADER if k != "error_m"]
        write_csv(self.dir / "ate_pairs.csv", header, [[1.0] * len(header)] * 3)
        self.assertFailsCleanly(run_script("plot_eval.py", self.dir),
                                f"{self.dir / 'ate_pairs.csv'}: no column error_m")
        self.assertFalse((self.dir / "trajectory_top.png").exists())

    def test_value_not_a_number(self):
        rows = [[1.0] * len(self.HEADER) for _ in range(3)]
        rows[1][1] = "nan?"
        write_csv(self.dir / "ate_pairs.csv", self.HEADER, rows)
        self.assertFailsCleanly(run_script("plot_eval.py", self.dir),
                                f"{self.dir / 'ate_pairs.csv'} line 3: not a number", "nan?")
        self.assertFalse((self.dir / "trajectory_top.png").exists())

    def test_usage(self):
        self.assertFailsCleanly(run_script("plot_eval.py"), "usage: plot_eval.py DIR")


class PlotWeightsTest(PlotTestCase):
    HEADER = ["t", "points", "lines", "points_used", "lines_used", "w_p", "w_l", "alpha"]

    def setUp(self):
        super().setUp()
        self.run_dir = self.dir / "sim_MH_05" / "lines"
        self.run_dir.mkdir(parents=True)
        rows = []
        # Frames before the first optimisation (zero or no weights) are left out.
        for k in range(5):
            rows.append([f"{100 + 0.05 * k:.6f}", 150, 40, 0, 0, "0" if k % 2 else "", "0", "0"])
        self.t, self.w_p, self.alpha, self.pts, self.lns = [], [], [], [], []
        for k in range(5, 85):
            t = 100 + 0.05 * k
            w_p = round(0.5 + 0.3 * math.sin(0.2 * k), 4)
            self.t.append(t)
            self.w_p.append(w_p)
            self.alpha.append(round(0.5 + 0.01 * k, 2))
            self.pts.append(100 + k % 17)
            self.lns.append(20 + k % 5)
            rows.append([f"{t:.6f}", 150, 40, self.pts[-1], self.lns[-1], f"{w_p:.4f}",
                         f"{1 - w_p:.4f}", f"{self.alpha[-1]:.2f}"])
        write_csv(self.run_dir / "frame_stats.csv", self.HEADER, rows)

    def main(self, *args):
        stdout = io.StringIO()
        with mock.patch.object(sys, "argv", ["plot_weights.py", *map(str, args)]), \
                contextlib.redirect_stdout(stdout):
            plot_weights.main()
        return stdout.getvalue()

    def test_plot_written_with_the_data(self):
        out = self.main(self.run_dir)
        self.assertIn(f"weights plot: {self.run_dir / 'weights.png'}", out)
        self.assertPng(self.run_dir / "weights.png", 1100, 660)  # 10 x 6 in at 110 dpi

        ax1, ax2, ax1b = plt.gcf().axes
        self.assertEqual(ax1.get_title(), "adaptive point/line weights: sim_MH_05/lines")
        t = np.array(self.t) - self.t[0]  # time since the first optimised frame
        w_p, w_l = ax1.lines
        np.testing.assert_allclose(w_p.get_xdata(), t, atol=1e-6)
        np.testing.assert_allclose(w_p.get_ydata(), self.w_p, atol=1e-9)
        np.testing.assert_allclose(w_l.get_ydata(), 1 - np.array(self.w_p), atol=1e-9)
        np.testing.assert_allclose(ax1b.lines[0].get_ydata(), self.alpha, atol=1e-9)
        np.testing.assert_allclose(ax2.lines[0].get_ydata(), self.pts)
        np.testing.assert_allclose(ax2.lines[1].get_ydata(), self.lns)

    def test_out_option(self):
        self.main(self.run_dir, "--out", self.dir / "w.png")
        self.assertPng(self.dir / "w.png", 1100, 660)
        self.assertFalse((self.run_dir / "weights.png").exists())

    def test_missing_frame_stats(self):
        (self.run_dir / "frame_stats.csv").unlink()
        self.assertFailsCleanly(run_script("plot_weights.py", self.run_dir),
                                f"{self.run_dir / 'frame_stats.csv'} does not exist")

    def test_missing_column(self):
        header = [k for k in self.HEADER if k != "w_p"]
        write_csv(self.run_dir / "frame_stats.csv", header, [[1] * len(header)] * 3)
        self.assertFailsCleanly(run_script("plot_weights.py", self.run_dir),
                                f"{self.run_dir / 'frame_stats.csv'} has no column w_p")
        self.assertFalse((self.run_dir / "weights.png").exists())

    def test_value_not_a_number(self):
        with open(self.run_dir / "frame_stats.csv", "a") as f:
            f.write("100.5,150,40,90,20,0.5,0.5,x2\n")
        n = len((self.run_dir / "frame_stats.csv").read_text().splitlines())
        self.assertFailsCleanly(run_script("plot_weights.py", self.run_dir),
                                f"{self.run_dir / 'frame_stats.csv'} line {n}: not a number",
                                "x2")
        self.assertFalse((self.run_dir / "weights.png").exists())

    def test_no_optimised_frames(self):
        write_csv(self.run_dir / "frame_stats.csv", self.HEADER,
                  [[f"{100 + k:.6f}", 1, 1, 0, 0, "0", "0", "0"] for k in range(3)])
        self.assertFailsCleanly(run_script("plot_weights.py", self.run_dir),
                                f"no optimised frames in {self.run_dir / 'frame_stats.csv'}")
        self.assertFalse((self.run_dir / "weights.png").exists())


class PlotMapTruthTest(PlotTestCase):
    HEADER = ["id", "length_m", "observations", "landmarks", "edge", "angle_deg",
              "midpoint_distance_m", "surface_distance_m", "midpoint_surface_distance_m",
              "precision", "texture_midpoint_distance_m", "precision_with_texture_edges",
              "x0", "y0", "z0", "x1", "y1", "z1"]

    def per_line(self, name, lines):
        """lines: (x0, y0, x1, y1, precision_with_texture_edges); length from the endpoints."""
        rows = []
        for k, (x0, y0, x1, y1, good) in enumerate(lines):
            length = math.hypot(x1 - x0, y1 - y0)
            rows.append([k, f"{length:.6f}", 5, 1, 0, 1.0, 0.01, 0.01, 0.01, good, 0.01, good,
                         x0, y0, 1.0, x1, y1, 1.0])
        write_csv(self.dir / name, self.HEADER, rows)
        return self.dir / name

    def setUp(self):
        super().setUp()
        # Map A: 10 m of lines, 2 + 3 m on an edge and 5 m half on one: 75 % on a true edge.
        self.a = self.per_line("a.csv", [(0, 0, 2, 0, 1.0), (0, 1, 0, 4, 1.0), (1, 1, 4, 5, 0.5)])
        # Map B: 8 m of lines, none on an edge.
        self.b = self.per_line("b.csv", [(0, 0, 4, 0, 0.0), (0, 2, 4, 2, 0.0)])
        self.sequence = self.dir / "seq"
        self.sequence.mkdir()
        self.edges = [((-1.0, -1.0), (5.0, -1.0)), ((-1.0, -1.0), (-1.0, 6.0))]
        with open(self.sequence / "scene_edges.csv", "w") as f:
            f.write("#id,ax,ay,az,bx,by,bz,object\n")
            for k, ((ax, ay), (bx, by)) in enumerate(self.edges):
                f.write(f"{k},{ax:.6f},{ay:.6f},-2.4,{bx:.6f},{by:.6f},-2.4,hall\n")

    def main(self, *args):
        stdout = io.StringIO()
        with mock.patch.object(sys, "argv", ["plot_map_truth.py", *map(str, args)]), \
                contextlib.redirect_stdout(stdout):
            plot_map_truth.main()
        return stdout.getvalue()

    def test_two_panels_with_scene(self):
        out_png = self.dir / "map_truth.png"
        out = self.main(self.a, self.b, "--out", out_png, "--titles", "before,after",
                        "--sequence", self.sequence)
        self.assertIn(f"wrote {out_png}", out)
        pixels = self.assertPng(out_png, 1430, 660)  # 2 x 6.5 in by 6 in at 110 dpi

        left, right = plt.gcf().axes
        self.assertEqual(left.get_title(), "before: 3 lines, 10 m, 75.0 % on a true edge")
        self.assertEqual(right.get_title(), "after: 2 lines, 8 m, 0.0 % on a true edge")
        for ax in (left, right):
            scene, lines = ax.collections
            np.testing.assert_allclose(np.array(scene.get_segments()), np.array(self.edges))
        np.testing.assert_allclose(np.array(left.collections[1].get_segments()),
                                   [[(0, 0), (2, 0)], [(0, 1), (0, 4)], [(1, 1), (4, 5)]])

        # On an edge is green (0, 0.6, 0), off an edge red (1, 0, 0): map A has green and no
        # red, map B red and no green.
        r, g, b = pixels[..., 0], pixels[..., 1], pixels[..., 2]
        green = (g > 0.45) & (r < 0.25) & (b < 0.25)
        red = (r > 0.8) & (g < 0.25) & (b < 0.25)
        half = pixels.shape[1] // 2
        self.assertGreater(green[:, :half].sum(), 50)
        self.assertEqual(red[:, :half].sum(), 0)
        self.assertGreater(red[:, half:].sum(), 50)
        self.assertEqual(green[:, half:].sum(), 0)

    def test_titles_default_to_file_names(self):
        self.main(self.a, "--out", self.dir / "one.png")
        self.assertPng(self.dir / "one.png", 715, 660)
        (ax,) = plt.gcf().axes
        self.assertTrue(ax.get_title().startswith("a.csv: 3 lines"))
        self.assertEqual(len(ax.collections), 1)  # no scene without --sequence

    def test_old_per_line_file(self):
        old = self.dir / "old.csv"
        write_csv(old, ["id", "length_m", "precision"], [[0, 1.0, 1.0]])
        p = run_script("plot_map_truth.py", old, "--out", self.dir / "x.png")
        self.assertFailsCleanly(p, f"{old} has no endpoint or precision_with_texture_edges columns")
        self.assertFalse((self.dir / "x.png").exists())

    def test_old_per_line_file_names_the_missing_columns(self):
        old = self.dir / "old.csv"
        write_csv(old, [k for k in self.HEADER if k not in ("x1", "y1")], [])  # header only
        p = run_script("plot_map_truth.py", self.a, old, "--out", self.dir / "x.png")
        self.assertFailsCleanly(p, f"{old} has no endpoint or precision_with_texture_edges columns "
                            "(no x1, y1;")
        self.assertFalse((self.dir / "x.png").exists())

    def test_missing_length_column(self):
        short = self.dir / "short.csv"
        write_csv(short, [k for k in self.HEADER if k != "length_m"], [[1] * 17])
        p = run_script("plot_map_truth.py", short, "--out", self.dir / "x.png")
        self.assertFailsCleanly(p, f"{short} has no length_m column")
        self.assertFalse((self.dir / "x.png").exists())

    def test_value_not_a_number(self):
        bad = self.dir / "bad.csv"
        bad.write_text(self.a.read_text().replace("\n2,", "\n2,?", 1))
        p = run_script("plot_map_truth.py", bad, "--out", self.dir / "x.png")
        self.assertFailsCleanly(p, f"{bad} line 4: not a number")
        self.assertFalse((self.dir / "x.png").exists())
        with open(self.sequence / "scene_edges.csv", "a") as f:
            f.write("7,1.0,2.0,-2.4,y,1.0,-2.4,hall\n")
        p = run_script("plot_map_truth.py", self.a, "--out", self.dir / "x.png",
                       "--sequence", self.sequence)
        self.assertFailsCleanly(p, f"{self.sequence / 'scene_edges.csv'} line 4: not a number")

    def test_empty_per_line_file(self):
        empty = self.dir / "empty.csv"
        empty.write_text("")
        p = run_script("plot_map_truth.py", empty, "--out", self.dir / "x.png")
        self.assertFailsCleanly(
            p, f"{empty} has no endpoint or precision_with_texture_edges columns")
        self.assertFalse((self.dir / "x.png").exists())

    def test_missing_per_line_file(self):
        missing = self.dir / "nowhere.csv"
        p = run_script("plot_map_truth.py", self.a, missing, "--out", self.dir / "x.png")
        self.assertFailsCleanly(p, f"{missing}: No such file or directory")
        self.assertFalse((self.dir / "x.png").exists())

    def test_short_scene_edges_row(self):
        with open(self.sequence / "scene_edges.csv", "a") as f:
            f.write("7,1.0,2.0\n")
        p = run_script("plot_map_truth.py", self.a, "--out", self.dir / "x.png",
                       "--sequence", self.sequence)
        self.assertFailsCleanly(p, f"{self.sequence / 'scene_edges.csv'} line 4 has 3 columns")
        self.assertFalse((self.dir / "x.png").exists())

    def test_sequence_without_scene_edges(self):
        (self.sequence / "scene_edges.csv").unlink()
        p = run_script("plot_map_truth.py", self.a, "--out", self.dir / "x.png",
                       "--sequence", self.sequence)
        self.assertFailsCleanly(p, f"{self.sequence / 'scene_edges.csv'} does not exist")

    def test_title_count_must_match(self):
        p = run_script("plot_map_truth.py", self.a, self.b, "--out", self.dir / "x.png",
                       "--titles", "only one")
        self.assertFailsCleanly(p, "give one title per file")


if __name__ == "__main__":
    unittest.main()
