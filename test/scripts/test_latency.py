"""Tests of scripts/latency.py: it reads a rosbag of alvio/PipelineStatus messages and reports
frames, dropped frames, the image-to-odometry latency (median, p95, max over tracking frames
with a known latency) and the front-end and estimator medians. The bag is written with the
rosbag Python API and a message class made by genpy from msg/PipelineStatus.msg (the same
definition, and so the same md5sum, as the built message); skipped without rosbag."""
import json
import math
import os
import subprocess
import tempfile
import unittest
from pathlib import Path

import numpy as np

from script_failures import CleanFailureAssertions  # test/scripts/, on the path

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "latency.py"

try:
    import genpy
    import genpy.dynamic
    import rosbag
    import std_msgs.msg
except ImportError as e:  # no ROS python packages (python3-rosbag, python3-genpy)
    rosbag = None
    IMPORT_ERROR = str(e)


def status_class(without=None):
    """alvio/PipelineStatus from the package's .msg file, with std_msgs/Header appended as
    gen_msg does, so no build tree is needed; without: leave out the lines of this field (as
    in a status recorded before the field was added)."""
    text = (ROOT / "msg" / "PipelineStatus.msg").read_text()
    if without:
        lines = text.splitlines()
        k = next(i for i, line in enumerate(lines) if line.split()[1:2] == [without])
        end = k + 1  # and the comment lines that continue the field's comment
        while end < len(lines) and lines[end].lstrip().startswith("#"):
            end += 1
        text = "\n".join(lines[:k] + lines[end:]) + "\n"
    full = text + "\n" + "=" * 80 + "\nMSG: std_msgs/Header\n" + std_msgs.msg.Header._full_text
    return genpy.dynamic.generate_dynamic("alvio/PipelineStatus", full)["alvio/PipelineStatus"]


def run_latency(*args):
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1")  # latency.py imports bench.py
    return subprocess.run(["/usr/bin/python3", str(SCRIPT), *map(str, args)], capture_output=True,
                          text=True, env=env, timeout=60)


