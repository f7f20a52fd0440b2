#!/usr/bin/env python3
"""Plots `brickworld tradeoff` CSVs: for each knob, cost (median step ms) against error.

One PNG per CSV with three panels: step time against final pose divergence from the reference
run, against the largest penetration, and box tests per frame against the LOD's contact
errors. Each knob is one series; its points are its values in order.
Uses matplotlib when it can be imported, else the built-in rasteriser (png_plot.py).
"""
import argparse
import csv
import sys

from png_plot import Canvas, draw_panel

TINY = 1e-6  # log axes: zero errors are drawn at this value


def read(path):
    rows = list(csv.DictReader(open(path)))
    if not rows:
        raise ValueError(f"{path} has no rows")
    by_knob = {}
    for r in rows:
        if r["knob"] == "reference":
            continue
        by_knob.setdefault(r["knob"], []).append({k: float(v) for k, v in r.items() if k != "knob"})
    return by_knob


def series(by_knob, x, y, only=None):
    out = {}
    for knob, rows in by_knob.items():
        if only and knob not in only:
            continue
        pts = [(max(r[x], TINY), max(r[y], TINY)) for r in rows if r[y] >= 0]
        if pts:
            out[knob.upper().replace("_", " ")] = pts
    return out


PANELS = [
    ("median_ms", "pose_divergence_mean", "COST VS POSE DIVERGENCE", "MEDIAN STEP MS", "MEAN POSE DIVERGENCE M", None),
    ("median_ms", "penetration_max", "COST VS PENETRATION", "MEDIAN STEP MS", "MAX PENETRATION M", None),
    ("box_tests_per_frame", "contacts_missed_share", "LOD: BOX TESTS VS MISSED CONTACTS", "BOX TESTS PER FRAME",
     "SHARE OF CONTACTS MISSED", {"lod_fraction"}),
]


def plot(by_knob, out):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, axes = plt.subplots(1, len(PANELS), figsize=(6 * len(PANELS), 5))
        for ax, (x, y, title, xl, yl, only) in zip(axes, PANELS):
            for label, pts in series(by_knob, x, y, only).items():
                ax.plot([p[0] for p in pts], [p[1] for p in pts], marker="o", label=label)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_title(title.lower())
            ax.set_xlabel(xl.lower())
            ax.set_ylabel(yl.lower())
            ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(out)
        return "matplotlib"
    except ImportError:
        cv = Canvas(650 * len(PANELS), 560)
        for i, (x, y, title, xl, yl, only) in enumerate(PANELS):
            draw_panel(cv, 650 * i, 0, 650, 560, series(by_knob, x, y, only), title, xl, yl, logx=True, logy=True)
        cv.png(out)
        return "the built-in rasteriser"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv", nargs="+", help="CSV written by `brickworld tradeoff`")
    ap.add_argument("-o", "--output", help="PNG to write (default: the CSV's name with .png; one input only)")
    args = ap.parse_args()
    if args.output and len(args.csv) > 1:
        print("plot_tradeoff: -o needs exactly one CSV", file=sys.stderr)
        return 2
    for path in args.csv:
        out = args.output or (path.rsplit(".", 1)[0] + ".png")
        try:
            by_knob = read(path)
        except (OSError, KeyError, ValueError) as e:
            print(f"plot_tradeoff: cannot read {path}: {e}", file=sys.stderr)
            return 1
        how = plot(by_knob, out)
        print(f"plot_tradeoff: wrote {out} ({how})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
