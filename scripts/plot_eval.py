#!/usr/bin/env python3
"""Plots for `alvio eval --plot DIR`: reads DIR/ate_pairs.csv (aligned estimate,
ground truth and error per matched pose) and writes DIR/trajectory_top.png and
DIR/ate_over_time.png."""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt  # noqa: E402

COLUMNS = ["t", "est_x", "est_y", "gt_x", "gt_y", "error_m"]  # the columns plotted


def main(out_dir):
    path = os.path.join(out_dir, "ate_pairs.csv")
    try:
        with open(path) as f:
            reader = csv.DictReader(f)
            # An empty file has no header: it ends below as "no rows".
            missing = [k for k in COLUMNS if k not in (reader.fieldnames or COLUMNS)]
            if missing:
                sys.exit(f"{path}: no column {', '.join(missing)}")
            rows = [[float(r[k]) for k in COLUMNS] for r in reader]
    except OSError as e:
        sys.exit(f"{path}: {e.strerror}")
    except (TypeError, ValueError) as e:  # TypeError: a short row
        sys.exit(f"{path} line {reader.line_num}: not a number ({e})")
    if not rows:
        sys.exit(f"{path}: no rows")
    col = {k: [r[i] for r in rows] for i, k in enumerate(COLUMNS)}
    t0 = col["t"][0]
    t = [x - t0 for x in col["t"]]

    fig, ax = plt.subplots(figsize=(7, 6))
    ax.plot(col["gt_x"], col["gt_y"], "k-", lw=1.2, label="ground truth")
    ax.plot(col["est_x"], col["est_y"], "r-", lw=1.0, label="estimate (aligned)")
    ax.plot(col["gt_x"][0], col["gt_y"][0], "go", label="start")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    ax.legend()
    ax.set_title("Trajectory, top view")
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "trajectory_top.png"), dpi=120)
    plt.close(fig)

    err = col["error_m"]
    rmse = (sum(e * e for e in err) / len(err)) ** 0.5
    fig, ax = plt.subplots(figsize=(8, 3.5))
    ax.plot(t, err, "b-", lw=1.0)
    ax.axhline(rmse, color="r", ls="--", label=f"RMSE {rmse:.3f} m")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("translation error [m]")
    ax.grid(True, alpha=0.3)
    ax.legend()
    ax.set_title("Absolute trajectory error over time")
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "ate_over_time.png"), dpi=120)
    plt.close(fig)
    print(f"plots written to {out_dir}")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: plot_eval.py DIR")
    main(sys.argv[1])
