"""Tests of scripts/bench.py's summary logic: percentile(), what Run.result() makes of a run
folder (summary.json, frame_stats.csv, timing.csv), the markdown tables, and main() end to
end with a stand-in alvio_run that copies prepared run files (no real runs are made)."""
import csv
import json
import math
import os
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

import numpy as np

SCRIPTS = Path(__file__).resolve().parents[2] / "scripts"
sys.dont_write_bytecode = True  # keep scripts/ free of __pycache__
sys.path.insert(0, str(SCRIPTS))
import bench  # noqa: E402

STAGES = ["preprocess", "point_tracking", "point_detection", "line_detection", "line_tracking",
          "optimization", "marginalization"]


def write_run_folder(folder, seed, lines=True, ate=0.1234, frames=40, initialised=True):
    """A run folder as alvio_run writes it, from seeded random numbers. Returns the inputs."""
    rng = np.random.default_rng(seed)
    folder.mkdir(parents=True, exist_ok=True)
    stages = [s for s in STAGES if (lines or not s.startswith("line")) and
              (initialised or s not in ("optimization", "marginalization"))]
    t = 100.0 + 0.05 * np.arange(frames)
    ms = {s: rng.uniform(0.5, 8.0, frames).round(4) for s in stages}
    # Detection every other frame, as with detect_every = 2.
    ms["point_detection"][1::2] = 0.0
    if lines:
        ms["line_detection"][::2] = 0.0
    total = sum(ms.values())
    with open(folder / "timing.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t"] + [s + "_ms" for s in stages] + ["total_ms"])
        for k in range(frames):
            w.writerow([f"{t[k]:.9f}"] + [f"{ms[s][k]:.4f}" for s in stages] + [f"{total[k]:.4f}"])
    # frame_stats: frames before initialisation use no features and must not count.
    points_used = rng.integers(20, 150, frames)
    lines_used = rng.integers(0, 40, frames) if lines else np.zeros(frames, int)
    points_used[:5] = 0
    lines_used[:5] = 0
    with open(folder / "frame_stats.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t", "points", "lines", "points_used", "lines_used", "w_p", "w_l", "alpha"])
        for k in range(frames):
            w.writerow([f"{t[k]:.6f}", 200, 50, points_used[k], lines_used[k], 0.5, 0.5, 1.0])
    timing = {s: {"median": float(np.median(ms[s])), "p95": float(np.percentile(ms[s], 95))}
              for s in stages}
    timing["total"] = {"median": float(np.median(total)), "p95": float(np.percentile(total, 95))}
    summary = {"frames": frames, "poses": frames - 5, "resets": seed % 3, "ate_rmse_m": ate,
               "initialization": {"time": 100.25, "scale_error": 0.0321,
                                  "gravity_error_deg": 0.456},
               "timing_ms": timing}
    (folder / "summary.json").write_text(json.dumps(summary))
    return {"t": t, "ms": ms, "total": total, "points_used": points_used,
            "lines_used": lines_used, "summary": summary}


FAKE_SIM = """#!/usr/bin/python3
# Stand-in for alvio_sim --benchmark DIR --only NAMES: records how it was started (into the
# data folder) and makes each sequence's folder.
import json, os, sys
from pathlib import Path
argv = sys.argv
root = Path(argv[argv.index("--benchmark") + 1])
data = root if not root.name.startswith("seed") else root.parent
with open(data / "sim_calls.jsonl", "a") as f:
    f.write(json.dumps({"argv": argv, "ld_library_path": os.environ.get("LD_LIBRARY_PATH", "")}))
    f.write("\\n")
for name in argv[argv.index("--only") + 1].split(","):
    if name == "sim_nowhere":  # as the real one: an unknown name is an error
        sys.exit("alvio sim: error: unknown benchmark sequence 'sim_nowhere'")
    (root / name / "mav0").mkdir(parents=True, exist_ok=True)
"""


def table_rows(text):
    """Markdown table rows (header and separator excluded) as lists of cells."""
    rows = [line for line in text.splitlines() if line.startswith("|")][2:]
    return [[c.strip() for c in row.strip().strip("|").split("|")] for row in rows]


class PercentileTest(unittest.TestCase):
    def test_known_values(self):
        # Linear interpolation between closest ranks, as numpy's default.
        self.assertEqual(bench.percentile([1, 2, 3, 4], 50), 2.5)
        self.assertAlmostEqual(bench.percentile([10, 20, 30, 40, 50], 95), 48.0)
        self.assertAlmostEqual(bench.percentile([10, 20, 30, 40, 50], 25), 20.0)
        self.assertEqual(bench.percentile([10, 20, 30, 40, 50], 0), 10)
        self.assertEqual(bench.percentile([10, 20, 30, 40, 50], 100), 50)
        self.assertEqual(bench.percentile([7.5], 95), 7.5)

    def test_empty_is_nan(self):
        self.assertTrue(math.isnan(bench.percentile([], 50)))

    def test_matches_numpy_on_random_lists(self):
        rng = np.random.default_rng(3)
        for n in (2, 3, 10, 101, 1000):
            v = sorted(rng.exponential(5.0, n))
            for q in (5, 50, 90, 95, 99):
                self.assertAlmostEqual(bench.percentile(v, q), float(np.percentile(v, q)), places=9)


class RunResultTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = Path(self.tmp.name)

    def tearDown(self):
        self.tmp.cleanup()

    def result(self, out, wall_s=0.5, rc=0):
        run = bench.Run("sim_X", self.dir, "lines", [], out, "alvio_run", -1)
        # What reap() sets once the process has ended.
        run.rc, run.wall_s, run.cpu_s, run.rss_mb = rc, wall_s, 0.4, 123.0
        return run.result()

    def test_summary_fields(self):
        d = write_run_folder(self.dir / "run", seed=4, ate=0.0567)
        r = self.result(self.dir / "run")
        self.assertEqual(r["ate"], 0.0567)
        self.assertEqual(r["resets"], 1)
        self.assertEqual(r["frames"], 40)
        self.assertEqual(r["poses"], 35)
        self.assertEqual(r["init"]["scale_error"], 0.0321)
        self.assertEqual(r["timing"], d["summary"]["timing_ms"])
        self.assertEqual((r["rc"], r["wall_s"], r["peak_rss_mb"]), (0, 0.5, 123.0))

    def test_features_used_exclude_frames_without_optimisation(self):
        d = write_run_folder(self.dir / "run", seed=5)
        r = self.result(self.dir / "run")
        used = (d["points_used"] > 0) | (d["lines_used"] > 0)
        self.assertAlmostEqual(r["points_used"], d["points_used"][used].mean())
        self.assertAlmostEqual(r["lines_used"], d["lines_used"][used].mean())
        # The five leading zero rows would pull the mean down if counted.
        self.assertGreater(r["points_used"], d["points_used"].mean())

    def test_timing_figures(self):
        d = write_run_folder(self.dir / "run", seed=6)
        r = self.result(self.dir / "run")
        ms = d["ms"]
        self.assertAlmostEqual(r["duration_s"], d["t"][-1] - d["t"][0])
        opt = ms["optimization"] + ms["marginalization"]
        self.assertAlmostEqual(r["opt_total_median"], np.median(opt), places=9)
        self.assertAlmostEqual(r["opt_total_p95"], np.percentile(opt, 95), places=9)
        pts = ms["preprocess"] + ms["point_tracking"] + ms["point_detection"]
        lns = ms["line_detection"] + ms["line_tracking"]
        self.assertAlmostEqual(r["points_front_end_median"], np.median(pts), places=9)
        self.assertAlmostEqual(r["points_front_end_mean"], pts.mean(), places=9)
        self.assertAlmostEqual(r["lines_front_end_median"], np.median(lns), places=9)
        self.assertAlmostEqual(r["lines_front_end_mean"], lns.mean(), places=9)
        # Guard: the data tell a median of per-frame sums from a sum of medians.
        sum_of_medians = sum(np.median(ms[s]) for s in ("line_detection", "line_tracking"))
        self.assertGreater(abs(sum_of_medians - np.median(lns)), 0.1)

    def test_points_only_run_has_no_lines_front_end(self):
        write_run_folder(self.dir / "run", seed=7, lines=False)
        r = self.result(self.dir / "run")
        self.assertIn("points_front_end_median", r)
        self.assertNotIn("lines_front_end_median", r)
        self.assertEqual(r["lines_used"], 0)

    def test_run_that_never_initialised_has_no_optimisation_time(self):
        # Its timing.csv has no optimisation columns (a run that failed to initialise).
        write_run_folder(self.dir / "run", seed=8, initialised=False)
        r = self.result(self.dir / "run")
        self.assertNotIn("opt_total_median", r)
        self.assertIn("points_front_end_median", r)

    def test_failed_run_without_files(self):
        (self.dir / "run").mkdir()
        r = self.result(self.dir / "run", rc=134)
        self.assertEqual(r["rc"], 134)
        for key in ("ate", "timing", "duration_s", "opt_total_median", "points_used"):
            self.assertNotIn(key, r)


