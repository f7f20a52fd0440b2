"""A small PNG plotter used when matplotlib is not installed (it is not one of the project's
Debian dependencies): lines, markers, a log or linear grid, a 5x7 bitmap font, zlib PNG output.
Shared by plot_batch.py and plot_sweep.py.
"""
import math
import struct
import zlib

COLORS = [(214, 39, 40), (31, 119, 180), (44, 160, 44), (255, 127, 14), (148, 103, 189), (140, 86, 75),
          (227, 119, 194), (127, 127, 127), (188, 189, 34), (23, 190, 207)]


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


def _ticks(lo, hi, log):
    """Tick values covering [lo, hi]: 1-2-5 per decade on log axes, ~6 round steps on linear."""
    if log:
        out = []
        for e in range(math.floor(math.log10(lo)), math.ceil(math.log10(hi)) + 1):
            for m in (1, 2, 5):
                v = m * 10 ** e
                if lo <= v <= hi:
                    out.append(v)
        return out
    step = 10 ** math.floor(math.log10((hi - lo) / 5 or 1))
    for m in (1, 2, 5, 10):
        if (hi - lo) / (m * step) <= 6:
            step *= m
            break
    v, out = math.floor(lo / step) * step, []
    while v <= hi + 1e-9:
        out.append(round(v, 10))
        v += step
    return out


def draw_panel(cv, x0, y0, w, h, series, title, xlabel, ylabel, logx=True, logy=True, dashed=()):
    """series: {label: [(x, y), ...]}; labels in `dashed` are drawn thin (e.g. bounds)."""
    points = [p for pts in series.values() for p in pts]
    if not points:
        cv.text(x0 + 10, y0 + 10, "NO DATA")
        return
    xs, ys = [p[0] for p in points], [p[1] for p in points]
    xlo, xhi = min(xs), max(xs)
    ylo, yhi = min(ys), max(ys)
    if logx:
        xlo, xhi = 10 ** math.floor(math.log10(xlo)), 10 ** math.ceil(math.log10(xhi))
    if logy:
        ylo, yhi = 10 ** math.floor(math.log10(ylo)), 10 ** math.ceil(math.log10(yhi))
    else:
        ylo = min(0.0, ylo)
    if xhi == xlo:
        xhi = xlo + 1
    if yhi == ylo:
        yhi = ylo + 1
    left, top, pw, ph = x0 + 90, y0 + 50, w - 110, h - 110

    def px(v):
        t = (math.log10(v) - math.log10(xlo)) / (math.log10(xhi) - math.log10(xlo)) if logx else (v - xlo) / (xhi - xlo)
        return left + t * pw

    def py(v):
        t = (math.log10(v) - math.log10(ylo)) / (math.log10(yhi) - math.log10(ylo)) if logy else (v - ylo) / (yhi - ylo)
        return top + ph - t * ph

    grid = (225, 225, 225)
    for v in _ticks(ylo, yhi, logy):
        cv.line(left, py(v), left + pw, py(v), grid)
        cv.text(left - 8 - 12 * len(fmt(v)), py(v) - 7, fmt(v))
    for v in _ticks(xlo, xhi, logx):
        cv.line(px(v), top, px(v), top + ph, grid)
        cv.text(px(v) - 6 * len(fmt(v)), top + ph + 10, fmt(v))
    cv.line(left, top, left, top + ph, (0, 0, 0))
    cv.line(left, top + ph, left + pw, top + ph, (0, 0, 0))
    cv.text(left, y0 + 8, title)
    cv.text(left + pw // 2 - 6 * len(xlabel), top + ph + 34, xlabel)
    cv.text(left, top - 16, ylabel, scale=1)
    for i, (label, pts) in enumerate(sorted(series.items())):
        color = COLORS[i % len(COLORS)]
        width = 1 if label in dashed else 3
        for a, b in zip(pts, pts[1:]):
            cv.line(px(a[0]), py(a[1]), px(b[0]), py(b[1]), color, width=width)
        if len(pts) <= 40:
            for p in pts:
                cv.rect(px(p[0]) - 3, py(p[1]) - 3, 7, 7, color)
        ly0 = top + 8 + 18 * i
        cv.rect(left + 12, ly0 + 3, 18, 6, color)
        cv.text(left + 36, ly0, label, scale=1)
