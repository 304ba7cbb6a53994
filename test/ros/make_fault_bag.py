#!/usr/bin/env python3
"""One fault of scripts/faults.py written into a copy of a bag, for the ROS tests.

  make_fault_bag.py CLEAN_BAG FAULT SECONDS OUT_BAG

SECONDS: when the fault starts, after the bag's first image.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))
import faults  # noqa: E402  (scripts/faults.py)


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    clean, name, seconds, out = sys.argv[1], sys.argv[2], float(sys.argv[3]), sys.argv[4]
    fault = faults.fault_named(name)
    if fault is None or fault.mutate is None:
        sys.exit(f"make_fault_bag.py: no fault {name!r} that rewrites a bag; known: "
                 f"{[f.name for f in faults.FAULTS if f.mutate is not None]}")
    import rosbag  # from Debian's ROS packages
    with rosbag.Bag(clean) as bag:
        first = next(bag.read_messages(topics=[faults.IMAGE_TOPIC]), None)
    if first is None:
        sys.exit(f"make_fault_bag.py: {clean} has no {faults.IMAGE_TOPIC}")
    faults.write_faulted_bag(clean, fault, faults.stamp_s(first.message) + seconds, out)


if __name__ == "__main__":
    main()
