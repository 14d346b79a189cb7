#!/usr/bin/env python3
"""Runs every fenced code block of README.md and docs/*.md, so that the documentation stays true.

    tests/docs/run.py --flexure build/flexure [--pythonpath build/python | --no-python] [--root .]
                      [--timeout 60] [--only README.md] [--verbose]

Standard library only (Python 3.11, /usr/bin/python3). Exit 0 when every block ran as its
document says; otherwise 1, with FILE:LINE (the command's line in a transcript, else the block's
opening fence) and what differed, or why the block cannot be run; 2 for a usage error.

Which blocks, and how
---------------------
The documents are README.md and docs/*.md (not the data under docs/study/). Every block is
run, or skipped by an explicit marker, or is a `text` block (a synopsis or a listing, not code);
an unlabelled fence is an error, so that nothing is left out silently. The runner prints, per
file, how many blocks ran and were skipped (with the reasons) and how many are text.

Each block runs in a fresh temporary directory laid out as the repository's root: copies of
scenes/examples/ and docs/study/, and build/flexure, build/flexure-draw and build/python as
links to what --flexure and --pythonpath name. The flexure binary's directory is first on PATH.

- ```sh, ```bash, ```shell and ```console blocks. When a line starts with "$ ", the block is a
  transcript: each "$ " line is a command (a line ending in "\\" continues on the next), and the
  lines up to the next command are its expected output (standard output and standard error, as
  one stream). Otherwise every line is a command (comment lines and blank lines skipped) and no
  output is compared. Each command is run by bash -c in the block's directory, so the files a
  command writes are there for the next one. A command must exit 0, unless a marker says
  "exit N" (then the block's last command must exit N).
- ```python blocks are run by the interpreter running this script, with --pythonpath on
  PYTHONPATH. A comment line right after a line that calls print( (or right after another such
  comment line) is expected output: "# flexible 1 (1, 6, 2)". When a block has any, everything
  it prints must equal them, in order. With --no-python, the Python and shell blocks that use
  the module (import flexure, build/python) are skipped, and counted as such.
- ```toml blocks are scenes: written to a file and read by `flexure analyze`, which must exit 0;
  a scene with a [sweep] table is also swept (`flexure sweep analyze --slice 0/1000`: every
  swept key checked, a thousandth of the items run, none in error).
  A file that a block names by `from = "NAME"` and that the runner can make is made first
  (grid.npz: a triangulated 4 x 4 grid, as numpy.savez would write it).

Markers
-------
An HTML comment on the line(s) right before a fence, invisible in the rendered page, says what
the block needs: <!-- doc-test: DIRECTIVE[; DIRECTIVE] -->.

  skip (REASON)   not run; the reason is printed (a long job, an install, a cluster, a fragment)
  exit N          the block's last command exits with status N
  file NAME       the block's text is the file NAME, in this block's directory and in that of
                  every later block of the same document (then it is run as its kind says)
  after FILE      a toml fragment: read as the end of the scene FILE (a path from the root)
  server          the block's one command serves until Ctrl-C (flexure view): it is started with
                  a free port (--port P) and kept running for the rest of the document, whose
                  later blocks reach it where they say 127.0.0.1:8765; its output is compared as
                  far as the block shows it; at the end of the document it gets SIGINT and must
                  exit 0

Normalization of compared output
--------------------------------
Both sides, line by line, after trailing spaces are removed (blank lines at the end ignored):

- a time or duration, a number followed by ms, s, us or min ("0.29 s", "(30 ms)"), becomes <t>;
- a rate, a number followed by items/s or frames/s, becomes <r>;
- "on N threads" becomes "on <n> threads" (the machine's core count);
- the viewer's port, 127.0.0.1:P, becomes 127.0.0.1:8765.

Everything else must match, with two kinds of ellipsis in the expected text: a line that is
"..." alone stands for any number of lines, and "..." inside a line for any text.
"""

import argparse
import json
import os
import re
import shutil
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time
import zipfile

