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
import math
import struct
import sys
import zlib
from collections import defaultdict

COLORS = [(214, 39, 40), (31, 119, 180), (44, 160, 44), (255, 127, 14), (148, 103, 189), (140, 86, 75),
          (227, 119, 194), (127, 127, 127), (188, 189, 34), (23, 190, 207)]


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


# --- fallback rasteriser ---------------------------------------------------------------------

FONT = {  # 5x7 glyphs, one byte per row, bit 4 = leftmost column
    "0": "0E11131519110E", "1": "040C040404040E", "2": "0E11010204081F", "3": "1F02040201110E",
    "4": "02060A121F0202", "5": "1F101E0101110E", "6": "0608101E11110E", "7": "1F010204080808",
    "8": "0E11110E11110E", "9": "0E11110F01020C", "A": "0E11111F111111", "B": "1E11111E11111E",
    "C": "0E11101010110E", "D": "1C12111111121C", "E": "1F10101E10101F", "F": "1F10101E101010",
    "G": "0E11101711110F", "H": "1111111F111111", "I": "0E04040404040E", "J": "0702020202120C",
    "K": "11121418141211", "L": "1010101010101F", "M": "111B1515111111", "N": "11111915131111",
    "O": "0E11111111110E", "P": "1E11111E101010", "Q": "0E11111115120D", "R": "1E11111E141211",
    "S": "0F10100E01011E", "T": "1F040404040404", "U": "1111111111110E", "V": "11111111110A04",
    "W": "1111111515150A", "X": "11110A040A1111", "Y": "1111110A040404", "Z": "1F01020408101F",
    ".": "00000000000C0C", "-": "0000001F000000", "(": "02040808080402", ")": "08040202020408",
    "/": "01010204081010", "=": "00001F001F0000", ",": "00000000000C04", ":": "000C0C000C0C00",
    " ": "00000000000000",
}


class Canvas:
    def __init__(self, width, height):
        self.w, self.h = width, height
        self.px = bytearray(b"\xff" * (width * height * 3))

    def set(self, x, y, color):
        if 0 <= x < self.w and 0 <= y < self.h:
            i = (y * self.w + x) * 3
            self.px[i:i + 3] = bytes(color)

    def line(self, x0, y0, x1, y1, color, width=1):
        x0, y0, x1, y1 = int(round(x0)), int(round(y0)), int(round(x1)), int(round(y1))
        dx, dy = abs(x1 - x0), -abs(y1 - y0)
        sx, sy = (1 if x0 < x1 else -1), (1 if y0 < y1 else -1)
        err = dx + dy
        while True:
            for ox in range(width):
                for oy in range(width):
                    self.set(x0 + ox - width // 2, y0 + oy - width // 2, color)
            if x0 == x1 and y0 == y1:
                break
            e2 = 2 * err
            if e2 >= dy:
                err += dy
                x0 += sx
            if e2 <= dx:
                err += dx
                y0 += sy

    def rect(self, x, y, w, h, color):
        for yy in range(int(y), int(y + h)):
            for xx in range(int(x), int(x + w)):
                self.set(xx, yy, color)

    def text(self, x, y, s, color=(0, 0, 0), scale=2):
        for ch in s.upper():
            rows = FONT.get(ch, FONT[" "])
            for r in range(7):
                bits = int(rows[2 * r:2 * r + 2], 16)
                for c in range(5):
                    if bits & (0x10 >> c):
                        self.rect(x + c * scale, y + r * scale, scale, scale, color)
            x += 6 * scale

    def png(self, path):
        raw = b"".join(b"\x00" + bytes(self.px[y * self.w * 3:(y + 1) * self.w * 3]) for y in range(self.h))

        def chunk(tag, data):
            return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xffffffff)

        with open(path, "wb") as f:
            f.write(b"\x89PNG\r\n\x1a\n")
            f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", self.w, self.h, 8, 2, 0, 0, 0)))
            f.write(chunk(b"IDAT", zlib.compress(raw, 9)))
            f.write(chunk(b"IEND", b""))


def fmt(v):
    if v >= 1000:
        return f"{v / 1000:g}K"
    return f"{v:g}"


def draw_panel(cv, x0, y0, w, h, series, title, ylabel):
    points = [p for pts in series.values() for p in pts]
    if not points:
        cv.text(x0 + 10, y0 + 10, "NO DATA")
        return
    lx = [math.log10(p[0]) for p in points]
    ly = [math.log10(p[1]) for p in points]
    xmin, xmax = math.floor(min(lx)), math.ceil(max(lx))
    ymin, ymax = math.floor(min(ly)), math.ceil(max(ly))
    xmax, ymax = max(xmax, xmin + 1), max(ymax, ymin + 1)
    left, top, pw, ph = x0 + 90, y0 + 50, w - 110, h - 110

    def px(v):
        return left + (math.log10(v) - xmin) / (xmax - xmin) * pw

    def py(v):
        return top + ph - (math.log10(v) - ymin) / (ymax - ymin) * ph

    grid = (225, 225, 225)
    for e in range(ymin, ymax + 1):
        for m in (1, 2, 5):
            v = m * 10 ** e
            if ymin <= math.log10(v) <= ymax:
                cv.line(left, py(v), left + pw, py(v), grid)
                cv.text(left - 8 - 12 * len(fmt(v)), py(v) - 7, fmt(v))
    for e in range(xmin, xmax + 1):
        v = 10 ** e
        cv.line(px(v), top, px(v), top + ph, grid)
        cv.text(px(v) - 6 * len(fmt(v)), top + ph + 10, fmt(v))
    cv.line(left, top, left, top + ph, (0, 0, 0))
    cv.line(left, top + ph, left + pw, top + ph, (0, 0, 0))
    cv.text(left, y0 + 8, title)
    cv.text(left + pw // 2 - 100, top + ph + 34, "MOVING ATTACHMENTS")
    cv.text(left, top - 16, ylabel, scale=1)
    for i, (label, pts) in enumerate(sorted(series.items())):
        color = COLORS[i % len(COLORS)]
        for a, b in zip(pts, pts[1:]):
            cv.line(px(a[0]), py(a[1]), px(b[0]), py(b[1]), color, width=3)
        for p in pts:
            cv.rect(px(p[0]) - 3, py(p[1]) - 3, 7, 7, color)
        ly0 = top + 8 + 18 * i
        cv.rect(left + 12, ly0 + 3, 18, 6, color)
        cv.text(left + 36, ly0, label, scale=1)


def plot_fallback(submission, transform, out):
    cv = Canvas(1300, 560)
    draw_panel(cv, 0, 0, 650, 560, submission, "RENDER SUBMISSION", "GAME-THREAD MS PER FRAME")
    draw_panel(cv, 650, 0, 650, 560, transform, "TRANSFORM UPDATE", "UPDATE MS PER FRAME")
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
