#!/usr/bin/env python3
"""Viewer latency, in headless Chromium (the page measures it: from the input event to the
animation frame after the new image has been decoded):
- a slider move to the new frame, for the double Watt at 800x800, and the bare HTTP time of
  one frame (render + PNG encode + transfer);
- a pointer move of a vertex drag to the new frame (POST /api/drag, then the frame), for the
  double Watt at 800x800 and for a 1,000-vertex framework (a 40 x 25 grid, braced in every
  other row of squares, its bottom row pinned: the unbraced rows shear), pointer moves at 60 Hz.
usage: viewer_latency.py FLEXURE_BINARY EXAMPLES_DIR [MOVES]"""
import os
import json
import math
import random
import shutil
import statistics
import sys
import tempfile
import time
import urllib.request

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "viewer"))
from browser import Viewer, chromium, quit_chromium, wait_for  # noqa: E402
from selenium.webdriver.common.action_chains import ActionChains  # noqa: E402
from selenium.webdriver.common.by import By  # noqa: E402


def summary(name, xs):
    xs = sorted(xs)
    p = lambda q: xs[min(len(xs) - 1, int(q * len(xs)))]
    print("%-44s n=%d  median %.1f ms  p90 %.1f ms  max %.1f ms" % (name, len(xs), statistics.median(xs), p(0.9), xs[-1]))


def grid_scene(path, cols=40, rows=25):
    """cols x rows vertices; squares braced in even rows; the bottom row pinned."""
    vid = lambda c, r: r * cols + c + 1
    vertices = ["[%d,%d]" % (c, r) for r in range(rows) for c in range(cols)]
    edges = []
    for r in range(rows):
        for c in range(cols):
            if c + 1 < cols:
                edges.append((vid(c, r), vid(c + 1, r)))
            if r + 1 < rows:
                edges.append((vid(c, r), vid(c, r + 1)))
            if c + 1 < cols and r + 1 < rows and r % 2 == 0:
                edges.append((vid(c, r), vid(c + 1, r + 1)))
    with open(path, "w") as f:
        f.write('title = "Grid of %d vertices, every other row unbraced"\n[system]\ntype = "framework"\n' % (cols * rows))
        f.write("vertices = [%s]\n" % ",".join(vertices))
        f.write("edges = [%s]\n" % ",".join("[%d,%d]" % e for e in edges))
        f.write("pinned = [%s]\n" % ",".join(str(vid(c, 0)) for c in range(cols)))
        f.write("[motion]\nsteps = 40\nstep_size = 0.05\n[render]\nlabels = false\nvertex_size = 5\nline_width = 1.5\n")


