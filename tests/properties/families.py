"""Systems built by construction, with the answer the construction guarantees.

Every generator takes a numpy Generator and returns a Case in a canonical labelling; `disguise`
then applies a random similarity (rotation or reflection, scale 1e-3..1e3, translation), a random
relabelling of the vertices, a random order of the constraints and of the vertices inside each
constraint. None of these may change the answer.
"""

import itertools
import math

import numpy as np


class Case:
    def __init__(self, family, variant, kind, vertices, keys, pinned=(), known=None):
        self.family = family
        self.variant = variant
        self.kind = kind  # flexure constructor / oracle kind
        self.vertices = np.asarray(vertices, dtype=float)
        self.keys = keys  # edges / angles / simplices / bodies / radii (+ edges for packings)
        self.pinned = sorted(int(i) for i in pinned)
        self.known = dict(known or {})

    @property
    def dim(self):
        return self.vertices.shape[1]

    def reproducer(self):
        V = [[float(c) for c in p] for p in self.vertices]
        args = [repr(V)]
        if self.kind == "framework":
            args.append(f"edges={self.keys['edges']!r}")
        elif self.kind == "angular_framework":
            args.append(f"angles={self.keys['angles']!r}")
        elif self.kind == "volume_hypergraph":
            args.append(f"simplices={self.keys['simplices']!r}")
        elif self.kind == "body_hinge":
            args.append(f"bodies={self.keys['bodies']!r}")
        elif self.kind == "sphere_packing":
            args.append(f"radii={[float(r) for r in self.keys['radii']]!r}")
        if self.pinned:
            args.append(f"pinned={self.pinned!r}")
        return f"flexure.{self.kind}({', '.join(args)})"


# --------------------------------------------------------------------------- disguises

def random_orthogonal(rng, d):
    Q, R = np.linalg.qr(rng.standard_normal((d, d)))
    return Q * np.sign(np.diag(R))


def disguise(case, rng):
    """Half the cases: a random similarity with scale 1e-3..1e3. A quarter: axis-aligned (a signed
    permutation of the axes), a power-of-ten scale and an integer translation, so exact zeros and
    exactly representable coordinates stay. A quarter: the coordinates as constructed (only the
    relabelling and the constraint order change)."""
    n, d = case.vertices.shape
    mode = rng.random()
    if mode < 0.5:
        scale = 10.0 ** rng.uniform(-3, 3)
        Q = random_orthogonal(rng, d)
        t = scale * rng.uniform(-5, 5, size=d)
    elif mode < 0.75:
        scale = 10.0 ** int(rng.integers(-3, 4))
        Q = np.eye(d)[rng.permutation(d)] * rng.choice([-1.0, 1.0], size=(d, 1))
        t = scale * rng.integers(-5, 6, size=d).astype(float)
    else:
        scale, Q, t = 1.0, np.eye(d), np.zeros(d)
    V = scale * case.vertices @ Q.T + t
    perm = rng.permutation(n)  # old i -> new perm[i]
    W = np.empty_like(V)
    W[perm] = V
    keys = {}
    for k, v in case.keys.items():
        if k == "radii":
            r = np.empty(n)
            r[perm] = scale * np.asarray(v, dtype=float)
            keys[k] = r.tolist()
            continue
        rows = [[int(perm[i]) for i in row] for row in v]
        if k == "edges":
            rows = [row[::-1] if rng.random() < 0.5 else row for row in rows]
        elif k == "angles":
            rows = [row[::-1] if rng.random() < 0.5 else row for row in rows]  # angle at the middle
        elif k in ("simplices", "bodies"):
            rows = [[row[j] for j in rng.permutation(len(row))] for row in rows]
        order = rng.permutation(len(rows))
        keys[k] = [rows[j] for j in order]
    pinned = [int(perm[i]) for i in case.pinned]
    known = dict(case.known)
    return Case(case.family, case.variant, case.kind, W, keys, pinned, known)


# --------------------------------------------------------------------------- 1. bar frameworks

def _henneberg(rng, d, n):
    """Minimally rigid graph in R^d by Henneberg type-1 and type-2 moves, random positions."""
    P = [rng.uniform(-1, 1, d) for _ in range(d + 1)]
    E = set(itertools.combinations(range(d + 1), 2))
    for v in range(d + 1, n):
        if rng.random() < 0.6 or len(E) == 0:
            nb = rng.choice(v, size=d, replace=False)
            for u in nb:
                E.add((int(u), v))
        else:
            a, b = sorted(E)[int(rng.integers(len(E)))]
            E.discard((a, b))
            others = [u for u in range(v) if u not in (a, b)]
            if len(others) < d - 1:
                E.add((a, b))
                nb = rng.choice(v, size=d, replace=False)
                for u in nb:
                    E.add((int(u), v))
            else:
                extra = rng.choice(others, size=d - 1, replace=False)
                for u in [a, b, *extra]:
                    E.add((int(u), v))
        P.append(rng.uniform(-1, 1, d))
    return np.array(P), sorted(E)


