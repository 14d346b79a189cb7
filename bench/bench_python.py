#!/usr/bin/env python3
"""The Python module's cost (CPU time, best of 3; run by bench/run with PYTHONPATH=build/python).

1. One call on a 10-vertex framework: flexure.framework(arrays) + analyze(), against the
   pipeline's own time for the same analysis (the C++ call on a scene already loaded). The
   difference is what Python adds: the scene text, the loader, the JSON, the result object.
2. A 100x100 triangulated grid (10,000 vertices, 29,601 bars) built from numpy arrays and
   analysed, with no file in between; its stages apart.
"""

import time

import numpy as np

import flexure


def best(f, repeat=3, number=1):
    times = []
    for _ in range(repeat):
        t0 = time.process_time()
        for _ in range(number):
            f()
        times.append((time.process_time() - t0) / number)
    return min(times)


def ring(n=10):
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    v = np.c_[np.cos(t), np.sin(t)] * (1 + 0.1 * np.arange(n) / n)[:, None]
    e = np.array([[i, (i + 1) % n] for i in range(n)] + [[i, (i + 3) % n] for i in range(n)])
    return v, e


def grid(k=100):
    ij = np.array([(i, j) for i in range(k) for j in range(k)], dtype=float)
    rng = np.random.default_rng(1)
    v = ij + 0.05 * rng.standard_normal(ij.shape)
    idx = np.arange(k * k).reshape(k, k)
    e = np.concatenate([
        np.c_[idx[:, :-1].ravel(), idx[:, 1:].ravel()],
        np.c_[idx[:-1, :].ravel(), idx[1:, :].ravel()],
        np.c_[idx[:-1, :-1].ravel(), idx[1:, 1:].ravel()],
    ])
    return v, e


def main():
    v, e = ring()
    s = flexure.framework(v, e, pinned=[0])
    scene = s._scene._target  # the C++ scene, loaded once (internal: only for this comparison)
    n = 300
    engine = best(lambda: scene.analyze(), number=n)
    cached = best(lambda: s.analyze(), number=n)
    full = best(lambda: flexure.framework(v, e, pinned=[0]).analyze(), number=n)
    print("10-vertex framework (20 bars), per call, CPU ms (best of 3 x %d calls):" % n)
    print(f"  pipeline alone (C++ analysis + JSON text)      {1e3 * engine:8.3f}")
    print(f"  system.analyze() on a built system             {1e3 * cached:8.3f}   overhead {1e3 * (cached - engine):.3f}")
    print(f"  flexure.framework(arrays).analyze()            {1e3 * full:8.3f}   overhead {1e3 * (full - engine):.3f}")

    gv, ge = grid()
    build = best(lambda: flexure.framework(gv, ge))
    g = flexure.framework(gv, ge)
    analyse = best(lambda: g.analyze())
    a = g.analyze()
    print(f"100x100 triangulated grid ({len(gv)} vertices, {len(ge)} bars), CPU s (best of 3):")
    print(f"  built from numpy arrays (given as numbers)   {build:8.3f}")
    print(f"  analyze()                                      {analyse:8.3f}   ({a.rigid}, rank {a.rigidity_rank}, "
          f"{a.numerics['method']})")
    print(f"  together                                       {build + analyse:8.3f}")


if __name__ == "__main__":
    main()
