#!/usr/bin/env python3
"""alvio bench / alvio ablation: run the offline runner over the simulator's benchmark set
and print markdown tables of accuracy, per-stage time, real-time factor and peak memory.

  ./alvio bench [--sequences sim_MH_01,sim_MH_05] [--variants points,lines] [--out DIR]
  ./alvio bench --compare lines "fast=--set estimator.max_iterations=4"
  ./alvio ablation --dataset sim_MH_05
  ./alvio bench --compare it8 it5 --repeats 3   # each run 3x, a noise setting nudged by 0.07 %

A variant is a name from VARIANTS or "name=<alvio run arguments>"; "--bin PATH" among the
arguments runs another build's alvio_run (to compare builds). Runs are single-threaded and
deterministic; --jobs runs several at once (times are then measured under load: compare
variants only within one invocation, where they are interleaved).

One run per sequence and variant cannot tell a small change from chance: nudging a noise
setting by 0.07 % has moved single-run ATE by up to 15 %. --repeats N runs each N times, the
k-th with --perturb's key (estimator.point_sigma_px) scaled by 1, 1 + s, 1 - s, 1 + 2s, ...
(s = --perturb-step, 7e-4), and the tables give the mean ATE with its range and the median
of the per-run times.

A nudge samples little of a run's chaos; other noise seeds sample more (on sim_MH_05 seeds
1, 2 and 3 gave 0.080, 0.080 and 0.098 m). --seeds 1,2,3 runs every sequence on each seed's
rendering: seed 1 is --data's set, seed S the copy in DATA/seedS (alvio sim --benchmark
DATA/seedS --seed S, which --render makes). The tables then give the mean over the seeds (and
repeats) with its range, and --compare the ratio of each seed's pair.

This machine's speed drifts by up to 1.4x within minutes, more than a small speed change.
--side-by-side (with --compare) starts each pair of runs (same sequence, seed and repeat) at
the same moment, one variant on each of two cores (swapped from pair to pair), so that a drift
slows both alike; the compare table then ends with the pooled ratio of the pairs' median frame
times. The two runs share the memory bus and caches, so compare its times only with each other.
"""
import argparse
import csv
import json
import math
import os
import shlex
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parent.parent
SURFACES = ROOT / "config" / "selection_surfaces.yaml"
SEL = "estimator.selection."

# Named variants: alvio run arguments.
VARIANTS = {
    "points": "--no-lines",
    "lines": "",
    "descriptor": "--line-tracker descriptor",
    "lines-analysis": "--analysis {out}/analysis",  # records for ./alvio analyze
    "equal-weights": f"--set {SEL}adaptive_weighting=false",
    "adaptive": f"--set {SEL}adaptive_weighting=true",
    "sel-none": f"--set {SEL}adaptive_weighting=true",
    "sel-lines": f"--set {SEL}adaptive_weighting=true,{SEL}lines=true,"
    f"{SEL}surfaces_file={SURFACES}",
    "sel-points": f"--set {SEL}adaptive_weighting=true,{SEL}points=true,"
    f"{SEL}surfaces_file={SURFACES}",
    "sel-both": f"--set {SEL}adaptive_weighting=true,{SEL}points=true,{SEL}lines=true,"
    f"{SEL}surfaces_file={SURFACES}",
}
ABLATION = [("no selection", "sel-none"), ("line selection", "sel-lines"),
            ("point selection", "sel-points"), ("both", "sel-both")]
DEFAULT_SEQUENCES = ["sim_MH_01", "sim_MH_02", "sim_MH_03", "sim_MH_05", "sim_MH_03_realimu",
                     "sim_MH_05_realimu", "sim_MH_05_lowtex", "sim_MH_05_dim",
                     "sim_corridor_lowtex"]


def log(msg):
    print(f"\033[1m[alvio bench]\033[0m {msg}", file=sys.stderr, flush=True)


def parse_variant(spec):
    if "=" in spec and spec.split("=", 1)[0] not in VARIANTS and not spec.startswith("-"):
        name, args = spec.split("=", 1)
    elif spec in VARIANTS:
        name, args = spec, VARIANTS[spec]
    else:
        sys.exit(f"alvio bench: unknown variant '{spec}' (known: {', '.join(VARIANTS)}, "
                 "or name=<alvio run arguments>)")
    return name, shlex.split(args)


