#!/usr/bin/env python3
"""End-to-end test of `flexure view` in a real headless browser (Debian's Chromium, driven by
ChromeDriver through Selenium): load the page, move the slider and see the picture change, edit
the scene file and see the page follow, break it and see the error with its line and column
while the last good state stays, recompute with the motion controls and save the scene, orbit
a 3D scene, and stop the server with Ctrl-C. Direct manipulation: drag vertices of the double
Watt and of a 3D framework with the pointer (every state read through the API satisfies the
constraints, pins stay), drag a parallelogram four-bar through its flat position (the branch
closest to the pointer is kept), follow another branch at a singular point, track from and
save the dragged configuration, and load what was saved.

usage: viewer_e2e.py FLEXURE_BINARY EXAMPLES_DIR"""
import hashlib
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
import urllib.request

from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.by import By

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from browser import Viewer, chromium, quit_chromium, wait_for  # noqa: E402


def digest(element):
    return hashlib.sha256(element.screenshot_as_png).hexdigest()


def shown(driver):
    return driver.execute_script("return window.flexureStats && window.flexureStats.shown")


def check(condition, message):
    if not condition:
        raise AssertionError(message)
    print("ok -", message)


def test_2d(flexure, examples, work, driver):
    scene = os.path.join(work, "double_watt.toml")
    shutil.copy(os.path.join(examples, "double_watt.toml"), scene)
    with open(scene) as f:
        original = f.read()
    viewer = Viewer(flexure, scene, "--quiet")
    try:
        driver.get(viewer.url)
        frame = driver.find_element(By.ID, "frame")
        wait_for(lambda: shown(driver) and shown(driver)["sample"] == 0, what="the first frame")
        check(driver.find_element(By.ID, "title").text == "Cuspidal double Watt mechanism", "the page shows the title")
        slider = driver.find_element(By.ID, "slider")
        check(slider.get_attribute("max") == "500", "the slider spans the 501 samples")
        report = driver.find_element(By.ID, "report").text
        check("rigid:" in report and "flexible" in report, "the rigidity report is beside the picture")
        before = digest(frame)

        # Move the slider the way a user does: focus it and press keys.
        slider.click()
        slider.send_keys("\ue010")  # End: the last sample
        wait_for(lambda: shown(driver)["sample"] == 500, what="the frame of the last sample")
        after = digest(frame)
        check(after != before, "moving the slider changes the picture")
        check(driver.find_element(By.ID, "projection").get_attribute("data-sample") == "500",
              "the projection plot's marker follows the slider")
        check(driver.find_element(By.ID, "count").text == "sample 500 / 500", "the sample number is shown")

        # Toggles: flex arrows change the picture.
        driver.find_element(By.ID, "flex").click()
        wait_for(lambda: digest(frame) != after, what="the flex arrows")
        print("ok - the flex-arrow toggle redraws")

        # Edit the scene file: a new title and fewer steps.
        edited = original.replace('title = "Cuspidal double Watt mechanism"', 'title = "Edited double Watt"')
        edited = edited.replace("steps = 500", "steps = 200")
        check(edited != original, "the edit changes the file")
        with open(scene, "w") as f:
            f.write(edited)
        wait_for(lambda: driver.find_element(By.ID, "title").text == "Edited double Watt", what="the edited title")
        wait_for(lambda: slider.get_attribute("max") == "200", what="the slider of the recomputed path")
        check(True, "editing the scene file updates the page (title, 201 samples)")
        wait_for(lambda: shown(driver)["sample"] == 200, what="the frame clamped to the new last sample")

        # A syntax error: reported with its line and column; the last good state stays.
        lines = edited.split("\n")
        n = next(i for i, l in enumerate(lines) if l.startswith("edges"))
        lines[n] = "edges = [[1,2],, [2,3]]"
        with open(scene, "w") as f:
            f.write("\n".join(lines))
        error = driver.find_element(By.ID, "error")
        wait_for(lambda: error.is_displayed(), what="the error box")
        text = driver.find_element(By.ID, "error-text").text
        check(text.startswith(scene + ":%d:" % (n + 1)), "the syntax error names the file and line %d: %s" % (n + 1, text))
        column = int(text.split(":")[2])
        check(column == lines[n].index(",,") + 2, "... and the column of the stray comma (%d)" % column)
        excerpt = driver.find_element(By.ID, "error-line").text
        check("edges = [[1,2],, [2,3]]" in excerpt and "^" in excerpt, "the offending line is quoted with a caret")
        check(driver.find_element(By.ID, "title").text == "Edited double Watt", "the last good state stays visible")
        check("last good state" in driver.find_element(By.ID, "error-kept").text, "... and the page says so")

        # A scene error that is not syntax (a vertex index out of range) is located too.
        lines[n] = "edges = [[1,2],[2,99]]"
        with open(scene, "w") as f:
            f.write("\n".join(lines))
        wait_for(lambda: ":%d:" % (n + 1) in driver.find_element(By.ID, "error-text").text
                 and "99" in driver.find_element(By.ID, "error-text").text, what="the semantic error")
        check(True, "a semantic error is reported at its line: " + driver.find_element(By.ID, "error-text").text)

        # Fixed again: the error goes away.
        with open(scene, "w") as f:
            f.write(edited)
        wait_for(lambda: not error.is_displayed(), what="the error box to go")
        check(True, "fixing the file clears the error")

        # Motion controls: 80 steps of 0.04, recomputed; then saved as a scene file.
        steps = driver.find_element(By.ID, "steps")
        steps.clear()
        steps.send_keys("80")
        size = driver.find_element(By.ID, "step_size")
        size.clear()
        size.send_keys("0.04")
        driver.find_element(By.ID, "apply").click()
        wait_for(lambda: slider.get_attribute("max") == "80", what="the recomputed path of 80 steps")
        check(True, "the motion controls recompute the path")
        name = driver.find_element(By.ID, "savename")
        name.clear()
        name.send_keys("../escape.toml")
        driver.find_element(By.ID, "save").click()
        wait_for(lambda: "file name" in driver.find_element(By.ID, "save-msg").text, what="the refused name")
        check(not os.path.exists(os.path.join(os.path.dirname(work), "escape.toml")), "save as refuses a path")
        name.clear()
        name.send_keys("saved.toml")
        driver.find_element(By.ID, "save").click()
        saved = os.path.join(work, "saved.toml")
        wait_for(lambda: "saved" in driver.find_element(By.ID, "save-msg").text, what="the save")
        with open(saved) as f:
            text = f.read()
        check("steps = 80" in text and "step_size = 0.04" in text and "# " in text,
              "the saved scene has the new motion and keeps the file's comments")
        out = subprocess.run([flexure, "track", saved, "-o", os.path.join(work, "saved_path.json")],
                             capture_output=True, text=True)
        check(out.returncode == 0 and "80/80" in out.stdout, "the saved scene tracks the same motion: " + out.stdout.split("\n")[0])

        status, err = viewer.interrupt()
        check(status == 0 and "stopped" in err, "Ctrl-C stops the viewer cleanly (exit 0)")
    finally:
        viewer.close()