class TablesTest(unittest.TestCase):
    def test_bench_table_row(self):
        r = {"sequence": "sim_MH_01", "variant": "lines", "rc": 0, "wall_s": 8.0,
             "peak_rss_mb": 211.6, "ate": 0.04321, "resets": 2,
             "init": {"scale_error": 0.0123, "gravity_error_deg": 0.347},
             "timing": {"total": {"median": 12.34, "p95": 20.06}},
             "points_front_end_median": 4.44, "points_front_end_mean": 5.06,
             "lines_front_end_median": 7.71, "lines_front_end_mean": 8.29,
             "opt_total_median": 3.96, "duration_s": 20.0}
        (row,) = table_rows(bench.bench_table([r]))
        self.assertEqual(row, ["sim_MH_01", "lines", "0.0432", "2", "1.2", "0.35", "12.3 / 20.1",
                               "4.4 / 5.1", "7.7 / 8.3", "4.0", "2.50", "212"])

    def test_bench_table_missing_values(self):
        # A run that failed before writing anything: every figure is a dash.
        r = {"sequence": "sim_MH_05", "variant": "points", "rc": 1, "wall_s": 1.0,
             "peak_rss_mb": None}
        (row,) = table_rows(bench.bench_table([r]))
        self.assertEqual(row[:2], ["sim_MH_05", "points"])
        self.assertEqual(row[2:6], ["–"] * 4)
        self.assertEqual(row[6:], ["– / –", "– / –", "–", "–", "–", "–"])

    def test_compare_table_ratios_b_over_a(self):
        results = [
            {"sequence": "s1", "variant": "a", "ate": 0.2, "opt_total_median": 4.0,
             "peak_rss_mb": 100.0, "timing": {"total": {"median": 10.0}}},
            {"sequence": "s1", "variant": "b", "ate": 0.1, "opt_total_median": 5.0,
             "peak_rss_mb": 150.0, "timing": {"total": {"median": 12.5}}},
            {"sequence": "s2", "variant": "a", "ate": 0.3},  # b did not run
        ]
        rows = table_rows(bench.compare_table(results, "a", "b"))
        self.assertEqual(rows[0], ["s1", "0.2000", "0.1000", "0.500", "1.250", "1.250", "1.500"])
        self.assertEqual(rows[1], ["s2", "0.3000", "–", "–", "–", "–", "–"])

    def test_compare_table_pools_the_paired_runs(self):
        # Two sequences, three seeds each; b's ATE is a's times the given ratios.
        ratios = {"s1": [0.9, 1.1, 1.0], "s2": [0.8, 0.95, 1.05]}
        per_run = []
        for seq, rs in ratios.items():
            for seed, r in enumerate(rs, start=1):
                run = {"sequence": seq, "seed": seed, "rc": 0}
                per_run.append(run | {"variant": "a", "ate": 0.1})
                per_run.append(run | {"variant": "b", "ate": 0.1 * r})
        text = bench.compare_table(bench.aggregate(per_run), "a", "b", per_run)
        logs = [math.log(r) for rs in ratios.values() for r in rs]
        mean = sum(logs) / 6
        sd = math.sqrt(sum((x - mean) ** 2 for x in logs) / 5)
        half = 2.571 * sd / math.sqrt(6)  # t, 5 degrees of freedom
        self.assertIn(f"All 6 paired runs: ATE ratio b/a {math.exp(mean):.3f} (geometric mean; "
                      f"95 % interval {math.exp(mean - half):.3f}–{math.exp(mean + half):.3f}); "
                      "3 of 6 runs lower with b.", text)
        # Each sequence's own runs pooled the same way, in its row.
        rows = {row[0]: row for row in table_rows(text)}
        s1 = [math.log(r) for r in ratios["s1"]]
        m1 = sum(s1) / 3
        half1 = 4.303 * math.sqrt(sum((x - m1) ** 2 for x in s1) / 2) / math.sqrt(3)  # t, 2 dof
        self.assertEqual(rows["s1"][5], f"{math.exp(m1):.3f} ({math.exp(m1 - half1):.3f}–"
                                        f"{math.exp(m1 + half1):.3f}); 1 of 3")
        self.assertTrue(rows["s2"][5].endswith("; 2 of 3"), rows["s2"][5])
        # Identical runs: ratio 1 with no spread.
        same = [r | {"ate": 0.1} for r in per_run]
        self.assertIn("ATE ratio b/a 1.000 (geometric mean; 95 % interval 1.000–1.000); 0 of 6",
                      bench.compare_table(bench.aggregate(same), "a", "b", same))
        # One run per variant: nothing to pool.
        self.assertNotIn("paired runs", bench.compare_table(bench.aggregate(per_run[:2]), "a", "b",
                                                            per_run[:2]))

    def test_ablation_table_against_reference(self):
        def res(v, ate, opt, pts, lns):
            return {"sequence": "sim_MH_05", "variant": v, "ate": ate, "opt_total_median": opt,
                    "points_used": pts, "lines_used": lns}
        results = [res("sel-none", 0.100, 8.0, 120.0, 30.0),
                   res("sel-lines", 0.110, 6.0, 120.0, 18.0),
                   res("sel-points", 0.095, 4.0, 60.0, 30.0),
                   res("sel-both", 0.125, 2.0, 60.0, 18.0),
                   res("sel-none", 9.9, 99.0, 1.0, 1.0) | {"sequence": "other"}]
        text = bench.ablation_table(results, "sim_MH_05")
        self.assertTrue(text.startswith("**sim_MH_05**"))
        rows = table_rows(text)
        self.assertEqual([r[0] for r in rows], [label for label, _ in bench.ABLATION])
        self.assertEqual(rows[0], ["no selection", "120.0", "30.0", "8.00", "reference", "0.1000",
                                   "reference"])
        self.assertEqual(rows[1][3:], ["6.00", "-25.0 %", "0.1100", "+10.0 %"])
        self.assertEqual(rows[2][3:], ["4.00", "-50.0 %", "0.0950", "-5.0 %"])
        self.assertEqual(rows[3][3:], ["2.00", "-75.0 %", "0.1250", "+25.0 %"])

    def test_parse_variant(self):
        self.assertEqual(bench.parse_variant("points"), ("points", ["--no-lines"]))
        self.assertEqual(bench.parse_variant("fast=--set estimator.max_iterations=4"),
                         ("fast", ["--set", "estimator.max_iterations=4"]))
        with self.assertRaises(SystemExit) as cm:
            bench.parse_variant("nonsense")
        self.assertIn("unknown variant 'nonsense'", str(cm.exception.code))


