#!/usr/bin/env python3
"""Viewer latency: from a slider move to the new frame on screen, for the double Watt at
800x800, in headless Chromium (the page measures it: from the slider's input event to the
animation frame after the new image has been decoded). Also the bare HTTP time of one frame
(render + PNG encode + transfer). usage: viewer_latency.py FLEXURE_BINARY EXAMPLES_DIR [MOVES]"""
import os
import random
import statistics
import sys
import time
import urllib.request

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "viewer"))
from browser import Viewer, chromium, quit_chromium, wait_for  # noqa: E402


def summary(name, xs):
    xs = sorted(xs)
    p = lambda q: xs[min(len(xs) - 1, int(q * len(xs)))]
    print("%-44s n=%d  median %.1f ms  p90 %.1f ms  max %.1f ms" % (name, len(xs), statistics.median(xs), p(0.9), xs[-1]))


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


if __name__ == "__main__":
    main()
