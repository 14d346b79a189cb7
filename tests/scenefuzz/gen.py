"""Generators of VALID flexure scenes, by construction, for every system type.

Every generator takes a random.Random and returns a Scene: the TOML document (nested dicts, in
the scene format of docs/scene-format.md, vertex numbers from `index_base`), and what the
checker needs to know (0-based combinatorics). Motions are chosen afterwards (motions.py), from
the start's analysis, so that given flex coefficients have the right length.
"""

import math
import random

TYPES = [
    "framework2d", "framework3d", "framework_on_surface", "angular_framework", "polytope", "body_hinge",
    "body_bar", "volume_hypergraph", "spherical_disk_packing", "sphere_packing", "origami", "catalog",
]


class Scene:
    def __init__(self, kind, doc, dim, variant=""):
        self.kind = kind            # a TYPES entry
        self.variant = variant      # the generator's sub-family (for the report)
        self.doc = doc              # the TOML document
        self.dim = dim
        self.catalog = None         # catalog entry name (kind "catalog")
        self.catalog_form = None    # "name" (SCENE is the name, --set overrides) or "file" (type = "catalog")
        self.sets = []              # --set KEY=VALUE overrides (catalog by name)
        self.motion_kind = "auto"
        self.exact_start = True     # the written vertices are samples[0] (no correction on load)
        self.files = {}             # other files the scene reads ([system] from = FILE)
        self.check_system = None    # the [system] the checker reads, when the scene's is not explicit

    @property
    def system(self):
        return self.doc["system"]

    @property
    def base(self):
        return self.doc.get("index_base", 1)

    @property
    def type(self):
        return (self.check_system or self.system)["type"]

    def n(self):
        return len((self.check_system or self.system).get("vertices", []))


# -- TOML text ---------------------------------------------------------------------------

def _val(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if not math.isfinite(v):
            raise ValueError("non-finite number in a generated scene")
        r = repr(v)
        return r if ("." in r or "e" in r or "n" in r) else r + ".0"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_val(x) for x in v) + "]"
    raise TypeError(type(v))


TABLE_ORDER = ["system", "motion", "analysis", "render", "projection"]


def toml_text(doc):
    out = []
    for k, v in doc.items():
        if not isinstance(v, dict) and k != "output":
            out.append(f"{k} = {_val(v)}")
    for t in TABLE_ORDER + [k for k in doc if isinstance(doc[k], dict) and k not in TABLE_ORDER]:
        if t in doc and isinstance(doc[t], dict):
            out.append("")
            out.append(f"[{t}]")
            for k, v in doc[t].items():
                out.append(f"{k} = {_val(v)}")
    for o in doc.get("output", []):
        out.append("")
        out.append("[[output]]")
        for k, v in o.items():
            out.append(f"{k} = {_val(v)}")
    return "\n".join(out) + "\n"


# -- geometry helpers ------------------------------------------------------------------------

def r4(x, nd=4):
    return float(round(x, nd))


def dist(a, b):
    return math.sqrt(sum((x - y) ** 2 for x, y in zip(a, b)))


def sub(a, b):
    return [x - y for x, y in zip(a, b)]


def add(a, b):
    return [x + y for x, y in zip(a, b)]


def mul(a, s):
    return [x * s for x in a]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def norm(a):
    return math.sqrt(dot(a, a))


def unit(a):
    n = norm(a)
    return [x / n for x in a]


def rand_unit(rng, d):
    while True:
        v = [rng.gauss(0, 1) for _ in range(d)]
        n = norm(v)
        if n > 1e-3:
            return [x / n for x in v]


def rand_scale(rng):
    return rng.choice([1.0] * 8 + [0.01, 0.1, 10.0, 100.0])


def random_points(rng, n, d, scale, min_sep=0.08, grid=False):
    """n points in [0, scale]^d, pairwise at least min_sep * scale apart (grid: small integers
    times scale/3, which makes collinear and coplanar subsets likely)."""
    for _ in range(200):
        pts = []
        tries = 0
        while len(pts) < n and tries < 5000:
            tries += 1
            if grid:
                p = [scale * rng.randint(0, 3) / 3.0 for _ in range(d)]
            else:
                p = [r4(scale * rng.random(), 4 - int(round(math.log10(scale)))) for _ in range(d)]
            if all(dist(p, q) > min_sep * scale for q in pts):
                pts.append(p)
        if len(pts) == n:
            return pts
    raise RuntimeError("could not place points")


def pick_pins(rng, n, most, weights=None):
    k = rng.choices(range(most + 1), weights=weights or [3] + [2] * most)[0]
    k = min(k, n - 1)
    return sorted(rng.sample(range(n), k))


def tri_area2(a, b, c):
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def det3(a, b, c):
    return dot(a, cross(b, c))


def angle_at(p, j, i, k):
    u, w = sub(p[i], p[j]), sub(p[k], p[j])
    c = dot(u, w) / (norm(u) * norm(w))
    return math.acos(max(-1.0, min(1.0, c)))


def base_doc(scene_type, vertices, base=1, **keys):
    sysd = {"type": scene_type, "vertices": vertices}
    for k, v in keys.items():
        if v is None:
            continue
        sysd[k] = v
    return {"system": sysd}