FAKE_RUN = """#!/usr/bin/python3
# Stand-in for alvio_run: records its arguments and copies the prepared run files.
import json, os, shutil, sys, time
from pathlib import Path
argv = sys.argv[1:]
out = Path(argv[argv.index("--out") + 1])
seq = Path(argv[argv.index("--dataset") + 1]).name
variant = "points" if "--no-lines" in argv else "lines"
(out / "argv.json").write_text(json.dumps(argv))
# The cores it may use and when it ran (FAKE_SLEEP: seconds to take).
start = time.monotonic()
time.sleep(float(os.environ.get("FAKE_SLEEP", "0")))
(out / "ran.json").write_text(json.dumps({"cpus": sorted(os.sched_getaffinity(0)),
                                          "start": start, "end": time.monotonic()}))
print(f"fake alvio_run: {seq} {variant}")
# FAKE_FIXTURES: where the prepared files are when this script runs from a frozen copy.
src = Path(os.environ.get("FAKE_FIXTURES", Path(__file__).parent / "fixtures")) / seq / variant
for f in src.iterdir():
    shutil.copy(f, out / f.name)
# A nudged noise setting (--repeats) changes the result: ATE scales with it here.
for a in [argv[i + 1] for i, x in enumerate(argv) if x == "--set"]:
    for kv in a.split(","):
        if kv.startswith("estimator.point_sigma_px="):
            summary = json.loads((out / "summary.json").read_text())
            summary["ate_rmse_m"] *= float(kv.split("=")[1]) / 1.5
            (out / "summary.json").write_text(json.dumps(summary))
# Another noise seed's rendering (DATA/seedS/<sequence>) gives another result: ATE x S.
seed_set = Path(argv[argv.index("--dataset") + 1]).parent.name
if seed_set.startswith("seed"):
    summary = json.loads((out / "summary.json").read_text())
    summary["ate_rmse_m"] *= int(seed_set[4:])
    (out / "summary.json").write_text(json.dumps(summary))
sys.exit(int((src / "rc").read_text()) if (src / "rc").exists() else 0)
"""


class RepeatsTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = Path(self.tmp.name)

    def tearDown(self):
        self.tmp.cleanup()

    def test_perturbation_steps_alternate_around_the_configured_value(self):
        (self.dir / "base.yaml").write_text(
            "estimator:\n  point_sigma_px: 2.0\n  window_size: 10\n")
        (self.dir / "real.yaml").write_text("base: base.yaml\nestimator:\n  window_size: 8\n")
        args = ["--no-lines", "--config", str(self.dir / "real.yaml")]
        key = "estimator.point_sigma_px"
        self.assertEqual(bench.perturbed_args(args, key, 1e-3, 0), args)
        # The value comes through real.yaml's base: chain.
        values = [float(bench.perturbed_args(args, key, 1e-3, k)[-1].split("=")[1])
                  for k in range(1, 5)]
        for v, want in zip(values, [2.002, 1.998, 2.004, 1.996]):
            self.assertAlmostEqual(v, want, places=9)
        self.assertEqual(bench.perturbed_args(args, key, 1e-3, 1)[-2], "--set")
        # A variant that sets the key itself is nudged around its own value.
        own = ["--set", "a.b=1," + key + "=3.0", "--config", str(self.dir / "real.yaml")]
        self.assertEqual(bench.perturbed_args(own, key, 1e-3, 2)[-1], key + "=2.997")
        # A list value in the same --set is one assignment, not split at its comma.
        listed = ["--set", "camera.resolution=[640,480]," + key + "=4.0", "--config",
                  str(self.dir / "real.yaml")]
        self.assertEqual(bench.perturbed_args(listed, key, 1e-3, 1)[-1], key + "=4.004")
        self.assertEqual(bench.split_assignments("a=[1,2],b='x,y',c=3"),
                         ["a=[1,2]", "b='x,y'", "c=3"])
        with self.assertRaises(SystemExit) as cm:
            bench.perturbed_args(args, "estimator.nowhere", 1e-3, 1)
        self.assertIn("estimator.nowhere", str(cm.exception.code))

    def test_aggregate_means_ate_and_takes_median_times(self):
        runs = [{"sequence": "s", "variant": "v", "repeat": k, "rc": 0, "ate": ate, "resets": rs,
                 "wall_s": w, "peak_rss_mb": 100.0 + k, "init": {"scale_error": 0.01},
                 "timing": {"total": {"median": t, "p95": 2 * t}}}
                for k, (ate, rs, w, t) in enumerate([(0.10, 0, 9.0, 20.0), (0.13, 1, 5.0, 22.0),
                                                     (0.07, 0, 7.0, 30.0)])]
        other = dict(runs[0], variant="w")
        (a, b) = bench.aggregate(runs + [other])
        self.assertEqual(a["repeats"], 3)
        self.assertAlmostEqual(a["ate"], 0.10)
        self.assertEqual((a["ate_min"], a["ate_max"]), (0.07, 0.13))
        self.assertEqual(a["resets"], 1)
        self.assertEqual((a["wall_s"], a["peak_rss_mb"]), (7.0, 101.0))
        self.assertEqual(a["timing"]["total"], {"median": 22.0, "p95": 44.0})
        self.assertIs(b, other)  # a single run stays as it is
        self.assertEqual(bench.ate_cell(a), "0.1000 (0.0700–0.1300)")
        self.assertEqual(bench.ate_cell(b), "0.1000")
        # A repeat without an ATE (a failed run) leaves no mean, and its exit code shows.
        runs[1] = dict(runs[1], ate=None, rc=3)
        (a,) = bench.aggregate(runs)
        self.assertIsNone(a["ate"])
        self.assertEqual(a["rc"], 3)
        # A repeat without timing leaves no median times, not the first run's.
        runs[1] = dict(runs[1], timing=None)
        (a,) = bench.aggregate(runs)
        self.assertIsNone(a["timing"])


