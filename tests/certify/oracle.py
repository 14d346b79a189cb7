#!/usr/bin/python3
"""An independent oracle for `flexure track SCENE --certify` (docs/exact.md, "track --certify").

    /usr/bin/python3 tests/certify/oracle.py --flexure build/flexure [--keep]

flexure certifies a tracked path in interval arithmetic: a radius r per sample (exactly one point
of the real solution curve within r, max norm over the free coordinates) and a flag per step (both
samples on one smooth arc). This script runs flexure on pinned one-degree-of-freedom bar-joint
mechanisms written here as TOML text in a temporary folder, and checks every claim by recomputing
the curve {x : |x_i - x_j|^2 = |p_i - p_j|^2 for every bar ij, pins fixed} in about 60 digits,
p the path's sample 0 (checked to be the scene's coordinates).

  Arithmetic   Coordinates are fixed-point Python integers (units of 2^-200); each bar's residual
               is computed exactly in integers, so F(x) has no rounding at all. Newton's linear
               solves are done in double (mixed-precision iterative refinement: each iteration
               gains about 16 digits less the condition number's), by a banded Gaussian elimination
               with partial pivoting written below, in a Cuthill-McKee order of the vertices.
  Slices       The curve is cut by x_j = s, j the free coordinate that moves most from the sample
               to its neighbour; Newton from the sample in that slice converges to a curve point.
  Check 1      For each sample with a radius r: the curve point nearest the sample in max norm (the
               slice point moved along the curve's tangent, the 1-D convex max-norm minimisation
               done in floats, then the point re-solved in its slice) lies within r (relative slack
               1e-9 for the comparison's own rounding), and r <= 1e-8 of the configuration's size
               (the largest extent of its bounding box), as the docs promise.
  Check 2      For each step flagged true: the curve is followed in high precision from sample k's
               witness point to sample k+1's, x_j (j the coordinate the step moves most) advanced in
               20 sub-steps (5 and 10 on the big grid and ladder, whose steps are short for their
               size; tangent, then secant predictor; Newton corrector; a sub-step is halved when the
               corrector moves more than a tenth of it). It must arrive at sample k+1's witness (to
               1e-30 of the size): both samples are then on one arc, witnessed independently.
  Fakes        flexure has no command that certifies a given path (`track` takes a path JSON only as
               its scene, and tracks again), so a path with a branch jump cannot be fed to it. The
               oracle checks itself instead: the four-bar's path with its samples 10.. mirrored
               across y = 0 (the other assembly mode) must fail check 2 at step 9-10 alone, and the
               path with sample 5 moved by 1e-9 must fail check 1 at sample 5 alone.

Nothing is shared with flexure: only the standard library (no numpy, no mpmath needed), no code
of engine/, pipeline/, python/ or cli/. Only what a certificate claims is checked (null radii and
false steps are allowed, e.g. next to the double Watt's cusps); also one radius per sample, one flag
per step, "certified" true exactly when all are, pins fixed in every sample.

Scenes: a pinned four-bar (20 steps), the double Watt (100 steps), 10x10 and 31x31 grids whose top
row of squares shears, ladders of 30 and 100 braced cells on a four-bar (flexure's dense and sparse
tests). One line per scene, flexure's reason, the failures; a summary; exit status 1 on any failure.
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib
from operator import mul

BITS = 200
ONE = 1 << BITS        # fixed point: the integer X stands for X / 2^200
ONEF = float(ONE)
ONE2 = ONE * ONE
SLACK = 1e-9           # relative slack on a radius, for the comparison's own rounding
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


class Failure(Exception):
    pass


def fix(v):
    """The double v in fixed point (exact for |v| >= 2^-147: multiplying by 2^200 is exact)."""
    return int(v * ONEF)


# --- Linear algebra in double: banded elimination with partial pivoting


class LU:
    """P A = L U for a square sparse matrix given as rows {column: value}; the last row is the
    slice row e_j. Rows are eliminated by their first column, so a banded matrix stays banded."""

    def __init__(self, rows, n, j):
        self.n, self.j, self.m = n, j, len(rows)
        buckets, self.ops, self.U = [[] for _ in range(n + 1)], [], []
        for rid, row in enumerate(rows):
            buckets[min(row)].append((rid, [row.get(c, 0.0) for c in range(min(row), max(row) + 1)]))
        for c in range(n):
            cand = buckets[c]
            pid, pv = max(cand, key=lambda t: abs(t[1][0])) if cand else (None, [0.0])
            if pv[0] == 0.0:
                raise Failure("singular Jacobian (no pivot in column %d)" % c)
            self.U.append((pid, pv))
            lp = len(pv)
            for rid, tv in cand:
                if rid == pid:
                    continue
                f = tv[0] / pv[0]
                if f != 0.0:
                    self.ops.append((pid, rid, f))
                    tv = tv + [0.0] * (lp - len(tv))
                    tv = [a - f * b for a, b in zip(tv[1:lp], pv[1:])] + tv[lp:]
                else:
                    tv = tv[1:]
                if tv:
                    buckets[c + 1].append((rid, tv))

    def solve(self, b):
        b = list(b)
        for pid, rid, f in self.ops:
            b[rid] -= f * b[pid]
        x = [0.0] * self.n
        for c in range(self.n - 1, -1, -1):
            pid, pv = self.U[c]
            x[c] = (b[pid] - sum(map(mul, pv[1:], x[c + 1:c + len(pv)]))) / pv[0]
        return x

    def tangent(self):
        """The kernel of the bars' Jacobian (at the factored point), normalised by t_j = 1."""
        return self.solve([0.0] * (self.m - 1) + [1.0])