def program_env(program):
    """The environment to start one of alvio's programs in: a frozen build's
    (scripts/freeze_build.sh: OUT/bin/<program>) needs its own libraries, not build/'s."""
    env = dict(os.environ)
    folder = Path(program).resolve().parent
    if folder.name == "bin" and (folder.parent / "lib").is_dir():
        env["LD_LIBRARY_PATH"] = str(folder.parent / "lib") + ":" + env.get("LD_LIBRARY_PATH", "")
    return env


class Run:
    def __init__(self, seq, data, variant, args, out, binary, max_frames, repeat=0, seed=1,
                 opencv_threads=1):
        self.seq, self.variant, self.out, self.repeat, self.seed = seq, variant, out, repeat, seed
        argv = [x.replace("{out}", str(out)) for x in args]  # "{out}": this run's folder
        if "--bin" in argv:
            i = argv.index("--bin")
            binary = argv[i + 1]
            del argv[i:i + 2]
        self.cmd = [binary, "--dataset", str(data), "--out", str(out), "--quiet", "--no-log"] + argv
        if max_frames > 0:
            self.cmd += ["--max-frames", str(max_frames)]
        if opencv_threads > 0:
            self.cmd += ["--opencv-threads", str(opencv_threads)]
        self.proc = None
        self.rss_mb = None
        self.wall_s = None
        self.rc = None

    def start(self, cpu=None):
        """Starts the run; on core `cpu` alone when given."""
        self.out.mkdir(parents=True, exist_ok=True)
        self.log = open(self.out / "run.log", "w")
        self.t0 = time.monotonic()
        pin = None if cpu is None else (lambda: os.sched_setaffinity(0, {cpu}))
        self.proc = subprocess.Popen(self.cmd, stdout=self.log, stderr=subprocess.STDOUT,
                                     env=program_env(self.cmd[0]), preexec_fn=pin)

    def reap(self, status, rusage):
        self.wall_s = time.monotonic() - self.t0
        self.rc = os.waitstatus_to_exitcode(status)
        self.rss_mb = rusage.ru_maxrss / 1024.0
        self.cpu_s = rusage.ru_utime + rusage.ru_stime
        self.log.close()

    def result(self):
        r = {"sequence": self.seq, "variant": self.variant, "repeat": self.repeat,
             "seed": self.seed, "rc": self.rc,
             "wall_s": self.wall_s, "cpu_s": self.cpu_s, "peak_rss_mb": self.rss_mb}
        summary = self.out / "summary.json"
        if summary.exists():
            s = json.loads(summary.read_text())
            r.update(ate=s.get("ate_rmse_m"), resets=s.get("resets"), frames=s.get("frames"),
                     poses=s.get("poses"), init=s.get("initialization"), timing=s.get("timing_ms"))
        stats = self.out / "frame_stats.csv"
        if stats.exists():
            with open(stats) as f:
                rows = [row for row in csv.DictReader(f) if float(row["points_used"] or 0) > 0
                        or float(row["lines_used"] or 0) > 0]
            if rows:
                r["points_used"] = statistics.mean(float(x["points_used"]) for x in rows)
                r["lines_used"] = statistics.mean(float(x["lines_used"]) for x in rows)
        timing = self.out / "timing.csv"
        if timing.exists():
            with open(timing) as f:
                rows = list(csv.DictReader(f))
            if rows:
                r["duration_s"] = float(rows[-1]["t"]) - float(rows[0]["t"])
                # Optimisation as the paper counts it: solve plus marginalisation, per frame.
                # A run that never initialised has no optimisation columns.
                if "optimization_ms" in rows[0] and "marginalization_ms" in rows[0]:
                    opt = sorted(float(x["optimization_ms"]) + float(x["marginalization_ms"])
                                 for x in rows)
                    r["opt_total_median"] = percentile(opt, 50)
                    r["opt_total_p95"] = percentile(opt, 95)
                # Front ends as per-frame sums: with detect_every > 1 the detection stages
                # alternate between frames, and a sum of their medians would hide that.
                for key, stages in FRONT_ENDS.items():
                    if all(st + "_ms" in rows[0] for st in stages):
                        v = [sum(float(x[st + "_ms"]) for st in stages) for x in rows]
                        r[key + "_median"] = percentile(sorted(v), 50)
                        r[key + "_mean"] = statistics.mean(v)
        return r


