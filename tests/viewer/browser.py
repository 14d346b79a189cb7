"""Shared by the viewer's end-to-end test and its latency benchmark: start `flexure view` on a
free loopback port, and Debian's Chromium (headless) through ChromeDriver with Selenium."""
import os
import re
import shutil
import signal
import subprocess
import tempfile
import time

from selenium import webdriver
from selenium.webdriver.chrome.service import Service


class Viewer:
    """`flexure view SCENE --port 0`; the address is read from its first line of output."""

    def __init__(self, flexure, scene, *extra):
        self.proc = subprocess.Popen([flexure, "view", scene, "--port", "0", *extra],
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        line = self.proc.stdout.readline()
        m = re.search(r"http://127\.0\.0\.1:(\d+)/", line)
        if not m:
            self.proc.kill()
            raise RuntimeError("flexure view printed no address: %r %r" % (line, self.proc.stderr.read()))
        self.url = m.group(0)

    def interrupt(self, timeout=10):
        """Ctrl-C; returns (exit status, stderr)."""
        self.proc.send_signal(signal.SIGINT)
        try:
            _, err = self.proc.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            raise RuntimeError("flexure view did not stop within %d s of SIGINT" % timeout)
        return self.proc.returncode, err

    def close(self):
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()


def chromium(width=1400, height=1000):
    """Headless Chromium; no network beyond loopback is tried (the flags the machine needs)."""
    profile = tempfile.mkdtemp(prefix="flexure-chromium-")
    options = webdriver.ChromeOptions()
    options.binary_location = os.environ.get("FLEXURE_CHROMIUM", "/usr/bin/chromium")
    for flag in ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync",
                 "--disable-dev-shm-usage", "--force-device-scale-factor=1",
                 "--window-size=%d,%d" % (width, height), "--user-data-dir=" + profile]:
        options.add_argument(flag)
    service = Service(os.environ.get("FLEXURE_CHROMEDRIVER", "/usr/bin/chromedriver"))
    driver = webdriver.Chrome(service=service, options=options)
    driver._flexure_profile = profile
    return driver


def quit_chromium(driver):
    profile = getattr(driver, "_flexure_profile", None)
    driver.quit()
    if profile:
        shutil.rmtree(profile, ignore_errors=True)


def wait_for(predicate, timeout=20.0, what="condition"):
    t0 = time.time()
    while time.time() - t0 < timeout:
        value = predicate()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError("timed out after %.0f s waiting for %s" % (timeout, what))