# --- The mechanism: its curve in fixed point


class Mechanism:
    def __init__(self, start, edges, pinned):
        self.d, self.pinned, nv = len(start[0]), set(pinned), len(start)
        adj = [set() for _ in range(nv)]
        for i, j in edges:
            adj[i].add(j)
            adj[j].add(i)
        order = cuthill_mckee([v for v in range(nv) if v not in self.pinned], adj)
        self.n = self.d * len(order)
        # index of (vertex, axis) in X + pins: free coordinates first, pinned ones after
        self.idx, self.pins = {}, []
        for k, v in enumerate(order):
            for a in range(self.d):
                self.idx[v, a] = self.d * k + a
        for v in sorted(self.pinned):
            for a in range(self.d):
                self.idx[v, a] = self.n + len(self.pins)
                self.pins.append(fix(start[v][a]))
        bars = [(i, j) for i, j in edges if not (i in self.pinned and j in self.pinned)]
        self.bars = sorted(([(self.idx[i, a], self.idx[j, a]) for a in range(self.d)] for i, j in bars),
                           key=lambda pairs: min(p for pq in pairs for p in pq))
        self.l2 = self.residual(self.vector(start), lengths=False)
        if len(self.bars) != self.n - 1:
            raise Failure("%d bars for %d free coordinates: not a one-parameter test case" % (len(self.bars), self.n))
        self.size = max(max(p[a] for p in start) - min(p[a] for p in start) for a in range(self.d))

    def vector(self, points):
        X = [0] * self.n
        for (v, a), k in self.idx.items():
            if k < self.n:
                X[k] = fix(points[v][a])
            elif fix(points[v][a]) != self.pins[k - self.n]:
                raise Failure("pinned vertex %d moved to %s" % (v + 1, points[v]))
        return X

    def residual(self, X, lengths=True):
        """Each bar's squared length minus its start value, exact, in units of 2^-400."""
        Z = X + self.pins
        sq = [sum((Z[p] - Z[q]) ** 2 for p, q in pairs) for pairs in self.bars]
        return [s - l for s, l in zip(sq, self.l2)] if lengths else sq

    def lu(self, X, j):
        Z, n = [z / ONE for z in X + self.pins], self.n
        rows = [{k: sign * 2.0 * (Z[p] - Z[q]) for p, q in pairs for k, sign in ((p, 1), (q, -1)) if k < n}
                for pairs in self.bars]
        return LU(rows + [{j: 1.0}], n, j)

    def newton(self, X, j, s, lu=None, tol=1e-45):
        """The curve point in the slice x_j = s, by Newton from X (fixed point), with the Jacobian
        refactored when the frozen one contracts too slowly. Returns (point, factorisation)."""
        X, prev, fresh = X[:j] + [s] + X[j + 1:], float("inf"), False
        if lu is None or lu.j != j:
            lu, fresh = self.lu(X, j), True
        for _ in range(60):
            d = lu.solve([f / ONE2 for f in self.residual(X)] + [0.0])
            step = max(map(abs, d))
            if step > 0.5 * prev and not fresh:
                lu, fresh = self.lu(X, j), True
                continue
            X = [x - fix(di) for x, di in zip(X, d)]
            X[j] = s
            prev, fresh = step, False
            if step <= tol * self.size:
                return X, lu
        raise Failure("Newton does not converge in the slice x_%d = %.17g" % (j, s / ONE))

    def follow(self, A, j, b, lu, substeps=20):
        """Continue the curve from its point A, x_j going from A_j to b; the point reached. The
        predictor is the tangent at A, then the secant through the last two points."""
        X, h, prev, halvings = A, (b - A[j]) // substeps or (b - A[j]), None, 0
        while X[j] != b:
            s = b if abs(b - X[j]) <= abs(h) else X[j] + h
            if prev is None:
                t = lu.tangent() if lu.j == j else self.lu(X, j).tangent()
            else:
                t = [(x - p) / (X[j] - prev[j]) for x, p in zip(X, prev)]
            dh = (s - X[j]) / ONE
            P = [x + fix(ti * dh) for x, ti in zip(X, t)]
            try:
                Y, lu2 = self.newton(P, j, s, lu, 1e-25 if s != b else 1e-45)
                ok = dist(Y, P) <= 0.1 * abs(dh) * max(map(abs, t)) + 1e-20 * self.size
            except Failure:
                ok = False
            if not ok:
                halvings += 1
                h = int(h / 2)
                if halvings > 30 or h == 0:
                    raise Failure("cannot follow the curve past x_%d = %.17g" % (j, X[j] / ONE))
                continue
            X, prev, lu = Y, X, lu2
        return X


