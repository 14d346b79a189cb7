#!/usr/bin/env python3
"""sweep analyze asking for counts only (--fields rigidity_rank,...) against a bare numpy rank
loop over the same graphs (issue 45: at least as fast per item). The graphs: every connected
graph on 8 vertices with 13 edges (1,454) and on 9 with 15 (20,303), from nauty-geng. The numpy
loop reads each graph6 line, realizes it at random in the plane and takes the rank of its
rigidity matrix (numpy.linalg.matrix_rank: an SVD); flexure also decides the trivial motions.
CPU time, min of 3; flexure on one thread (child process CPU). Per item: flexure's whole sweep
less a sweep of the first graph alone (start-up), over the other graphs.

    bench/sweep_counts_bench.py BUILD_DIR
"""

import os
import subprocess
import sys
import tempfile
import time

import numpy as np

from child_process import child_cpu


def graph6(line):
    """Vertex count and edges of a graph6 line (n < 63)."""
    data = [ord(c) - 63 for c in line.strip()]
    n, bits = data[0], []
    for d in data[1:]:
        bits.extend((d >> (5 - k)) & 1 for k in range(6))
    edges, k = [], 0
    for j in range(1, n):
        for i in range(j):
            if bits[k]:
                edges.append((i, j))
            k += 1
    return n, edges


def numpy_loop(lines):
    rng = np.random.default_rng(1)
    ranks = []
    for line in lines:
        n, edges = graph6(line)
        p = rng.standard_normal((n, 2))
        R = np.zeros((len(edges), 2 * n))
        for r, (i, j) in enumerate(edges):
            d = p[i] - p[j]
            R[r, 2 * i:2 * i + 2] = d
            R[r, 2 * j:2 * j + 2] = -d
        ranks.append(np.linalg.matrix_rank(R))
    return ranks


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else "build"
    flexure = os.path.join(build, "flexure")
    with tempfile.TemporaryDirectory() as d:
        for n, m in ((8, 13), (9, 15)):
            g6 = os.path.join(d, "g.g6")
            with open(g6, "w") as f:
                subprocess.run(["/usr/bin/nauty-geng", "-c", "-q", str(n), "%d:%d" % (m, m)], stdout=f, check=True)
            lines = open(g6).read().split()
            best_np = 1e300
            for _ in range(3):
                t0 = time.process_time()
                numpy_loop(lines)
                best_np = min(best_np, time.process_time() - t0)
            out = os.path.join(d, "out.jsonl")
            first = os.path.join(d, "first.g6")
            with open(first, "w") as f:
                f.write(lines[0] + "\n")
            times = {}
            for name, extra in (("counts", ["--fields", "rigidity_rank,nontrivial_inf_flexes,stress_dim,inf_rigid"]),
                                ("full report", [])):
                for which, source in (("all", g6), ("one", first)):
                    best = 1e300
                    for _ in range(3):
                        if os.path.exists(out):
                            os.remove(out)
                        best = min(best, child_cpu([flexure, "sweep", "analyze", source, "--threads", "1", "--quiet",
                                                    "-o", out] + extra)[0])
                    times[name, which] = best
            # Per item: the whole sweep less a sweep of its first graph (the process's start, the
            # output's set-up), over the other graphs; numpy's loop is timed inside Python (no
            # start-up, no import).
            per_np = best_np / len(lines)
            per = {k: (times[k, "all"] - times[k, "one"]) / (len(lines) - 1) for k in ("counts", "full report")}
            print("n=%d m=%d %6d graphs | numpy rank loop %6.3f s CPU (%.1f us/item) | flexure sweep --fields (counts) "
                  "%6.3f s whole, %.1f us/item (%.2fx numpy per item) | full report %6.3f s, %.1f us/item (%.2fx)"
                  % (n, m, len(lines), best_np, 1e6 * per_np, times["counts", "all"], 1e6 * per["counts"],
                     per["counts"] / per_np, times["full report", "all"], 1e6 * per["full report"],
                     per["full report"] / per_np), flush=True)


if __name__ == "__main__":
    main()