def _special_framework(rng):
    """Non-generic frameworks whose answer is exact."""
    kind = ["collinear_triangle", "collinear_path", "parallelogram_4bar", "rectangle_with_diagonals",
            "square_grid_2x2", "braced_square_grid_2x2", "dixon_k33", "k33_on_ellipse", "parallel_prism",
            "vertex_on_segment", "parallel_prism_3d"][int(rng.integers(11))]
    if kind == "parallel_prism_3d":
        # two congruent tetrahedra, one a translate of the other, joined by four parallel bars:
        # the translate can move on a sphere (flexible); the four parallel bars carry a stress
        A = rng.uniform(-1, 1, (4, 3))
        w = rng.uniform(-2, 2, 3)
        P = np.r_[A, A + w]
        E = [[i, j] for i in range(4) for j in range(i + 1, 4)] + \
            [[i + 4, j + 4] for i in range(4) for j in range(i + 1, 4)] + [[i, i + 4] for i in range(4)]
        return 3, kind, P, E, {"trivial": 6, "stress": 1, "verdict": "flexible"}
    if kind == "parallel_prism":
        # two congruent triangles, one a translate of the other, joined by the three parallel bars
        # a_i b_i: generically the prism is rigid, here the translate moves along a circle
        # (flexible), with the three parallel bars carrying a stress
        A = rng.uniform(-1, 1, (3, 2))
        w = rng.uniform(-2, 2, 2)
        P = np.r_[A, A + w]
        E = [[0, 1], [1, 2], [0, 2], [3, 4], [4, 5], [3, 5], [0, 3], [1, 4], [2, 5]]
        return 2, kind, P, E, {"rank": 8, "trivial": 3, "nontrivial": 1, "stress": 1, "verdict": "flexible"}
    if kind == "vertex_on_segment":
        # a minimally rigid framework and a new vertex on the segment between two of its vertices,
        # joined to both: the new vertex can move across the segment infinitesimally (d - 1
        # flexes) but not really (a stress through the two collinear bars: prestress stable)
        d = 2 if rng.random() < 0.6 else 3
        n = int(rng.integers(d + 1, 8))
        P, E = _henneberg(rng, d, n)
        a, b = (int(u) for u in rng.choice(n, size=2, replace=False))
        t = rng.uniform(0.2, 0.8)
        P = np.r_[P, [(1 - t) * P[a] + t * P[b]]]
        E = [list(e) for e in E] + [[a, n], [b, n]]
        triv = d * (d + 1) // 2
        return d, kind, P, E, {"rank": d * n - triv + 1, "trivial": triv, "nontrivial": d - 1, "stress": 1,
                               "verdict": "rigid"}
    if kind in ("dixon_k33", "k33_on_ellipse"):
        E = [[i, j] for i in range(3) for j in range(3, 6)]
        if kind == "dixon_k33":
            # Dixon's first mechanism: one side on the x-axis, the other on the y-axis. The bar
            # lengths^2 are x_i^2 + y_j^2, kept by x_i^2 += t, y_j^2 -= t: flexible.
            while True:
                x = rng.uniform(-2, 2, 3) * rng.choice([-1, 1], 3)
                y = rng.uniform(-2, 2, 3)
                if min(abs(x).min(), abs(y).min()) > 0.2 and len(set(np.round(abs(x), 2))) == 3 and \
                        len(set(np.round(abs(y), 2))) == 3:
                    break
            P = np.r_[np.c_[x, np.zeros(3)], np.c_[np.zeros(3), y]]
            return 2, kind, P, E, {"rank": 8, "trivial": 3, "nontrivial": 1, "stress": 1, "verdict": "flexible"}
        # six points on an ellipse: infinitesimally flexible with one stress (the verdict is not
        # asserted; the counts are exact)
        t = rng.permutation(np.sort(rng.uniform(0, 2 * math.pi, 6)))
        a, b = rng.uniform(0.5, 2.0, 2)
        P = np.c_[a * np.cos(t), b * np.sin(t)]
        return 2, kind, P, E, {"rank": 8, "trivial": 3, "nontrivial": 1, "stress": 1}
    if kind in ("collinear_triangle", "collinear_path"):
        d = 2 if rng.random() < 0.6 else 3
        x = np.sort(rng.uniform(-2, 2, 3))
        while np.diff(x).min() < 0.2:
            x = np.sort(rng.uniform(-2, 2, 3))
        P = np.zeros((3, d))
        P[:, 0] = x
        triv = 3 if d == 2 else 5  # Euclidean motions of collinear points
        if kind == "collinear_triangle":
            # rigid (second-order rigid, prestress stable) but not infinitesimally rigid
            E = [[0, 1], [1, 2], [0, 2]]
            known = {"rank": 2, "trivial": triv, "nontrivial": d * 3 - 2 - triv, "stress": 1, "verdict": "rigid"}
        else:
            E = [[0, 1], [1, 2]]
            known = {"rank": 2, "trivial": triv, "nontrivial": d * 3 - 2 - triv, "stress": 0, "verdict": "flexible"}
        return d, kind, P, E, known
    if kind == "parallelogram_4bar":
        w, h = rng.uniform(0.3, 3.0, 2)
        phi = rng.uniform(0.3, math.pi - 0.3) if rng.random() < 0.7 else math.pi / 2
        u, v = np.array([w, 0.0]), h * np.array([math.cos(phi), math.sin(phi)])
        P = np.array([[0, 0], u, u + v, v])
        return 2, kind, P, [[0, 1], [1, 2], [2, 3], [3, 0]], {"rank": 4, "trivial": 3, "nontrivial": 1, "stress": 0,
                                                              "verdict": "flexible"}
    if kind == "rectangle_with_diagonals":
        w, h = rng.uniform(0.3, 3.0, 2)
        P = np.array([[0, 0], [w, 0], [w, h], [0, h]])
        E = [[0, 1], [1, 2], [2, 3], [3, 0], [0, 2], [1, 3]]
        return 2, kind, P, E, {"rank": 5, "trivial": 3, "nontrivial": 0, "stress": 1, "verdict": "rigid"}
    # 2x2 grid of unit squares: 9 vertices, 12 bars; a square grid's flexes are the row/column
    # shears (2 + 2 - 1 = 3 nontrivial), bracing one square's diagonal in each... (braced below)
    P = np.array([[i, j] for j in range(3) for i in range(3)], dtype=float)
    E = [[3 * j + i, 3 * j + i + 1] for j in range(3) for i in range(2)] + \
        [[3 * j + i, 3 * (j + 1) + i] for j in range(2) for i in range(3)]
    if kind == "square_grid_2x2":
        return 2, kind, P, E, {"rank": 12, "trivial": 3, "nontrivial": 3, "stress": 0, "verdict": "flexible"}
    # braced: diagonals in squares (0,0) and (1,1) tie row 0 to column 0 and row 1 to column 1;
    # the bracing graph (rows r0 r1, columns c0 c1, edges r0c0 r1c1) is disconnected: 1 flex left
    E = E + [[0, 4], [4, 8]]
    return 2, "braced_square_grid_2x2", P, E, {"rank": 14, "trivial": 3, "nontrivial": 1, "stress": 0,
                                               "verdict": "flexible"}