def api(viewer, path="api/state"):
    with urllib.request.urlopen(viewer.url + path) as r:
        return json.load(r)


def to_css(driver, frame, px, py):
    """Offsets from the frame's centre (what ActionChains takes) of frame pixel (px, py)."""
    r = wait_for(lambda: driver.execute_script(
        "const r = arguments[0].getBoundingClientRect(), d = arguments[0].dataset;"
        "return d.w > 0 ? [r.width, r.height, Number(d.w), Number(d.h)] : null", frame), what="the frame's size")
    return int(round(px * r[0] / r[2] - r[0] / 2)), int(round(py * r[1] / r[3] - r[1] / 2))


def settle(driver, viewer):
    """The drag requests have been answered and their frame shown; returns the state."""
    wait_for(lambda: driver.execute_script("return !window.flexureStats || true"), what="the page")
    time.sleep(0.3)
    wait_for(lambda: driver.execute_script("return document.getElementById('frame').dataset.dragged") == "1",
             what="the dragged frame")
    return api(viewer)


def drag_through(driver, frame, start, points):
    """Presses at frame pixel `start` and moves through the frame pixels `points`."""
    x, y = to_css(driver, frame, *start)
    chain = ActionChains(driver, duration=15).move_to_element_with_offset(frame, x, y).click_and_hold()
    for p in points:
        nx, ny = to_css(driver, frame, *p)
        chain = chain.move_by_offset(nx - x, ny - y)
        x, y = nx, ny
    chain.release().perform()


