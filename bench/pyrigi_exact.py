#!/usr/bin/env python3
"""PyRigi's exact infinitesimal rigidity test on n x n triangulated unit grids, for comparison
with flexure's exact mode (issue 44; bench/exact_bench.cpp). Run by hand, not by CI:

    /usr/bin/python3 bench/pyrigi_exact.py --pyrigi /path/to/PyRigi [--sizes 3,4,5,6] [--timeout 300]

The grid: vertex (c, r) at the integer point (c, r), bars (c,r)-(c+1,r), (c,r)-(c,r+1) and the
diagonal (c,r)-(c+1,r+1) of every square; rigid, so its rigidity matrix has rank 2 n^2 - 3.
Measured, as CPU time (time.process_time) of the call alone, each in its own subprocess that
gives up after --timeout CPU seconds (reported as "> T s"):

1. PyRigi: Framework(...).is_inf_rigid() with numerical=False (sympy Matrix.rank() of the
   rigidity matrix over the integers), for --sizes.
2. sympy DomainMatrix(...).rank() over QQ of the same matrix, for --domain-sizes, in both
   formats: sparse (SDM, what DomainMatrix.from_Matrix gives by default) and dense (DDM).
3. Rank modulo p = 2^31 - 1 by Gaussian elimination in numpy int64 (written here), for
   --modp-sizes.
"""

import argparse
import os
import signal
import subprocess
import sys
import time
import types

P = 2**31 - 1
TIMEOUT = 300.0  # CPU seconds; set by the worker


def timed(f):
    """CPU seconds of f() and its value; SIGPROF stops the worker after TIMEOUT CPU seconds."""
    signal.setitimer(signal.ITIMER_PROF, TIMEOUT)
    t = time.process_time()
    value = f()
    cpu = time.process_time() - t
    signal.setitimer(signal.ITIMER_PROF, 0)
    return cpu, value


def grid(n):
    """Vertices (index r * n + c -> (c, r)) and bars of the n x n triangulated grid."""
    points = {r * n + c: (c, r) for r in range(n) for c in range(n)}
    edges = []
    for r in range(n):
        for c in range(n):
            v = r * n + c
            if c + 1 < n:
                edges.append((v, v + 1))
            if r + 1 < n:
                edges.append((v, v + n))
            if c + 1 < n and r + 1 < n:
                edges.append((v, v + n + 1))
    return points, edges


def rigidity_rows(n):
    """The rigidity matrix as sparse integer rows {column: value}, columns 2v and 2v + 1."""
    points, edges = grid(n)
    rows = []
    for u, v in edges:
        d = [points[u][k] - points[v][k] for k in range(2)]
        rows.append({2 * u: d[0], 2 * u + 1: d[1], 2 * v: -d[0], 2 * v + 1: -d[1]})
    return rows


def import_pyrigi(path):
    """Import pyrigi from its source tree. PyRigi imports notebook and plotting modules at top
    level (IPython, matplotlib, distinctipy, ipycanvas, ipyevents, ipywidgets) that the rank test
    never calls; those missing here (none of the last three is packaged for Debian) are replaced
    by empty stand-ins in sys.modules. Nothing else is stubbed."""
    import importlib

    class Stub(types.ModuleType):
        def __getattr__(self, name):
            if name.startswith("__"):
                raise AttributeError(name)
            return type(name, (), {"__init__": lambda self, *a, **k: None})

    for name in ["IPython", "IPython.core", "IPython.core.magic", "IPython.display",
                 "matplotlib", "matplotlib.pyplot", "matplotlib.axes", "matplotlib.animation",
                 "distinctipy", "ipycanvas", "ipyevents", "ipywidgets"]:
        try:
            importlib.import_module(name)
        except ImportError:
            sys.modules[name] = Stub(name)
            parent, _, child = name.rpartition(".")
            if parent:
                setattr(sys.modules[parent], child, sys.modules[name])
    sys.path.insert(0, path)
    import pyrigi

    return pyrigi


def measure_pyrigi(n, path):
    pyrigi = import_pyrigi(path)
    points, edges = grid(n)
    F = pyrigi.Framework(pyrigi.Graph.from_vertices_and_edges(list(points), edges), points)
    cpu, rigid = timed(lambda: F.is_inf_rigid(numerical=False))  # the exact path
    rank = f"{2 * n * n - 3} (= 2V-3: is_inf_rigid() is True)" if rigid else "< 2V-3 (is_inf_rigid() is False)"
    return cpu, rank


def measure_domainmatrix(n, dense):
    from sympy.polys.domains import QQ
    from sympy.polys.matrices import DomainMatrix

    rows = rigidity_rows(n)
    A = DomainMatrix({i: {j: QQ(x) for j, x in row.items() if x} for i, row in enumerate(rows)},
                     (len(rows), 2 * n * n), QQ)
    if dense:
        A = A.to_dense()
    cpu, rank = timed(A.rank)
    return cpu, str(rank)