def shift(x, base):
    """0-based vertex numbers (nested lists) written from `base`."""
    if isinstance(x, list):
        return [shift(y, base) for y in x]
    return x + base


def choose_base(rng):
    return 0 if rng.random() < 0.2 else 1


def finish(doc, base):
    if base == 0:
        doc = {"index_base": 0, **doc}
    elif base == 1 and random.random() < 0:  # never: keep the default implicit
        doc = {"index_base": 1, **doc}
    return doc


# -- graphs -------------------------------------------------------------------------------

def henneberg(rng, n, d):
    """A minimally rigid graph on n vertices (Henneberg type 1 steps), as sorted pairs."""
    k0 = min(n, d)
    edges = {(i, j) for i in range(k0) for j in range(i + 1, k0)}
    for v in range(k0, n):
        for u in rng.sample(range(v), min(d, v)):
            edges.add((u, v))
    return edges


def modify_graph(rng, edges, n):
    edges = set(edges)
    for _ in range(rng.choice([0, 0, 1, 1, 2])):
        if len(edges) > 1:
            edges.remove(rng.choice(sorted(edges)))
    for _ in range(rng.choice([0, 0, 1, 2])):
        i, j = sorted(rng.sample(range(n), 2))
        edges.add((i, j))
    return sorted(edges)


def cycle_edges(n):
    return sorted({tuple(sorted((i, (i + 1) % n))) for i in range(n)})


# -- the generators ------------------------------------------------------------------------

def gen_framework(rng, d):
    variant = rng.choice(["henneberg", "henneberg", "henneberg", "random", "grid", "cycle", "chain", "special"])
    scale = rand_scale(rng)
    base = choose_base(rng)
    attached = None
    if variant == "special":
        # Small mechanisms with singular positions: parallelograms, squares, collinear bars.
        if d == 2:
            pick = rng.choice(["square", "parallelogram", "collinear", "kite", "square_diag"])
            if pick == "square":
                pts = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
                edges = [(0, 1), (1, 2), (2, 3), (0, 3)]
            elif pick == "parallelogram":
                s = r4(rng.uniform(0.2, 0.8))
                pts = [[0.0, 0.0], [2.0, 0.0], [2.0 + s, 1.0], [s, 1.0]]
                edges = [(0, 1), (1, 2), (2, 3), (0, 3)]
            elif pick == "collinear":
                pts = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0], [1.5, 1.0]]
                edges = [(0, 1), (1, 2), (2, 3), (1, 4), (2, 4)]
            elif pick == "kite":
                pts = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [1.0, 1.0]]
                edges = [(0, 1), (1, 2), (0, 3), (2, 3), (1, 3)]
            else:
                pts = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [2.0, 0.0], [2.0, 1.0]]
                edges = [(0, 1), (1, 2), (2, 3), (0, 3), (1, 4), (4, 5), (2, 5), (0, 2)]
            pts = [[x * scale for x in p] for p in pts]
        else:
            pick = rng.choice(["octahedron", "cube", "bipyramid"])
            if pick == "octahedron":
                pts = [[0, 0, -1], [-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0], [0, 0, 1]]
                edges = [(0, 1), (0, 2), (0, 3), (0, 4), (1, 5), (2, 5), (3, 5), (4, 5), (1, 3), (3, 2), (2, 4), (4, 1)]
            elif pick == "cube":
                pts = [[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)]
                edges = [(i, j) for i in range(8) for j in range(i + 1, 8) if sum(a != b for a, b in zip(pts[i], pts[j])) == 1]
            else:
                pts = [[1, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0], [0, 0, 1], [0, 0, -1]]
                edges = [(0, 1), (1, 2), (0, 2)] + [(i, j) for i in range(3) for j in (3, 4)]
            pts = [[float(x) * scale for x in p] for p in pts]
        n = len(pts)
        variant += ":" + pick
    else:
        n = rng.randint(d + 1, 9 if d == 2 else 8)
        pts = random_points(rng, n, d, scale, grid=(variant == "grid"))
        if variant in ("henneberg", "grid"):
            edges = modify_graph(rng, henneberg(rng, n, d), n)
        elif variant == "random":
            p = rng.uniform(0.3, 0.7)
            edges = sorted({(i, j) for i in range(n) for j in range(i + 1, n) if rng.random() < p})
            if not edges:
                edges = [(0, 1)]
        elif variant == "cycle":
            edges = cycle_edges(n)
            if rng.random() < 0.5:
                i, j = sorted(rng.sample(range(n), 2))
                edges = sorted(set(edges) | {(i, j)})
        else:  # chain between pinned ends
            edges = [(i, i + 1) for i in range(n - 1)]
    if variant == "chain":
        pins = [0, n - 1] if d == 2 else [0, n - 1]
    else:
        pins = pick_pins(rng, n, d + 1 if d == 3 else 3)
    keys = {"edges": shift([list(e) for e in edges], base)}
    lengths = None
    if rng.random() < 0.15 and variant != "grid":
        lengths = [dist(pts[i], pts[j]) for i, j in edges]
        keys["lengths"] = lengths
    if rng.random() < 0.2 and n >= d:
        # A coupler point held in the frame of d (2D: 2, 3D: 3) vertices, not collinear.
        for _ in range(20):
            frame = rng.sample(range(n), d)
            ok = dist(pts[frame[0]], pts[frame[1]]) > 0.05 * scale
            if d == 3 and ok:
                ok = norm(cross(sub(pts[frame[1]], pts[frame[0]]), sub(pts[frame[2]], pts[frame[0]]))) > 0.01 * scale ** 2
            if ok:
                break
        else:
            frame = None
        if frame:
            q = [r4(scale * rng.random(), 6) for _ in range(d)]
            if all(dist(q, p) > 0.03 * scale for p in pts):
                pts.append(q)
                attached = [n] + frame
                n += 1
                keys["attached"] = [shift(attached, base)]
                if rng.random() < 0.3:
                    other = rng.choice([v for v in range(n - 1) if v not in frame])
                    edges = sorted(set(edges) | {(other, n - 1)})
                    keys["edges"] = shift([list(e) for e in edges], base)
                    if lengths is not None:
                        keys["lengths"] = [dist(pts[i], pts[j]) for i, j in edges]
    if pins:
        keys["pinned"] = shift(pins, base)
    doc = finish(base_doc("framework", pts, **keys), base)
    s = Scene("framework2d" if d == 2 else "framework3d", doc, d, variant)
    return s