def framework_case(rng):
    r = rng.random()
    if r < 0.2:
        d, kind, P, E, known = _special_framework(rng)
        known["exact"] = True
        return Case("frameworks", f"{d}d_{kind}", "framework", P, {"edges": E}, [], known)
    if r < 0.35:
        # a random graph at random positions: generic, so flexible exactly when a nontrivial
        # infinitesimal flex exists (the realization space is a manifold there)
        d = 2 if rng.random() < 0.6 else 3
        n = int(rng.integers(d + 2, 9))
        m = max(1, d * n - d * (d + 1) // 2 + int(rng.integers(-2, 3)))
        allE = list(itertools.combinations(range(n), 2))
        m = min(m, len(allE))
        idx = rng.choice(len(allE), size=m, replace=False)
        E = [list(allE[j]) for j in sorted(idx)]
        pinned = sorted(int(i) for i in rng.choice(n, size=int(rng.integers(0, d + 1)), replace=False))
        return Case("frameworks", f"{d}d_random_graph" + ("_pinned" if pinned else ""), "framework",
                    rng.uniform(-1, 1, (n, d)), {"edges": E}, pinned, {"generic": True})
    d = 2 if rng.random() < 0.6 else 3
    n = int(rng.integers(d + 1, 10 if d == 2 else 9))
    u = rng.random()
    if u < 0.05:
        n = int(rng.integers(20, 121))  # large
    elif u < 0.06 and d == 2:
        n = int(rng.integers(250, 400))  # huge: flexure switches to sparse QR around here
    P, E = _henneberg(rng, d, n)
    variant = rng.choice(["minimal", "minimal", "minus_edge", "plus_edge", "minimal_pinned", "plus_edge_pinned"])
    triv = d * (d + 1) // 2
    known = {}
    pinned = []
    if variant.startswith("minimal"):
        known = {"nontrivial": 0, "verdict": "rigid"}
        if variant == "minimal":
            known.update(rank=d * n - triv, stress=0, trivial=triv)
    elif variant == "minus_edge":
        if len(E) <= 1:
            variant = "minimal"
            known = {"nontrivial": 0, "stress": 0, "trivial": triv, "rank": d * n - triv, "verdict": "rigid"}
        else:
            E.pop(int(rng.integers(len(E))))
            known = {"nontrivial": 1, "stress": 0, "trivial": triv, "rank": d * n - triv - 1, "verdict": "flexible"}
    if variant.startswith("plus_edge"):
        have = set(E)
        non = [e for e in itertools.combinations(range(n), 2) if e not in have]
        if not non:
            variant = variant.replace("plus_edge", "minimal")
            known = {"nontrivial": 0, "verdict": "rigid"}
            if variant == "minimal":
                known.update(rank=d * n - triv, stress=0, trivial=triv)
        else:
            E.append(non[int(rng.integers(len(non)))])
            known = {"nontrivial": 0, "verdict": "rigid"}
            if variant == "plus_edge":
                known.update(rank=d * n - triv, stress=1, trivial=triv)
    if variant.endswith("pinned"):
        k = int(rng.integers(1, d + 1))
        pinned = sorted(int(i) for i in rng.choice(n, size=min(k, n), replace=False))
    return Case("frameworks", f"{d}d_{variant}", "framework", P, {"edges": [list(e) for e in E]}, pinned, known)


# --------------------------------------------------------------------------- 2. angular polygons

def _angles_ok(P, lo=0.12):
    n = len(P)
    for i in range(n):
        a = P[i - 1] - P[i]
        b = P[(i + 1) % n] - P[i]
        na, nb = np.linalg.norm(a), np.linalg.norm(b)
        if na == 0 or nb == 0:
            return False
        th = math.acos(max(-1.0, min(1.0, float(np.dot(a, b) / (na * nb)))))
        if th < lo or th > math.pi - lo:
            return False
    return True


def _polygon(rng, shape, n):
    if shape == "square":
        return np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    if shape == "rectangle":
        w, h = rng.uniform(0.2, 3.0, 2)
        return np.array([[0, 0], [w, 0], [w, h], [0, h]], float)
    if shape == "parallelogram":
        w, h = rng.uniform(0.3, 3.0, 2)
        phi = rng.uniform(0.3, math.pi - 0.3)
        u, v = np.array([w, 0.0]), h * np.array([math.cos(phi), math.sin(phi)])
        return np.array([[0, 0], u, u + v, v], float)
    if shape == "rhombus":
        phi = rng.uniform(0.3, math.pi - 0.3)
        u, v = np.array([1.0, 0.0]), np.array([math.cos(phi), math.sin(phi)])
        return np.array([[0, 0], u, u + v, v], float)
    if shape == "isosceles_trapezoid":
        a, b, h = rng.uniform(1.0, 3.0), rng.uniform(0.2, 0.9), rng.uniform(0.3, 2.0)
        b *= a
        return np.array([[-a / 2, 0], [a / 2, 0], [b / 2, h], [-b / 2, h]], float)
    if shape == "regular":
        t = 2 * math.pi * np.arange(n) / n
        return np.c_[np.cos(t), np.sin(t)]
    if shape == "convex":
        t = np.sort(rng.uniform(0, 2 * math.pi, n))
        a, b = rng.uniform(0.5, 2.0, 2)
        return np.c_[a * np.cos(t), b * np.sin(t)]
    # simple (star-shaped, possibly non-convex)
    t = np.sort(rng.uniform(0, 2 * math.pi, n))
    r = rng.uniform(0.4, 1.6, n)
    return np.c_[r * np.cos(t), r * np.sin(t)]


def _gaps_ok(P):
    t = np.sort(np.arctan2(P[:, 1], P[:, 0]))
    g = np.diff(np.r_[t, t[0] + 2 * math.pi])
    return g.max() < math.pi - 0.1 and g.min() > 0.05


def _random_angles(rng, n, m):
    """m distinct angles [i, j, k] (at j, i < k) on n points, chosen at random."""
    trip = [(i, j, k) for j in range(n) for i in range(n) for k in range(i + 1, n) if j not in (i, k)]
    idx = rng.choice(len(trip), size=min(m, len(trip)), replace=False)
    return [list(trip[t]) for t in sorted(idx)]


def _triangulation(rng, min_angle=0.2):
    """A triangulated convex polygon with interior points, all triangle angles >= min_angle."""
    while True:
        P, T = _triangulated_polygon(rng, concentration=3)
        ok = True
        for tri in T:
            for r in range(3):
                a, b, c = P[tri[r - 1]], P[tri[r]], P[tri[(r + 1) % 3]]
                u, v = a - b, c - b
                ang = math.acos(np.clip(u @ v / (np.linalg.norm(u) * np.linalg.norm(v)), -1, 1))
                ok &= ang > min_angle
        if ok:
            return P, T


def angular_case(rng):
    r = rng.random()
    if r < 0.08:
        # every angle of every triangle of a triangulated disc: the triangles' shapes, hence the
        # whole disc, are fixed up to similarity (infinitesimally too): rigid, rank 2n - 4
        P, T = _triangulation(rng)
        A = [[tri[r - 1], tri[r], tri[(r + 1) % 3]] for tri in T for r in range(3)]
        n = len(P)
        return Case("angular", f"triangulation_all_angles_n{n}", "angular_framework", P, {"angles": A}, [],
                    {"rank": 2 * n - 4, "trivial": 4, "nontrivial": 0, "stress": 3 * len(T) - (2 * n - 4),
                     "verdict": "rigid", "exact": True})
    if r < 0.16:
        # random angle triples at random points in the plane (generic), maybe pinned
        n = int(rng.integers(4, 8))
        m = max(1, 2 * n - 4 + int(rng.integers(-2, 3)))
        A = _random_angles(rng, n, m)
        pinned = sorted(int(i) for i in rng.choice(n, size=int(rng.integers(0, 3)), replace=False))
        return Case("angular", f"2d_random_n{n}" + ("_pinned" if pinned else ""), "angular_framework",
                    rng.uniform(-1, 1, (n, 2)), {"angles": A}, pinned, {"generic": True})
    if r < 0.25:
        # a planar polygon in 3D, every angle fixed: moving a vertex off the plane changes no
        # angle to first order, so rank n - 1 as in the plane; the planar family still flexes
        n = int(rng.integers(3, 8))
        for _ in range(1000):
            P = _polygon(rng, "convex", n)
            if _gaps_ok(P - P.mean(axis=0)) and _angles_ok(P):
                break
        P = np.c_[P, np.zeros(n)]
        A = [[(i - 1) % n, i, (i + 1) % n] for i in range(n)]
        return Case("angular", f"planar_polygon_in_3d_n{n}", "angular_framework", P, {"angles": A}, [],
                    {"rank": n - 1, "stress": 1, "trivial": 7, "nontrivial": 3 * n - (n - 1) - 7,
                     "verdict": "flexible" if n >= 4 else "rigid", "exact": True})
    if r < 0.01:
        # a huge star-shaped zigzag polygon (radii alternating), every angle fixed
        n = 2 * int(rng.integers(100, 200))
        t = 2 * math.pi * (np.arange(n) + rng.uniform(-0.2, 0.2, n)) / n
        rad = np.where(np.arange(n) % 2 == 0, 1.0, 0.6) * rng.uniform(0.95, 1.05, n)
        P = np.c_[rad * np.cos(t), rad * np.sin(t)]
        A = [[(i - 1) % n, i, (i + 1) % n] for i in range(n)]
        return Case("angular", f"huge_zigzag_n{n}", "angular_framework", P, {"angles": A}, [],
                    {"rank": n - 1, "stress": 1, "trivial": 4, "nontrivial": n - 3, "verdict": "flexible",
                     "exact": True})
    if r < 0.30:
        # an a x b grid of rectangles with the four right angles of every cell fixed: every cell
        # stays a rectangle, the column widths and row heights can change: flexible
        a, b = int(rng.integers(1, 4)), int(rng.integers(1, 4))
        if rng.random() < 0.03:
            a, b = int(rng.integers(8, 14)), int(rng.integers(8, 14))  # huge
        xs = np.r_[0, np.cumsum(rng.uniform(0.3, 2.0, a))]
        ys = np.r_[0, np.cumsum(rng.uniform(0.3, 2.0, b))]
        idx = lambda i, j: j * (a + 1) + i  # noqa: E731
        P = np.array([[xs[i], ys[j]] for j in range(b + 1) for i in range(a + 1)])
        A = []
        for i in range(a):
            for j in range(b):
                c = [idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)]
                A += [[c[k - 1], c[k], c[(k + 1) % 4]] for k in range(4)]
        return Case("angular", f"rectangle_grid_{a}x{b}", "angular_framework", P, {"angles": A}, [],
                    {"verdict": "flexible"})
    if r < 0.36:
        # random angle triples at random points in 3D (generic): flexible iff a nontrivial flex
        n = int(rng.integers(4, 7))
        m = max(1, 3 * n - 7 + int(rng.integers(-2, 3)))
        A = _random_angles(rng, n, m)
        return Case("angular", f"3d_random_n{n}", "angular_framework", rng.uniform(-1, 1, (n, 3)), {"angles": A}, [],
                    {"generic": True})
    shapes = ["rectangle", "square", "parallelogram", "rhombus", "isosceles_trapezoid", "regular", "convex", "simple"]
    shape = shapes[int(rng.integers(len(shapes)))]
    for _ in range(1000):
        n = 4 if shape in ("rectangle", "square", "parallelogram", "rhombus", "isosceles_trapezoid") else int(rng.integers(3, 9))
        if shape in ("regular", "convex") and rng.random() < 0.05:
            n = int(rng.integers(9, 41))
        P = _polygon(rng, shape, n)
        if shape in ("convex", "simple"):
            c = P.mean(axis=0) if shape == "convex" else np.zeros(2)
            if not _gaps_ok(P - c):
                continue
        if _angles_ok(P):
            break
    else:
        raise RuntimeError("no polygon")
    pinned = []
    if rng.random() < 0.3:
        i = int(rng.integers(n))
        # two pins: no similarity left; one pin: rotations and scalings about it
        pinned = sorted([i, (i + 1) % n]) if rng.random() < 0.6 else [i]
    angles = [[(i - 1) % n, i, (i + 1) % n] for i in range(n)]
    known = {"rank": n - 1, "stress": 1, "trivial": 4 - 2 * len(pinned), "nontrivial": n - 3,
             "verdict": "flexible" if n >= 4 else "rigid", "exact": True}
    variant = f"{shape}_n{n}" + ("_pinned" if pinned else "")
    return Case("angular", variant, "angular_framework", P, {"angles": angles}, pinned, known)


