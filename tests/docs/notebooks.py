#!/usr/bin/python3
"""Runs every notebook of docs/ (docs/tutorial.ipynb) with Debian's Jupyter, and fails on any error.

    tests/docs/notebooks.py --pythonpath build/python [--root .] [--jupyter /usr/bin/jupyter]
                            [--timeout 300] [--only tutorial.ipynb] [--keep]

Standard library only; needs Debian's jupyter-nbconvert, python3-nbclient, python3-ipykernel
and python3-matplotlib (scripts/setup installs them). For each notebook:

1. It must be committed without outputs: no code cell with outputs or an execution count
   (`jupyter nbconvert --clear-output --inplace docs/NAME.ipynb` strips one), so that the
   repository stays small and the file the same from run to run.
2. A copy in a temporary folder (where the files it writes go) is run by
   `jupyter nbconvert --to notebook --execute`, cell by cell, with a kernel of this test's own:
   the interpreter running this script (/usr/bin/python3) with --pythonpath on PYTHONPATH and
   MPLBACKEND=Agg, whatever kernels and configuration the user has.
3. The executed copy must have run every code cell, hold no error, and show a PNG in every cell
   that shows a picture (`plt.show()`, `Image(...)`).

Exit 0 when every notebook passes; 1 naming the notebook and the cell that failed (with
nbconvert's output, whose end has the cell's traceback); 2 for a usage error.
"""

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

PACKAGES = "jupyter-nbconvert python3-nbclient python3-ipykernel python3-matplotlib"
KERNEL = "flexure-test-python3"
ANSI = re.compile(r"\x1b\[[0-9;]*m")  # the colours of IPython's tracebacks
SHOWS_PICTURE = ("plt.show()", "Image(")


class Failure(Exception):
    pass


def source(cell):
    s = cell.get("source", "")
    return "".join(s) if isinstance(s, list) else s


def check_stripped(name, nb):
    for i, cell in enumerate(nb["cells"]):
        if cell["cell_type"] != "code":
            continue
        if cell.get("outputs") or cell.get("execution_count") is not None:
            raise Failure(f"{name}: cell {i} is committed with its outputs; strip them: "
                          f"jupyter nbconvert --clear-output --inplace {name}")


def check_executed(name, nb):
    code = pictures = 0
    for i, cell in enumerate(nb["cells"]):
        if cell["cell_type"] != "code":
            continue
        code += 1
        where = f"{name}, cell {i} ({source(cell).strip().splitlines()[0][:60]!r})"
        if cell.get("execution_count") is None:
            raise Failure(f"{where} did not run")
        outputs = cell.get("outputs", [])
        for o in outputs:
            if o.get("output_type") == "error":
                raise Failure(f"{where} raised {o.get('ename')}: {o.get('evalue')}")
        if any(p in source(cell) for p in SHOWS_PICTURE):
            if not any("image/png" in o.get("data", {}) for o in outputs):
                raise Failure(f"{where} shows a picture, but has no PNG output "
                              f"(outputs: {[o.get('output_type') for o in outputs]})")
            pictures += 1
    return code, pictures


def kernel_env(tmp, pythonpath):
    """The environment of nbconvert and the kernel: a kernelspec of this test's own (this
    interpreter) found first, and Jupyter's and IPython's files in tmp, not the user's."""
    spec_dir = os.path.join(tmp, "jupyter", "kernels", KERNEL)
    os.makedirs(spec_dir)
    env = dict(os.environ)
    env["PYTHONPATH"] = pythonpath + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    env["MPLBACKEND"] = "Agg"
    env["LC_ALL"] = "C.UTF-8"
    with open(os.path.join(spec_dir, "kernel.json"), "w", encoding="utf-8") as f:
        # -Xfrozen_modules=off: else the kernel's debugger warns on every start
        json.dump({"argv": [sys.executable, "-Xfrozen_modules=off", "-m", "ipykernel_launcher", "-f",
                            "{connection_file}"],
                   "display_name": "Python 3 (flexure test)", "language": "python",
                   "env": {"PYTHONPATH": env["PYTHONPATH"], "MPLBACKEND": "Agg"}}, f)
    env["JUPYTER_PATH"] = os.path.join(tmp, "jupyter")
    env["JUPYTER_CONFIG_DIR"] = os.path.join(tmp, "config")
    env["JUPYTER_RUNTIME_DIR"] = os.path.join(tmp, "runtime")
    env["IPYTHONDIR"] = os.path.join(tmp, "ipython")
    return env


