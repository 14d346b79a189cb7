import os
import subprocess

import pytest

SOURCE = os.environ.get("FLEXURE_SOURCE", os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..")))
EXAMPLES = os.path.join(SOURCE, "scenes", "examples")


def _exe():
    exe = os.path.abspath(os.environ.get("FLEXURE_EXE") or os.path.join(SOURCE, "build", "flexure"))
    if not os.path.exists(exe):
        raise RuntimeError(f"no flexure executable at {exe} (set FLEXURE_EXE)")
    return exe


@pytest.fixture(scope="session")
def cli():
    """Runs the flexure executable in a directory; returns its stdout (bytes), asserting exit 0."""
    exe = _exe()

    def run(args, cwd, check=True):
        r = subprocess.run([exe, *args], cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        if check and r.returncode != 0:
            raise AssertionError(f"flexure {' '.join(args)} exited {r.returncode}: {r.stderr.decode()}")
        return r.stdout

    return run