# --------------------------------------------------------------------------- 3. volume hypergraphs

def _vol_henneberg(rng, d, n):
    """Start at one simplex; each new vertex gets d simplices with existing vertices: minimally
    infinitesimally volume-rigid (rank d*n - (d*d + d - 1)) at generic positions."""
    P = [rng.uniform(-1, 1, d) for _ in range(d + 1)]
    S = [tuple(range(d + 1))]
    for v in range(d + 1, n):
        while True:
            faces = set()
            while len(faces) < d:
                faces.add(tuple(sorted(int(u) for u in rng.choice(v, size=d, replace=False))))
            # faces all through one line (a common pair) leave v free to slide along it: not generic
            common = set.intersection(*(set(f) for f in faces))
            if len(common) < 2:
                break
        for f in faces:
            S.append(tuple(sorted((*f, v))))
        P.append(rng.uniform(-1, 1, d))
    return np.array(P), S


def _triangulated_polygon(rng, concentration=2):
    """A convex polygon fanned from vertex 0, with up to 3 interior points each splitting a
    triangle (placed by Dirichlet weights of this concentration)."""
    k = int(rng.integers(3, 7))
    t = np.sort(rng.uniform(0, 2 * math.pi, k))
    P = list(np.c_[np.cos(t), np.sin(t)] * rng.uniform(0.7, 1.3, (k, 1)))
    T = [(0, i, i + 1) for i in range(1, k - 1)]
    for _ in range(int(rng.integers(0, 4))):
        j = int(rng.integers(len(T)))
        a, b, c = T.pop(j)
        w = rng.dirichlet([concentration] * 3)
        P.append(w[0] * P[a] + w[1] * P[b] + w[2] * P[c])
        v = len(P) - 1
        T += [(a, b, v), (b, c, v), (c, a, v)]
    return np.array(P), T