def run_notebook(args, name, tmp):
    path = os.path.join(args.root, name)
    with open(path, encoding="utf-8") as f:
        nb = json.load(f)
    check_stripped(name, nb)
    work = os.path.join(tmp, os.path.splitext(os.path.basename(name))[0])
    os.makedirs(work)
    copy = os.path.join(work, os.path.basename(name))
    shutil.copyfile(path, copy)
    cmd = [args.jupyter, "nbconvert", "--to", "notebook", "--execute", copy, "--output-dir", work,
           "--output", "executed.ipynb", f"--ExecutePreprocessor.kernel_name={KERNEL}",
           f"--ExecutePreprocessor.timeout={int(args.timeout)}"]
    t0 = time.time()
    try:
        p = subprocess.run(cmd, cwd=work, env=kernel_env(os.path.join(tmp, "env-" + os.path.basename(work)),
                                                           args.pythonpath),
                           stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                           timeout=args.timeout)
    except subprocess.TimeoutExpired:
        raise Failure(f"{name}: not done in {args.timeout} s")
    seconds = time.time() - t0
    out = ANSI.sub("", p.stdout.decode("utf-8", "replace"))
    if p.returncode != 0:
        raise Failure(f"{name}: `jupyter nbconvert --execute` exited {p.returncode}\n"
                      + "".join("    | " + l + "\n" for l in out.splitlines()[-40:]))
    with open(os.path.join(work, "executed.ipynb"), encoding="utf-8") as f:
        executed = json.load(f)
    code, pictures = check_executed(name, executed)
    return code, pictures, seconds


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--pythonpath", required=True, help="the built Python module's directory (build/python)")
    ap.add_argument("--root", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."),
                    help="the repository's root (default: two levels up from this script)")
    ap.add_argument("--jupyter", default="/usr/bin/jupyter", help="Debian's jupyter (default /usr/bin/jupyter)")
    ap.add_argument("--timeout", type=float, default=300, help="seconds per notebook, and per cell (default 300)")
    ap.add_argument("--only", action="append", help="run only this notebook (repeatable), e.g. tutorial.ipynb")
    ap.add_argument("--keep", action="store_true", help="keep the temporary folder (the executed notebooks)")
    args = ap.parse_args()
    args.root = os.path.abspath(args.root)
    args.pythonpath = os.path.abspath(args.pythonpath)
    if not os.path.isdir(os.path.join(args.pythonpath, "flexure")):
        ap.error(f"{args.pythonpath} holds no flexure package (build the Python module first)")
    if not os.access(args.jupyter, os.X_OK):
        print(f"FAIL {args.jupyter} is not there: install {PACKAGES} (scripts/setup does)", file=sys.stderr)
        return 1
    docs = os.path.join(args.root, "docs")
    names = sorted("docs/" + f for f in os.listdir(docs) if f.endswith(".ipynb"))
    if args.only:
        names = [n for n in names if n in args.only or os.path.basename(n) in args.only]
    if not names:
        print("FAIL no notebook to run in docs/", file=sys.stderr)
        return 1
    tmp = tempfile.mkdtemp(prefix="flexure-notebooks-")
    try:
        for name in names:
            try:
                code, pictures, seconds = run_notebook(args, name, tmp)
            except Failure as e:
                print(f"FAIL {e}", file=sys.stderr)
                return 1
            print(f"{name}: {code} code cells ran, {pictures} pictures shown ({seconds:.1f} s)")
    finally:
        if args.keep:
            print(f"kept {tmp}")
        else:
            shutil.rmtree(tmp, ignore_errors=True)
    print(f"all notebooks: {len(names)} ran")
    return 0


if __name__ == "__main__":
    sys.exit(main())