def drag_latency(flexure, scene, name, vertex, direction, moves, start_sample=0):
    """Drags `vertex` (0-based) of sample `start_sample` with pointer moves of 3 CSS pixels along
    `direction` (unit, frame pixels) and back: first one move at a time (each waits for its
    frame, as the slider benchmark does), then a stream of moves at 60 Hz, the way a hand moves
    (each latency then includes waiting for the request before it). Prints both."""
    viewer = Viewer(flexure, scene, "--quiet")
    driver = chromium(1800, 1100)
    try:
        driver.get(viewer.url + "?size=800")
        wait_for(lambda: driver.execute_script("return window.flexureStats.shown"), timeout=120, what="the first frame")
        frame = driver.find_element(By.ID, "frame")
        driver.execute_script("const s = document.getElementById('slider'); s.value = arguments[0];"
                              "s.dispatchEvent(new Event('input', {bubbles: true}));", start_sample)
        wait_for(lambda: driver.execute_script("return window.flexureStats.shown.sample") == start_sample, what="the sample")
        state = json.load(urllib.request.urlopen(viewer.url + "api/state"))
        r = driver.execute_script("const r = arguments[0].getBoundingClientRect(); return [r.width, r.height]", frame)
        k = r[0] / 800.0
        sx, sy = state["screen"][vertex]
        x, y = int(round(sx * k - r[0] / 2)), int(round(sy * k - r[1] / 2))
        step = (round(3 * direction[0]), round(3 * direction[1]))
        half = max(1, moves // 2)
        sign = lambda i: 1 if (i // half) % 2 == 0 else -1
        ActionChains(driver, duration=0).move_to_element_with_offset(frame, x, y).click_and_hold().perform()
        count = lambda: driver.execute_script("return window.flexureStats.drags")
        for i in range(moves):
            before = count()
            ActionChains(driver, duration=0).move_by_offset(sign(i) * step[0], sign(i) * step[1]).perform()
            wait_for(lambda: count() > before, timeout=20, what="the frame of drag move %d" % i)
            time.sleep(0.02)
        ActionChains(driver, duration=0).release().perform()
        stats = lambda key: driver.execute_script("return window.flexureStats." + key)[-moves:]
        summary("pointer move -> dragged frame (%s)" % name, stats("dragLatencies"))
        summary("  of which: POST /api/drag (drag + state)", [p["post"] for p in stats("dragPosts")])
        for key, label in (("fetch", "  GET /frame.png"), ("decode", "  PNG decode"),
                           ("paint", "  until the next animation frame")):
            summary(label, [p[key] for p in stats("dragParts")])
        state = json.load(urllib.request.urlopen(viewer.url + "api/state"))
        print("  server: the last drag took %.1f ms, %d move(s); residual %.1e" %
              (state["drag"]["milliseconds"], state["drag"]["moves"], state["residual"]))
        # A stream at 60 Hz.
        done = count()
        ActionChains(driver, duration=0).move_to_element_with_offset(frame, x, y).click_and_hold().perform()
        chain = ActionChains(driver, duration=16)
        for i in range(moves):
            chain = chain.move_by_offset(sign(i) * step[0], sign(i) * step[1])
        chain.release().perform()
        time.sleep(1.5)
        streamed = driver.execute_script("return window.flexureStats.dragLatencies")[-(count() - done):]
        summary("  60 Hz stream: pointer move -> frame", streamed)
        print("  60 Hz stream: %d frames for %d pointer moves" % (len(streamed), moves))
    finally:
        quit_chromium(driver)
        viewer.close()


def main():
    flexure, examples = sys.argv[1], sys.argv[2]
    moves = int(sys.argv[3]) if len(sys.argv) > 3 else 100
    viewer = Viewer(flexure, os.path.join(examples, "double_watt.toml"), "--quiet")
    driver = chromium()
    try:
        driver.get(viewer.url + "?size=800")
        wait_for(lambda: driver.execute_script("return window.flexureStats.shown"), what="the first frame")
        rng = random.Random(1)
        for labels in (True,):
            for i in range(moves + 5):
                before = driver.execute_script("return window.flexureStats.frames")
                k = rng.randrange(0, 501)
                driver.execute_script(
                    "const s = document.getElementById('slider'); s.value = arguments[0];"
                    "s.dispatchEvent(new Event('input', {bubbles: true}));", k)
                wait_for(lambda: driver.execute_script("return window.flexureStats.frames") > before, timeout=10,
                         what="frame %d" % i)
        latencies = driver.execute_script("return window.flexureStats.latencies")[-moves:]
        summary("slider move -> frame on screen (800x800)", latencies)
        parts = driver.execute_script("return window.flexureStats.parts")[-moves:]
        for key, name in (("wait", "  of which: waiting for the previous frame"), ("fetch", "  request + response"),
                          ("decode", "  PNG decode"), ("paint", "  until the next animation frame")):
            summary(name, [p[key] for p in parts])
        # The server's part alone.
        times = []
        for i in range(moves):
            url = viewer.url + "frame.png?sample=%d&w=800&h=800" % rng.randrange(0, 501)
            t0 = time.perf_counter()
            data = urllib.request.urlopen(url).read()
            times.append(1e3 * (time.perf_counter() - t0))
        summary("GET /frame.png 800x800 (%d KB)" % (len(data) // 1024), times)
    finally:
        quit_chromium(driver)
        viewer.close()
    # Dragging: vertex 4 of the double Watt (it moves up and down along its curve), and a top
    # vertex of the 1,000-vertex grid (sideways: the unbraced rows shear).
    if not os.environ.get("FLEXURE_BENCH_GRID_ONLY"):
        drag_latency(flexure, os.path.join(examples, "double_watt.toml"), "double Watt, 800x800", 3, (0.0, -1.0), moves,
                     100)
    work = tempfile.mkdtemp(prefix="flexure-bench-")
    try:
        grid = os.path.join(work, "grid1000.toml")
        grid_scene(grid)
        drag_latency(flexure, grid, "1,000-vertex grid, 800x800", 980, (-1.0, 0.0), moves)
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
