#!/usr/bin/python3
"""Image-to-odometry latency and dropped frames of a nodelet run, from its recorded
estimator status (scripts/ros_demo.sh --record-status writes <out>/run/status.bag).

    scripts/latency.py out/demo/run/status.bag [--json FILE]
"""
import argparse
import json
import statistics
import sys

from bench import percentile  # scripts/bench.py: linear interpolation over sorted values

FIELDS = ["state", "frames", "dropped_frames", "frontend_ms", "estimator_ms", "latency_ms"]


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("bag")
    ap.add_argument("--json", help="write the figures to this file")
    args = ap.parse_args()
    try:
        import rosbag
    except ImportError:
        sys.exit("latency.py: python3-rosbag is needed (./alvio build installs it)")
    statuses = []
    try:
        with rosbag.Bag(args.bag) as bag:
            for topic, m, _ in bag.read_messages():
                missing = [k for k in FIELDS if not hasattr(m, k)]
                if missing:  # another message type, or a status from before a field was added
                    sys.exit(f"latency.py: {args.bag}: {topic} ({m._type}) has no field "
                             f"{', '.join(missing)}")
                statuses.append(m)
    except Exception as e:  # rosbag raises several types for a bad file
        sys.exit(f"latency.py: {args.bag}: cannot read: {e}")
    if not statuses:
        sys.exit(f"latency.py: {args.bag}: no status messages")
    tracking = [m for m in statuses if m.state == "tracking"]
    latency = sorted(m.latency_ms for m in tracking if m.latency_ms >= 0)
    frontend = [m.frontend_ms for m in tracking]
    estimator = [m.estimator_ms for m in tracking]
    last = statuses[-1]
    out = {
        "frames": last.frames,
        "tracking_frames": len(tracking),
        "dropped_frames": last.dropped_frames,
        "latency_ms": {"median": percentile(latency, 50), "p95": percentile(latency, 95),
                       "max": max(latency) if latency else float("nan")},
        "frontend_ms_median": statistics.median(frontend) if frontend else float("nan"),
        "estimator_ms_median": statistics.median(estimator) if estimator else float("nan"),
    }
    print(f"{out['frames']} frames ({out['tracking_frames']} tracking), "
          f"{out['dropped_frames']} dropped; image-to-odometry latency median "
          f"{out['latency_ms']['median']:.1f} ms, p95 {out['latency_ms']['p95']:.1f} ms, "
          f"max {out['latency_ms']['max']:.1f} ms (front end {out['frontend_ms_median']:.1f} ms, "
          f"estimator {out['estimator_ms_median']:.1f} ms median)")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=2)


if __name__ == "__main__":
    main()