SURFACES = ["sphere", "cylinder", "hyperboloid", "paraboloid", "plane", "ellipsoid", "torus", "cone_like"]


def gen_surface(rng):
    which = rng.choice(SURFACES)
    n = rng.randint(3, 7)
    R = r4(rng.uniform(0.7, 2.0), 2)
    pts = []
    if which == "sphere":
        expr = f"x^2 + y^2 + z^2 - {R}^2"
        for _ in range(n):
            u = rand_unit(rng, 3)
            pts.append([R * c for c in u])
    elif which == "cylinder":
        expr = f"x^2 + y^2 - {R * R!r}"
        for _ in range(n):
            t = rng.uniform(0, 2 * math.pi)
            pts.append([R * math.cos(t), R * math.sin(t), r4(rng.uniform(-1, 1))])
    elif which == "hyperboloid":
        expr = "x^2 + y^2 - z^2 - 1"
        for _ in range(n):
            t, u = rng.uniform(0, 2 * math.pi), rng.uniform(-0.8, 0.8)
            pts.append([math.cosh(u) * math.cos(t), math.cosh(u) * math.sin(t), math.sinh(u)])
    elif which == "paraboloid":
        a = r4(rng.uniform(0.3, 1.5), 2)
        expr = f"z - {a}*(x^2 + y^2)"
        for _ in range(n):
            x, y = rng.uniform(-1, 1), rng.uniform(-1, 1)
            pts.append([x, y, a * (x * x + y * y)])
    elif which == "plane":
        a, b, c = (r4(rng.uniform(-1, 1), 2) for _ in range(3))
        expr = f"z - ({a}*x + {b}*y + {c})"
        for _ in range(n):
            x, y = rng.uniform(-1, 1), rng.uniform(-1, 1)
            pts.append([x, y, a * x + b * y + c])
    elif which == "ellipsoid":
        a, b, c = (r4(rng.uniform(0.6, 1.8), 2) for _ in range(3))
        expr = f"x^2/{a}^2 + y^2/{b}^2 + z^2/{c}^2 - 1"
        for _ in range(n):
            u = rand_unit(rng, 3)
            pts.append([a * u[0], b * u[1], c * u[2]])
    elif which == "torus":
        r = r4(rng.uniform(0.2, 0.5), 2)
        expr = f"(sqrt(x^2 + y^2) - {R})^2 + z^2 - {r}^2"
        for _ in range(n):
            u, v = rng.uniform(0, 2 * math.pi), rng.uniform(0, 2 * math.pi)
            pts.append([(R + r * math.cos(v)) * math.cos(u), (R + r * math.cos(v)) * math.sin(u), r * math.sin(v)])
    else:  # a cubic surface: z = x^3/3 - y^2/2 (not a quadric)
        expr = "z - (x^3/3 - y^2/2)"
        for _ in range(n):
            x, y = rng.uniform(-1, 1), rng.uniform(-1, 1)
            pts.append([x, y, x ** 3 / 3 - y ** 2 / 2])
    # well separated points only
    keep = []
    for p in pts:
        if all(dist(p, q) > 0.15 for q in keep):
            keep.append(p)
    pts = keep
    n = len(pts)
    if n < 3:
        return gen_surface(rng)
    edges = set(cycle_edges(n)) if n > 3 else {(0, 1), (1, 2), (0, 2)}
    for _ in range(rng.choice([0, 0, 1, 2])):
        i, j = sorted(rng.sample(range(n), 2))
        edges.add((i, j))
    base = choose_base(rng)
    keys = {"edges": shift([list(e) for e in sorted(edges)], base), "surface": expr}
    pins = pick_pins(rng, n, 2, [4, 2, 1])
    if pins:
        keys["pinned"] = shift(pins, base)
    exact = True
    if rng.random() < 0.15:
        pts = [p if i in pins else [c + rng.uniform(-1e-3, 1e-3) for c in p] for i, p in enumerate(pts)]
        keys["project_start"] = True
        exact = False
    doc = finish(base_doc("framework_on_surface", pts, **keys), base)
    s = Scene("framework_on_surface", doc, 3, which)
    s.exact_start = exact
    s.surface_expr = expr
    return s