class PairedTimeTest(unittest.TestCase):
    def test_pools_blocks_of_two_pairs_with_the_cores_swapped(self):
        # B is 0.9x A; the second core runs 1.4x slower, and the pairs swap cores: B on the
        # slow core in pairs 0 and 2, A in pairs 1 and 3. A fifth pair has no partner.
        slow, per_run = 1.4, []
        for k in range(5):
            ta, tb = (10.0, 9.0 * slow) if k % 2 == 0 else (10.0 * slow, 9.0)
            tb *= 1.0 + 0.01 * k  # a little noise that stays
            run = {"sequence": "s", "seed": 1, "repeat": k, "rc": 0, "ate": 0.1}
            per_run.append(run | {"variant": "a", "timing": {"total": {"median": ta}}})
            per_run.append(run | {"variant": "b", "timing": {"total": {"median": tb}}})
        blocks = [0.9 * math.sqrt(1.00 * 1.01), 0.9 * math.sqrt(1.02 * 1.03)]
        logs = [math.log(x) for x in blocks]
        mean = sum(logs) / 2
        sd = math.sqrt(sum((x - mean) ** 2 for x in logs))
        half = 12.706 * sd / math.sqrt(2)  # t, 1 degree of freedom
        expected = (f"Median frame time b/a over 2 blocks of two pairs with the cores swapped: "
                    f"{math.exp(mean):.3f} (geometric mean; 95 % interval "
                    f"{math.exp(mean - half):.3f}–{math.exp(mean + half):.3f}).")
        self.assertEqual(bench.paired_time_line(per_run, "a", "b"), expected)
        self.assertIn(": 0.913 (geometric mean", expected)  # 0.9 x 1.015: the 1.4 cancelled
        text = bench.compare_table(bench.aggregate(per_run), "a", "b", per_run, side_by_side=True)
        self.assertIn(expected, text)
        self.assertNotIn("Median frame time", bench.compare_table(bench.aggregate(per_run), "a",
                                                                  "b", per_run))