FRONT_ENDS = {"points_front_end": ("preprocess", "point_tracking", "point_detection"),
              "lines_front_end": ("line_detection", "line_tracking")}


def is_real_imu(sequence):
    return sequence.endswith("_realimu")


def percentile(values, q):
    if not values:
        return float("nan")
    k = (len(values) - 1) * q / 100.0
    lo = int(k)
    hi = min(lo + 1, len(values) - 1)
    return values[lo] + (values[hi] - values[lo]) * (k - lo)


def config_value(path, key, depth=0):
    """A dotted key's value in a configuration file, following its `base:` chain."""
    if depth > 8:
        sys.exit(f"alvio bench: error: {path}: too many nested base: files")
    with open(path) as f:
        doc = yaml.safe_load(f) or {}
    node = doc
    for part in key.split("."):
        if not isinstance(node, dict) or part not in node:
            node = None
            break
        node = node[part]
    if node is not None:
        return node
    if "base" in doc:
        return config_value(Path(path).parent / doc["base"], key, depth + 1)
    sys.exit(f"alvio bench: error: --perturb key '{key}' is not in {path}")


def split_assignments(text):
    """`--set` assignments split at the commas between them, not inside [...] or quotes
    (as alvio run reads them: camera.resolution=[640,480] is one assignment)."""
    parts, depth, quote, start = [], 0, None, 0
    for i, c in enumerate(text):
        if quote:
            quote = None if c == quote else quote
        elif c in "'\"":
            quote = c
        elif c in "[{":
            depth += 1
        elif c in "]}":
            depth -= 1
        elif c == "," and depth == 0:
            parts.append(text[start:i])
            start = i + 1
    parts.append(text[start:])
    return parts