def cuthill_mckee(free, adj):
    """The free vertices in Cuthill-McKee order (breadth first from a vertex of least degree)."""
    freeset, seen, order = set(free), set(), []
    for root in sorted(free, key=lambda v: len(adj[v])):
        if root in seen:
            continue
        seen.add(root)
        queue = [root]
        for v in queue:
            order.append(v)
            for w in sorted(adj[v] - seen, key=lambda w: len(adj[w])):
                if w in freeset:
                    seen.add(w)
                    queue.append(w)
    return order


def dist(X, Y):
    """Max-norm distance of two fixed-point vectors, as a float."""
    return max(abs(x - y) for x, y in zip(X, Y)) / ONE


def argmax_move(X, Y):
    return max(range(len(X)), key=lambda i: abs(X[i] - Y[i]))


# --- The checks


def witness(mech, x, j):
    """The curve point nearest x in max norm: the point q of the slice x_j = x_j, then
    min over s of |q + s t - x| (t the tangent, t_j = 1), then that point re-solved."""
    q, lu = mech.newton(x, j, x[j])
    t = lu.tangent()
    d = [(a - b) / ONE for a, b in zip(q, x)]
    g = lambda s: max(abs(di + s * ti) for di, ti in zip(d, t))
    lo, hi = -2 * g(0.0), 2 * g(0.0)
    for _ in range(80):
        m1, m2 = lo + (hi - lo) / 3, hi - (hi - lo) / 3
        lo, hi = (lo, m2) if g(m1) < g(m2) else (m1, hi)
    return mech.newton(q, j, x[j] + fix((lo + hi) / 2), lu)