def go_to(driver, k):
    """Moves the slider to sample k as its input event does, and waits for the frame."""
    driver.execute_script("const s = document.getElementById('slider'); s.value = arguments[0];"
                          "s.dispatchEvent(new Event('input', {bubbles: true}));", k)
    wait_for(lambda: shown(driver)["sample"] == k, what="the frame of sample %d" % k)


def open_page(driver, viewer, query=""):
    """Loads the page; returns the frame element once the first frame is shown."""
    driver.get(viewer.url + query)
    wait_for(lambda: shown(driver) and shown(driver)["sample"] == 0, what="the first frame")
    return driver.find_element(By.ID, "frame")


def edge_residual(state, edges, base=1):
    v = state["vertices"]
    return max(abs(math.dist(v[a - base], v[b - base]) - l) for (a, b), l in edges.items())


def test_drag_2d(flexure, examples, work, driver):
    scene = os.path.join(work, "double_watt.toml")
    shutil.copy(os.path.join(examples, "double_watt.toml"), scene)
    viewer = Viewer(flexure, scene, "--quiet")
    try:
        frame = open_page(driver, viewer)
        go_to(driver, 100)
        start = api(viewer)
        check(start["view"]["sample"] == 100 and not start["view"]["dragged"], "the API reports the frame shown")
        edges = {tuple(e): math.dist(start["vertices"][e[0] - 1], start["vertices"][e[1] - 1])
                 for e in [[1, 2], [2, 3], [2, 4], [3, 9], [3, 4], [3, 5], [4, 5], [5, 6], [6, 7], [7, 8], [7, 9],
                           [8, 9], [8, 10], [9, 10], [10, 11]]}
        before = digest(frame)
        sx, sy = start["screen"][3]  # vertex 4
        drag_through(driver, frame, (sx, sy), [(sx + 2 * i, sy - 4 * i) for i in range(1, 16)])
        state = settle(driver, viewer)
        check(state["view"]["dragged"] and state["drag"]["vertex"] == 4, "the pointer dragged vertex 4")
        check(math.dist(state["screen"][3], (sx, sy)) > 10, "vertex 4 moved on screen (%.0f px)" % math.dist(state["screen"][3], (sx, sy)))
        wait_for(lambda: digest(frame) != before, what="the dragged picture")
        check(True, "the picture shows the dragged configuration")
        check(state["residual"] <= 1e-10 and edge_residual(state, edges) <= 1e-9,
              "the dragged configuration keeps every bar length (residual %.1e)" % state["residual"])
        check(all(state["vertices"][i] == start["vertices"][i] for i in (0, 5, 10)), "the pinned vertices 1, 6, 11 stay")
        check(driver.execute_script("return window.flexureStats.drags") > 0, "the page measured its drag frames")
        # A pull the mechanism cannot follow: vertex 2 straight away from pinned vertex 1.
        s2 = state["screen"]
        ax, ay = s2[1]
        ux, uy = ax - s2[0][0], ay - s2[0][1]
        drag_through(driver, frame, (ax, ay), [(ax + ux * 0.1 * i, ay + uy * 0.1 * i) for i in range(1, 8)])
        # The press resolves its vertex through the API first: wait for this drag's answer.
        wait_for(lambda: (api(viewer)["drag"] or {}).get("vertex") == 2, what="the drag of vertex 2")
        time.sleep(0.5)
        held = api(viewer)
        check(not held["drag"]["reached"] and held["drag"]["held"][0]["constraint"] == "edge 1-2",
              "pulling vertex 2 off its crank is held, and the page names the bar: " + driver.find_element(By.ID, "dragtext").text)
        check(edge_residual(held, edges) <= 1e-9, "... and the held state keeps the bar lengths")

        # Keyboard: L toggles the labels, Esc goes back to the path.
        labels = driver.find_element(By.ID, "labels").is_selected()
        driver.find_element(By.TAG_NAME, "body").send_keys("l")
        check(driver.find_element(By.ID, "labels").is_selected() != labels, "the L key toggles the labels")
        driver.find_element(By.TAG_NAME, "body").send_keys("l")

        # Track from the dragged configuration: the new path starts there.
        dragged = held["vertices"]
        driver.find_element(By.ID, "trackhere").click()
        wait_for(lambda: api(viewer)["loaded"]["generation"] != held["loaded"]["generation"] and not api(viewer)["computing"],
                 what="the path from the dragged start")
        wait_for(lambda: shown(driver)["generation"] == api(viewer)["loaded"]["generation"], what="its frame")
        go_to(driver, 0)
        fresh = api(viewer)
        check(max(math.dist(a, b) for a, b in zip(fresh["vertices"], dragged)) <= 1e-12,
              "track from here: sample 0 of the new path is the dragged configuration")
        check(fresh["loaded"]["samples"] > 1, "... and the motion is tracked from it (%d samples)" % fresh["loaded"]["samples"])

        # Save as: the file keeps its comments and starts at the dragged configuration.
        name = driver.find_element(By.ID, "savename")
        name.clear()
        name.send_keys("dragged.toml")
        driver.find_element(By.ID, "save").click()
        wait_for(lambda: "saved" in driver.find_element(By.ID, "save-msg").text, what="the save")
        saved = os.path.join(work, "dragged.toml")
        with open(saved) as f:
            text = f.read()
        check("# " in text and "vertices" in text, "the saved scene keeps the comments")
        out = os.path.join(work, "dragged_path.json")
        subprocess.run([flexure, "track", saved, "-o", out, "--set", "motion.steps=3"], check=True, capture_output=True)
        with open(out) as f:
            reloaded = json.load(f)["samples"][0]
        check(max(math.dist(a, b) for a, b in zip(reloaded, dragged)) <= 1e-12,
              "save as, then reload: the saved scene starts at the dragged configuration")

        # Exports: the path as JSON and CSV, the frame as PNG, the scene as TOML.
        with urllib.request.urlopen(viewer.url + "path.json") as r:
            check("attachment" in r.headers["Content-Disposition"] and len(json.load(r)["samples"]) == fresh["loaded"]["samples"],
                  "the path exports as JSON")
        with urllib.request.urlopen(viewer.url + "path.csv") as r:
            check(r.read().decode().startswith("sample,"), "the path exports as CSV")
        png_href = driver.find_element(By.ID, "export-png").get_attribute("href")
        with urllib.request.urlopen(png_href) as r:
            check(r.read(8) == b"\x89PNG\r\n\x1a\n" and "attachment" in r.headers["Content-Disposition"],
                  "the frame exports as PNG")
        for ext, head in (("svg", b"<?xml"), ("pdf", b"%PDF-"), ("tex", b"% ")):
            href = driver.find_element(By.ID, "export-" + ext).get_attribute("href")
            with urllib.request.urlopen(href) as r:
                check(r.read(5).startswith(head) and "attachment" in r.headers["Content-Disposition"],
                      "the frame exports as " + ext.upper())
    finally:
        viewer.close()