def volume_case(rng):
    d = 2 if rng.random() < 0.75 else 3
    variant = rng.choice(["minimal", "minimal", "minus_simplex", "plus_simplex", "complete", "triangulated",
                          "triangulated"])
    triv = d * d + d - 1
    if variant == "triangulated" and d == 2:
        P, S = _triangulated_polygon(rng)
        known = {"generic": True}
        if rng.random() < 0.5:
            k = int(rng.integers(1, 4))
            tri_pins = sorted(int(i) for i in rng.choice(len(P), size=k, replace=False))
            known["pins"] = tri_pins
        else:
            known["trivial"] = triv
    elif variant == "complete":
        n = int(rng.integers(d + 2, d + 4))
        P = rng.uniform(-1, 1, (n, d))
        S = list(itertools.combinations(range(n), d + 1))
        known = {"trivial": triv, "nontrivial": 0, "rank": d * n - triv, "stress": len(S) - (d * n - triv),
                 "verdict": "rigid"}
    else:
        if variant == "triangulated":
            variant = "minimal"
        n = int(rng.integers(d + 1, 9 if d == 2 else 7))
        if d == 2 and rng.random() < 0.03:
            # larger (random area-Henneberg systems get ill-conditioned quickly: from about 100
            # vertices the smallest singular value falls to 1e-7..1e-11 and no rank is clear)
            n = int(rng.integers(15, 40))
        P, S = _vol_henneberg(rng, d, n)
        known = {"trivial": triv, "nontrivial": 0, "rank": d * n - triv, "stress": 0, "verdict": "rigid"}
        if variant == "minus_simplex" and len(S) > 1:
            S.pop(int(rng.integers(len(S))))
            known = {"trivial": triv, "nontrivial": 1, "rank": d * n - triv - 1, "stress": 0, "verdict": "flexible"}
        elif variant == "plus_simplex":
            have = set(S)
            non = None
            for _ in range(1000):  # a random new simplex, by rejection
                cand = tuple(sorted(int(u) for u in rng.choice(n, size=d + 1, replace=False)))
                if cand not in have:
                    non = cand
                    break
            if non:
                S.append(non)
                known["stress"] = 1
            else:
                variant = "minimal"
        elif variant == "minus_simplex":
            variant = "minimal"
    pinned = known.pop("pins", [])
    if pinned:
        variant += "_pinned"
    if variant == "minimal" and rng.random() < 0.3:
        # pin the vertices of the first simplex: no trivial motion left, the same nontrivial ones
        pinned = list(S[0])
        variant = "minimal_pinned_simplex"
        known = {"trivial": 0, "nontrivial": 0, "verdict": "rigid", "rank": d * (len(P) - d - 1),
                 "stress": len(S) - 1 - d * (len(P) - d - 1)}
    elif variant == "minus_simplex" and rng.random() < 0.2:
        # the paper's example: the octahedral hypergraph without two faces, the inner triangle pinned
        P = np.array([[0, 0], [3, 0], [0, 3], [1, 1], [1, 0.5], [0.5, 1]], float)
        S = [[0, 2, 5], [0, 1, 4], [1, 2, 3], [0, 4, 5], [5, 3, 4]]
        d, pinned, variant = 2, [3, 4, 5], "paper_octahedral_pinned"
        known = {"trivial": 0, "verdict": "flexible", "generic": False}
    return Case("volume", f"{d}d_{variant}", "volume_hypergraph", P, {"simplices": [list(s) for s in S]}, pinned,
                known)