def listed_scene(rng, typ, pts, key, items, n, pin_weights, d):
    """A scene of `typ` whose constraints are one list of vertex tuples under `key`, in a random
    index base, with up to 2 random pins (pick_pins's weights)."""
    base = choose_base(rng)
    keys = {key: shift(items, base)}
    pins = pick_pins(rng, n, 2, pin_weights)
    if pins:
        keys["pinned"] = shift(pins, base)
    return Scene(typ, finish(base_doc(typ, pts, **keys), base), d, f"{d}d")


def gen_angular(rng):
    d = 2 if rng.random() < 0.75 else 3
    n = rng.randint(3, 7)
    scale = rand_scale(rng)
    pts = random_points(rng, n, d, scale, min_sep=0.15)
    angles = []
    seen = set()
    want = rng.randint(1, max(1, 2 * n - 4))
    for _ in range(200):
        if len(angles) >= want:
            break
        i, j, k = rng.sample(range(n), 3)
        key = (j, frozenset((i, k)))
        if key in seen:
            continue
        a = angle_at(pts, j, i, k)
        if not (0.2 < a < math.pi - 0.2):
            continue
        seen.add(key)
        angles.append([i, j, k])
    if not angles:
        return gen_angular(rng)
    return listed_scene(rng, "angular_framework", pts, "angles", angles, n, [3, 2, 3], d)


def random_affine(rng):
    while True:
        A = [[(1.0 if i == j else 0.0) + rng.uniform(-0.35, 0.35) for j in range(3)] for i in range(3)]
        det = det3(A[0], A[1], A[2])
        if det > 0.3:
            return A, [rng.uniform(-1, 1) for _ in range(3)]


def apply_affine(A, b, p):
    return [dot(A[i], p) + b[i] for i in range(3)]


def gen_polytope(rng):
    variant = rng.choice(["hull", "hull", "prism", "frustum", "pyramid", "bipyramid", "antiprism", "box"])
    scale = rand_scale(rng)
    facets = None
    if variant == "hull":
        n = rng.randint(4, 14)
        ax = [rng.uniform(0.6, 1.4) for _ in range(3)]
        while True:
            pts = [[ax[i] * c for i, c in enumerate(rand_unit(rng, 3))] for _ in range(n)]
            if min(dist(p, q) for i, p in enumerate(pts) for q in pts[:i]) > 0.2:
                break
        facets = "hull"
    else:
        k = rng.randint(3, 7)
        ang = [2 * math.pi * i / k + rng.uniform(-0.15, 0.15) for i in range(k)]
        rad = [rng.uniform(0.85, 1.15) for _ in range(k)]
        ring = [[rad[i] * math.cos(ang[i]), rad[i] * math.sin(ang[i]), 0.0] for i in range(k)]
        h = rng.uniform(0.6, 1.6)
        if variant in ("prism", "frustum", "box"):
            if variant == "box":
                k = 4
                ring = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]
            s = 1.0 if variant != "frustum" else rng.uniform(0.4, 0.8)
            top = [[s * p[0], s * p[1], h] for p in ring]
            if variant == "box":
                top = [[p[0], p[1], 1.0] for p in ring]
            pts = ring + top
            facets = [list(range(k - 1, -1, -1)), list(range(k, 2 * k))]
            facets += [[i, (i + 1) % k, k + (i + 1) % k, k + i] for i in range(k)]
        elif variant == "pyramid":
            pts = ring + [[0.0, 0.0, h]]
            facets = [list(range(k - 1, -1, -1))] + [[i, (i + 1) % k, k] for i in range(k)]
        elif variant == "bipyramid":
            pts = ring + [[0.0, 0.0, h], [0.0, 0.0, -rng.uniform(0.6, 1.6)]]
            facets = [[i, (i + 1) % k, k] for i in range(k)] + [[(i + 1) % k, i, k + 1] for i in range(k)]
        else:  # antiprism
            top = [[rad[i] * math.cos(ang[i] + math.pi / k), rad[i] * math.sin(ang[i] + math.pi / k), h] for i in range(k)]
            # top ring must be planar: z = h for all, fine
            pts = ring + top
            facets = [list(range(k - 1, -1, -1)), list(range(k, 2 * k))]
            for i in range(k):
                facets.append([i, (i + 1) % k, k + i])
                facets.append([(i + 1) % k, k + (i + 1) % k, k + i])
        A, b = random_affine(rng)
        pts = [apply_affine(A, b, p) for p in pts]
    pts = [[c * scale for c in p] for p in pts]
    n = len(pts)
    base = choose_base(rng)
    keys = {"facets": facets if facets == "hull" else shift(facets, base)}
    pins = pick_pins(rng, n, 3, [4, 1, 1, 2])
    if pins:
        keys["pinned"] = shift(pins, base)
    doc = finish(base_doc("polytope", pts, **keys), base)
    s = Scene("polytope", doc, 3, variant)
    s.facets0 = facets
    return s