class MainTest(unittest.TestCase):
    """bench.py as ./alvio bench runs it, with --bin pointing at FAKE_RUN."""

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = Path(self.tmp.name)
        self.data = self.dir / "data"
        self.fake = self.dir / "fake" / "alvio_run"
        self.fake.parent.mkdir()
        self.fake.write_text(FAKE_RUN)
        self.fake.chmod(0o755)
        self.inputs = {}
        for k, seq in enumerate(["sim_A", "sim_B_realimu"]):
            (self.data / seq / "mav0").mkdir(parents=True)
            for j, variant in enumerate(["points", "lines"]):
                self.inputs[seq, variant] = write_run_folder(
                    self.fake.parent / "fixtures" / seq / variant, seed=10 + 2 * k + j,
                    lines=variant == "lines", ate=0.05 + 0.01 * (2 * k + j))

    def tearDown(self):
        self.tmp.cleanup()

    def bench(self, *args, sleep=0.0):
        # FAKE_FIXTURES: the fixtures also for a frozen copy of FAKE_RUN (--freeze).
        env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1",
                   FAKE_FIXTURES=str(self.fake.parent / "fixtures"), FAKE_SLEEP=str(sleep))
        return subprocess.run(["/usr/bin/python3", str(SCRIPTS / "bench.py"),
                               "--data", str(self.data), "--out", str(self.dir / "out"),
                               "--bin", str(self.fake), *args],
                              capture_output=True, text=True, env=env, timeout=60)

    def test_runs_and_tables(self):
        p = self.bench("--sequences", "sim_A,sim_B_realimu", "--variants", "points,lines")
        self.assertEqual(p.returncode, 0, p.stderr)
        out = self.dir / "out"
        results = json.loads((out / "results.json").read_text())
        # Variants interleaved per sequence.
        self.assertEqual([(r["sequence"], r["variant"]) for r in results],
                         [("sim_A", "points"), ("sim_A", "lines"),
                          ("sim_B_realimu", "points"), ("sim_B_realimu", "lines")])
        for r in results:
            argv = json.loads((out / r["sequence"] / r["variant"] / "argv.json").read_text())
            self.assertEqual(argv[argv.index("--dataset") + 1], str(self.data / r["sequence"]))
            self.assertEqual(argv[argv.index("--out") + 1], str(out / r["sequence"] / r["variant"]))
            self.assertIn("--quiet", argv)
            self.assertEqual("--no-lines" in argv, r["variant"] == "points")
            # One core per run unless asked otherwise (issue 10's single-thread figures).
            self.assertEqual(argv[argv.index("--opencv-threads") + 1], "1")
            # The real EuRoC IMU runs with the in-flight noise configuration.
            config = Path(argv[argv.index("--config") + 1]).name
            self.assertEqual(config, "euroc_real.yaml" if r["sequence"] == "sim_B_realimu"
                             else "euroc.yaml")
            # The program's output goes to the run's log.
            log = (out / r["sequence"] / r["variant"] / "run.log").read_text()
            self.assertIn(f"fake alvio_run: {r['sequence']} {r['variant']}", log)

        md = (out / "results.md").read_text()
        self.assertEqual(p.stdout, md)
        self.assertIn("config/euroc_real.yaml", md)  # the real-IMU note
        rows = table_rows(md)
        self.assertEqual(len(rows), 4)
        for row, r in zip(rows, results):
            d = self.inputs[r["sequence"], r["variant"]]
            ms = d["ms"]
            pts = ms["preprocess"] + ms["point_tracking"] + ms["point_detection"]
            self.assertEqual(row[:2], [r["sequence"], r["variant"]])
            self.assertEqual(row[2], f"{d['summary']['ate_rmse_m']:.4f}")
            self.assertEqual(row[4], "3.2")  # 100 * scale_error
            total = d["total"]
            self.assertEqual(row[6], f"{np.median(total):.1f} / {np.percentile(total, 95):.1f}")
            self.assertEqual(row[7], f"{np.median(pts):.1f} / {pts.mean():.1f}")
            if r["variant"] == "points":
                self.assertEqual(row[8], "–")
            else:
                lns = ms["line_detection"] + ms["line_tracking"]
                self.assertEqual(row[8], f"{np.median(lns):.1f} / {lns.mean():.1f}")
            opt = ms["optimization"] + ms["marginalization"]
            self.assertEqual(row[9], f"{np.median(opt):.1f}")
            # Real-time factor: sequence time over the run's wall time.
            duration = d["t"][-1] - d["t"][0]
            self.assertGreater(r["wall_s"], 0)
            self.assertEqual(row[10], f"{duration / r['wall_s']:.2f}")

    def test_opencv_threads_zero_leaves_the_option_out(self):
        # Builds from before the option reject it: 0 must not pass it at all.
        p = self.bench("--sequences", "sim_A", "--variants", "lines", "--opencv-threads", "0")
        self.assertEqual(p.returncode, 0, p.stderr)
        argv = json.loads((self.dir / "out" / "sim_A" / "lines" / "argv.json").read_text())
        self.assertNotIn("--opencv-threads", argv)

    def test_failed_run_gives_exit_1(self):
        (self.fake.parent / "fixtures" / "sim_A" / "lines" / "rc").write_text("3")
        p = self.bench("--sequences", "sim_A", "--variants", "points,lines")
        self.assertEqual(p.returncode, 1)
        results = json.loads((self.dir / "out" / "results.json").read_text())
        self.assertEqual([r["rc"] for r in results], [0, 3])

    def test_compare_appends_ratio_table(self):
        p = self.bench("--sequences", "sim_A", "--compare", "points", "lines")
        self.assertEqual(p.returncode, 0, p.stderr)
        tables = p.stdout.split("\n\n")
        self.assertEqual(len(tables), 2)
        (row,) = table_rows(tables[1])
        ate_points = self.inputs["sim_A", "points"]["summary"]["ate_rmse_m"]
        ate_lines = self.inputs["sim_A", "lines"]["summary"]["ate_rmse_m"]
        self.assertEqual(row[:4], ["sim_A", f"{ate_points:.4f}", f"{ate_lines:.4f}",
                                   f"{ate_lines / ate_points:.3f}"])

    @unittest.skipUnless({0, 1} <= os.sched_getaffinity(0), "needs cores 0 and 1")
    def test_side_by_side_runs_each_pair_at_once_on_swapped_cores(self):
        # Each stand-in run takes 1 s: a pair started together overlaps even when one of them
        # takes a few tenths of a second longer to start (0.35 s seen on a loaded machine,
        # where 0.3 s runs missed each other).
        p = self.bench("--sequences", "sim_A", "--compare", "points", "lines", "--repeats", "4",
                       "--side-by-side", sleep=1.0)
        self.assertEqual(p.returncode, 0, p.stderr)
        out = self.dir / "out" / "sim_A"
        ran = {(v, k): json.loads((out / v / f"r{k}" / "ran.json").read_text())
               for v in ("points", "lines") for k in range(4)}
        # One core each, swapped from one pair to the next.
        self.assertEqual([(ran["points", k]["cpus"], ran["lines", k]["cpus"]) for k in range(4)],
                         [([0], [1]), ([1], [0]), ([0], [1]), ([1], [0])])
        for k in range(4):
            a, b = ran["points", k], ran["lines", k]
            self.assertLess(max(a["start"], b["start"]), min(a["end"], b["end"]))  # overlapping
            if k:  # the next pair only once both of the last have ended
                last = max(ran["points", k - 1]["end"], ran["lines", k - 1]["end"])
                self.assertGreaterEqual(min(a["start"], b["start"]), last)
        lines = self.inputs["sim_A", "lines"]["summary"]["timing_ms"]["total"]["median"]
        points = self.inputs["sim_A", "points"]["summary"]["timing_ms"]["total"]["median"]
        self.assertIn(f"Median frame time lines/points over 2 blocks of two pairs with the cores "
                      f"swapped: {lines / points:.3f}", p.stdout)
        self.assertIn("pairs side by side", p.stderr)

    def test_side_by_side_needs_compare(self):
        p = self.bench("--sequences", "sim_A", "--variants", "points,lines", "--side-by-side")
        self.assertNotEqual(p.returncode, 0)
        self.assertIn("--side-by-side needs --compare", p.stderr)

    def test_repeats_nudge_the_noise_setting_and_average(self):
        p = self.bench("--sequences", "sim_A", "--variants", "points,lines", "--repeats", "3")
        self.assertEqual(p.returncode, 0, p.stderr)
        out = self.dir / "out"
        results = json.loads((out / "results.json").read_text())
        # Every repeat of every variant ran, interleaved, each in a folder of its own.
        self.assertEqual([(r["variant"], r["repeat"]) for r in results],
                         [("points", 0), ("lines", 0), ("points", 1), ("lines", 1),
                          ("points", 2), ("lines", 2)])
        sigma = [1.5, 1.5 * (1 + 7e-4), 1.5 * (1 - 7e-4)]  # config/euroc.yaml's 1.5, nudged
        for r in results:
            argv = json.loads((out / "sim_A" / r["variant"] / f"r{r['repeat']}" /
                               "argv.json").read_text())
            sets = [argv[i + 1] for i, x in enumerate(argv) if x == "--set"]
            if r["repeat"] == 0:
                self.assertEqual(sets, [])
            else:
                (kv,) = sets
                self.assertAlmostEqual(float(kv.split("=")[1]), sigma[r["repeat"]], places=9)
        rows = table_rows(p.stdout.split("\n\n")[0])
        self.assertEqual([row[:2] for row in rows], [["sim_A", "points"], ["sim_A", "lines"]])
        for row in rows:
            base = self.inputs["sim_A", row[1]]["summary"]["ate_rmse_m"]
            ates = [base * s / 1.5 for s in sigma]
            self.assertEqual(row[2], f"{np.mean(ates):.4f} ({min(ates):.4f}–{max(ates):.4f})")
        self.assertIn("3 runs with estimator.point_sigma_px scaled", p.stdout)

    def test_seeds_run_each_seeds_rendering_and_pair_the_ratios(self):
        for seed in (2, 5):
            for seq in ("sim_A", "sim_B_realimu"):
                (self.data / f"seed{seed}" / seq / "mav0").mkdir(parents=True)
        p = self.bench("--sequences", "sim_A,sim_B_realimu", "--compare", "points", "lines",
                       "--seeds", "1,2,5")
        self.assertEqual(p.returncode, 0, p.stderr)
        out = self.dir / "out"
        results = json.loads((out / "results.json").read_text())
        # Interleaved per sequence and seed; each run on its seed's copy, in a folder of its own.
        self.assertEqual([(r["sequence"], r["seed"], r["variant"]) for r in results],
                         [(q, s, v) for q in ("sim_A", "sim_B_realimu") for s in (1, 2, 5)
                          for v in ("points", "lines")])
        for r in results:
            folder = out / r["sequence"] / r["variant"] / f"s{r['seed']}"
            argv = json.loads((folder / "argv.json").read_text())
            data = self.data if r["seed"] == 1 else self.data / f"seed{r['seed']}"
            self.assertEqual(argv[argv.index("--dataset") + 1], str(data / r["sequence"]))
        tables = p.stdout.split("\n\n")
        rows = table_rows(tables[0])
        self.assertEqual([row[:2] for row in rows],
                         [[q, v] for q in ("sim_A", "sim_B_realimu") for v in ("points", "lines")])
        for row in rows:
            base = self.inputs[row[0], row[1]]["summary"]["ate_rmse_m"]
            ates = [base * s for s in (1, 2, 5)]
            self.assertEqual(row[2], f"{np.mean(ates):.4f} ({min(ates):.4f}–{max(ates):.4f})")
        compare = table_rows(tables[1])
        self.assertIn("ATE ratio per run (seeds 1, 2, 5)", tables[1])
        for row in compare:
            r = (self.inputs[row[0], "lines"]["summary"]["ate_rmse_m"] /
                 self.inputs[row[0], "points"]["summary"]["ate_rmse_m"])
            self.assertEqual(row[3], f"{r:.3f}")  # the ratio of the means
            self.assertEqual(row[4], " / ".join([f"{r:.3f}"] * 3))
        self.assertIn("noise seeds 1,2,5", p.stdout)

    def test_one_other_seed_is_labelled_too(self):
        (self.data / "seed2" / "sim_A" / "mav0").mkdir(parents=True)
        p = self.bench("--sequences", "sim_A", "--variants", "lines", "--seeds", "2")
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertTrue((self.dir / "out" / "sim_A" / "lines" / "s2" / "summary.json").exists())
        self.assertIn("noise seeds 2", p.stdout)

    def test_seed_without_its_rendering_names_the_folder(self):
        p = self.bench("--sequences", "sim_A", "--seeds", "1,3")
        self.assertNotEqual(p.returncode, 0)
        self.assertIn(str(self.data / "seed3" / "sim_A"), p.stderr)
        self.assertIn("--seed 3", p.stderr)
        for bad in ("0,1", "1,1", "x"):
            p = self.bench("--sequences", "sim_A", "--seeds", bad)
            self.assertNotEqual(p.returncode, 0)
            self.assertIn("--seeds", p.stderr)

    def fake_build(self):
        """A build folder as scripts/freeze_build.sh expects it: a library, the stand-in
        alvio_run and a stand-in alvio_sim that records how it was started and makes the
        rendering. Returns alvio_run's path."""
        lib = self.dir / "build" / "devel" / "lib"
        (lib / "alvio").mkdir(parents=True)
        (lib / "libalvio_core.so").write_text("core")
        for name, text in (("alvio_run", FAKE_RUN), ("alvio_sim", FAKE_SIM)):
            (lib / "alvio" / name).write_text(text)
            (lib / "alvio" / name).chmod(0o755)
        return lib / "alvio" / "alvio_run"

    def test_render_uses_the_frozen_simulator(self):
        run = self.fake_build()
        out = self.dir / "out"
        # The last --bin counts: this build's alvio_run instead of the stand-in's.
        p = self.bench("--bin", str(run), "--freeze", "--render", "--sequences", "sim_A",
                       "--seeds", "1,3", "--variants", "lines")
        self.assertEqual(p.returncode, 0, p.stderr)
        calls = [json.loads(line) for line in
                 (self.data / "sim_calls.jsonl").read_text().splitlines()]
        config = str(out / "frozen" / "config" / "euroc.yaml")
        self.assertEqual([c["argv"][1:] for c in calls],
                         [["--benchmark", str(self.data), "--seed", "1", "--only", "sim_A",
                           "--config", config],
                          ["--benchmark", str(self.data / "seed3"), "--seed", "3", "--only",
                           "sim_A", "--config", config]])
        for c in calls:
            self.assertEqual(c["argv"][0], str(out / "frozen" / "bin" / "alvio_sim"))
            self.assertTrue(c["ld_library_path"].startswith(str(out / "frozen" / "lib")))
        self.assertTrue((out / "sim_A" / "lines" / "s3" / "summary.json").exists())

    def test_render_leaves_sequences_given_as_folders_alone(self):
        # ./alvio ablation always renders what is missing or out of date: a folder of one's
        # own is not the simulator's to make (an empty --only would render the whole set).
        run = self.fake_build()
        p = self.bench("--bin", str(run), "--render", "--sequences", str(self.data / "sim_A"),
                       "--variants", "lines")
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertFalse((self.data / "sim_calls.jsonl").exists())
        self.assertTrue((self.dir / "out" / "sim_A" / "lines" / "summary.json").exists())

    def test_render_of_an_unknown_sequence_fails_without_a_traceback(self):
        p = self.bench("--bin", str(self.fake_build()), "--render", "--sequences", "sim_nowhere")
        self.assertNotEqual(p.returncode, 0)
        self.assertIn("unknown benchmark sequence 'sim_nowhere'", p.stderr)
        self.assertIn("alvio bench: rendering", p.stderr)
        self.assertNotIn("Traceback", p.stderr)

    def test_missing_sequence_names_it(self):
        p = self.bench("--sequences", "sim_nowhere")
        self.assertNotEqual(p.returncode, 0)
        self.assertIn(str(self.data / "sim_nowhere"), p.stderr)
        self.assertFalse((self.dir / "out" / "results.json").exists())

    def test_missing_sequence_stops_before_freezing(self):
        # A build --freeze could copy: a mistyped name must not leave OUT/frozen behind.
        p = self.bench("--bin", str(self.fake_build()), "--freeze",
                       "--sequences", "sim_A,sim_nowhere")
        self.assertNotEqual(p.returncode, 0)
        self.assertIn(str(self.data / "sim_nowhere"), p.stderr)
        self.assertFalse((self.dir / "out" / "frozen").exists())


if __name__ == "__main__":
    unittest.main()