def check_path(mech, path, substeps=20):
    """Check a path's certificate against the curve; (summary, failures)."""
    fails, cert, samples = [], path.get("certificate") or {}, path["samples"]
    radii, steps, ns = cert.get("radii"), cert.get("steps"), len(samples)
    if not isinstance(radii, list) or len(radii) != ns:
        return "", ["certificate.radii: %r for %d samples" % (radii, ns)]
    if not isinstance(steps, list) or len(steps) != ns - 1:
        return "", ["certificate.steps: %r for %d samples" % (steps, ns)]
    whole = all(r is not None for r in radii) and all(s is True for s in steps)
    if path.get("certified") is not whole:
        fails.append('"certified" is %r, the radii and steps say %r' % (path.get("certified"), whole))
    if not isinstance(cert.get("reason"), str) or not cert["reason"]:
        fails.append("no reason")
    try:
        X = [mech.vector(p) for p in samples]
    except Failure as e:
        return "", [str(e)]
    js = [argmax_move(X[k], X[k + 1] if k + 1 < ns else X[k - 1]) for k in range(ns)]
    W, ratio, rsize = {}, 0.0, 0.0
    for k, r in enumerate(radii):
        if r is None and not (k > 0 and steps[k - 1]) and not (k < ns - 1 and steps[k]):
            continue
        try:
            W[k] = witness(mech, X[k], js[k])
        except Failure as e:
            fails.append("sample %d: %s" % (k, e))
            continue
        if r is None:
            continue
        D = dist(W[k][0], X[k])
        ratio, rsize = max(ratio, D / r if r > 0 else float("inf")), max(rsize, r / mech.size)
        if not r > 0 or D > r * (1 + SLACK):
            fails.append("sample %d: the curve's nearest point is %.3g away (max norm), radius %.3g" % (k, D, r))
        if r > 1e-8 * mech.size:
            fails.append("sample %d: radius %.3g > 1e-8 of the size %g" % (k, r, mech.size))
    gap, followed = 0.0, 0
    for k, ok in enumerate(steps):
        if ok is not True or k not in W or k + 1 not in W:
            continue
        j, B = js[k], W[k + 1][0]
        try:
            Y = mech.follow(W[k][0], j, B[j], W[k][1], substeps)
        except Failure as e:
            fails.append("step %d-%d: %s" % (k, k + 1, e))
            continue
        followed += 1
        gap = max(gap, dist(Y, B) / mech.size)
        if dist(Y, B) > 1e-30 * mech.size:
            fails.append("step %d-%d: followed from sample %d, the curve reaches x_%d = %.17g %.3g away from "
                         "sample %d's curve point: another arc" % (k, k + 1, k, j, B[j] / ONE, dist(Y, B), k + 1))
    nr = sum(r is not None for r in radii)
    summary = ("%d/%d samples, %d/%d steps certified; check 1: max distance/r %.3g, max r/size %.3g; "
               "check 2: %d steps followed, max gap/size %.3g" % (nr, ns, sum(s is True for s in steps),
                                                                 ns - 1, ratio, rsize, followed, gap))
    return summary, fails


# --- Scenes


def scene_text(vertices, edges, pinned, steps, step_size):
    return ('[system]\ntype = "framework"\nvertices = %s\nedges = %s\npinned = %s\n\n'
            "[motion]\nsteps = %d\nstep_size = %r\n" % (json.dumps(vertices), json.dumps(edges),
                                                         json.dumps(pinned), steps, step_size))


def grid(w, h, steps):
    """Unit squares, w x h, braced along the first row and the first column but its top square;
    pinned at the bottom-left bar: the top row of squares shears."""
    num = lambda c, r: r * (w + 1) + c + 1
    V = [[c, r] for r in range(h + 1) for c in range(w + 1)]
    E = [[num(c, r), num(c + 1, r)] for r in range(h + 1) for c in range(w)]
    E += [[num(c, r), num(c, r + 1)] for r in range(h) for c in range(w + 1)]
    E += [[num(c, r), num(c + 1, r + 1)] for r in range(h) for c in range(w) if r == 0 or (c == 0 and r < h - 1)]
    return scene_text(V, E, [1, 2], steps, 0.01)


def ladder(cells, steps):
    """2 x (cells + 1) vertices, each square braced but the first (a four-bar), pinned at the first
    square's bottom vertices."""
    num = lambda c, r: r * (cells + 1) + c + 1
    V = [[c, r] for r in range(2) for c in range(cells + 1)]
    E = [[num(c, r), num(c + 1, r)] for r in range(2) for c in range(cells)]
    E += [[num(c, 0), num(c, 1)] for c in range(cells + 1)]
    E += [[num(c, 0), num(c + 1, 1)] for c in range(1, cells)]
    return scene_text(V, E, [1, 2], steps, 0.05)


FOUR_BAR = scene_text([[0, 0], [2, 0], [2.2, 1.1], [0.3, 1.2]], [[1, 4], [2, 3], [3, 4]], [1, 2], 20, 0.05)