def planar_quad(rng, a, b, normal_hint):
    """Two more points c, d making a planar quad a b c d (a flat panel on edge a-b)."""
    e = sub(b, a)
    w = unit(cross(e, normal_hint))
    if norm(w) == 0:
        w = unit(cross(e, [0.3, 0.5, 0.8]))
    h = rng.uniform(0.6, 1.4)
    t1, t2 = rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3)
    c = add(add(b, mul(w, h)), mul(e, t1))
    d = add(add(a, mul(w, h)), mul(e, t2))
    return c, d


def gen_body_hinge(rng):
    variant = rng.choice(["fan", "strip", "planar_chain", "quads"])
    scale = rand_scale(rng)
    if variant == "fan":
        k = rng.randint(3, 7)
        closed = rng.random() < 0.7 and k >= 4
        ang = sorted(rng.uniform(0, 2 * math.pi) for _ in range(k))
        ang = [2 * math.pi * i / k + rng.uniform(-0.2, 0.2) for i in range(k)]
        pts = [[0.0, 0.0, rng.uniform(0.5, 1.5)]] + [[math.cos(a), math.sin(a), rng.uniform(-0.3, 0.3)] for a in ang]
        bodies = [[0, 1 + i, 1 + (i + 1) % k] for i in range(k if closed else k - 1)]
        d = 3
        variant += ":closed" if closed else ":open"
    elif variant == "strip":
        m = rng.randint(4, 8)
        pts = [[r4(rng.uniform(0, 1)), r4(rng.uniform(0, 1)), r4(rng.uniform(0, 1))] for _ in range(m)]
        pts = [[i * 0.6 + p[0], p[1], p[2]] for i, p in enumerate(pts)]
        bodies = [[i, i + 1, i + 2] for i in range(m - 2)]
        d = 3
    elif variant == "planar_chain":
        # 2D bodies (triangles or bars) sharing single vertices: a linkage of rigid plates.
        k = rng.randint(3, 6)
        ring = [[math.cos(2 * math.pi * i / k) + rng.uniform(-0.1, 0.1), math.sin(2 * math.pi * i / k) + rng.uniform(-0.1, 0.1)]
                for i in range(k)]
        pts = [list(p) for p in ring]
        bodies = []
        for i in range(k):
            j = (i + 1) % k
            if rng.random() < 0.5:
                mid = mul(add(ring[i], ring[j]), 0.5)
                out = unit(mid)
                pts.append(add(mid, mul(out, rng.uniform(0.2, 0.5))))
                bodies.append([i, j, len(pts) - 1])
            else:
                bodies.append([i, j])
        d = 2
    else:  # flat quads hinged along shared edges
        a, b = [0.0, 0.0, 0.0], [1.0, 0.0, 0.0]
        pts = [a, b]
        bodies = []
        hint = [0.0, 0.0, 1.0]
        cnt = rng.randint(2, 4)
        ia, ib = 0, 1
        for _ in range(cnt):
            c, dd = planar_quad(rng, pts[ia], pts[ib], hint)
            pts += [c, dd]
            ic, idd = len(pts) - 2, len(pts) - 1
            bodies.append([ia, ib, ic, idd])
            hint = unit([rng.gauss(0, 1) for _ in range(3)])
            ia, ib = idd, ic
        d = 3
    pts = [[c * scale for c in p] for p in pts]
    n = len(pts)
    base = choose_base(rng)
    keys = {"bodies": shift(bodies, base)}
    pins = pick_pins(rng, n, 3 if d == 3 else 2, [3, 2, 2, 1][: (4 if d == 3 else 3)])
    if pins:
        keys["pinned"] = shift(pins, base)
    doc = finish(base_doc("body_hinge", pts, **keys), base)
    s = Scene("body_hinge", doc, d, variant)
    return s


def gen_body_bar(rng):
    d = 3 if rng.random() < 0.6 else 2
    scale = rand_scale(rng)
    nb = rng.randint(2, 3)
    pts, bodies = [], []
    for b in range(nb):
        m = rng.randint(d, d + 2)
        offset = [2.0 * b] + [0.0] * (d - 1)
        idx = []
        for _ in range(m):
            for _ in range(100):
                p = [r4(o + rng.uniform(0, 1.2)) for o in offset]
                if all(dist(p, q) > 0.15 for q in pts):
                    break
            pts.append(p)
            idx.append(len(pts) - 1)
        bodies.append(idx)
    bars = set()
    want = rng.randint(1, (3 if d == 2 else 6) * (nb - 1) + 1)
    for _ in range(100):
        if len(bars) >= want:
            break
        b1, b2 = rng.sample(range(nb), 2)
        i, j = rng.choice(bodies[b1]), rng.choice(bodies[b2])
        bars.add(tuple(sorted((i, j))))
    pts = [[c * scale for c in p] for p in pts]
    n = len(pts)
    base = choose_base(rng)
    keys = {"bodies": shift(bodies, base), "bars": shift([list(b) for b in sorted(bars)], base)}
    pins = pick_pins(rng, n, d, [3, 1, 1] + ([1] if d == 3 else []))
    if pins:
        keys["pinned"] = shift(pins, base)
    doc = finish(base_doc("body_bar", pts, **keys), base)
    return Scene("body_bar", doc, d, f"{d}d:{nb}bodies")


