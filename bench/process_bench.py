#!/usr/bin/env python3
"""The whole `flexure analyze` process against the analysis alone (issue 45: within 1.3x at
10^5 and 10^6 vertices). Writes each framework as a scene file (the vertices and bars of
bench/grids.h, in its order), runs `flexure analyze --json` on it (CPU time of the child, user
and system, and its peak memory), and bench_rigidity on the same framework built in memory.

    bench/process_bench.py BUILD_DIR
"""

import os
import re
import subprocess
import sys
import tempfile

from child_process import child_cpu


def braced_grid(cols, rows, brace):
    """bench/grids.h's bracedGrid: 1-based vertex numbers."""
    vertices = [(c, r) for r in range(rows) for c in range(cols)]
    edges = []
    for r in range(rows):
        for c in range(cols):
            i = r * cols + c + 1
            if c + 1 < cols:
                edges.append((i, i + 1))
            if r + 1 < rows:
                edges.append((i, i + cols))
            if c + 1 < cols and r + 1 < rows and brace(c, r):
                edges.append((i, i + cols + 1))
    return vertices, edges


def write_scene(path, vertices, edges):
    with open(path, "w") as f:
        f.write('[system]\ntype = "framework"\nvertices = [\n')
        for k in range(0, len(vertices), 1000):
            f.write(", ".join("[%d, %d]" % v for v in vertices[k:k + 1000]) + ",\n")
        f.write("]\nedges = [\n")
        for k in range(0, len(edges), 1000):
            f.write(", ".join("[%d, %d]" % e for e in edges[k:k + 1000]) + ",\n")
        f.write("]\n")


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else "build"
    n = 224
    cases = [
        ("grid 224x224, 2 flexes, 20 redundant braces (10^5 vertices)", ["sparse", "224", "20"],
         lambda: braced_grid(n, n, lambda c, r: c == 0 or (r == 0 and c >= 3) or (r == 1 and 3 <= c < 23))),
        ("grid 224x224, every other row braced (10^5 vertices)", ["grid", "224", "224", "2"],
         lambda: braced_grid(n, n, lambda c, r: r % 2 == 0)),
        ("triangulated grid 1000x1000 (10^6 vertices)", ["grid", "1000", "1000", "1"],
         lambda: braced_grid(1000, 1000, lambda c, r: True)),
    ]
    with tempfile.TemporaryDirectory() as d:
        for name, args, make in cases:
            scene = os.path.join(d, "scene.toml")
            write_scene(scene, *make())
            size = os.path.getsize(scene) / 1e6
            out = subprocess.run([os.path.join(build, "bench", "bench_rigidity")] + args, check=True,
                                 capture_output=True, text=True).stdout
            alone = float(re.search(r"([0-9.]+) s CPU", out).group(1))
            peak_alone = float(re.search(r"peak +([0-9.]+) MB", out).group(1))
            whole, peak = child_cpu([os.path.join(build, "flexure"), "analyze", "--quiet", "--json", scene])
            print("%-62s scene %5.1f MB | analysis alone %7.2f s CPU, peak %5.0f MB | flexure analyze %7.2f s CPU, "
                  "peak %5.0f MB | %.2fx" % (name, size, alone, peak_alone, whole, peak, whole / alone), flush=True)


if __name__ == "__main__":
    main()