# --------------------------------------------------------------------------- 4. body-hinge in 3D

def body_hinge_case(rng):
    variant = rng.choice(["triangle_strip", "tetra_chain", "triangle_fan_cycle", "planar_quad_chain",
                          "five_point_body_chain", "flat_fan_cycle"])
    formulation_free = False
    if rng.random() < 0.12:
        # random bodies of 3 or 4 vertices at random points (generic): flexible iff a nontrivial flex
        n = int(rng.integers(5, 10))
        nb = int(rng.integers(2, 6))
        bodies = []
        while len(bodies) < nb:
            k = int(rng.integers(3, 5))
            body = sorted(int(u) for u in rng.choice(n, size=k, replace=False))
            if body not in bodies:
                bodies.append(body)
        used = sorted({v for b in bodies for v in b})
        relabel = {v: i for i, v in enumerate(used)}
        bodies = [[relabel[v] for v in b] for b in bodies]
        pinned = sorted(int(i) for i in rng.choice(len(used), size=int(rng.integers(0, 4)), replace=False))
        return Case("body_hinge", f"random_bodies_n{len(used)}" + ("_pinned" if pinned else ""), "body_hinge",
                    rng.uniform(-1, 1, (len(used), 3)), {"bodies": bodies}, pinned, {"generic": True})
    if variant == "triangle_strip" and rng.random() < 0.25:
        # a flat strip of triangles in 3D: rigid in its plane, folds along its b - 1 hinges
        b = int(rng.integers(1, 7))
        P = np.c_[np.arange(b + 2) * 0.7 + rng.uniform(-0.2, 0.2, b + 2),
                  np.where(np.arange(b + 2) % 2 == 0, 0.0, 1.0) + rng.uniform(-0.2, 0.2, b + 2), np.zeros(b + 2)]
        bodies = [[i, i + 1, i + 2] for i in range(b)]
        return Case("body_hinge", f"flat_triangle_strip_b{b}", "body_hinge", P, {"bodies": bodies}, [],
                    {"trivial": 6, "rank": 2 * b + 1, "nontrivial": b - 1, "stress": 0,
                     "verdict": "rigid" if b == 1 else "flexible", "exact": True})
    if variant == "flat_fan_cycle":
        # b triangles around a vertex, all in one plane (a flat origami vertex of degree b):
        # b = 3 is a planar K4, infinitesimally flexible but rigid (prestress stable);
        # b >= 4 folds rigidly (a degree-4 flat vertex is a spherical 4-bar at its flat state)
        b = int(rng.integers(3, 7))
        while True:
            t = np.sort(rng.uniform(0, 2 * math.pi, b))
            g = np.diff(np.r_[t, t[0] + 2 * math.pi])
            if g.max() < math.pi - 0.2 and g.min() > 0.3:
                break
        rad = rng.uniform(0.5, 1.5, b)
        P = np.r_[[[0.0, 0.0, 0.0]], np.c_[rad * np.cos(t), rad * np.sin(t), np.zeros(b)]]
        bodies = [[0, i, i % b + 1] for i in range(1, b + 1)]
        # in the plane a wheel: rank 2b - 1 with one stress; out of the plane nothing to first order
        known = {"trivial": 6, "rank": 2 * b - 1, "nontrivial": b - 2, "stress": 1,
                 "verdict": "rigid" if b == 3 else "flexible"}
        return Case("body_hinge", f"flat_fan_cycle_b{b}", "body_hinge", P, {"bodies": bodies}, [], known)
    if variant == "planar_quad_chain":
        # planar quadrilateral panels, consecutive ones sharing an edge (a hinge), each in its own
        # plane through the hinge: b - 1 dihedral angles
        b = int(rng.integers(1, 6))
        a0, b0 = rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 3)
        w = rng.standard_normal(3)
        P = [a0, b0, b0 + w + 0.3 * (b0 - a0), a0 + w * rng.uniform(0.5, 1.5)]
        bodies = [[0, 1, 2, 3]]
        for k in range(1, b):
            ha, hb = bodies[-1][2], bodies[-1][3]
            A, B = P[ha], P[hb]
            w = rng.standard_normal(3)
            v = len(P)
            P += [B + w + rng.uniform(-0.3, 0.3) * (B - A), A + w * rng.uniform(0.5, 1.5)]
            bodies.append([ha, hb, v, v + 1])
        P = np.array(P)
        nt = b - 1
        formulation_free = True
    elif variant == "five_point_body_chain":
        b = int(rng.integers(1, 5))
        P = [rng.uniform(-1, 1, 3) for _ in range(5)]
        bodies = [[0, 1, 2, 3, 4]]
        for k in range(1, b):
            hinge = bodies[-1][-2:]
            v = len(P)
            P += [rng.uniform(-1, 1, 3) for _ in range(3)]
            bodies.append([*hinge, v, v + 1, v + 2])
        P = np.array(P)
        nt = b - 1
        formulation_free = True
    elif variant == "triangle_strip":
        u = rng.random()
        b = int(rng.integers(1, 7)) if u < 0.94 else int(rng.integers(7, 41)) if u < 0.99 else int(rng.integers(150, 250))
        P = rng.uniform(-1, 1, (b + 2, 3))
        bodies = [[i, i + 1, i + 2] for i in range(b)]
        nt = b - 1
    elif variant == "tetra_chain":
        b = int(rng.integers(1, 5))
        P = [rng.uniform(-1, 1, 3) for _ in range(4)]
        bodies = [[0, 1, 2, 3]]
        for k in range(1, b):
            prev = bodies[-1]
            hinge = [prev[2], prev[3]]
            v = len(P)
            P += [rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 3)]
            bodies.append([*hinge, v, v + 1])
        P = np.array(P)
        nt = b - 1
    else:
        b = int(rng.integers(3, 8))
        P = rng.uniform(-1, 1, (b + 1, 3))
        bodies = [[0, i, i % b + 1] for i in range(1, b + 1)]
        nt = b - 3
    known = {"trivial": 6, "nontrivial": nt, "verdict": "rigid" if nt == 0 else "flexible"}
    if formulation_free:
        # equations (hence stress_dim) depend on how a body of more than 4, or of 4 coplanar,
        # vertices is made rigid; rank, trivial and nontrivial do not
        known["free_fields"] = ["equations", "stress_dim"]
    pinned = []
    u = rng.random()
    if u < 0.2:
        pinned = sorted(bodies[0])  # one body held: no trivial motion left
        known["trivial"] = 0
        variant += "_pinned"
    elif u < 0.35:
        # two vertices of the first body held: only the rotation about their axis is left; it
        # turns the first body, so the nontrivial flexes stay
        pinned = sorted(bodies[0][-2:])
        known["trivial"] = 1
        variant += "_pinned_axis"
    return Case("body_hinge", f"{variant}_b{b}", "body_hinge", np.asarray(P), {"bodies": bodies}, pinned, known)