def gen_volume(rng):
    d = 2 if rng.random() < 0.65 else 3
    n = rng.randint(d + 1, 8)
    scale = rand_scale(rng)
    pts = random_points(rng, n, d, scale, min_sep=0.12)
    simp = []
    seen = set()
    want = rng.randint(1, max(1, (2 * n - 3) if d == 2 else (3 * n - 8)))
    for _ in range(300):
        if len(simp) >= want:
            break
        s = rng.sample(range(n), d + 1)
        if frozenset(s) in seen:
            continue
        if d == 2:
            v = abs(tri_area2(pts[s[0]], pts[s[1]], pts[s[2]])) / scale ** 2
        else:
            v = abs(det3(sub(pts[s[1]], pts[s[0]]), sub(pts[s[2]], pts[s[0]]), sub(pts[s[3]], pts[s[0]]))) / scale ** 3
        if v < 0.02:
            continue
        seen.add(frozenset(s))
        simp.append(s)
    if not simp:
        return gen_volume(rng)
    return listed_scene(rng, "volume_hypergraph", pts, "simplices", simp, n, [4, 2, 1], d)


def gen_caps(rng):
    n = rng.randint(3, 8)
    pts = []
    while len(pts) < n:
        p = mul(rand_unit(rng, 3), rng.uniform(1.15, 2.2))
        p = [r4(c, 5) for c in p]
        if norm(p) > 1.05 and all(dist(p, q) > 0.2 for q in pts):
            pts.append(p)
    contacts = set(cycle_edges(n)) if n > 3 else {(0, 1), (1, 2), (0, 2)}
    for _ in range(rng.randint(0, n)):
        i, j = sorted(rng.sample(range(n), 2))
        contacts.add((i, j))
    base = choose_base(rng)
    keys = {"contacts": shift([list(c) for c in sorted(contacts)], base)}
    pins = pick_pins(rng, n, 1, [2, 1])
    if pins:
        keys["pinned"] = shift(pins, base)
    doc = finish(base_doc("spherical_disk_packing", pts, **keys), base)
    return Scene("spherical_disk_packing", doc, 3, "caps")


def _circle_touch2(a, ra, b, rb, r, rng):
    """A centre touching disk a (radius ra) and disk b (rb) with radius r, or None."""
    R1, R2 = ra + r, rb + r
    dd = dist(a, b)
    if dd > R1 + R2 or dd < abs(R1 - R2) or dd == 0:
        return None
    x = (dd * dd + R1 * R1 - R2 * R2) / (2 * dd)
    h2 = R1 * R1 - x * x
    if h2 <= 0:
        return None
    h = math.sqrt(h2)
    e = [(b[0] - a[0]) / dd, (b[1] - a[1]) / dd]
    nrm = [-e[1], e[0]]
    sgn = rng.choice([-1, 1])
    return [a[0] + x * e[0] + sgn * h * nrm[0], a[1] + x * e[1] + sgn * h * nrm[1]]


def gen_packing(rng):
    d = 2 if rng.random() < 0.6 else 3
    n = rng.randint(2, 8)
    same = rng.random() < 0.5
    R0 = r4(rng.uniform(0.5, 1.5), 2)
    radii = [R0 if same else r4(rng.uniform(0.5, 1.5), 2) for _ in range(n)]
    tol = 1e-6
    centres = [[0.0] * d]
    for i in range(1, n):
        placed = None
        for _ in range(200):
            p = None
            if d == 2 and i >= 2 and rng.random() < 0.5:
                a, b = rng.sample(range(i), 2)
                p = _circle_touch2(centres[a], radii[a], centres[b], radii[b], radii[i], rng)
            if p is None:
                a = rng.randrange(i)
                u = rand_unit(rng, d)
                p = add(centres[a], mul(u, radii[a] + radii[i]))
            ok = True
            for j in range(i):
                g = dist(p, centres[j]) - (radii[i] + radii[j])
                if g < -1e-12 * (radii[i] + radii[j]):
                    ok = False
                elif abs(g) <= 1e-9 * (radii[i] + radii[j]):
                    pass  # touching
                elif g < 0.02 * (radii[i] + radii[j]):
                    ok = False  # nearly touching: ambiguous
            if ok:
                placed = p
                break
        if placed is None:
            break
        centres.append(placed)
    n = len(centres)
    radii = radii[:n]
    base = choose_base(rng)
    keys = {}
    if same and rng.random() < 0.7:
        keys["radius"] = R0
    else:
        keys["radii"] = radii
    if rng.random() < 0.2:
        tol = rng.choice([1e-8, 1e-7, 1e-5, 1e-4, 1e-3])
        keys["tolerance"] = tol
    pins = pick_pins(rng, n, 2 if d == 2 else 3, [2, 3, 1] + ([1] if d == 3 else []))
    if pins:
        keys["pinned"] = shift(pins, base)
    doc = finish(base_doc("sphere_packing", centres, **keys), base)
    s = Scene("sphere_packing", doc, d, f"{d}d")
    s.radii = radii
    s.tolerance = tol
    s.exact_start = False
    return s