FOUR_BAR = """title = "Parallelogram four-bar with a triangle on its coupler"
# Cranks 1-3 and 2-4 of length 1 on the base 1-2 of length 2; the coupler 3-4 carries vertex 5.
[system]
type = "framework"
vertices = [[0,0],[2,0],[{c},{s}],[{c2},{s}],[{c1},{s1}]]
edges = [[1,3],[2,4],[3,4],[3,5],[4,5]]
pinned = [1,2]

[motion]
steps = 60
step_size = 0.02
"""


def four_bar(theta):
    c, s = math.cos(theta), math.sin(theta)
    return FOUR_BAR.format(c=repr(c), s=repr(s), c2=repr(2 + c), c1=repr(1 + c), s1=repr(1 + s))


def crank_angles(state):
    v = state["vertices"]
    return math.atan2(v[2][1], v[2][0]), math.atan2(v[3][1], v[3][0] - 2)


def pixel_map(state):
    """World -> frame pixels of a 2D scene without alignment (pinned): px = a x + b, py = -a y + c."""
    (x0, y0), (x1, y1) = state["vertices"][0], state["vertices"][1]
    (p0, q0), (p1, q1) = state["screen"][0], state["screen"][1]
    a = (p1 - p0) / (x1 - x0)
    return lambda x, y: (p0 + a * (x - x0), q0 - a * (y - y0))


