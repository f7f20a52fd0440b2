#!/usr/bin/env python3
"""Plot thread scaling and frame-time distributions from brickworld runs.

    ./build/release/bin/brickworld sweep crates_on_grid --threads 1,2 --json > sweep.json
    ./build/release/bin/brickworld run crates_on_grid --csv frames.csv
    python3 profiles/plot_sweep.py sweep.json [more.json ...] --frames frames.csv [...] -o sweep.png

Left panel: speedup over 1 thread against thread count, measured (thick) and the bound that the
1-thread run's work and span allow at 2/4/8/16 threads (thin), one pair of lines per sweep.
Right panel (with --frames): frame time against percentile of frames, one line per run CSV.
Uses matplotlib when it can be imported, else the built-in rasteriser (png_plot.py).
"""
import argparse
import csv
import json
import os
import sys

from png_plot import Canvas, draw_panel


def read_sweeps(paths):
    """{label: [(threads, speedup), ...]} for measured and bound lines; bound labels separately."""
    series, bounds = {}, set()
    for path in paths:
        with open(path) as f:
            j = json.load(f)
        scene = j["scene"]
        series[f"{scene} measured"] = sorted((r["threads"], r["measured_speedup"]) for r in j["runs"])
        bound = [(1, 1.0)] + sorted((int(k), v) for k, v in j["bound_speedup"].items())
        series[f"{scene} bound"] = bound
        bounds.add(f"{scene} bound")
    return series, bounds


def read_frames(paths):
    """{label: [(percentile, ms), ...]} from per-frame CSVs of `brickworld run --csv`."""
    series = {}
    for path in paths:
        with open(path, newline="") as f:
            ms = sorted(float(r["total_ms"]) for r in csv.DictReader(f))
        if not ms:
            continue
        n = len(ms)
        series[os.path.splitext(os.path.basename(path))[0]] = [(100.0 * (i + 0.5) / n, max(v, 1e-4)) for i, v in enumerate(ms)]
    return series


def plot_matplotlib(scaling, bounds, frames, out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2 if frames else 1, figsize=(12 if frames else 6, 5), squeeze=False)
    ax = axes[0][0]
    for label, pts in sorted(scaling.items()):
        ax.plot([p[0] for p in pts], [p[1] for p in pts], marker="o", linestyle="--" if label in bounds else "-", label=label)
    ax.set_xscale("log", base=2)
    ax.set_xlabel("threads")
    ax.set_ylabel("speedup over 1 thread")
    ax.set_title("Thread scaling: measured vs work/span bound")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    if frames:
        ax = axes[0][1]
        for label, pts in sorted(frames.items()):
            ax.plot([p[0] for p in pts], [p[1] for p in pts], label=label)
        ax.set_yscale("log")
        ax.set_xlabel("percentile of frames")
        ax.set_ylabel("frame ms")
        ax.set_title("Frame-time distribution")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=100)


def plot_fallback(scaling, bounds, frames, out):
    cv = Canvas(1300 if frames else 650, 560)
    draw_panel(cv, 0, 0, 650, 560, scaling, "THREAD SCALING", "THREADS", "SPEEDUP OVER 1 THREAD (THIN: WORK/SPAN BOUND)",
               logx=True, logy=False, dashed=bounds)
    if frames:
        draw_panel(cv, 650, 0, 650, 560, frames, "FRAME-TIME DISTRIBUTION", "PERCENTILE OF FRAMES", "FRAME MS",
                   logx=False, logy=True)
    cv.png(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("sweeps", nargs="+", help="JSON written by `brickworld sweep ... --json`")
    ap.add_argument("--frames", nargs="*", default=[], help="per-frame CSVs written by `brickworld run --csv`")
    ap.add_argument("-o", "--output", default="sweep.png", help="PNG to write (default sweep.png)")
    args = ap.parse_args()
    try:
        scaling, bounds = read_sweeps(args.sweeps)
        frames = read_frames(args.frames)
    except (OSError, KeyError, ValueError) as e:
        print(f"plot_sweep: cannot read the input: {e}", file=sys.stderr)
        return 1
    try:
        import matplotlib  # noqa: F401
        plot_matplotlib(scaling, bounds, frames, args.output)
        print(f"plot_sweep: wrote {args.output} (matplotlib)")
    except ImportError:
        plot_fallback(scaling, bounds, frames, args.output)
        print(f"plot_sweep: matplotlib is not importable; wrote {args.output} with the built-in rasteriser")
    return 0


if __name__ == "__main__":
    sys.exit(main())