class LatencyTest(CleanFailureAssertions, unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if rosbag is None:
            raise unittest.SkipTest(f"rosbag or genpy/std_msgs cannot be imported "
                                    f"({IMPORT_ERROR}): install python3-rosbag to run the "
                                    "latency.py tests")
        cls.Status = status_class()

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.dir = Path(self.tmp.name)

    def tearDown(self):
        self.tmp.cleanup()

    def write_bag(self, name, messages, message_class=None):
        path = self.dir / name
        with rosbag.Bag(str(path), "w") as bag:
            for k, fields in enumerate(messages):
                m = (message_class or self.Status)(**fields)
                m.header.stamp = genpy.Time(1600000000 + k // 20, (k % 20) * 50_000_000)
                m.header.frame_id = "world"
                bag.write("/alvio/status", m, t=m.header.stamp)
        return path

    def test_figures_from_known_statuses(self):
        rng = np.random.default_rng(11)
        msgs, latency, frontend, estimator = [], [], [], []
        # Initialising frames: slow and without latency; they must not count.
        for k in range(10):
            msgs.append(dict(state="initialising", frames=k + 1, latency_ms=-1.0,
                             frontend_ms=500.0, estimator_ms=500.0))
        for k in range(10, 70):
            fe, es = rng.uniform(2, 9), rng.uniform(5, 30)
            lat = -1.0 if k % 7 == 0 else fe + es + rng.uniform(0, 20)  # some unknown
            msgs.append(dict(state="tracking", frames=k + 1, dropped_frames=k // 30,
                             frontend_ms=fe, estimator_ms=es, latency_ms=lat))
            frontend.append(fe)
            estimator.append(es)
            if lat >= 0:
                latency.append(lat)
        msgs.append(dict(state="reset", frames=71, dropped_frames=2, latency_ms=999.0,
                         frontend_ms=999.0, estimator_ms=999.0, message="lost track"))
        msgs.append(dict(state="initialising", frames=72, dropped_frames=3, latency_ms=-1.0))
        bag = self.write_bag("status.bag", msgs)
        json_path = self.dir / "latency.json"
        p = run_latency(bag, "--json", json_path)
        self.assertEqual(p.returncode, 0, p.stderr)
        out = json.loads(json_path.read_text())
        # Counts come from the last message.
        self.assertEqual(out["frames"], 72)
        self.assertEqual(out["dropped_frames"], 3)
        self.assertEqual(out["tracking_frames"], 60)
        self.assertAlmostEqual(out["latency_ms"]["median"], np.percentile(latency, 50), places=9)
        self.assertAlmostEqual(out["latency_ms"]["p95"], np.percentile(latency, 95), places=9)
        self.assertAlmostEqual(out["latency_ms"]["max"], max(latency), places=9)
        self.assertAlmostEqual(out["frontend_ms_median"], np.median(frontend), places=9)
        self.assertAlmostEqual(out["estimator_ms_median"], np.median(estimator), places=9)
        median, p95 = np.percentile(latency, [50, 95])
        self.assertIn(f"72 frames (60 tracking), 3 dropped; image-to-odometry latency median "
                      f"{median:.1f} ms, p95 {p95:.1f} ms", p.stdout)

    def test_no_known_latency(self):
        # latency_ms -1 throughout (unknown): NaN figures, but the counts still.
        msgs = [dict(state="tracking", frames=k + 1, latency_ms=-1.0, frontend_ms=3.0,
                     estimator_ms=float(k)) for k in range(5)]
        json_path = self.dir / "latency.json"
        p = run_latency(self.write_bag("status.bag", msgs), "--json", json_path)
        self.assertEqual(p.returncode, 0, p.stderr)
        out = json.loads(json_path.read_text())
        self.assertEqual((out["frames"], out["tracking_frames"]), (5, 5))
        self.assertTrue(all(math.isnan(v) for v in out["latency_ms"].values()))
        self.assertEqual(out["estimator_ms_median"], 2.0)

    def test_empty_bag(self):
        bag = self.dir / "empty.bag"
        rosbag.Bag(str(bag), "w").close()
        p = run_latency(bag)
        self.assertNotEqual(p.returncode, 0)
        self.assertIn(f"{bag}: no status messages", p.stderr)

    def test_not_a_bag(self):
        bag = self.dir / "garbage.bag"
        bag.write_bytes(b"this is not a rosbag\n" * 10)
        p = run_latency(bag)
        self.assertNotEqual(p.returncode, 0)
        self.assertIn(f"{bag}: cannot read", p.stderr)
        self.assertNotIn("Traceback", p.stderr)

    def test_status_without_a_field(self):
        # A bag recorded before PipelineStatus had latency_ms.
        old = status_class(without="latency_ms")
        self.assertFalse(hasattr(old(), "latency_ms"))
        msgs = [dict(state="tracking", frames=k + 1, frontend_ms=3.0, estimator_ms=5.0)
                for k in range(5)]
        bag = self.write_bag("old.bag", msgs, old)
        self.assertFailsCleanly(run_latency(bag), f"{bag}: /alvio/status (alvio/PipelineStatus) "
                                                  "has no field latency_ms")

    def test_not_status_messages(self):
        bag = self.dir / "strings.bag"
        with rosbag.Bag(str(bag), "w") as b:
            b.write("/chatter", std_msgs.msg.String(data="hello"), t=genpy.Time(1600000000))
        self.assertFailsCleanly(run_latency(bag), f"{bag}: /chatter (std_msgs/String) has no "
                                                  "field state, frames")

    def test_missing_bag(self):
        bag = self.dir / "nowhere.bag"
        p = run_latency(bag)
        self.assertNotEqual(p.returncode, 0)
        self.assertIn(f"{bag}: cannot read", p.stderr)


if __name__ == "__main__":
    unittest.main()