def perturbed_args(args, key, step, repeat):
    """The run's arguments with `key` scaled for the repeat-th run (none for the first)."""
    if repeat == 0:
        return args
    base = None
    for i, a in enumerate(args[:-1]):  # the variant's own --set of the key wins over the file
        if a == "--set":
            for assignment in split_assignments(args[i + 1]):
                if assignment.startswith(key + "="):
                    base = assignment.split("=", 1)[1]
    if base is None:
        base = config_value(args[args.index("--config") + 1], key)
    try:
        base = float(base)
    except (TypeError, ValueError):
        sys.exit(f"alvio bench: error: --perturb key '{key}' is '{base}', not a number")
    factor = 1 + step * ((repeat + 1) // 2) * (1 if repeat % 2 else -1)
    return args + ["--set", f"{key}={base * factor:.9g}"]


def aggregate(results):
    """One result per sequence and variant: the mean ATE (with its range over the repeats)
    and the median of every per-run figure."""
    groups = {}
    for r in results:
        groups.setdefault((r["sequence"], r["variant"]), []).append(r)
    out = []
    for runs in groups.values():
        if len(runs) == 1:
            out.append(runs[0])
            continue
        a = dict(runs[0])
        a["repeats"] = len(runs)
        a["rc"] = next((r["rc"] for r in runs if r["rc"] != 0), 0)
        ates = [r["ate"] for r in runs if r.get("ate") is not None]
        a["ate"] = statistics.mean(ates) if len(ates) == len(runs) else None
        a["ate_min"], a["ate_max"] = (min(ates), max(ates)) if ates else (None, None)
        a["resets"] = max((r.get("resets") or 0) for r in runs)
        for k, v in runs[0].items():
            if k in ("ate", "resets", "repeat", "seed", "rc") or not isinstance(v, (int, float)):
                continue
            vals = [r[k] for r in runs if isinstance(r.get(k), (int, float))]
            a[k] = statistics.median(vals) if len(vals) == len(runs) else None
        # A repeat without timing leaves the medians undefined: none, not the first run's.
        a["timing"] = None
        if all(r.get("timing") for r in runs):
            a["timing"] = {st: {q: statistics.median(r["timing"][st][q] for r in runs)
                                for q in runs[0]["timing"][st]}
                           for st in runs[0]["timing"]
                           if all(st in r["timing"] for r in runs)}
        out.append(a)
    return out


def run_all(runs, jobs, side_by_side=False):
    """Start runs in order (interleaved by the caller), at most `jobs` at a time. Side by side:
    each pair of consecutive runs at once, on cores 0 and 1, swapped from one pair to the next;
    the next pair only once both have ended."""
    pending = list(runs)
    active = {}
    done = 0
    pairs = 0
    while pending or active:
        if side_by_side and not active:
            for r, cpu in zip(pending[:2], (0, 1) if pairs % 2 == 0 else (1, 0)):
                r.start(cpu)
                active[r.proc.pid] = r
            del pending[:2]
            pairs += 1
        while not side_by_side and pending and len(active) < jobs:
            r = pending.pop(0)
            r.start()
            active[r.proc.pid] = r
        pid, status, rusage = os.wait4(-1, 0)
        r = active.pop(pid, None)
        if r is None:
            continue
        r.reap(status, rusage)
        done += 1
        res = r.result()
        ate = f"ATE {res['ate']:.4f} m" if res.get("ate") is not None else f"exit {r.rc}"
        # An ATE over the poses after a reset can look excellent: say how few they were.
        if res.get("resets") or (res.get("poses") or 0) < 0.5 * (res.get("frames") or 0):
            ate += f" ({res.get('resets') or 0} resets, {res.get('poses') or 0} poses of " \
                   f"{res.get('frames') or 0} frames)"
        seed = f" seed {r.seed}" if r.seed != 1 else ""
        log(f"[{done}/{len(runs)}] {r.seq}{seed} {r.variant}: {ate}, {r.wall_s:.0f} s "
            f"(see {r.out}/run.log)")


def fmt(x, spec=".3f"):
    return "–" if x is None else format(x, spec)


def stage(res, name, key="median"):
    t = res.get("timing") or {}
    return t.get(name, {}).get(key)


def ate_cell(r):
    if r.get("repeats") and r.get("ate_min") is not None:
        return f"{fmt(r.get('ate'), '.4f')} ({r['ate_min']:.4f}–{r['ate_max']:.4f})"
    return fmt(r.get("ate"), ".4f")


def bench_table(results):
    lines = ["| sequence | variant | ATE (m) | resets | init scale err (%) | init gravity err (°) "
             "| total ms median / p95 | points front end ms median / mean "
             "| lines front end ms median / mean "
             "| opt+marg ms median | real-time factor | peak RSS (MB) |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        init = r.get("init") or {}
        pts = (f"{fmt(r.get('points_front_end_median'), '.1f')} / "
               f"{fmt(r.get('points_front_end_mean'), '.1f')}")
        lns = ("–" if r.get("lines_front_end_median") is None else
               f"{fmt(r['lines_front_end_median'], '.1f')} / "
               f"{fmt(r['lines_front_end_mean'], '.1f')}")
        rtf = r["duration_s"] / r["wall_s"] if r.get("duration_s") and r.get("wall_s") else None
        lines.append(
            f"| {r['sequence']} | {r['variant']} | {ate_cell(r)} | {fmt(r.get('resets'), 'd')} "
            f"| {fmt(100 * init['scale_error'] if 'scale_error' in init else None, '.1f')} "
            f"| {fmt(init.get('gravity_error_deg'), '.2f')} "
            f"| {fmt(stage(r, 'total'), '.1f')} / {fmt(stage(r, 'total', 'p95'), '.1f')} "
            f"| {pts} | {lns} | {fmt(r.get('opt_total_median'), '.1f')} "
            f"| {fmt(rtf, '.2f')} | {fmt(r.get('peak_rss_mb'), '.0f')} |")
    return "\n".join(lines)


def ratio(a, b):
    return None if a is None or b is None or a == 0 else b / a


def paired_ratios(per_run, seq, a, b, value=lambda r: r.get("ate")):
    """B/A ratios of `value` (ATE unless given) of the runs that share sequence, seed and
    repeat, in seed and repeat order: the order they ran in."""
    values = {(r["variant"], r.get("seed", 1), r.get("repeat", 0)): value(r)
              for r in per_run if r["sequence"] == seq}
    return [ratio(values[(a, s, k)], values[(b, s, k)])
            for (v, s, k) in sorted(values, key=lambda key: (key[1], key[2]))
            if v == a and (b, s, k) in values]


# Two-sided 95 % quantiles of Student's t for 1..30 degrees of freedom; 1.96 beyond.
T95 = [12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179,
       2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060,
       2.056, 2.052, 2.048, 2.045, 2.042]


def pooled_ratio(ratios):
    """Geometric mean of B/A ratios with its 95 % interval (t on the log ratios), or None for
    fewer than two. A change whose interval holds 1 is not told apart from the runs' noise:
    one seed's trajectory can move by 20 % from any small change to the tracking
    (docs/benchmarks.md)."""
    logs = [math.log(r) for r in ratios if r is not None and r > 0]
    n = len(logs)
    if n < 2:
        return None
    mean = sum(logs) / n
    sd = math.sqrt(sum((x - mean) ** 2 for x in logs) / (n - 1))
    half = (T95[n - 2] if n - 1 <= len(T95) else 1.96) * sd / math.sqrt(n)
    return math.exp(mean), math.exp(mean - half), math.exp(mean + half), n


def pooled_line(per_run, a, b):
    """The compare table's pooled ATE line: every paired run's B/A ATE ratio, pooled."""
    ratios = [x for seq in dict.fromkeys(r["sequence"] for r in per_run)
              for x in paired_ratios(per_run, seq, a, b) if x is not None]
    pooled = pooled_ratio(ratios)
    if pooled is None:
        return ""
    g, lo, hi, n = pooled
    better = sum(x < 1 for x in ratios)
    return (f"All {n} paired runs: ATE ratio {b}/{a} {g:.3f} (geometric mean; 95 % interval "
            f"{lo:.3f}–{hi:.3f}); {better} of {n} runs lower with {b}.")


def paired_time_line(per_run, a, b):
    """The B/A ratios of the paired runs' median frame times (--side-by-side), pooled. The two
    cores of this machine can differ in speed by 1.4x for minutes, and consecutive pairs swap
    them, so each two consecutive pairs' ratios are combined (their geometric mean) before
    pooling: a constant difference between the cores then cancels."""
    ratios = [x for seq in dict.fromkeys(r["sequence"] for r in per_run)
              for x in paired_ratios(per_run, seq, a, b, lambda r: stage(r, "total"))]
    blocks = [math.sqrt(x * y) for x, y in zip(ratios[0::2], ratios[1::2])
              if x is not None and y is not None and x > 0 and y > 0]
    pooled = pooled_ratio(blocks)
    if pooled is None:
        return ""
    g, lo, hi, n = pooled
    return (f"Median frame time {b}/{a} over {n} blocks of two pairs with the cores swapped: "
            f"{g:.3f} (geometric mean; 95 % interval {lo:.3f}–{hi:.3f}).")


def compare_table(results, a, b, per_run=None, side_by_side=False):
    """Ratios B/A. With per_run from several seeds, also each seed's ATE ratio."""
    seeds = sorted({r.get("seed", 1) for r in per_run or []})
    each = len(seeds) > 1
    lines = [f"| sequence | ATE {a} | ATE {b} | ATE ratio |"
             + (" ATE ratio per run (seeds " + ", ".join(map(str, seeds)) + ") |"
                " per-run ratio: geometric mean (95 %); runs lower |" if each else "")
             + " total median ratio | opt+marg ratio | peak RSS ratio |",
             "|---|---|---|---|" + ("---|---|" if each else "") + "---|---|---|"]
    by = {(r["sequence"], r["variant"]): r for r in results}
    for seq in dict.fromkeys(r["sequence"] for r in results):
        ra, rb = by.get((seq, a), {}), by.get((seq, b), {})
        per_seed = ""
        if each:
            ratios = paired_ratios(per_run, seq, a, b)
            pooled = pooled_ratio(ratios)
            pooled_cell = "–" if pooled is None else (
                f"{pooled[0]:.3f} ({pooled[1]:.3f}–{pooled[2]:.3f}); "
                f"{sum(x is not None and x < 1 for x in ratios)} of {pooled[3]}")
            per_seed = " / ".join(fmt(x, ".3f") for x in ratios) + f" | {pooled_cell} | "
        lines.append(
            f"| {seq} | {ate_cell(ra)} | {ate_cell(rb)} "
            f"| {fmt(ratio(ra.get('ate'), rb.get('ate')), '.3f')} | {per_seed}"
            f"{fmt(ratio(stage(ra, 'total'), stage(rb, 'total')), '.3f')} "
            f"| {fmt(ratio(ra.get('opt_total_median'), rb.get('opt_total_median')), '.3f')} "
            f"| {fmt(ratio(ra.get('peak_rss_mb'), rb.get('peak_rss_mb')), '.3f')} |")
    tail = [pooled_line(per_run or [], a, b)]
    if side_by_side:
        tail.append(paired_time_line(per_run or [], a, b))
    return "\n\n".join(["\n".join(lines)] + [t for t in tail if t])


def ablation_table(results, seq):
    by = {r["variant"]: r for r in results if r["sequence"] == seq}
    ref = by.get("sel-none", {})
    lines = [f"**{seq}**", "",
             "| configuration | points used / frame | lines used / frame | optimisation ms / frame "
             "(median) | time vs reference | ATE (m) | ATE vs reference |",
             "|---|---|---|---|---|---|---|"]
    for label, v in ABLATION:
        r = by.get(v, {})
        dt = ratio(ref.get("opt_total_median"), r.get("opt_total_median"))
        da = ratio(ref.get("ate"), r.get("ate"))
        time_vs_ref = ("reference" if v == "sel-none" else
                       fmt(None if dt is None else 100 * (dt - 1), "+.1f") + " %")
        ate_vs_ref = ("reference" if v == "sel-none" else
                      fmt(None if da is None else 100 * (da - 1), "+.1f") + " %")
        lines.append(
            f"| {label} | {fmt(r.get('points_used'), '.1f')} | {fmt(r.get('lines_used'), '.1f')} "
            f"| {fmt(r.get('opt_total_median'), '.2f')} "
            f"| {time_vs_ref} "
            f"| {ate_cell(r)} "
            f"| {ate_vs_ref} |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", default=os.environ.get("ALVIO_BENCHMARK_DATA",
                                                     str(ROOT / "out" / "sim_benchmark")),
                    help="benchmark set folder (alvio sim --benchmark DIR) [%(default)s]")
    ap.add_argument("--sequences", "--dataset", default=None,
                    help="comma-separated sequence names or dataset folders")
    ap.add_argument("--variants", default="points,lines",
                    help="comma-separated variants [%(default)s]")
    ap.add_argument("--compare", nargs=2, metavar=("A", "B"),
                    help="compare two variants, as ratios B/A")
    ap.add_argument("--ablation", action="store_true",
                    help="the paper's four selection configurations")
    ap.add_argument("--out", default=str(ROOT / "out" / "bench"),
                    help="run folders and tables [%(default)s]")
    ap.add_argument("--jobs", type=int, default=1, help="runs at once [%(default)s]")
    ap.add_argument("--side-by-side", action="store_true",
                    help="with --compare: each pair of runs at once, one variant per core "
                    "(swapped from pair to pair), and the pooled ratio of their median frame "
                    "times; needs two cores")
    ap.add_argument("--max-frames", type=int, default=-1,
                    help="stop each run after this many images")
    ap.add_argument("--opencv-threads", type=int, default=1,
                    help="alvio run's --opencv-threads: 1 keeps each run on one core (issue 10's "
                         "single-thread figures; trajectories are the same with more); 0 leaves "
                         "OpenCV's own default, and is needed for builds before the option "
                         "[%(default)s]")
    ap.add_argument("--repeats", type=int, default=1,
                    help="runs per sequence and variant, each with --perturb's key nudged "
                    "[%(default)s]")
    ap.add_argument("--perturb", default="estimator.point_sigma_px",
                    help="the configuration key --repeats scales [%(default)s]")
    ap.add_argument("--perturb-step", type=float, default=7e-4,
                    help="relative step of that scaling [%(default)s]")
    ap.add_argument("--seeds", default="1",
                    help="comma-separated noise seeds; seed S > 1 runs DATA/seedS's copy of each "
                    "sequence [%(default)s]")
    ap.add_argument("--bin", default=os.environ.get("ALVIO_RUN",
                                                    str(ROOT / "build/devel/lib/alvio/alvio_run")))
    ap.add_argument("--freeze", action="store_true",
                    help="copy the build's programs, libraries and config into OUT/frozen first "
                    "(refused while a build is running), so that a rebuild during the runs or "
                    "the rendering cannot break them")
    ap.add_argument("--render", action="store_true",
                    help="render missing or out-of-date sequences first (alvio sim --benchmark, "
                    "which keeps what is up to date; with --freeze, the frozen alvio_sim); "
                    "./alvio ablation always passes it")
    a = ap.parse_args()
    if a.repeats < 1:
        sys.exit("alvio bench: error: --repeats must be at least 1")
    if a.side_by_side and not a.compare:
        sys.exit("alvio bench: error: --side-by-side needs --compare A B")
    if a.side_by_side and not {0, 1} <= os.sched_getaffinity(0):
        sys.exit("alvio bench: error: --side-by-side needs cores 0 and 1, this process may use "
                 f"{sorted(os.sched_getaffinity(0))}")
    try:
        seeds = [int(x) for x in a.seeds.split(",")]
    except ValueError:
        seeds = []
    if not seeds or min(seeds) < 1 or len(set(seeds)) != len(seeds):
        sys.exit(f"alvio bench: error: --seeds '{a.seeds}' is not a list of distinct seeds >= 1")

    if a.ablation:
        variants = [v for _, v in ABLATION]
    elif a.compare:
        variants = list(a.compare)
    else:
        variants = a.variants.split(",")
    parsed = [parse_variant(v) for v in variants]
    seqs = (a.sequences.split(",") if a.sequences else
            (["sim_MH_05"] if a.ablation else DEFAULT_SEQUENCES))
    data = Path(a.data)

    def seed_set(seed):
        return data if seed == 1 else data / f"seed{seed}"

    if seeds != [1]:
        given = [s for s in seqs if Path(s).is_dir()]
        if given:
            sys.exit(f"alvio bench: error: --seeds needs sequence names, not folders ({given[0]})")

    def sequence_folders():
        """(name, folder, seed) of every run's input; exits naming the first one missing."""
        found = []
        for s in seqs:
            for seed in seeds:
                d = Path(s) if Path(s).is_dir() else seed_set(seed) / s
                if not (d / "mav0").is_dir():
                    sys.exit(f"alvio bench: no sequence {d} (render it: ./alvio sim --benchmark "
                             f"{seed_set(seed)} --seed {seed} --only {s}, or pass --render)")
                found.append((d.name, d, seed))
        return found

    # Checked before --freeze copies anything, so that a mistyped name leaves no OUT/frozen;
    # with --render, once the rendering is done.
    if not a.render:
        datasets = sequence_folders()
    if (any(v in ("sel-lines", "sel-points", "sel-both") for v in variants)
            and not SURFACES.exists()):
        sys.exit(f"alvio bench: {SURFACES} is missing (make it with ./alvio analyze)")
    out = Path(a.out)
    # Frozen first, so that --render uses the frozen simulator too: a rebuild during a long
    # rendering would otherwise swap its libraries underneath it.
    if a.freeze:
        env = dict(os.environ, ALVIO_BUILD_DIR=str(Path(a.bin).resolve().parents[3]))
        frozen = subprocess.run([str(ROOT / "scripts/freeze_build.sh"), str(out / "frozen")],
                                env=env, capture_output=True, text=True)
        if frozen.returncode != 0:
            sys.exit(f"alvio bench: --freeze failed: {frozen.stderr.strip()}")
        a.bin = frozen.stdout.strip()
        # The configuration too: a run reads it when it starts, and an edit during a long
        # benchmark would otherwise split the runs between two settings.
        frozen_config = out / "frozen" / "config"
        if frozen_config.exists():
            shutil.rmtree(frozen_config)
        shutil.copytree(ROOT / "config", frozen_config)
        parsed = [(name, [x.replace(str(ROOT / "config"), str(frozen_config)) for x in args])
                  for name, args in parsed]
        config_dir = frozen_config
        log(f"frozen build: {a.bin}, configuration: {frozen_config}")
    else:
        config_dir = ROOT / "config"
    if a.render:
        # Only sequence names: a folder given is the user's own, and an empty --only would
        # render the whole set.
        names = [s for s in seqs if not Path(s).is_dir()]
        sim = Path(a.bin).with_name("alvio_sim")
        if names:
            for seed in seeds:
                rendered = subprocess.run(
                    [str(sim), "--benchmark", str(seed_set(seed)), "--seed", str(seed), "--only",
                     ",".join(names), "--config", str(config_dir / "euroc.yaml")],
                    env=program_env(sim))
                if rendered.returncode != 0:  # the simulator has said why
                    sys.exit(f"alvio bench: rendering {','.join(names)} into {seed_set(seed)} "
                             f"failed (alvio sim exit {rendered.returncode})")
        datasets = sequence_folders()

    def with_config(name, args):
        # A real IMU is weighed by its in-flight noise (config/euroc_real.yaml); the synthetic
        # IMU by the datasheet noise it was made with (config/euroc.yaml).
        if "--config" in args:
            return args
        return args + ["--config", str(config_dir / ("euroc_real.yaml" if is_real_imu(name)
                                                     else "euroc.yaml"))]

    def folder(name, v, k, seed):
        f = out / name / v
        if seeds != [1]:  # a run on another seed's rendering says so in its folder
            f = f / f"s{seed}"
        return f if a.repeats == 1 else f / f"r{k}"

    # Interleave variants per sequence (seed and repeat) so that load drifts hit all alike.
    runs = [Run(name, d, v, perturbed_args(with_config(name, args), a.perturb, a.perturb_step, k),
                folder(name, v, k, seed), a.bin, a.max_frames, k, seed, a.opencv_threads)
            for name, d, seed in datasets for k in range(a.repeats) for v, args in parsed]
    log(f"{len(runs)} runs ({len(seqs)} sequences"
        f"{f' x {len(seeds)} seeds' if len(seeds) > 1 else ''} x {len(parsed)} variants"
        f"{f' x {a.repeats} repeats' if a.repeats > 1 else ''}), "
        f"{'pairs side by side' if a.side_by_side else f'{a.jobs} at a time'}, into {out}")
    run_all(runs, a.jobs, a.side_by_side)
    per_run = [r.result() for r in runs]
    (out / "results.json").write_text(json.dumps(per_run, indent=2))
    results = aggregate(per_run)

    if a.ablation:
        text = "\n\n".join(ablation_table(results, name) for name in dict.fromkeys(
            name for name, _, _ in datasets))
    else:
        text = bench_table(results)
        if a.compare:
            text += "\n\n" + compare_table(results, parsed[0][0], parsed[1][0], per_run,
                                            a.side_by_side)
    if seeds != [1]:
        text += (f"\n\nEach row: the runs on noise seeds {a.seeds} (seed S > 1: {data}/seedS)"
                 f"{f', {a.repeats} each' if a.repeats > 1 else ''}; ATE is their mean (range), "
                 "times and memory their median.")
    elif a.repeats > 1:
        text += (f"\n\nEach row: {a.repeats} runs with {a.perturb} scaled by 1, "
                 f"1 ± {a.perturb_step:g}, "
                 "...; ATE is their mean (range), times and memory their median.")
    if any(is_real_imu(name) for name, _, _ in datasets):
        text += ("\n\nSequences with the real EuRoC IMU (`*_realimu`) run with "
                 "config/euroc_real.yaml (in-flight IMU noise), the others with config/euroc.yaml.")
    (out / "results.md").write_text(text + "\n")
    print(text)
    log(f"tables in {out}/results.md, numbers in {out}/results.json")
    return 0 if all(r.rc == 0 for r in runs) else 1


if __name__ == "__main__":
    sys.exit(main())