# --------------------------------------------------------------------------- 5. disk packings in 2D

def _place_ok(C, R, c, r, touching, min_gap=0.1):
    for j in range(len(C)):
        if j in touching:
            continue
        if np.linalg.norm(C[j] - c) < (R[j] + r) * (1 + min_gap):
            return False
    return True


def _lattice_packing(rng, variant):
    r = rng.uniform(0.5, 2.0)
    a, b = int(rng.integers(2, 5)), int(rng.integers(2, 5))
    if rng.random() < 0.05:
        a, b = int(rng.integers(12, 18)), int(rng.integers(12, 18))  # huge
    if variant == "triangular_lattice":
        e1, e2 = np.array([2 * r, 0.0]), np.array([r, math.sqrt(3) * r])
    else:
        e1, e2 = np.array([2 * r, 0.0]), np.array([0.0, 2 * r])
    C = np.array([i * e1 + j * e2 for j in range(b) for i in range(a)])
    n = len(C)
    D = np.linalg.norm(C[:, None, :] - C[None, :, :], axis=2)
    E = [[int(p), int(q)] for p, q in zip(*np.nonzero(np.abs(D - 2 * r) < 1e-9 * r)) if p < q]
    if variant == "triangular_lattice":
        # a triangulated parallelogram patch: infinitesimally rigid, the extra contacts are stresses
        known = {"trivial": 3, "nontrivial": 0, "rank": 2 * n - 3, "stress": len(E) - (2 * n - 3), "verdict": "rigid"}
    else:
        # square grid: rows and columns shear, (a - 1) + (b - 1) - 1 flexes
        known = {"trivial": 3, "nontrivial": a + b - 3, "stress": 0, "verdict": "flexible"}
    known["exact"] = True
    return Case("packing", f"{variant}_{a}x{b}", "sphere_packing", C, {"radii": [r] * n, "edges": E}, [], known)


def _sphere_packing_3d(rng, variant):
    for _ in range(200):
        if variant == "3d_chain":
            n = int(rng.integers(2, 7))
            R = list(rng.uniform(0.5, 2.0, n))
            C = [np.zeros(3)]
            E = []
            for i in range(1, n):
                for _ in range(100):
                    u = rng.standard_normal(3)
                    c = C[-1] + (R[i - 1] + R[i]) * u / np.linalg.norm(u)
                    if _place_ok(C, R[:i], c, R[i], {i - 1}):
                        break
                else:
                    break
                C.append(c)
                E.append([i - 1, i])
            if len(C) < n:
                continue
            nt = 0 if n == 2 else 2 * n - 5  # two balls: collinear, 5 trivial motions
            known = {"trivial": 5 if n == 2 else 6, "nontrivial": nt, "stress": 0,
                     "verdict": "rigid" if nt == 0 else "flexible"}
        else:
            # four mutually touching spheres: a tetrahedron of contacts, rigid
            R = list(rng.uniform(0.5, 2.0, 4))
            d01, d02, d12 = R[0] + R[1], R[0] + R[2], R[1] + R[2]
            x = (d01 ** 2 + d02 ** 2 - d12 ** 2) / (2 * d01)
            C = [np.zeros(3), np.array([d01, 0, 0]), np.array([x, math.sqrt(d02 ** 2 - x * x), 0])]
            # the fourth centre at distance R3 + Ri from the three others
            d = [R[3] + R[i] for i in range(3)]
            px = (d[0] ** 2 - d[1] ** 2 + d01 ** 2) / (2 * d01)
            c2 = C[2]
            py = (d[0] ** 2 - d[2] ** 2 + c2[0] ** 2 + c2[1] ** 2 - 2 * c2[0] * px) / (2 * c2[1])
            pz2 = d[0] ** 2 - px ** 2 - py ** 2
            if pz2 <= 0.05:
                continue
            C.append(np.array([px, py, math.sqrt(pz2)]))
            E = [[i, j] for i in range(4) for j in range(i + 1, 4)]
            known = {"trivial": 6, "nontrivial": 0, "rank": 6, "stress": 0, "verdict": "rigid"}
        return Case("packing", f"{variant}_n{len(C)}", "sphere_packing", np.array(C), {"radii": R, "edges": E}, [],
                    known)
    raise RuntimeError("no packing")