def cases():
    with open(os.path.join(ROOT, "scenes", "examples", "double_watt.toml")) as f:
        watt_text = f.read()
    return [("four_bar", FOUR_BAR, [], 20),
            ("double_watt_100", watt_text, ["--set", "motion.steps=100"], 20),
            ("grid_10x10", grid(10, 10, 5), [], 20),
            ("grid_31x31", grid(31, 31, 4), [], 5),
            ("ladder_30", ladder(30, 10), [], 20),
            ("ladder_100", ladder(100, 4), [], 10)]


def run_track(flexure, folder, name, text, extra, timeout=120):
    scene, out = os.path.join(folder, name + ".toml"), os.path.join(folder, name + ".json")
    with open(scene, "w") as f:
        f.write(text)
    t0 = time.time()
    r = subprocess.run([flexure, "-q", "track", scene, "--certify", "-o", out] + extra,
                       capture_output=True, text=True, timeout=timeout)
    if r.returncode != 0:
        raise Failure("flexure exit %d: %s" % (r.returncode, r.stderr.strip()[-400:]))
    with open(out) as f:
        path = json.load(f)
    return tomllib.loads(text)["system"], path, time.time() - t0


def mechanism(system, path):
    base = 1  # the scenes here count vertices from 1
    start = [[float(x) for x in p] for p in system["vertices"]]
    if path["samples"][0] != start:
        raise Failure("sample 0 is not the scene's start: %s" % path["samples"][0])
    return Mechanism(start, [(i - base, j - base) for i, j in system["edges"]], [v - base for v in system["pinned"]])


def self_checks(path, mech):
    """The oracle must see through fakes of the four-bar's path: its samples 10.. mirrored across
    y = 0 (the other assembly mode: a branch jump at step 9-10), and its sample 5 moved by 1e-9
    (off the curve by far more than its radius)."""
    out = []
    mirrored = dict(path, samples=path["samples"][:10] + [[[x, -y] for x, y in s] for s in path["samples"][10:]])
    moved = dict(path, samples=[[[x + (1e-9 if (k, v) == (5, 2) else 0), y] for v, (x, y) in enumerate(s)]
                                for k, s in enumerate(path["samples"])])
    for what, fake, where in (("the mirrored branch jump", mirrored, "step 9-10:"),
                              ("sample 5 moved by 1e-9", moved, "sample 5:")):
        fails = check_path(mech, fake)[1]
        if len(fails) != 1 or not fails[0].startswith(where):
            out.append("the oracle does not detect %s (expected one failure at %s): %s" % (what, where, fails))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--flexure", required=True)
    ap.add_argument("--keep", action="store_true", help="keep the temporary folder")
    args = ap.parse_args()
    flexure, folder = os.path.abspath(args.flexure), tempfile.mkdtemp(prefix="flexure-certify-")
    t0, failures, todo = time.time(), 0, cases()
    try:
        for name, text, extra, substeps in todo:
            t1, summary, fails, reason = time.time(), "", [], ""
            try:
                system, path, tf = run_track(flexure, folder, name, text, extra)
                reason = str((path.get("certificate") or {}).get("reason", ""))
                mech = mechanism(system, path)
                summary, fails = check_path(mech, path, substeps=substeps)
                if name == "four_bar":
                    bad = self_checks(path, mech)
                    summary += "; self-checks (branch jump, moved sample) %s" % ("FAILED" if bad else "detected")
                    fails += bad
                summary += " (flexure %.2f s, oracle %.2f s)" % (tf, time.time() - t1 - tf)
            except (Failure, subprocess.TimeoutExpired, OSError, ValueError, KeyError) as e:
                fails.append("%s: %s" % (type(e).__name__, e))
            failures += bool(fails)
            print("%-16s %s | %s" % (name, summary, "FAIL" if fails else "ok"))
            if reason:
                print("      flexure: %s" % (reason if len(reason) < 160 else reason[:157] + "..."))
            for f in fails:
                print("      - " + f)
            sys.stdout.flush()
    finally:
        if args.keep:
            print("scenes and paths kept in %s" % folder)
        else:
            shutil.rmtree(folder, ignore_errors=True)
    print("summary: %d scenes, %d passed, %d failed (%.1f s); branch jump through flexure: skipped "
          "(no command certifies a given path)" % (len(todo), len(todo) - failures, failures, time.time() - t0))
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
