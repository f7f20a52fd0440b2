#!/usr/bin/env python3
"""The replay page in headless Chromium, as a user would make and open it.

For each scene: `brickworld run SCENE --record` then `brickworld view`, then Chromium
(Debian's chromium-headless-shell, which setup.sh installs) loads the page at its last frame:
the page must report no errors and no console errors, the frame count and the body count of the
run, every body drawn (and every brick, for grids recorded brick by brick), and a screenshot
whose 3D view is not blank; with a small brick budget (#budget=N) no more than N bricks drawn one
by one and more cells drawn as boxes.

usage: browser_check.py BRICKWORLD WORK_DIR
"""
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import zlib

# scene, frames, extra run options, what the last frame must show
SCENES = [
    ("crates_on_grid", 90, ["--record-contacts", "--submission", "all"], {"contacts": True, "bricks": True, "modes": 3, "budget": 5000}),
    ("demolition", 120, [], {"bricks": True, "mark_inside": True}),
    ("quarry", 200, [], {"terrain": True}),
    ("city_rain", 60, [], {}),  # the city (1M bricks) drawn as its OctoBVH boxes
]
WIDTH, HEIGHT = 1280, 800


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def chromium():
    for name in ("chromium-headless-shell", "chromium"):
        path = shutil.which(name)
        if path:
            return path
    fail("no chromium-headless-shell on PATH: install Debian's chromium-headless-shell (bash setup.sh does)")


def browse(page, extra, address="frame=last&contacts", timeout=300):
    # swiftshader: WebGL on the CPU (no GPU on CI machines); a virtual time budget lets the
    # page's scripts finish before the DOM is dumped or the picture taken.
    cmd = [chromium(), "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--enable-logging=stderr",
           "--v=0", "--window-size=%d,%d" % (WIDTH, HEIGHT), "--virtual-time-budget=60000"] + extra + \
          ["file://" + os.path.abspath(page) + "#" + address]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)


def png_pixels(path):
    """(width, height, rows of RGB tuples) of an 8-bit RGB or RGBA PNG."""
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        fail(path + " is not a PNG")
    at, idat, width, height, kind = 8, b"", 0, 0, 0
    while at < len(data):
        length, tag = struct.unpack(">I4s", data[at:at + 8])
        body = data[at + 8:at + 8 + length]
        if tag == b"IHDR":
            width, height, depth, kind = struct.unpack(">IIBB", body[:10])
            if depth != 8 or kind not in (2, 6):
                fail("screenshot PNG of bit depth %d, colour type %d: not read here" % (depth, kind))
        elif tag == b"IDAT":
            idat += body
        at += 12 + length
    raw = zlib.decompress(idat)
    bpp = 3 if kind == 2 else 4
    stride = width * bpp
    rows, prev, at = [], bytearray(stride), 0
    for _ in range(height):
        filt, line = raw[at], bytearray(raw[at + 1:at + 1 + stride])
        at += 1 + stride
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if filt == 1:
                line[i] = (line[i] + a) & 255
            elif filt == 2:
                line[i] = (line[i] + b) & 255
            elif filt == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif filt == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    return width, height, rows, bpp


def mark_inside_solid(recording):
    """Rewrites the last frame's first moving body as inside solid (an uncompressed recording):
    the page must list it and mark the frame."""
    data = bytearray(open(recording, "rb").read())
    at, stages, last = 12, 0, None
    while at + 8 <= len(data):
        tag, length = struct.unpack_from("<4sI", data, at)
        if tag == b"HEAD":
            stages = len(json.loads(data[at + 8:at + 8 + length].decode())["stages"])
        if tag == b"FRAM":
            last = at
        at += 8 + length
    moving = struct.unpack_from("<I", data, last + 8 + 4 + 4 * stages + 4)[0]
    if moving == 0:
        fail(recording + ": no moving body to mark")
    data[last + 8 + 4 + 4 * stages + 8 + 32] = 2
    open(recording, "wb").write(bytes(data))


def page_report(scene, page, address="frame=last&contacts"):
    """The page's #bw-report and the console messages Chromium logged while it loaded."""
    dom = browse(page, ["--dump-dom"], address)
    match = re.search(r'<pre id="bw-report">([^<]*)</pre>', dom.stdout)
    if not match:
        fail("%s: the page wrote no report (Chromium exit %d):\n%s" % (scene, dom.returncode, dom.stderr[-3000:]))
    report = json.loads(match.group(1).replace("&quot;", '"').replace("&amp;", "&"))
    return report, [l for l in dom.stderr.splitlines() if ":CONSOLE(" in l or "Uncaught" in l]