FENCE = re.compile(r"^(\s*)(`{3,})\s*([\w+-]*)\s*$")
MARKER = re.compile(r"^\s*<!--\s*doc-test:\s*(.*?)\s*-->\s*$")
SHELLS = {"sh", "bash", "shell", "console"}
PYTHON_MODULE = re.compile(r"\b(import|from)\s+flexure\b|build/python")
DEFAULT_PORT = "8765"


class Failure(Exception):
    pass


def split_directives(marker):
    """'skip (a; b); exit 1' -> ['skip (a; b)', 'exit 1']: semicolons inside parentheses stay."""
    parts, depth, cur = [], 0, ""
    for ch in marker:
        depth += (ch == "(") - (ch == ")")
        if ch == ";" and depth == 0:
            parts.append(cur)
            cur = ""
        else:
            cur += ch
    return parts + [cur]


class Block:
    def __init__(self, doc, line, lang, lines, markers):
        self.doc, self.line, self.lang, self.lines, self.markers = doc, line, lang, lines, markers
        self.directives = {}
        for m in markers:
            for part in [p.strip() for p in split_directives(m) if p.strip()]:
                word, _, rest = part.partition(" ")
                word = word.rstrip(":")
                if word not in ("skip", "exit", "file", "after", "server"):
                    raise Failure(f"{self.where}: unknown doc-test directive {part!r}")
                rest = rest.strip()
                if word == "skip":
                    rest = rest.strip("():").strip()
                    if not rest:
                        raise Failure(f"{self.where}: 'skip' needs a reason: <!-- doc-test: skip (why) -->")
                if word == "exit" and not rest.isdigit():
                    raise Failure(f"{self.where}: 'exit' needs a status number")
                if word in ("file", "after") and not rest:
                    raise Failure(f"{self.where}: '{word}' needs a file name")
                self.directives[word] = rest

    @property
    def where(self):
        return f"{self.doc}:{self.line}"

    @property
    def text(self):
        return "\n".join(self.lines) + "\n"