# -- origami --------------------------------------------------------------------------------

def _origami_doc(rng, pts, faces, creases, assign, variant):
    base = choose_base(rng)
    keys = {"faces": shift(faces, base), "creases": shift(creases, base), "assignments": assign}
    n = len(pts)
    if rng.random() < 0.2:
        f = rng.choice(faces)
        keys["pinned"] = shift(sorted(rng.sample(f, rng.randint(1, min(3, len(f))))), base)
    doc = finish(base_doc("origami", [list(p) for p in pts], **keys), base)
    s = Scene("origami", doc, 3, variant)
    s.faces0 = faces
    s.creases0 = creases
    s.assign = assign
    return s


def _creases_of(faces):
    es = set()
    for f in faces:
        for i in range(len(f)):
            es.add(tuple(sorted((f[i], f[(i + 1) % len(f)]))))
    return sorted(es)


def _interior(faces, creases):
    cnt = {}
    for f in faces:
        for i in range(len(f)):
            e = tuple(sorted((f[i], f[(i + 1) % len(f)])))
            cnt[e] = cnt.get(e, 0) + 1
    return [cnt.get(tuple(e), 0) == 2 for e in creases]


def _mv(rng, allow_f=True):
    return rng.choice(["M", "V", "M", "V", "U"] + (["F"] if allow_f else []))


def gen_origami(rng):
    variant = rng.choice(["strip", "miura", "degree4", "degreen", "grid"])
    if variant == "strip":
        k = rng.randint(2, 5)
        h = r4(rng.uniform(0.5, 1.5), 2)
        xs = [0.0]
        for _ in range(k):
            xs.append(r4(xs[-1] + rng.uniform(0.5, 1.5), 3))
        pts = [[x, 0.0] for x in xs] + [[x, h] for x in xs]
        faces = [[i, i + 1, k + 1 + i + 1, k + 1 + i] for i in range(k)]
    elif variant == "miura":
        nx, ny = rng.randint(2, 3), rng.randint(2, 3)
        w, hh, sft = r4(rng.uniform(0.6, 1.2), 3), r4(rng.uniform(0.8, 1.3), 3), r4(rng.uniform(0.2, 0.6), 3)
        v = lambda i, j: i * (ny + 1) + j
        pts = [[i * w, j * hh + (sft if i % 2 else 0.0)] for i in range(nx + 1) for j in range(ny + 1)]
        faces = [[v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)] for i in range(nx) for j in range(ny)]
    elif variant == "degree4":
        g = rng.uniform(0.5, 1.3)
        R = [r4(rng.uniform(0.8, 1.2), 3) for _ in range(4)]
        th = [0.0, g, math.pi, 2 * math.pi - g]
        pts = [[0.0, 0.0]] + [[R[i] * math.cos(t), R[i] * math.sin(t)] for i, t in enumerate(th)]
        faces = [[0, 1 + i, 1 + (i + 1) % 4] for i in range(4)]
    elif variant == "degreen":
        k = rng.randint(4, 8)
        while True:
            gaps = [rng.uniform(0.3, 2.5) for _ in range(k)]
            s = sum(gaps)
            gaps = [2 * math.pi * x / s for x in gaps]
            if max(gaps) < math.pi - 0.2 and min(gaps) > 0.2:
                break
        th = [sum(gaps[:i]) for i in range(k)]
        pts = [[0.0, 0.0]] + [[math.cos(t) * r4(rng.uniform(0.8, 1.2), 3), math.sin(t) * r4(rng.uniform(0.8, 1.2), 3)]
                              for t in th]
        faces = [[0, 1 + i, 1 + (i + 1) % k] for i in range(k)]
    else:  # a square grid, both crease families
        nx, ny = rng.randint(1, 3), rng.randint(2, 3)
        v = lambda i, j: i * (ny + 1) + j
        pts = [[float(i), float(j)] for i in range(nx + 1) for j in range(ny + 1)]
        faces = [[v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)] for i in range(nx) for j in range(ny)]
    creases = [list(e) for e in _creases_of(faces)]
    inner = _interior(faces, creases)
    assign = []
    for e, isin in zip(creases, inner):
        if not isin:
            assign.append("B")
            continue
        if variant == "miura":
            (i1, j1), (i2, j2) = divmod(e[0], ny + 1), divmod(e[1], ny + 1)
            if i1 == i2:
                a = "V" if (i1 + min(j1, j2)) % 2 else "M"
            else:
                a = "M" if j1 % 2 else "V"
            assign.append(a)
        elif variant == "degree4":
            assign.append("X")
        else:
            assign.append(_mv(rng, allow_f=(variant in ("strip", "grid"))))
    if variant == "degree4":
        pat = rng.choice(["MVVV", "VMMM", "MMMV", "VVVM", "MFMF", "MVMV", "UUUU"])
        rot = rng.randint(0, 3)
        pat = pat[rot:] + pat[:rot]
        ray = 0
        for idx, (e, isin) in enumerate(zip(creases, inner)):
            if isin:
                outer = e[1] if e[0] == 0 else e[0]
                assign[idx] = pat[outer - 1]
                ray += 1
    if variant == "miura" and rng.random() < 0.3:
        assign = ["V" if a == "M" else "M" if a == "V" else a for a in assign]
    # at least one foldable crease: turn an F into M when everything is F/B
    if not any(a in "MVU" for a in assign):
        for i, isin in enumerate(inner):
            if isin:
                assign[i] = "M"
                break
    # round the points (keep miura/degree-n exact enough: round to 12 digits)
    pts = [[float(round(c, 12)) for c in p] for p in pts]
    s = _origami_doc(rng, pts, faces, creases, "".join(assign), variant)
    return s


