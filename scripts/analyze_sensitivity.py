#!/usr/bin/env python3
"""Sensitivity analysis of the feature trackers (ALVIO, Sec. 3), for `alvio analyze`.

Reads the CSV records written by `alvio run --analysis DIR` (one or more DIRs, e.g. the
whole simulator benchmark set) and, for points and lines separately:
  * fits a polynomial surface of track length over the image position (Fig. 5) and plots
    the raw data beside the fitted surface;
  * plots the mean track length per window against illumination (Fig. 6) and motion (Fig. 7);
  * derives the selection threshold: features whose fitted expected track length is below
    the level (the given quantile of the fitted values at the observed feature positions)
    are left out of the optimisation. The surfaces and levels are written to
    OUT/selection_surfaces.yaml, which the estimator reads (estimator.selection.surfaces_file).
"""
import argparse
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")  # no display
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import yaml  # noqa: E402

# Records written before alvio run saved image_size.yaml came from EuRoC's cam0.
EUROC_SIZE = (752, 480)


def read_csv(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    if not rows:
        return {}
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def load(dirs, name):
    parts = [read_csv(os.path.join(d, name)) for d in dirs]
    parts = [p for p in parts if p]
    if not parts:
        return {}
    return {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}


def image_size(dirs):
    """The (width, height) the feature positions of all DIRs refer to; they must agree."""
    sizes = {}
    for d in dirs:
        path = os.path.join(d, "image_size.yaml")
        if not os.path.isfile(path):
            print(f"alvio analyze: {d} has no image_size.yaml; assuming EuRoC's "
                  f"{EUROC_SIZE[0]}x{EUROC_SIZE[1]}", file=sys.stderr)
            sizes[d] = EUROC_SIZE
            continue
        with open(path) as f:
            doc = yaml.safe_load(f) or {}
        try:
            sizes[d] = (int(doc["width"]), int(doc["height"]))
        except (KeyError, TypeError, ValueError):
            sys.exit(f"alvio analyze: error: {path} needs integer width and height")
        if min(sizes[d]) <= 0:
            sys.exit(f"alvio analyze: error: {path}: width and height must be positive")
    if len(set(sizes.values())) > 1:
        listing = ", ".join(f"{d} {w}x{h}" for d, (w, h) in sizes.items())
        sys.exit("alvio analyze: error: the records come from different image sizes "
                 f"({listing}); analyse each camera on its own")
    return next(iter(sizes.values()))


def monomials(u, v, degree):
    """Columns u^i v^j with i + j <= degree, in a fixed order (the estimator's order)."""
    cols = []
    for total in range(degree + 1):
        for j in range(total + 1):
            cols.append(u ** (total - j) * v ** j)
    return np.stack(cols, axis=1)


def normalised(x, y, size):
    # The estimator evaluates the surface at (x / width - 0.5, y / height - 0.5).
    return x / size[0] - 0.5, y / size[1] - 0.5


def fit_surface(x, y, z, degree, size):
    u, v = normalised(x, y, size)
    A = monomials(u, v, degree)
    coeffs, *_ = np.linalg.lstsq(A, z, rcond=None)
    pred = A @ coeffs
    ss_res = float(np.sum((z - pred) ** 2))
    ss_tot = float(np.sum((z - z.mean()) ** 2)) or 1.0
    return coeffs, pred, 1.0 - ss_res / ss_tot


def plot_surface(kind, x, y, z, coeffs, degree, level, size, out):
    width, height = size
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.2))
    # Raw data: mean track length per 16 px cell.
    bins = (max(1, width // 16), max(1, height // 16))
    s, _, _ = np.histogram2d(x, y, bins=bins, range=[[0, width], [0, height]], weights=z)
    n, _, _ = np.histogram2d(x, y, bins=bins, range=[[0, width], [0, height]])
    with np.errstate(invalid="ignore"):
        mean = s / n
    im = axes[0].imshow(mean.T, origin="upper", extent=[0, width, height, 0], cmap="viridis")
    axes[0].set_title(f"{kind}: mean track length (raw, {len(z)} features)")
    fig.colorbar(im, ax=axes[0], label="frames tracked in the window")
    gx, gy = np.meshgrid(np.linspace(0, width, 188), np.linspace(0, height, 120))
    gu, gv = normalised(gx.ravel(), gy.ravel(), size)
    surf = (monomials(gu, gv, degree) @ coeffs).reshape(gx.shape)
    im = axes[1].imshow(surf, origin="upper", extent=[0, width, height, 0], cmap="viridis")
    axes[1].contour(gx, gy, surf, levels=[level], colors="red", linewidths=1.5)
    axes[1].set_title(f"{kind}: fitted surface (degree {degree}); red: selection level {level:.2f}")
    fig.colorbar(im, ax=axes[1], label="expected frames tracked")
    for ax in axes:
        ax.set_xlabel("x [px]")
        ax.set_ylabel("y [px]")
    fig.tight_layout()
    path = os.path.join(out, f"{kind}_track_surface.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_factor(windows, column, label, out, name):
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.8))
    for ax, kind, track in ((axes[0], "points", "mean_point_track"),
                            (axes[1], "lines", "mean_line_track")):
        x, y = windows[column], windows[track]
        ok = y > 0
        ax.scatter(x[ok], y[ok], s=6, alpha=0.35)
        if ok.sum() > 10:
            edges = np.quantile(x[ok], np.linspace(0, 1, 11))
            idx = np.clip(np.digitize(x[ok], edges[1:-1]), 0, 9)
            centres = [x[ok][idx == k].mean() for k in range(10) if np.any(idx == k)]
            means = [y[ok][idx == k].mean() for k in range(10) if np.any(idx == k)]
            ax.plot(centres, means, "r-o", lw=2, label="binned mean")
            ax.legend()
        ax.set_xlabel(label)
        ax.set_ylabel("mean frames tracked")
        ax.set_title(f"{kind}")
        ax.grid(True, alpha=0.3)
    fig.tight_layout()
    path = os.path.join(out, name)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dirs", nargs="+", help="folders written by alvio run --analysis")
    ap.add_argument("--out", required=True, help="output folder (plots, selection_surfaces.yaml)")
    ap.add_argument("--degree", type=int, default=3, help="polynomial degree of the surfaces")
    ap.add_argument("--point-quantile", type=float, default=0.5,
                    help="drop points whose expected track length is below this quantile")
    ap.add_argument("--line-quantile", type=float, default=0.4,
                    help="drop lines whose expected track length is below this quantile")
    args = ap.parse_args()
    for d in args.dirs:
        if not os.path.isfile(os.path.join(d, "windows.csv")):
            sys.exit(f"alvio analyze: error: {d} has no windows.csv (run alvio run --analysis {d})")
    size = image_size(args.dirs)
    os.makedirs(args.out, exist_ok=True)

    surfaces = {}
    report = []
    for kind, quantile in (("points", args.point_quantile), ("lines", args.line_quantile)):
        data = load(args.dirs, f"{kind}.csv")
        if not data or len(data["tracked_frames"]) < 50:
            report.append(f"{kind}: too few records, no surface")
            continue
        x, y, z = data["x_px"], data["y_px"], data["tracked_frames"]
        coeffs, pred, r2 = fit_surface(x, y, z, args.degree, size)
        level = float(np.quantile(pred, quantile))
        kept = float(np.mean(pred >= level))
        surfaces[kind] = (coeffs, level)
        png = plot_surface(kind, x, y, z, coeffs, args.degree, level, size, args.out)
        report.append(f"{kind}: {len(z)} features, mean track {z.mean():.2f} frames, "
                      f"surface R^2 {r2:.3f}, "
                      f"level {level:.3f} (quantile {quantile}) keeps {100 * kept:.1f} % -> {png}")

    windows = load(args.dirs, "windows.csv")
    if windows:
        report.append("illumination: " + plot_factor(windows, "mean_intensity",
                                                     "mean intensity of the window",
                                                     args.out, "track_vs_illumination.png"))
        report.append("motion: " + plot_factor(windows, "motion_m",
                                               "motion |dx|+|dy|+|dz| over the window [m]",
                                               args.out, "track_vs_motion.png"))

    path = os.path.join(args.out, "selection_surfaces.yaml")
    with open(path, "w") as f:
        f.write("# Written by alvio analyze from: " + ", ".join(args.dirs) + "\n")
        f.write("# Expected track length over the image, evaluated at "
                "(x/width - 0.5, y/height - 0.5) with\n")
        f.write("# monomials u^i v^j (i + j <= degree) in order of total degree, "
                "then increasing j.\n")
        f.write(f"width: {size[0]}\nheight: {size[1]}\ndegree: {args.degree}\n")
        for kind, (coeffs, level) in surfaces.items():
            f.write(f"{kind}:\n  min_expected_track: {level:.6f}\n")
            f.write("  coefficients: [" + ", ".join(f"{c:.8g}" for c in coeffs) + "]\n")
    report.append(f"selection surfaces: {path}")
    print("\n".join(report))


if __name__ == "__main__":
    main()
