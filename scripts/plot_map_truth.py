#!/usr/bin/env python3
"""Top view of line maps against the simulator's true scene, one panel per map.

  scripts/plot_map_truth.py PER_LINE.csv [PER_LINE.csv ...] --out map_truth.png
      [--titles "before,after"] [--sequence SEQ_DIR]

Each PER_LINE.csv is written by `alvio_map_truth --per-line FILE RUN SEQ` (endpoints in the
true world). A line is green where it lies within the tolerance of a true edge (geometry or
texture edges: the precision_with_texture_edges column) and red where not, so that floating
and shifted lines stand out. With --sequence, the scene's geometry edges (scene_edges.csv) are
drawn in grey underneath.
"""
import argparse
import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402

ENDPOINTS = ["x0", "y0", "x1", "y1"]
NUMBERS = ENDPOINTS + ["precision_with_texture_edges", "length_m"]  # the columns plotted


def read_lines(path):
    try:
        with open(path) as f:
            reader = csv.DictReader(f)
            columns = reader.fieldnames or []  # none in an empty file
            missing = [k for k in ENDPOINTS + ["precision_with_texture_edges"] if k not in columns]
            if missing:
                sys.exit(f"plot_map_truth: {path} has no endpoint or precision_with_texture_edges "
                         f"columns (no {', '.join(missing)}; write it with a current "
                         "alvio_map_truth --per-line)")
            if "length_m" not in columns:
                sys.exit(f"plot_map_truth: {path} has no length_m column (write it with "
                         "alvio_map_truth --per-line)")
            return [{k: float(r[k]) for k in NUMBERS} for r in reader]
    except OSError as e:
        sys.exit(f"plot_map_truth: {path}: {e.strerror}")
    except (TypeError, ValueError) as e:  # TypeError: a short row
        sys.exit(f"plot_map_truth: {path} line {reader.line_num}: not a number ({e})")


def read_scene_edges(sequence):
    path = Path(sequence) / "scene_edges.csv"
    if not path.exists():
        sys.exit(f"plot_map_truth: {path} does not exist (a simulator sequence has one)")
    edges = []
    with open(path) as f:
        for number, row in enumerate(f, 1):
            if row.startswith("#"):
                continue
            v = row.strip().split(",")
            if len(v) < 6:
                sys.exit(f"plot_map_truth: {path} line {number} has {len(v)} columns, not "
                         "id,ax,ay,az,bx,by,...")
            try:
                edges.append([(float(v[1]), float(v[2])), (float(v[4]), float(v[5]))])
            except ValueError as e:
                sys.exit(f"plot_map_truth: {path} line {number}: not a number ({e})")
    return edges


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("per_line", nargs="+", help="alvio_map_truth --per-line CSV files")
    ap.add_argument("--out", required=True, help="PNG file")
    ap.add_argument("--titles", help="comma-separated panel titles [the file names]")
    ap.add_argument("--sequence", help="simulator sequence folder: draw its scene edges")
    a = ap.parse_args()
    titles = a.titles.split(",") if a.titles else [Path(p).name for p in a.per_line]
    if len(titles) != len(a.per_line):
        sys.exit("plot_map_truth: give one title per file")
    scene = read_scene_edges(a.sequence) if a.sequence else []
    fig, axes = plt.subplots(1, len(a.per_line), figsize=(6.5 * len(a.per_line), 6), squeeze=False,
                             sharex=True, sharey=True)
    for ax, path, title in zip(axes[0], a.per_line, titles):
        rows = read_lines(path)
        if scene:
            ax.add_collection(LineCollection(scene, colors="0.8", linewidths=0.5))
        segments = [[(r["x0"], r["y0"]), (r["x1"], r["y1"])] for r in rows]
        good = [r["precision_with_texture_edges"] for r in rows]
        ax.add_collection(LineCollection(segments, colors=[(1 - g, 0.6 * g, 0) for g in good],
                                         linewidths=1.2))
        length = sum(r["length_m"] for r in rows)
        on_edge = sum(r["length_m"] * g for r, g in zip(rows, good))
        ax.set_title(f"{title}: {len(rows)} lines, {length:.0f} m, "
                     f"{100 * on_edge / max(length, 1e-9):.1f} % on a true edge")
        ax.set_aspect("equal")
        ax.autoscale()
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
    fig.tight_layout()
    fig.savefig(a.out, dpi=110)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
