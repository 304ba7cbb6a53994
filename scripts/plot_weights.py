#!/usr/bin/env python3
"""Point and line weights over time (the paper's Fig. 8) from a run's frame_stats.csv.

  ./alvio plot-weights RUN_DIR [--out weights.png]

Top: w_p and w_l (the residual weights of points and lines, w_p + w_l = 1) and the alpha
chosen per frame; bottom: the features used in the optimisation per frame. The weights are
logged whether or not estimator.selection.adaptive_weighting applies them to the residuals.
"""
import argparse
import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt  # noqa: E402

COLUMNS = ["t", "w_p", "w_l", "alpha", "points_used", "lines_used"]  # the columns plotted


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run", help="an alvio run folder (with frame_stats.csv)")
    ap.add_argument("--out", help="PNG file [RUN/weights.png]")
    a = ap.parse_args()
    stats = Path(a.run) / "frame_stats.csv"
    if not stats.exists():
        sys.exit(f"plot-weights: {stats} does not exist (alvio run writes it)")
    with open(stats) as f:
        reader = csv.DictReader(f)
        missing = [k for k in COLUMNS if k not in (reader.fieldnames or [])]
        if missing:
            sys.exit(f"plot-weights: {stats} has no column {', '.join(missing)}")
        rows = []
        try:
            for r in reader:  # frames before the first optimisation have empty weights
                if float(r["w_p"] or 0) + float(r["w_l"] or 0) > 0:
                    rows.append({k: float(r[k]) for k in COLUMNS})
        except (TypeError, ValueError) as e:  # TypeError: a short row
            sys.exit(f"plot-weights: {stats} line {reader.line_num}: not a number ({e})")
    if not rows:
        sys.exit(f"plot-weights: no optimised frames in {stats}")
    t0 = rows[0]["t"]
    t = [r["t"] - t0 for r in rows]
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
    ax1.plot(t, [r["w_p"] for r in rows], label="w_p (points)", lw=1)
    ax1.plot(t, [r["w_l"] for r in rows], label="w_l (lines)", lw=1)
    ax1.set_ylabel("weight")
    ax1.set_ylim(0, 1)
    ax1b = ax1.twinx()
    ax1b.plot(t, [r["alpha"] for r in rows], color="grey", lw=0.6, alpha=0.6, label="alpha")
    ax1b.set_ylabel("alpha")
    ax1.legend(loc="upper left")
    run = Path(a.run).resolve()
    ax1.set_title(f"adaptive point/line weights: {run.parent.name}/{run.name}")
    ax2.plot(t, [r["points_used"] for r in rows], label="points used", lw=1)
    ax2.plot(t, [r["lines_used"] for r in rows], label="lines used", lw=1)
    ax2.set_xlabel("time since initialisation [s]")
    ax2.set_ylabel("features per frame")
    ax2.legend(loc="upper left")
    fig.tight_layout()
    out = Path(a.out) if a.out else Path(a.run) / "weights.png"
    fig.savefig(out, dpi=110)
    print(f"weights plot: {out}")


if __name__ == "__main__":
    main()