def test_four_bar(flexure, examples, work, driver):
    edges = {(1, 3): 1.0, (2, 4): 1.0, (3, 4): 2.0, (3, 5): math.sqrt(2), (4, 5): math.sqrt(2)}
    # Up through the flat position along vertex 5's arc on the parallelogram: the branch closest
    # to the pointer is the parallelogram (the antiparallelogram moves vertex 5 sideways there).
    scene = os.path.join(work, "four_bar.toml")
    with open(scene, "w") as f:
        f.write(four_bar(-0.3))
    viewer = Viewer(flexure, scene, "--quiet")
    try:
        frame = open_page(driver, viewer, "?size=800")
        state = api(viewer)
        world = pixel_map(state)
        arc = [world(1 + math.cos(t), 1 + math.sin(t)) for t in [-0.3 + 0.6 * i / 30 for i in range(1, 31)]]
        drag_through(driver, frame, state["screen"][4], arc)
        state = settle(driver, viewer)
        t, p = crank_angles(state)
        check(state["drag"]["vertex"] == 5, "the pointer took vertex 5")
        check(abs(t - p) <= 1e-9 and t > 0.2,
              "dragged up through the flat position, the four-bar stays a parallelogram (theta %.3f, phi %.3f)" % (t, p))
        check(edge_residual(state, edges) <= 1e-9, "... every bar keeps its length")
    finally:
        viewer.close()
    # Sideways from the flat position: only the antiparallelogram carries vertex 5 right.
    with open(scene, "w") as f:
        f.write(four_bar(0.0))
    viewer = Viewer(flexure, scene, "--quiet")
    try:
        frame = open_page(driver, viewer, "?size=800")
        state = api(viewer)
        world = pixel_map(state)
        drag_through(driver, frame, state["screen"][4], [world(2 + 0.01 * i, 1 - 0.004 * i) for i in range(1, 16)])
        state = settle(driver, viewer)
        t, p = crank_angles(state)
        check(state["drag"]["vertex"] == 5, "the pointer took vertex 5")
        check(state["vertices"][4][0] > 2.08 and abs(t - p) > 0.02,
              "dragged sideways at the flat position, it takes the antiparallelogram (theta %.3f, phi %.3f)" % (t, p))
        check(edge_residual(state, edges) <= 1e-9, "... every bar keeps its length")
        # The singular start lists its branch directions; continuing along another one retracks.
        points = state["loaded"]["branches"]
        check(points and points[0]["sample"] == 0 and len(points[0]["directions"]) == 4,
              "the page lists the four half-branches leaving the flat position")
        buttons = driver.find_elements(By.CSS_SELECTOR, "#branches button")
        check(len(buttons) >= 4, "... each with a button to continue along it")
        generation = state["loaded"]["generation"]
        buttons[1].click()
        wait_for(lambda: api(viewer)["loaded"]["generation"] != generation and not api(viewer)["computing"],
                 what="the path along the chosen branch")
        after = api(viewer)["loaded"]
        check("from sample 0 along branch direction 1" in after["motion"]["flex_note"] and after["samples"] > 1,
              "continuing along branch direction 2 tracks a new path: " + after["motion"]["flex_note"])
    finally:
        viewer.close()


