"""Tests of scripts/start_anywhere.py (./alvio starts): the start list, the summary of the
runs, and main() end to end with a stand-in alvio_run that writes a summary.json from its
--start (no real runs are made)."""
import json
import os
import subprocess
import sys
import tempfile
import unittest
from pathlib import Path

SCRIPTS = Path(__file__).resolve().parents[2] / "scripts"
sys.dont_write_bytecode = True  # keep scripts/ free of __pycache__
sys.path.insert(0, str(SCRIPTS))
import start_anywhere  # noqa: E402

# Writes OUT/summary.json as alvio_run would: ATE 10 x start, so a start of 0.06 s or more
# diverges at 0.5 m; start 3 exits with an error, and the arguments are echoed for the test.
STAND_IN = """#!/usr/bin/env python3
import json, sys
from pathlib import Path
a = sys.argv[1:]
start = float(a[a.index("--start") + 1])
out = Path(a[a.index("--out") + 1])
(out / "args.json").write_text(json.dumps(a))
if start == 3:
    sys.exit(2)
init = {"since_first_motion_s": 0.5 + start, "scale_error": start / 100, "gravity_error_deg": 1.0}
(out / "summary.json").write_text(json.dumps({"ate_rmse_m": 0.01 * start, "poses": 10,
                                               "initialization": init}))
"""


class ParseStarts(unittest.TestCase):
    def test_a_list_is_sorted_and_a_range_includes_its_end(self):
        self.assertEqual(start_anywhere.parse_starts("4,2,7.5"), [2, 4, 7.5])
        self.assertEqual(start_anywhere.parse_starts("2:4:0.5"), [2, 2.5, 3, 3.5, 4])

    def test_bad_starts_are_refused(self):
        for bad in ["", "-1,2", "2:1:1", "1:3:0", "1:3"]:
            with self.assertRaises(ValueError, msg=bad):
                start_anywhere.parse_starts(bad)


class Summarize(unittest.TestCase):
    def test_counts_diverged_and_failed_starts(self):
        rows = [{"start_s": 1, "ate_m": 0.1, "scale_error": 0.02},
                {"start_s": 2, "ate_m": 3.0, "scale_error": 0.6},
                {"start_s": 3, "exit": 2},
                {"start_s": 4, "ate_m": 0.3, "scale_error": 0.1}]
        s = start_anywhere.summarize(rows, 0.5)
        self.assertEqual((s["starts"], s["diverged"], s["failed"]), (4, 1, 1))
        self.assertAlmostEqual(s["median_ate_m"], 0.3)
        self.assertAlmostEqual(s["mean_ate_not_diverged_m"], 0.2)
        self.assertAlmostEqual(s["median_scale_error"], 0.1)
        self.assertAlmostEqual(s["max_scale_error"], 0.6)
        text = start_anywhere.table(rows, s, 0.5)
        self.assertIn("| 2 | – | 60.0 % | – | 3.000 (diverged) |", text)
        self.assertIn("(exit 2)", text)
        self.assertIn("4 starts: 1 diverged (ATE > 0.5 m), 1 failed", text)


class Main(unittest.TestCase):
    def test_runs_every_start_and_writes_the_table_and_json(self):
        with tempfile.TemporaryDirectory() as tmp:
            tmp = Path(tmp)
            stand_in = tmp / "alvio_run"
            stand_in.write_text(STAND_IN)
            stand_in.chmod(0o755)
            (tmp / "data").mkdir()
            out = tmp / "out"
            r = subprocess.run(
                [sys.executable, str(SCRIPTS / "start_anywhere.py"), "--bin", str(stand_in),
                 "--dataset", str(tmp / "data"), "--starts", "1:3:1", "--frames", "50",
                 "--set", "a.b=1", "--out", str(out), "--no-plot", "--diverged-m", "0.015"],
                capture_output=True, text=True, env=dict(os.environ, PYTHONDONTWRITEBYTECODE="1"))
            self.assertEqual(r.returncode, 0, r.stderr)
            data = json.loads((out / "starts.json").read_text())
            self.assertEqual([row["start_s"] for row in data["rows"]], [1, 2, 3])
            self.assertEqual(data["summary"]["diverged"], 1)  # start 2: 0.02 m
            self.assertEqual(data["summary"]["failed"], 1)  # start 3 exited with 2
            args = json.loads((out / "start_2" / "args.json").read_text())
            for expected in (["--start", "2"], ["--max-frames", "50"], ["--set", "a.b=1"]):
                i = args.index(expected[0])
                self.assertEqual(args[i:i + 2], expected)
            self.assertIn("| 1 | 1.50 | 1.0 % | 1.00 | 0.010 |", (out / "starts.md").read_text())

    def test_a_missing_dataset_is_named(self):
        r = subprocess.run([sys.executable, str(SCRIPTS / "start_anywhere.py"), "--bin", "x",
                            "--dataset", "/nowhere/data", "--starts", "1", "--out", "/tmp/x"],
                           capture_output=True, text=True)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("/nowhere/data", r.stderr)


if __name__ == "__main__":
    unittest.main()