def graph6(n, edges):
    """nauty's graph6 text of a graph on n < 63 vertices."""
    es = {tuple(sorted(e)) for e in edges}
    bits = [1 if (i, j) in es else 0 for j in range(1, n) for i in range(j)]
    bits += [0] * (-len(bits) % 6)
    out = chr(63 + n)
    for k in range(0, len(bits), 6):
        v = 0
        for b in bits[k:k + 6]:
            v = 2 * v + b
        out += chr(63 + v)
    return out


def gen_from_file(rng, kind):
    """A scene whose system comes from another format's file ([system] from = FILE): a graph6 or
    edge-list graph realized at random (frameworks), or an OFF/OBJ mesh (polytopes)."""
    if kind in ("framework2d", "framework3d"):
        d = 2 if kind == "framework2d" else 3
        n = rng.randint(d + 1, 9)
        edges = modify_graph(rng, henneberg(rng, n, d), n)
        # every vertex on some edge (a file lists edges only)
        used = {v for e in edges for v in e}
        for v in range(n):
            if v not in used:
                edges.append((v, (v + 1) % n) if v + 1 < n else (0, v))
        edges = sorted({tuple(sorted(e)) for e in edges})
        fmt = rng.choice(["g6", "g6", "edges"])
        if fmt == "g6":
            fname, text = "graph.g6", graph6(n, edges) + "\n"
        else:
            # integer labels 0..n-1, each on some edge: flexure numbers them in label order
            fname, text = "graph.edges", "".join(f"{i} {j}\n" for i, j in rng.sample(edges, len(edges)))
        sysd = {"from": fname, "seed": rng.randint(1, 10 ** 6)}
        if d == 3:
            sysd["dimension"] = 3
        pins = pick_pins(rng, n, d, [3, 2, 2] + ([1] if d == 3 else []))
        if pins:
            sysd["pinned"] = [p + 1 for p in pins]
        s = Scene(kind, {"system": sysd}, d, "from:" + fname)
        s.files = {fname: text}
        s.check_system = {"type": "framework", "vertices": [[0.0] * d] * n, "edges": [[i + 1, j + 1] for i, j in edges],
                          "pinned": sysd.get("pinned", [])}
        s.exact_start = False
        return s
    # polytope from an OFF or OBJ mesh
    p = gen_polytope(rng)
    while p.facets0 == "hull":
        p = gen_polytope(rng)
    pts = p.system["vertices"]
    facets = p.facets0
    fmt = rng.choice(["off", "obj"])
    if fmt == "off":
        text = f"OFF\n{len(pts)} {len(facets)} 0\n" + "".join(" ".join(repr(c) for c in q) + "\n" for q in pts) + \
            "".join(f"{len(f)} " + " ".join(str(v) for v in f) + "\n" for f in facets)
    else:
        text = "".join("v " + " ".join(repr(c) for c in q) + "\n" for q in pts) + \
            "".join("f " + " ".join(str(v + 1) for v in f) + "\n" for f in facets)
    fname = "mesh." + fmt
    sysd = {"from": fname}
    pins = pick_pins(rng, len(pts), 3, [4, 1, 1, 2])
    if pins:
        sysd["pinned"] = [q + 1 for q in pins]
    s = Scene("polytope", {"system": sysd}, 3, "from:" + fname)
    s.files = {fname: text}
    s.check_system = {"type": "polytope", "vertices": pts, "facets": [[v + 1 for v in f] for f in facets],
                      "pinned": sysd.get("pinned", [])}
    s.exact_start = True
    return s


GENERATORS = {
    "framework2d": lambda rng: gen_framework(rng, 2) if rng.random() < 0.85 else gen_from_file(rng, "framework2d"),
    "framework3d": lambda rng: gen_framework(rng, 3) if rng.random() < 0.85 else gen_from_file(rng, "framework3d"),
    "framework_on_surface": gen_surface,
    "angular_framework": gen_angular,
    "polytope": lambda rng: gen_polytope(rng) if rng.random() < 0.85 else gen_from_file(rng, "polytope"),
    "body_hinge": gen_body_hinge,
    "body_bar": gen_body_bar,
    "volume_hypergraph": gen_volume,
    "spherical_disk_packing": gen_caps,
    "sphere_packing": gen_packing,
    "origami": gen_origami,
}
