#!/usr/bin/env python3
"""alvio starts: does the VIO start well mid-way, as on a robot switched on while it moves?

Runs `alvio run --start T --max-frames N` from each start time T on one dataset (EuRoC folder
or bag with ground truth) and reports, per start: when it initialised after the start, the
scale and gravity error of the initialised window, and the ATE of the segment. A start
"diverges" when its ATE exceeds --diverged-m. Writes OUT/starts.md, OUT/starts.json and
OUT/starts.png (ATE and scale error against the start time).

  ./alvio starts --dataset out/demo/sim --starts 2:20:1 --out out/starts
  ./alvio starts --dataset DIR --starts 10,20,30 --frames 400 \\
      --set estimator.init_min_parallax_px=60
"""
import argparse
import json
import statistics
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from bench import fmt  # scripts/bench.py: "–" for a missing figure


def log(msg):
    print(f"\033[1m[alvio starts]\033[0m {msg}", file=sys.stderr, flush=True)


def parse_starts(text):
    """'2,4,7.5' or 'first:last:step' (inclusive) -> sorted start times in seconds."""
    if ":" in text:
        parts = text.split(":")
        if len(parts) != 3:
            raise ValueError(f"--starts {text}: use first:last:step")
        first, last, step = (float(p) for p in parts)
        if step <= 0 or last < first:
            raise ValueError(f"--starts {text}: step must be > 0 and last >= first")
        n = int(round((last - first) / step)) + 1
        return [round(first + i * step, 6) for i in range(n)]
    values = sorted(float(v) for v in text.split(",") if v.strip())
    if not values or values[0] < 0:
        raise ValueError(f"--starts {text}: give start times >= 0 s")
    return values


def run_one(args, start):
    out = Path(args.out) / f"start_{start:g}"
    cmd = [args.bin, "--dataset", args.dataset, "--out", str(out), "--start", f"{start:g}",
           "--max-frames", str(args.frames), "--no-log", "--quiet"]
    if args.config:
        cmd += ["--config", args.config]
    for assignment in args.set or []:
        cmd += ["--set", assignment]
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "run.log", "w") as logf:
        code = subprocess.run(cmd, stdout=logf, stderr=subprocess.STDOUT).returncode
    row = {"start_s": start, "exit": code}
    summary = out / "summary.json"
    if code == 0 and summary.exists():
        s = json.loads(summary.read_text())
        row["ate_m"] = s.get("ate_rmse_m")
        row["poses"] = s.get("poses")
        init = s.get("initialization") or {}
        row["init_after_s"] = init.get("since_first_motion_s")
        row["scale_error"] = init.get("scale_error")
        row["gravity_error_deg"] = init.get("gravity_error_deg")
    return row


def summarize(rows, diverged_m):
    """Counts and medians over the starts (a start without ATE counts as failed)."""
    ates = [r["ate_m"] for r in rows if r.get("ate_m") is not None]
    scales = [r["scale_error"] for r in rows if r.get("scale_error") is not None]
    failed = sum(1 for r in rows if r.get("ate_m") is None)
    diverged = sum(1 for a in ates if a > diverged_m)
    kept = [a for a in ates if a <= diverged_m]
    return {
        "starts": len(rows),
        "failed": failed,
        "diverged": diverged,
        "median_ate_m": statistics.median(ates) if ates else None,
        "mean_ate_not_diverged_m": statistics.mean(kept) if kept else None,
        "median_scale_error": statistics.median(scales) if scales else None,
        "max_scale_error": max(scales) if scales else None,
    }


def table(rows, summary, diverged_m):
    lines = ["| start (s) | initialised after (s) | scale error | gravity error (deg) | ATE (m) |",
             "|---|---|---|---|---|"]
    for r in rows:
        flag = " (diverged)" if r.get("ate_m") is not None and r["ate_m"] > diverged_m else ""
        if r.get("exit"):
            flag = f" (exit {r['exit']})"
        scale = None if r.get("scale_error") is None else 100 * r["scale_error"]
        lines.append(f"| {r['start_s']:g} | {fmt(r.get('init_after_s'), '.2f')} | "
                     f"{fmt(scale, '.1f')} % | {fmt(r.get('gravity_error_deg'), '.2f')} | "
                     f"{fmt(r.get('ate_m'), '.3f')}{flag} |")
    s = summary
    scale_med = None if s["median_scale_error"] is None else 100 * s["median_scale_error"]
    lines.append("")
    lines.append(f"{s['starts']} starts: {s['diverged']} diverged (ATE > {diverged_m:g} m), "
                 f"{s['failed']} failed; median ATE {fmt(s['median_ate_m'], '.3f')} m, "
                 f"median scale error at initialisation {fmt(scale_med, '.1f')} %.")
    return "\n".join(lines) + "\n"


def plot(rows, path, diverged_m):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a, b) = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
    t = [r["start_s"] for r in rows if r.get("ate_m") is not None]
    a.semilogy(t, [r["ate_m"] for r in rows if r.get("ate_m") is not None], "o-")
    a.axhline(diverged_m, color="r", ls="--", lw=0.8, label=f"diverged above {diverged_m:g} m")
    a.set_ylabel("segment ATE (m)")
    a.legend(loc="upper left", fontsize=8)
    ts = [r["start_s"] for r in rows if r.get("scale_error") is not None]
    b.plot(ts, [100 * r["scale_error"] for r in rows if r.get("scale_error") is not None], "o-")
    b.set_ylabel("scale error at init (%)")
    b.set_xlabel("start time (s into the dataset)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", required=True, help="alvio_run")
    ap.add_argument("--dataset", required=True, help="EuRoC folder or bag with ground truth")
    ap.add_argument("--starts", required=True, help="'2,4,6' or 'first:last:step' (s)")
    ap.add_argument("--frames", type=int, default=400, help="images per run after its start")
    ap.add_argument("--config", help="alvio configuration (default: alvio run's)")
    ap.add_argument("--set", action="append", help="key=value override, may be repeated")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--diverged-m", type=float, default=0.5)
    ap.add_argument("--out", required=True)
    ap.add_argument("--no-plot", action="store_true")
    args = ap.parse_args()
    try:
        starts = parse_starts(args.starts)
    except ValueError as e:
        sys.exit(f"alvio starts: {e}")
    if not Path(args.dataset).exists():
        sys.exit(f"alvio starts: --dataset {args.dataset} does not exist")
    Path(args.out).mkdir(parents=True, exist_ok=True)
    log(f"{len(starts)} starts on {args.dataset}, {args.frames} images each, {args.jobs} at a time")
    rows = []
    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        for row in pool.map(lambda s: run_one(args, s), starts):
            rows.append(row)
            scale = None if row.get("scale_error") is None else 100 * row["scale_error"]
            log(f"start {row['start_s']:g} s: ATE {fmt(row.get('ate_m'), '.3f')} m, scale error "
                f"{fmt(scale, '.1f')} %")
    summary = summarize(rows, args.diverged_m)
    text = table(rows, summary, args.diverged_m)
    (Path(args.out) / "starts.md").write_text(text)
    (Path(args.out) / "starts.json").write_text(
        json.dumps({"rows": rows, "summary": summary}, indent=1))
    if not args.no_plot:
        plot(rows, Path(args.out) / "starts.png", args.diverged_m)
    print(text)
    log(f"written: {args.out}/starts.md, starts.json" + ("" if args.no_plot else ", starts.png"))


if __name__ == "__main__":
    main()