def _near_contact(rng):
    """Three disks, two contacts exact and the third pair at a relative gap g: |g| <= 1e-6 (the
    default tolerance) touches, so a rigid triangle; g = 1e-4 does not, so a flexible chain."""
    R = list(rng.uniform(0.5, 2.0, 3))
    g = float(rng.choice([-5e-7, -2e-7, 2e-7, 5e-7, 1e-4, 3e-4]))
    a, b, c = R[0] + R[1], R[0] + R[2], (R[1] + R[2]) * (1 + g)
    x = (a * a + b * b - c * c) / (2 * a)
    C = np.array([[0, 0], [a, 0], [x, math.sqrt(b * b - x * x)]])
    touching = abs(g) <= 1e-6
    E = [[0, 1], [0, 2]] + ([[1, 2]] if touching else [])
    known = {"trivial": 3, "nontrivial": 0 if touching else 1, "stress": 0,
             "verdict": "rigid" if touching else "flexible", "exact": True}
    return Case("packing", f"near_contact_gap{g:+.0e}", "sphere_packing", C, {"radii": R, "edges": E}, [], known)


def packing_case(rng):
    u = rng.random()
    if u < 0.08:
        return _near_contact(rng)
    if u < 0.2:
        return _lattice_packing(rng, "triangular_lattice" if rng.random() < 0.5 else "square_lattice")
    if u < 0.35:
        return _sphere_packing_3d(rng, "3d_chain" if rng.random() < 0.6 else "3d_tetrahedron")
    variant = rng.choice(["chain", "triangle", "henneberg", "straight_chain"])
    if variant == "straight_chain":
        # disks in a row, each touching the next: the chain bends at every inner disk
        n = int(rng.integers(2, 7))
        R = list(rng.uniform(0.5, 2.0, n))
        x = np.r_[0, np.cumsum([R[i] + R[i + 1] for i in range(n - 1)])]
        C = np.c_[x, np.zeros(n)]
        E = [[i, i + 1] for i in range(n - 1)]
        return Case("packing", f"straight_chain_n{n}", "sphere_packing", C, {"radii": R, "edges": E}, [],
                    {"trivial": 3, "nontrivial": n - 2, "stress": 0, "rank": n - 1,
                     "verdict": "rigid" if n == 2 else "flexible", "exact": True})
    for _ in range(200):
        C, R, E = [], [], []
        if variant == "chain":
            n = int(rng.integers(2, 8))
            R = list(rng.uniform(0.5, 2.0, n))
            C = [np.zeros(2)]
            ok = True
            for i in range(1, n):
                for _ in range(100):
                    t = rng.uniform(0, 2 * math.pi)
                    c = C[-1] + (R[i - 1] + R[i]) * np.array([math.cos(t), math.sin(t)])
                    if _place_ok(C, R[:i], c, R[i], {i - 1}):
                        break
                else:
                    ok = False
                    break
                C.append(c)
                E.append([i - 1, i])
            if not ok:
                continue
            nt = n - 2
        else:
            R = list(rng.uniform(0.5, 2.0, 3))
            a, b, c = R[0] + R[1], R[0] + R[2], R[1] + R[2]
            x = (a * a + b * b - c * c) / (2 * a)
            C = [np.zeros(2), np.array([a, 0.0]), np.array([x, math.sqrt(max(b * b - x * x, 0.0))])]
            E = [[0, 1], [0, 2], [1, 2]]
            nt = 0
            if variant == "henneberg":
                n = int(rng.integers(4, 8))
                ok = True
                for i in range(3, n):
                    for _ in range(200):
                        r = rng.uniform(0.5, 2.0)
                        p, q = (int(u) for u in rng.choice(i, size=2, replace=False))
                        dpq = np.linalg.norm(C[q] - C[p])
                        ra, rb = R[p] + r, R[q] + r
                        if not (abs(ra - rb) + 1e-3 < dpq < ra + rb - 1e-3):
                            continue
                        x = (ra * ra - rb * rb + dpq * dpq) / (2 * dpq)
                        y = math.sqrt(ra * ra - x * x)
                        e = (C[q] - C[p]) / dpq
                        f = np.array([-e[1], e[0]])
                        c = C[p] + x * e + (y if rng.random() < 0.5 else -y) * f
                        if _place_ok(C, R, c, r, {p, q}):
                            break
                    else:
                        ok = False
                        break
                    C.append(c)
                    R.append(r)
                    E += [[p, i], [q, i]]
                if not ok:
                    continue
        break
    else:
        raise RuntimeError("no packing")
    n = len(C)
    known = {"trivial": 3, "nontrivial": nt, "stress": 0, "verdict": "rigid" if nt == 0 else "flexible"}
    pinned = []
    if rng.random() < 0.25:
        pinned = [int(rng.integers(n))]  # rotations about the pinned centre remain
        known["trivial"] = 1
        variant += "_pinned1"
    return Case("packing", f"{variant}_n{n}", "sphere_packing", np.array(C), {"radii": R, "edges": E}, pinned,
                known)


FAMILIES = {
    "frameworks": framework_case,
    "angular": angular_case,
    "volume": volume_case,
    "body_hinge": body_hinge_case,
    "packing": packing_case,
}