def test_3d(flexure, examples, work, driver):
    scene = os.path.join(work, "coned_cube.toml")
    shutil.copy(os.path.join(examples, "coned_cube.toml"), scene)
    viewer = Viewer(flexure, scene, "--quiet")
    try:
        driver.get(viewer.url)
        frame = driver.find_element(By.ID, "frame")
        wait_for(lambda: shown(driver) and shown(driver)["sample"] == 0, what="the first 3D frame")
        before = digest(frame)
        frames = driver.execute_script("return window.flexureStats.frames")
        x, y = to_css(driver, frame, 15, 15)  # a corner: no vertex there
        ActionChains(driver).move_to_element_with_offset(frame, x, y).click_and_hold().move_by_offset(120, 40).release().perform()
        wait_for(lambda: driver.execute_script("return window.flexureStats.frames") > frames, what="an orbited frame")
        wait_for(lambda: digest(frame) != before, what="the orbited picture")
        check(True, "dragging orbits the 3D scene")
        orbited = digest(frame)
        driver.execute_script("document.getElementById('stage').dispatchEvent(new WheelEvent('wheel', {deltaY: -400, bubbles: true, cancelable: true}))")
        wait_for(lambda: digest(frame) != orbited, what="the zoomed picture")
        check(True, "the wheel zooms")
    finally:
        viewer.close()
    # Drag a vertex of a 3D framework (the Bricard octahedron, three vertices pinned).
    scene = os.path.join(work, "bricard.toml")
    shutil.copy(os.path.join(examples, "bricard_octahedron.toml"), scene)
    viewer = Viewer(flexure, scene, "--quiet", "--set", "system.pinned=[1,2,5]")
    try:
        frame = open_page(driver, viewer)
        start = api(viewer)
        edges = {tuple(e): math.dist(start["vertices"][e[0] - 1], start["vertices"][e[1] - 1])
                 for e in [[1, 2], [1, 3], [1, 4], [1, 5], [2, 6], [3, 6], [4, 6], [5, 6], [2, 4], [4, 3], [3, 5], [5, 2]]}
        # One flex: each vertex moves along a curve. Drag the free vertex that moves most on
        # screen (vertex 6 is still to first order at this start), the way the path goes.
        go_to(driver, 10)
        later = api(viewer)["screen"]
        i = max((2, 3, 5), key=lambda j: math.dist(later[j], start["screen"][j]))
        ahead = later[i]
        go_to(driver, 0)
        before = digest(frame)
        sx, sy = start["screen"][i]
        n = math.dist(ahead, (sx, sy))
        ux, uy = (ahead[0] - sx) / n, (ahead[1] - sy) / n
        drag_through(driver, frame, (sx, sy), [(sx + 4 * i * ux, sy + 4 * i * uy) for i in range(1, 12)])
        state = settle(driver, viewer)
        wait_for(lambda: digest(frame) != before, what="the dragged 3D picture")
        moved = math.dist(state["vertices"][i], start["vertices"][i])
        check(state["drag"]["vertex"] == i + 1 and moved > 0.01,
              "dragging vertex %d of the 3D framework moves it (%.3f)" % (i + 1, moved))
        check(edge_residual(state, edges) <= 1e-9 and state["residual"] <= 1e-10,
              "the 3D drag keeps every bar length (residual %.1e)" % state["residual"])
        check(all(state["vertices"][i] == start["vertices"][i] for i in (0, 1, 4)), "the pinned vertices 1, 2, 5 stay")
    finally:
        viewer.close()


def main():
    flexure, examples = sys.argv[1], sys.argv[2]
    work = tempfile.mkdtemp(prefix="flexure-view-e2e-")
    driver = chromium()
    try:
        for part, test in (("a", test_2d), ("b", test_3d), ("c", test_drag_2d), ("d", test_four_bar)):
            os.makedirs(os.path.join(work, part))
            test(flexure, examples, os.path.join(work, part), driver)
    finally:
        quit_chromium(driver)
        shutil.rmtree(work, ignore_errors=True)
    print("viewer end-to-end: all passed")


if __name__ == "__main__":
    main()