def check_scene(brickworld, work, scene, frames, options, expect):
    recording = os.path.join(work, scene + ".bwr")
    page = os.path.join(work, scene + ".html")
    run = subprocess.run([brickworld, "run", scene, "--frames", str(frames), "--threads", "2", "--record", recording, "--json"] + options,
                         capture_output=True, text=True, timeout=600)
    if run.returncode != 0:
        fail("%s: brickworld run failed:\n%s" % (scene, run.stderr[-2000:]))
    ran = json.loads(run.stdout)
    if expect.get("mark_inside"):
        mark_inside_solid(recording)
    view = subprocess.run([brickworld, "view", recording, "-o", page], capture_output=True, text=True, timeout=300)
    if view.returncode != 0:
        fail("%s: brickworld view failed:\n%s" % (scene, view.stderr))

    report, console = page_report(scene, page)
    print("%s: %s" % (scene, json.dumps(report)))
    problems = []
    if not report.get("ready"):
        problems.append("the page did not finish loading")
    if report.get("errors"):
        problems.append("page errors: %s" % report["errors"])
    if console:
        problems.append("console messages: %s" % console[:5])
    if not report.get("webgl"):
        problems.append("no WebGL context")
    if report.get("frames") != frames or report.get("timelineFrames") != frames:
        problems.append("frames %s (timeline %s), the run made %d" % (report.get("frames"), report.get("timelineFrames"), frames))
    if report.get("frame") != frames - 1:
        problems.append("shows frame %s, not the last" % report.get("frame"))
    if report.get("bodies") != ran["bodies"] or report.get("bodiesDrawn") != ran["bodies"]:
        problems.append("bodies %s (drawn %s), the run ended with %d" % (report.get("bodies"), report.get("bodiesDrawn"), ran["bodies"]))
    if expect.get("bricks") and report.get("bricksDrawn") != ran["bricks"]:
        problems.append("bricks drawn %s, the run ended with %d" % (report.get("bricksDrawn"), ran["bricks"]))
    if expect.get("contacts") and not report.get("contactsDrawn"):
        problems.append("no contacts drawn")
    if report.get("modeLanes", 0) != expect.get("modes", 0):
        problems.append("%s submission-mode lanes, the run made %d" % (report.get("modeLanes"), expect.get("modes", 0)))
    inside = 1 if expect.get("mark_inside") else ran["bodies_inside_solid"]
    if report.get("insideSolid") != inside:
        problems.append("%s bodies shown inside solid, the recording has %d" % (report.get("insideSolid"), inside))
    if expect.get("terrain") and not report.get("terrainTriangles"):
        problems.append("no terrain drawn")
    if not report.get("bricksInFull") and ran["bricks"] and expect.get("bricks"):
        problems.append("no brick drawn brick by brick")
    if expect.get("budget"):
        # A brick budget below what the view holds: fewer bricks drawn one by one, more cells as boxes.
        small, _ = page_report(scene, page, "frame=last&budget=%d" % expect["budget"])
        print("%s with budget %d: %s" % (scene, expect["budget"], json.dumps(small)))
        if small.get("bricksInFull", 0) > expect["budget"] or small.get("brickBudget") != expect["budget"]:
            problems.append("budget %d: %s bricks drawn brick by brick" % (expect["budget"], small.get("bricksInFull")))
        if small.get("cellsAsBoxes", 0) <= report.get("cellsAsBoxes", 0):
            problems.append("budget %d: %s cells as boxes, %s without it" % (expect["budget"], small.get("cellsAsBoxes"), report.get("cellsAsBoxes")))

    shot = os.path.join(work, scene + ".png")
    if os.path.exists(shot):
        os.remove(shot)
    browse(page, ["--screenshot=" + shot])
    if not os.path.exists(shot):
        problems.append("no screenshot")
    else:
        width, height, rows, bpp = png_pixels(shot)
        # The 3D view sits between the bar and the timeline: count pixels there that are not the
        # page's background (#15181c).
        lit = total = 0
        for y in range(height // 8, height * 5 // 8):
            row = rows[y]
            for x in range(0, width, 2):
                r, g, b = row[bpp * x], row[bpp * x + 1], row[bpp * x + 2]
                total += 1
                lit += abs(r - 0x15) + abs(g - 0x18) + abs(b - 0x1C) > 24
        share = lit / max(total, 1)
        print("%s: screenshot %dx%d, %.1f%% of the view drawn" % (scene, width, height, 100 * share))
        if share < 0.01:
            problems.append("the screenshot's view is blank (%.2f%% drawn)" % (100 * share))
    if problems:
        fail(scene + ": " + "; ".join(problems))


def main():
    if len(sys.argv) != 3:
        fail("usage: browser_check.py BRICKWORLD WORK_DIR")
    brickworld, work = sys.argv[1], sys.argv[2]
    os.makedirs(work, exist_ok=True)
    only = os.environ.get("BW_BROWSER_SCENES")
    for scene, frames, options, expect in SCENES:
        if only and scene not in only.split(","):
            continue
        check_scene(brickworld, work, scene, frames, options, expect)
    print("browser check: every page drew its recording")


if __name__ == "__main__":
    main()
