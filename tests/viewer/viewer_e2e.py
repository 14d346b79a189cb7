#!/usr/bin/env python3
"""End-to-end test of `flexure view` in a real headless browser (Debian's Chromium, driven by
ChromeDriver through Selenium): load the page, move the slider and see the picture change, edit
the scene file and see the page follow, break it and see the error with its line and column
while the last good state stays, recompute with the motion controls and save the scene, orbit
a 3D scene, and stop the server with Ctrl-C.

usage: viewer_e2e.py FLEXURE_BINARY EXAMPLES_DIR"""
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile

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
        ActionChains(driver).move_to_element(frame).click_and_hold().move_by_offset(120, 40).release().perform()
        wait_for(lambda: driver.execute_script("return window.flexureStats.frames") > frames, what="an orbited frame")
        wait_for(lambda: digest(frame) != before, what="the orbited picture")
        check(True, "dragging orbits the 3D scene")
        orbited = digest(frame)
        driver.execute_script("document.getElementById('stage').dispatchEvent(new WheelEvent('wheel', {deltaY: -400, bubbles: true, cancelable: true}))")
        wait_for(lambda: digest(frame) != orbited, what="the zoomed picture")
        check(True, "the wheel zooms")
    finally:
        viewer.close()


def main():
    flexure, examples = sys.argv[1], sys.argv[2]
    work = tempfile.mkdtemp(prefix="flexure-view-e2e-")
    driver = chromium()
    try:
        for part, test in (("a", test_2d), ("b", test_3d)):
            os.makedirs(os.path.join(work, part))
            test(flexure, examples, os.path.join(work, part), driver)
    finally:
        quit_chromium(driver)
        shutil.rmtree(work, ignore_errors=True)
    print("viewer end-to-end: all passed")


if __name__ == "__main__":
    main()
