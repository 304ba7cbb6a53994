"""Tests of scripts/faults.py's fault names: the listed faults, and image or IMU gaps of any
length (image_gap_3s), which drop exactly their topic's messages stamped inside the gap."""
import sys
import unittest
from pathlib import Path
from types import SimpleNamespace

SCRIPTS = Path(__file__).resolve().parents[2] / "scripts"
sys.dont_write_bytecode = True  # keep scripts/ free of __pycache__
sys.path.insert(0, str(SCRIPTS))
import faults  # noqa: E402


def message(stamp):
    return SimpleNamespace(header=SimpleNamespace(stamp=SimpleNamespace(to_sec=lambda: stamp)))


def kept(fault, t_fault, stream):
    """The (topic, stamp) pairs of the stream that the fault lets through."""
    ctx = faults.FaultContext(t_fault, t_fault + fault.duration)
    out = []
    for topic, stamp in stream:
        out += [(o_topic, o_msg.header.stamp.to_sec())
                for o_topic, o_msg, _ in fault.mutate(ctx, topic, message(stamp), stamp)]
    return out


# 20 Hz images and 200 Hz IMU over 10 s, stamps in milliseconds to keep them exact.
STREAM = sorted([(faults.IMAGE_TOPIC, ms / 1000) for ms in range(0, 10000, 50)] +
                [(faults.IMU_TOPIC, ms / 1000) for ms in range(0, 10000, 5)],
                key=lambda m: m[1])


class FaultNamed(unittest.TestCase):
    def test_a_listed_fault_is_found_by_its_name(self):
        for f in faults.FAULTS:
            self.assertIs(faults.fault_named(f.name), f)

    def test_an_image_gap_of_any_length_drops_the_images_inside_it_and_nothing_else(self):
        gap = faults.fault_named("image_gap_3.5s")
        self.assertEqual(gap.duration, 3.5)
        self.assertEqual(gap.what, "no images for 3.5 s")
        out = kept(gap, 2.0, STREAM)
        expected = [(topic, t) for topic, t in STREAM
                    if topic == faults.IMU_TOPIC or not 2.0 <= t < 5.5]
        self.assertEqual(out, expected)
        self.assertEqual(len(STREAM) - len(out), 70)  # 3.5 s of 20 Hz images

    def test_an_imu_gap_drops_the_imu_inside_it(self):
        gap = faults.fault_named("imu_gap_0.25s")
        out = kept(gap, 4.0, STREAM)
        self.assertEqual(out, [(topic, t) for topic, t in STREAM
                               if topic == faults.IMAGE_TOPIC or not 4.0 <= t < 4.25])
        self.assertEqual(len(STREAM) - len(out), 50)

    def test_the_generated_1s_gap_drops_what_the_listed_one_drops(self):
        listed = faults.fault_named("image_gap_1s")
        made = faults.Fault("made", "", 1.0, faults.fault_named("image_gap_1.0s").mutate)
        self.assertEqual(kept(listed, 3.0, STREAM), kept(made, 3.0, STREAM))

    def test_malformed_or_unbounded_gaps_are_unknown(self):
        for bad in ["image_gap_s", "image_gap_3", "image_gap_0s", "image_gap_-1s",
                    "image_gap_nans", "image_gap_infs", "image_gap_61s", "camera_gap_3s",
                    "image_gap_threes", "gap_3s", ""]:
            self.assertIsNone(faults.fault_named(bad), bad)


class FaultsNamed(unittest.TestCase):
    def test_the_list_keeps_its_order_and_each_name_once(self):
        got = faults.faults_named("image_gap_5s,none,image_gap_2s,none")
        self.assertEqual([f.name for f in got], ["image_gap_5s", "none", "image_gap_2s"])

    def test_an_unknown_name_exits_naming_it_and_the_gap_pattern(self):
        with self.assertRaises(SystemExit) as e:
            faults.faults_named("none,image_gap_xs,flickr")
        msg = str(e.exception.code)
        self.assertIn("'image_gap_xs'", msg)
        self.assertIn("'flickr'", msg)
        self.assertNotIn("'none'", msg.split("known")[0])
        self.assertIn("image_gap_<S>s", msg)


if __name__ == "__main__":
    unittest.main()
