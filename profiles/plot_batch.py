#!/usr/bin/env python3
"""Plot `brickworld batch-bench --csv F` output: frame time vs attachments per mode.

    ./build/release/bin/brickworld batch-bench --csv batch.csv
    python3 profiles/plot_batch.py batch.csv -o batch.png

Left panel: game-thread ms per frame for each submission mode and thread count.
Right panel: transform update ms per frame, SoA vs object-style. Both axes logarithmic.

Uses matplotlib when it can be imported. Without it, the same two panels are drawn by a small
built-in rasteriser (lines, log grid, a 5x7 bitmap font) and written with zlib as a PNG, and
the script says so on stdout.
"""
import argparse
import csv
import sys
from collections import defaultdict

from png_plot import Canvas, draw_panel

def read_series(path):
    """Returns (submission, transform): {label: [(attachments, ms), ...]} sorted by attachments."""
    submission, transform = defaultdict(list), defaultdict(list)
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            label = f"{row['mode']} t{row['threads']}"
            point = (float(row["attachments"]), float(row["game_ms"]))
            if point[1] <= 0:
                continue
            (submission if row["section"] == "submission" else transform)[label].append(point)
    for series in (submission, transform):
        for points in series.values():
            points.sort()
    return submission, transform


def plot_matplotlib(submission, transform, out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(12, 5))
    for ax, series, title, ylabel in ((axes[0], submission, "Render submission", "game-thread ms per frame"),
                                      (axes[1], transform, "Transform update", "update ms per frame")):
        for label, points in sorted(series.items()):
            ax.plot([p[0] for p in points], [p[1] for p in points], marker="o", label=label)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("moving attachments")
        ax.set_ylabel(ylabel)
        ax.set_title(title)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=100)


def plot_fallback(submission, transform, out):
    cv = Canvas(1300, 560)
    draw_panel(cv, 0, 0, 650, 560, submission, "RENDER SUBMISSION", "MOVING ATTACHMENTS", "GAME-THREAD MS PER FRAME")
    draw_panel(cv, 650, 0, 650, 560, transform, "TRANSFORM UPDATE", "MOVING ATTACHMENTS", "UPDATE MS PER FRAME")
    cv.png(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv", help="CSV written by `brickworld batch-bench --csv`")
    ap.add_argument("-o", "--output", default="batch.png", help="PNG to write (default batch.png)")
    args = ap.parse_args()
    try:
        submission, transform = read_series(args.csv)
    except (OSError, KeyError, ValueError) as e:
        print(f"plot_batch: cannot read {args.csv}: {e}", file=sys.stderr)
        return 1
    try:
        import matplotlib  # noqa: F401
        have_matplotlib = True
    except ImportError:
        have_matplotlib = False
    if have_matplotlib:
        plot_matplotlib(submission, transform, args.output)
        print(f"plot_batch: wrote {args.output} (matplotlib)")
    else:
        plot_fallback(submission, transform, args.output)
        print(f"plot_batch: matplotlib is not importable; wrote {args.output} with the built-in rasteriser "
              "(same data, plainer drawing)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