def parse(root, doc):
    path = os.path.join(root, doc)
    with open(path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    blocks, i, pending = [], 0, []
    while i < len(lines):
        m = MARKER.match(lines[i])
        if m:
            pending.append(m.group(1))
            i += 1
            continue
        f = FENCE.match(lines[i])
        if not f:
            if lines[i].strip():
                pending = []
            i += 1
            continue
        indent, ticks, lang = f.group(1), f.group(2), f.group(3).lower()
        start, body = i + 1, []
        i += 1
        while i < len(lines):
            close = re.match(r"^\s*(`{3,})\s*$", lines[i])
            if close and len(close.group(1)) >= len(ticks):
                break
            body.append(lines[i][len(indent):] if lines[i].startswith(indent) else lines[i].lstrip())
            i += 1
        else:
            raise Failure(f"{doc}:{start}: the code block is not closed")
        i += 1
        blocks.append(Block(doc, start, lang, body, pending))
        pending = []
    return blocks


# -- output comparison

TIME = re.compile(r"(?<![\w.])\d+(?:\.\d+)?(?:e[-+]?\d+)? ?(?:ms|us|µs|s|min)\b")
RATE = re.compile(r"(?<![\w.])\d+(?:\.\d+)? ?(?:items|frames)/s\b")
THREADS = re.compile(r"\bon \d+ threads?\b")


def normalize(line, port=None):
    line = line.rstrip()
    if port:
        line = line.replace(f"127.0.0.1:{port}", f"127.0.0.1:{DEFAULT_PORT}")
    line = RATE.sub("<r>", line)
    line = TIME.sub("<t>", line)
    line = THREADS.sub("on <n> threads", line)
    return line


def line_matches(expected, actual):
    if "..." not in expected:
        return expected == actual
    parts = [re.escape(p) for p in expected.split("...")]
    return re.fullmatch(".*".join(parts), actual) is not None


def lines_match(expected, actual):
    """Expected lines (with '...' lines that match any number of lines) against actual lines."""
    memo = {}

    def go(i, j):
        if (i, j) in memo:
            return memo[i, j]
        if i == len(expected):
            r = j == len(actual)
        elif expected[i].strip() == "...":
            r = any(go(i + 1, k) for k in range(j, len(actual) + 1))
        else:
            r = j < len(actual) and line_matches(expected[i], actual[j]) and go(i + 1, j + 1)
        memo[i, j] = r
        return r

    return go(0, 0)


def trimmed(lines):
    lines = list(lines)
    while lines and not lines[-1].strip():
        lines.pop()
    return lines


def compare(where, what, expected, actual, port=None):
    exp = trimmed(normalize(l) for l in expected)
    act = trimmed(normalize(l, port) for l in actual)
    if lines_match(exp, act):
        return
    diff = [f"{where}: the output of {what} differs from the document (after normalization)",
            "  expected:"] + ["    | " + l for l in exp] + ["  got:"] + ["    | " + l for l in act]
    raise Failure("\n".join(diff))


# -- the working directory

def grid_npz(path, n=4):
    """numpy.savez(path, vertices=V, edges=E) for a triangulated n x n grid, by hand."""
    verts = [(float(i), float(j)) for j in range(n) for i in range(n)]
    edges = []
    for j in range(n):
        for i in range(n):
            k = j * n + i
            if i + 1 < n:
                edges.append((k, k + 1))
            if j + 1 < n:
                edges.append((k, k + n))
            if i + 1 < n and j + 1 < n:
                edges.append((k, k + n + 1))

    def npy(descr, shape, payload):
        header = "{'descr': '%s', 'fortran_order': False, 'shape': (%d, %d), }" % (descr, shape[0], shape[1])
        pad = 64 - (10 + len(header) + 1) % 64
        header = header + " " * pad + "\n"
        return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode("latin1") + payload

    with zipfile.ZipFile(path, "w", zipfile.ZIP_STORED) as z:
        z.writestr("vertices.npy", npy("<f8", (len(verts), 2), b"".join(struct.pack("<2d", *v) for v in verts)))
        # 1-based like the scene's own numbers (index_base 1)
        z.writestr("edges.npy", npy("<i8", (len(edges), 2), b"".join(struct.pack("<2q", a + 1, b + 1) for a, b in edges)))


FIXTURES = {"grid.npz": grid_npz}


class Runner:
    def __init__(self, args):
        self.args = args
        self.root = os.path.abspath(args.root)
        self.flexure = os.path.abspath(args.flexure)
        self.pythonpath = None if args.no_python else os.path.abspath(args.pythonpath)
        self.tmp = tempfile.mkdtemp(prefix="flexure-docs-")
        self.base = os.path.join(self.tmp, "root")
        self._make_base()
        self.counter = 0
        self.server = None
        self.port = None
        self.files = {}  # `file NAME` blocks of the current document

    def _make_base(self):
        os.makedirs(os.path.join(self.base, "scenes"))
        shutil.copytree(os.path.join(self.root, "scenes", "examples"), os.path.join(self.base, "scenes", "examples"))
        os.makedirs(os.path.join(self.base, "docs"))
        shutil.copytree(os.path.join(self.root, "docs", "study"), os.path.join(self.base, "docs", "study"))
        build = os.path.join(self.base, "build")
        os.makedirs(build)
        for name in ("flexure", "flexure-draw", "libflexure-av.so"):
            src = os.path.join(os.path.dirname(self.flexure), name)
            if os.path.exists(src):
                os.symlink(src, os.path.join(build, name))
        if self.pythonpath:
            os.symlink(self.pythonpath, os.path.join(build, "python"))

    def workdir(self):
        self.counter += 1
        d = os.path.join(self.tmp, f"block{self.counter}")
        shutil.copytree(self.base, d, symlinks=True)
        for name, text in self.files.items():
            with open(os.path.join(d, name), "w", encoding="utf-8") as f:
                f.write(text)
        return d

    def env(self):
        e = dict(os.environ)
        e["PATH"] = os.path.dirname(self.flexure) + os.pathsep + e.get("PATH", "/usr/bin:/bin")
        if self.pythonpath:
            e["PYTHONPATH"] = self.pythonpath + (os.pathsep + e["PYTHONPATH"] if e.get("PYTHONPATH") else "")
        e["LC_ALL"] = "C.UTF-8"
        e.pop("SOURCE_DATE_EPOCH", None)
        e.pop("FLEXURE_FONT", None)
        return e

    def ported(self, text):
        return text.replace(f"127.0.0.1:{DEFAULT_PORT}", f"127.0.0.1:{self.port}") if self.port else text

    # -- shell blocks

    @staticmethod
    def commands(block):
        """[(command, expected output lines or None, line number)]"""
        transcript = any(l.startswith("$ ") or l == "$" for l in block.lines)
        out, i = [], 0
        lines = block.lines
        while i < len(lines):
            line = lines[i]
            if transcript and not line.startswith("$ "):
                raise Failure(f"{block.doc}:{block.line + 1 + i}: output before the first command")
            if not transcript and (not line.strip() or line.lstrip().startswith("#")):
                i += 1
                continue
            first = block.line + 1 + i
            cmd = line[2:] if transcript else line
            while cmd.rstrip().endswith("\\") and i + 1 < len(lines):
                i += 1
                nxt = lines[i]
                if transcript and nxt.startswith("> "):
                    nxt = nxt[2:]
                cmd = cmd.rstrip()[:-1] + "\n" + nxt
            i += 1
            expected = None
            if transcript:
                expected = []
                while i < len(lines) and not lines[i].startswith("$ "):
                    expected.append(lines[i])
                    i += 1
            out.append((cmd, expected, first))
        return out

    def run_shell(self, block):
        if "server" in block.directives:
            return self.start_server(block)
        d = self.workdir()
        cmds = self.commands(block)
        if not cmds:
            raise Failure(f"{block.where}: a shell block without a command")
        want_last = int(block.directives.get("exit", "0"))
        for n, (cmd, expected, line) in enumerate(cmds):
            want = want_last if n == len(cmds) - 1 else 0
            cmd = self.ported(cmd)
            try:
                p = subprocess.run(["bash", "-c", cmd], cwd=d, env=self.env(), stdin=subprocess.DEVNULL,
                                   stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=self.args.timeout)
            except subprocess.TimeoutExpired:
                raise Failure(f"{block.doc}:{line}: `{cmd}` ran longer than {self.args.timeout} s "
                              "(mark a long job <!-- doc-test: skip (why) --> or shorten it)")
            text = p.stdout.decode("utf-8", "replace")
            if self.args.verbose:
                print(f"  $ {cmd}\n" + "".join("    " + l + "\n" for l in text.splitlines()[:40]))
            if p.returncode != want:
                raise Failure(f"{block.doc}:{line}: `{cmd}` exited {p.returncode}, the document says {want}\n"
                              + "".join("    | " + l + "\n" for l in text.splitlines()[-30:]))
            if expected is not None:
                compare(f"{block.doc}:{line}", f"`{cmd.splitlines()[0]}`", [self.ported(l) for l in expected],
                        text.splitlines(), self.port)

    def start_server(self, block):
        cmds = self.commands(block)
        if len(cmds) != 1:
            raise Failure(f"{block.where}: a server block holds one command")
        cmd, expected, line = cmds[0]
        if self.server:
            raise Failure(f"{block.where}: a second server in one document")
        s = socket.socket()
        s.bind(("127.0.0.1", 0))
        self.port = str(s.getsockname()[1])
        s.close()
        d = self.workdir()
        self.server_lines = []
        self.server = subprocess.Popen(["bash", "-c", "exec " + cmd + " --port " + self.port], cwd=d, env=self.env(),
                                       stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
        self.server_where = f"{block.doc}:{line}"

        def read():
            for raw in self.server.stdout:
                self.server_lines.append(raw.decode("utf-8", "replace").rstrip("\n"))

        self.server_reader = threading.Thread(target=read, daemon=True)
        self.server_reader.start()
        wanted = len(trimmed(expected or []))
        deadline = time.time() + self.args.timeout
        while time.time() < deadline and len(self.server_lines) < max(wanted, 1) and self.server.poll() is None:
            time.sleep(0.05)
        if self.server.poll() is not None:
            time.sleep(0.2)
            raise Failure(f"{block.doc}:{line}: `{cmd}` exited {self.server.returncode} instead of serving\n"
                          + "".join("    | " + l + "\n" for l in self.server_lines))
        if expected:
            compare(f"{block.doc}:{line}", f"`{cmd}`", expected, self.server_lines[:wanted], self.port)

    def stop_server(self):
        if not self.server:
            return
        server, where = self.server, self.server_where
        self.server, self.port = None, None
        server.send_signal(signal.SIGINT)
        try:
            rc = server.wait(timeout=15)
        except subprocess.TimeoutExpired:
            server.kill()
            server.wait()
            raise Failure(f"{where}: the server did not stop within 15 s of Ctrl-C")
        self.server_reader.join(timeout=5)
        if rc != 0:
            raise Failure(f"{where}: the server exited {rc} after Ctrl-C (the document says 0)\n"
                          + "".join("    | " + l + "\n" for l in self.server_lines[-20:]))

    # -- python blocks

    @staticmethod
    def python_expected(block):
        exp, follows = [], False
        for line in block.lines:
            s = line.strip()
            if s.startswith("#") and follows:
                exp.append(s[2:] if s.startswith("# ") else s[1:])
                continue
            follows = "print(" in line and not s.startswith("#")
        return exp

    def run_python(self, block):
        d = self.workdir()
        script = os.path.join(d, "block.py")
        with open(script, "w", encoding="utf-8") as f:
            f.write(self.ported(block.text))
        try:
            p = subprocess.run([sys.executable, script], cwd=d, env=self.env(), stdin=subprocess.DEVNULL,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=self.args.timeout)
        except subprocess.TimeoutExpired:
            raise Failure(f"{block.where}: the Python block ran longer than {self.args.timeout} s")
        out, err = p.stdout.decode("utf-8", "replace"), p.stderr.decode("utf-8", "replace")
        if p.returncode != 0:
            raise Failure(f"{block.where}: the Python block exited {p.returncode}\n"
                          + "".join("    | " + l + "\n" for l in (err or out).splitlines()[-30:]))
        expected = self.python_expected(block)
        if expected:
            compare(block.where, "the Python block", expected, out.splitlines(), self.port)

    # -- toml blocks

    def run_toml(self, block):
        d = self.workdir()
        name = block.directives.get("file") or "block.toml"
        text = block.text
        if "after" in block.directives:
            with open(os.path.join(d, block.directives["after"]), encoding="utf-8") as f:
                text = f.read().rstrip("\n") + "\n\n" + text
            name = "block.toml"
        for m in re.finditer(r'^\s*from\s*=\s*"([^"]+)"', text, re.M):
            if m.group(1) in FIXTURES and not os.path.exists(os.path.join(d, m.group(1))):
                FIXTURES[m.group(1)](os.path.join(d, m.group(1)))
        with open(os.path.join(d, name), "w", encoding="utf-8") as f:
            f.write(text)
        try:
            p = subprocess.run([self.flexure, "analyze", name, "--quiet"], cwd=d, env=self.env(),
                               stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                               timeout=self.args.timeout)
        except subprocess.TimeoutExpired:
            raise Failure(f"{block.where}: `flexure analyze` of the block ran longer than {self.args.timeout} s")
        if p.returncode != 0:
            raise Failure(f"{block.where}: `flexure analyze` of the block exited {p.returncode} (a fragment needs "
                          "<!-- doc-test: after SCENE --> or <!-- doc-test: skip (fragment) -->)\n"
                          + "".join("    | " + l + "\n" for l in p.stdout.decode("utf-8", "replace").splitlines()[-20:]))
        if re.search(r"^\s*\[sweep\]", text, re.M):
            # Every swept key and value checked; a thousandth of the items run.
            p = subprocess.run([self.flexure, "sweep", "analyze", name, "--slice", "0/1000", "--quiet", "-o",
                                "sweep.jsonl"], cwd=d, env=self.env(), stdin=subprocess.DEVNULL,
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=self.args.timeout)
            out = p.stdout.decode("utf-8", "replace")
            errors = None
            if p.returncode == 0:
                with open(os.path.join(d, "sweep.jsonl"), encoding="utf-8") as f:
                    errors = json.loads(f.read().splitlines()[-1])["summary"]["status"]["error"]
            if p.returncode != 0 or errors:
                raise Failure(f"{block.where}: `flexure sweep analyze` of the block's [sweep] exited {p.returncode}"
                              f"{f' with {errors} items in error' if errors else ''}\n"
                              + "".join("    | " + l + "\n" for l in out.splitlines()[-20:]))

    # -- a document

    def run_doc(self, doc):
        blocks = parse(self.root, doc)
        stats = {"ran": 0, "skipped": [], "text": 0}
        self.files = {}
        t0 = time.time()
        try:
            for b in blocks:
                if "file" in b.directives:
                    self.files[b.directives["file"]] = b.text
                if "skip" in b.directives:
                    stats["skipped"].append((b, b.directives["skip"]))
                    continue
                if b.lang == "":
                    raise Failure(f"{b.where}: a code block without a language: label it (sh, console, python, "
                                  "toml, or text for a listing that is not run)")
                if b.lang == "text":
                    stats["text"] += 1
                    continue
                if not self.pythonpath and b.lang in SHELLS | {"python"} and PYTHON_MODULE.search(b.text):
                    stats["skipped"].append((b, "needs the Python module (--no-python)"))
                    continue
                if b.lang in SHELLS:
                    self.run_shell(b)
                elif b.lang == "python":
                    self.run_python(b)
                elif b.lang == "toml":
                    self.run_toml(b)
                else:
                    raise Failure(f"{b.where}: a ```{b.lang} block: the runner runs sh, bash, console, python and "
                                  "toml; mark it <!-- doc-test: skip (why) --> or label it text")
                stats["ran"] += 1
        finally:
            try:
                self.stop_server()
            finally:
                self.files = {}
        stats["time"] = time.time() - t0
        return stats


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--flexure", required=True, help="the flexure binary (flexure-draw beside it)")
    ap.add_argument("--pythonpath", help="the built Python module's directory (build/python)")
    ap.add_argument("--no-python", action="store_true", help="skip the Python blocks that import flexure")
    ap.add_argument("--root", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."),
                    help="the repository's root (default: two levels up from this script)")
    ap.add_argument("--timeout", type=float, default=60, help="seconds per command or block (default 60)")
    ap.add_argument("--only", action="append", help="run only this document (repeatable), e.g. README.md")
    ap.add_argument("--keep", action="store_true", help="keep the temporary directories")
    ap.add_argument("--verbose", action="store_true")
    args = ap.parse_args()
    if not args.no_python and not args.pythonpath:
        ap.error("give --pythonpath DIR or --no-python")
    root = os.path.abspath(args.root)
    if not os.path.isfile(os.path.join(root, "README.md")):
        ap.error(f"{root} is not the repository's root (no README.md)")
    if not os.access(args.flexure, os.X_OK):
        ap.error(f"{args.flexure} is not an executable")
    docs = ["README.md"] + sorted("docs/" + f for f in os.listdir(os.path.join(root, "docs")) if f.endswith(".md"))
    if args.only:
        docs = [d for d in docs if d in args.only or os.path.basename(d) in args.only]
    runner = Runner(args)
    t0 = time.time()
    total = {"ran": 0, "skipped": 0, "text": 0}
    try:
        for doc in docs:
            try:
                s = runner.run_doc(doc)
            except Failure as e:
                print(f"FAIL {e}", file=sys.stderr)
                print(f"docs_commands_run: failed in {doc} after {time.time() - t0:.1f} s", file=sys.stderr)
                return 1
            print(f"{doc}: {s['ran']} ran, {len(s['skipped'])} skipped, {s['text']} text ({s['time']:.1f} s)")
            for b, why in s["skipped"]:
                print(f"  skipped {b.where} ({b.lang or 'unlabelled'}): {why}")
            total["ran"] += s["ran"]
            total["skipped"] += len(s["skipped"])
            total["text"] += s["text"]
    finally:
        if not args.keep:
            shutil.rmtree(runner.tmp, ignore_errors=True)
        else:
            print(f"kept {runner.tmp}")
    print(f"all documents: {total['ran']} blocks ran, {total['skipped']} skipped, {total['text']} text, "
          f"{time.time() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except Failure as e:
        print(f"FAIL {e}", file=sys.stderr)
        sys.exit(2)