def rank_mod_p(A, p=P):
    """Rank of the int64 matrix A modulo the prime p < 2^31 (products stay below 2^62)."""
    import numpy as np

    A = A % p
    rank = 0
    for c in range(A.shape[1]):
        nz = np.flatnonzero(A[rank:, c])
        if nz.size == 0:
            continue
        A[[rank, rank + nz[0]]] = A[[rank + nz[0], rank]]
        A[rank, c:] = A[rank, c:] * pow(int(A[rank, c]), p - 2, p) % p
        below = rank + 1 + np.flatnonzero(A[rank + 1:, c])
        A[below, c:] = (A[below, c:] - A[below, c, None] * A[rank, c:]) % p
        rank += 1
        if rank == A.shape[0]:
            break
    return rank


def measure_modp(n):
    import numpy as np

    rows = rigidity_rows(n)
    A = np.zeros((len(rows), 2 * n * n), dtype=np.int64)
    for i, row in enumerate(rows):
        for j, x in row.items():
            A[i, j] = x
    cpu, rank = timed(lambda: rank_mod_p(A))
    return cpu, str(rank)


WHAT = {
    "pyrigi": "PyRigi Framework.is_inf_rigid() (exact: sympy Matrix.rank)",
    "sparse": "sympy DomainMatrix.rank() over QQ, sparse (SDM)",
    "dense": "sympy DomainMatrix.rank() over QQ, dense (DDM)",
    "modp": "numpy int64 Gaussian elimination mod 2^31-1",
}


def worker(kind, n, timeout, path):
    """In the subprocess: run one measurement and print "CPU<tab>rank", or TIMEOUT."""
    global TIMEOUT
    TIMEOUT = timeout

    def give_up(*_):
        print("TIMEOUT", flush=True)
        os._exit(0)

    signal.signal(signal.SIGPROF, give_up)
    if kind == "pyrigi":
        cpu, rank = measure_pyrigi(n, path)
    elif kind in ("sparse", "dense"):
        cpu, rank = measure_domainmatrix(n, kind == "dense")
    else:
        cpu, rank = measure_modp(n)
    print(f"{cpu:.3f}\t{rank}", flush=True)


def run(kind, n, timeout, path):
    V, E = n * n, 3 * n * n - 4 * n + 1
    head = f"{n}x{n} triangulated grid ({V} vertices, {E} bars) | {2 * V} variables | {WHAT[kind]}"
    cmd = [sys.executable, __file__, "--worker", kind, str(n), "--timeout", str(timeout),
           "--pyrigi", path or ""]
    try:  # the wall-clock limit is only a backstop for the CPU-time limit in the worker
        out = subprocess.run(cmd, capture_output=True, text=True, timeout=2 * timeout + 120)
    except subprocess.TimeoutExpired:
        print(f"{head} | > {timeout} s CPU (wall-clock backstop) | rank -", flush=True)
        return
    result = out.stdout.strip().splitlines()[-1:] if out.returncode == 0 else []
    if result == ["TIMEOUT"]:
        print(f"{head} | > {timeout} s CPU | rank -", flush=True)
    elif result:
        cpu, rank = result[0].split("\t")
        print(f"{head} | {cpu} s CPU | rank {rank}", flush=True)
    else:
        print(f"{head} | failed (exit {out.returncode}): {out.stderr.strip().splitlines()[-1:]}", flush=True)


def sizes(text):
    return [int(x) for x in text.split(",") if x]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--pyrigi", help="PyRigi source tree (the directory holding pyrigi/)")
    ap.add_argument("--sizes", default="3,4,5,6", help="n for PyRigi's is_inf_rigid()")
    ap.add_argument("--domain-sizes", default="10,15,20", help="n for sympy's DomainMatrix rank")
    ap.add_argument("--modp-sizes", default="15,20,30", help="n for the numpy rank mod p")
    ap.add_argument("--timeout", type=float, default=300, help="CPU seconds per measurement")
    ap.add_argument("--worker", nargs=2, metavar=("KIND", "N"), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        return worker(args.worker[0], int(args.worker[1]), args.timeout, args.pyrigi)
    import numpy
    import sympy

    print(f"# python {sys.version.split()[0]}, sympy {sympy.__version__}, numpy {numpy.__version__}, "
          f"PyRigi from {args.pyrigi}", flush=True)
    timeout = int(args.timeout) if args.timeout == int(args.timeout) else args.timeout
    if args.pyrigi:
        for n in sizes(args.sizes):
            run("pyrigi", n, timeout, args.pyrigi)
    else:
        print("no --pyrigi: PyRigi's own test skipped", flush=True)
    for kind in ("sparse", "dense"):
        for n in sizes(args.domain_sizes):
            run(kind, n, timeout, args.pyrigi)
    for n in sizes(args.modp_sizes):
        run("modp", n, timeout, args.pyrigi)


if __name__ == "__main__":
    main()
