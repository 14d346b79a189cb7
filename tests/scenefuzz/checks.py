"""Independent checks of flexure's outputs: finiteness of every JSON number, the analysis's counting
identities, and the tracked samples against the scene's constraints (recomputed here from the
scene's own combinatorics, not from flexure's residual)."""

import csv
import io
import math
import re

# JSON keys whose value may be null by the documentation (docs/scene-format.md, "Outputs"):
# prestress_stable / second_order_rigid ("null where the theory does not apply ... or the
# question was not decided"), second_order.stress_margin ("null when not computed"), the
# numerics of a rank decision with nothing dropped (gap, sigma_largest_dropped) or nothing kept
# (sigma_smallest_kept), the motion check's change when no motion check ran.
NULLABLE = {
    "prestress_stable", "second_order_rigid", "stress_margin", "gap", "sigma_largest_dropped",
    "sigma_smallest_kept", "motion_check_change", "blocking_stress",
    # second_order.contradiction: a message, null when there is none (engine/rigidity.h: "empty: none")
    "contradiction",
}

NONFINITE_STRINGS = {"nan", "-nan", "+nan", "inf", "-inf", "+inf", "infinity", "-infinity", "+infinity"}
NONFINITE_TEXT = re.compile(r"(?<![\w.])[-+]?(nan|inf|infinity)(?![\w])", re.IGNORECASE)


def _bad_constant(c):
    raise ValueError(f"non-standard JSON constant {c}")


def parse_json(text):
    """json.loads that refuses NaN/Infinity literals (they are not JSON)."""
    import json
    return json.loads(text, parse_constant=_bad_constant)


def nonfinite_paths(obj, path="", key=None, out=None, nullable=NULLABLE):
    """Every place in a JSON value where a number is not finite: null outside the nullable keys,
    a float that is nan/inf, or a string spelling nan/inf."""
    if out is None:
        out = []
    if isinstance(obj, dict):
        for k, v in obj.items():
            nonfinite_paths(v, f"{path}.{k}", k, out, nullable)
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            nonfinite_paths(v, f"{path}[{i}]", key, out, nullable)
    elif obj is None:
        if key not in nullable:
            out.append(f"{path or '.'} = null")
    elif isinstance(obj, float):
        if not math.isfinite(obj):
            out.append(f"{path} = {obj}")
    elif isinstance(obj, str):
        if obj.strip().lower() in NONFINITE_STRINGS:
            out.append(f"{path} = {obj!r}")
    return out


def nonfinite_in_text(text):
    m = NONFINITE_TEXT.search(text or "")
    if not m:
        return None
    line = text[text.rfind("\n", 0, m.start()) + 1:]
    return line.split("\n", 1)[0][:300]


def analysis_invariants(a):
    """The counting identities of docs/scene-format.md's analysis table."""
    errs = []
    try:
        ker = a["variables"] - a["rigidity_rank"]
        if a["nontrivial_inf_flexes"] + a["trivial_inf_flexes"] != ker:
            errs.append(f"nontrivial_inf_flexes {a['nontrivial_inf_flexes']} + trivial_inf_flexes "
                        f"{a['trivial_inf_flexes']} != variables {a['variables']} - rigidity_rank {a['rigidity_rank']}")
        if a["stress_dim"] != a["equations"] - a["rigidity_rank"]:
            errs.append(f"stress_dim {a['stress_dim']} != equations {a['equations']} - rigidity_rank {a['rigidity_rank']}")
        if a["nontrivial_inf_flexes"] < 0 or a["trivial_inf_flexes"] < 0 or a["stress_dim"] < 0:
            errs.append("a negative dimension")
        if a["inf_rigid"] != (a["nontrivial_inf_flexes"] == 0):
            errs.append(f"inf_rigid {a['inf_rigid']} with nontrivial_inf_flexes {a['nontrivial_inf_flexes']}")
        if a["rigid"] not in ("rigid", "flexible", "unknown"):
            errs.append(f"rigid is {a['rigid']!r}")
        if a["inf_rigid"] and a["rigid"] != "rigid":
            errs.append(f"infinitesimally rigid but rigid = {a['rigid']!r}")
        if a["rigid"] == "flexible" and a["inf_rigid"]:
            errs.append("flexible although infinitesimally rigid")
        b = a.get("nontrivial_flex_basis")
        if b is not None and len(b) != a["nontrivial_inf_flexes"]:
            errs.append(f"nontrivial_flex_basis has {len(b)} flexes, nontrivial_inf_flexes is {a['nontrivial_inf_flexes']}")
        sb = a.get("stress_basis")
        if sb is not None and len(sb) != a["stress_dim"]:
            errs.append(f"stress_basis has {len(sb)} stresses, stress_dim is {a['stress_dim']}")
        if a["vertices"] <= 0 or a["pinned"] > a["vertices"]:
            errs.append("vertex counts")
    except (KeyError, TypeError) as e:
        errs.append(f"missing or mistyped analysis field: {e!r}")
    return errs


# -- geometry -------------------------------------------------------------------------------

def _d2(p, q):
    return sum((a - b) ** 2 for a, b in zip(p, q))


def _extent(conf):
    dim = len(conf[0])
    lo = [min(p[i] for p in conf) for i in range(dim)]
    hi = [max(p[i] for p in conf) for i in range(dim)]
    return math.sqrt(sum((h - l) ** 2 for l, h in zip(lo, hi)))


def _sub(a, b):
    return [x - y for x, y in zip(a, b)]


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def _det(vs):
    if len(vs) == 2:
        return vs[0][0] * vs[1][1] - vs[0][1] * vs[1][0]
    return _dot(vs[0], _cross(vs[1], vs[2]))


def eval_expr(expr, x=0.0, y=0.0, z=0.0):
    """The scene language's expressions (numbers, + - * / ^, functions, pi, e, x y z)."""
    py = expr.replace("^", "**")
    env = {"sqrt": math.sqrt, "sin": math.sin, "cos": math.cos, "tan": math.tan, "asin": math.asin,
           "acos": math.acos, "atan": math.atan, "exp": math.exp, "log": math.log, "abs": abs,
           "pi": math.pi, "e": math.e, "x": x, "y": y, "z": z}
    return float(eval(py, {"__builtins__": {}}, env))


class Constraints:
    """What a path of the scene must keep, 0-based."""

    def __init__(self):
        self.dist_pairs = set()      # (i, j): |xi - xj| kept
        self.contract = None         # (i, j): excluded from dist_pairs
        self.facets = []             # planar vertex cycles
        self.angles2 = []            # (i, j, k), signed angle at j (2D)
        self.angles3 = []            # unsigned angle at j (3D)
        self.simplices = []          # signed volume kept
        self.caps = []               # (i, j): inversive distance kept
        self.surface = None          # expression f(x, y, z) = 0
        self.radii = None            # sticky packing
        self.pack_tol = 1e-6
        self.pinned = []
        self.creases = None          # origami: creases (0-based pairs), assignments
        self.assign = None
        self.fold_crease = None      # index into creases
        self.fold_angle = None
        self.fold_percent = None
        self.target_length = None
        self.attached = []           # (v, frame): v's coordinates in the frame kept
        self.groups = []             # rigid vertex sets (bodies, origami panels)


def _pairs(vs):
    vs = sorted(set(vs))
    return {(vs[a], vs[b]) for a in range(len(vs)) for b in range(a + 1, len(vs))}


def constraints_from_system(sysdoc, base, structure=None, motion=None):
    c = Constraints()
    t = sysdoc["type"]
    z = lambda v: [x - base for x in v]
    sb = structure.get("index_base", 1) if structure else 1
    c.pinned = z(sysdoc.get("pinned", []))
    if t in ("framework", "framework_on_surface"):
        for e in sysdoc["edges"]:
            c.dist_pairs.add(tuple(sorted(z(e))))
        for a in sysdoc.get("attached", []):
            c.attached.append((a[0] - base, [f - base for f in a[1:]]))
        if t == "framework_on_surface":
            c.surface = sysdoc["surface"]
    elif t == "angular_framework":
        dim = len(sysdoc["vertices"][0])
        for a in sysdoc["angles"]:
            (c.angles2 if dim == 2 else c.angles3).append(tuple(z(a)))
    elif t == "polytope":
        facets = sysdoc["facets"]
        if facets == "hull":
            facets = [[v - sb for v in f] for f in structure["facets"]] if structure else []
        else:
            facets = [z(f) for f in facets]
        c.facets = facets
        for f in facets:
            for i in range(len(f)):
                c.dist_pairs.add(tuple(sorted((f[i], f[(i + 1) % len(f)]))))
    elif t in ("body_hinge", "body_bar"):
        for b in sysdoc["bodies"]:
            c.groups.append(set(z(b)))
        for e in sysdoc.get("bars", []):
            c.dist_pairs.add(tuple(sorted(z(e))))
    elif t == "origami":
        faces = [z(f) for f in sysdoc["faces"]]
        creases = [tuple(z(e)) for e in sysdoc["creases"]]
        assign = sysdoc.get("assignments", "U" * len(creases))
        # panels: faces joined by F or J creases
        parent = list(range(len(faces)))

        def find(a):
            while parent[a] != a:
                parent[a] = parent[parent[a]]
                a = parent[a]
            return a
        side = {}
        for fi, f in enumerate(faces):
            for i in range(len(f)):
                side.setdefault(tuple(sorted((f[i], f[(i + 1) % len(f)]))), []).append(fi)
        for e, a in zip(creases, assign):
            fs = side.get(tuple(sorted(e)), [])
            if a in "FJ" and len(fs) == 2:
                parent[find(fs[0])] = find(fs[1])
        panels = {}
        for fi, f in enumerate(faces):
            panels.setdefault(find(fi), set()).update(f)
        for vs in panels.values():
            c.groups.append(set(vs))
        c.creases = creases
        c.assign = assign
        c.interior = [len(side.get(tuple(sorted(e)), [])) == 2 for e in creases]
    elif t == "sphere_packing":
        n = len(sysdoc["vertices"])
        if "radii" in sysdoc:
            c.radii = [float(eval_expr(r) if isinstance(r, str) else r) for r in sysdoc["radii"]]
        else:
            r = sysdoc["radius"]
            c.radii = [float(eval_expr(r) if isinstance(r, str) else r)] * n
        c.pack_tol = float(sysdoc.get("tolerance", 1e-6))
    elif t == "spherical_disk_packing":
        for e in sysdoc["contacts"]:
            c.caps.append(tuple(z(e)))
    elif t == "volume_hypergraph":
        for s in sysdoc["simplices"]:
            c.simplices.append(tuple(z(s)))
    if motion and "contract_edge" in motion:
        e = tuple(sorted(x - base for x in motion["contract_edge"]))
        c.contract = e
        c.target_length = float(motion["target_length"])
    # rigid groups (bodies, panels): every distance inside kept, except in a group whose own
    # edge is contracted (it deforms by design: its frame changes, the rest follows affinely)
    for g in c.groups:
        if c.contract is None or not set(c.contract) <= g:
            c.dist_pairs |= _pairs(g)
    if motion:
        if "fold_crease" in motion and c.creases is not None:
            e = sorted(x - base for x in motion["fold_crease"])
            for idx, ce in enumerate(c.creases):
                if sorted(ce) == e:
                    c.fold_crease = idx
            c.fold_angle = float(motion["fold_angle"])
        if "fold_percent" in motion:
            c.fold_percent = float(motion["fold_percent"])
    return c


def _solve(M, r):
    """M x = r for a small square M (Gaussian elimination with pivoting)."""
    n = len(M)
    A = [list(M[i]) + [r[i]] for i in range(n)]
    for col in range(n):
        p = max(range(col, n), key=lambda i: abs(A[i][col]))
        A[col], A[p] = A[p], A[col]
        if A[col][col] == 0:
            return None
        for i in range(n):
            if i != col:
                f = A[i][col] / A[col][col]
                A[i] = [x - f * y for x, y in zip(A[i], A[col])]
    return [A[i][n] / A[i][i] for i in range(n)]


def frame_coords(conf, v, frame):
    """v's coordinates in its frame, as the scene format defines them ([system] attached)."""
    a = conf[frame[0]]
    w = _sub(conf[v], a)
    e1 = _sub(conf[frame[1]], a)
    dim = len(a)
    if len(frame) == 2:
        l2 = _dot(e1, e1)
        if dim == 2:
            return [_dot(w, e1) / l2, (w[1] * e1[0] - w[0] * e1[1]) / l2]
        return [_dot(w, e1) / l2]
    e2 = _sub(conf[frame[2]], a)
    cols = [e1, e2] + ([_cross(e1, e2)] if dim == 3 else [])
    M = [[cols[j][i] for j in range(len(cols))] for i in range(dim)]
    return _solve(M, w)


def _inv(a, b):
    ab = _dot(a, b) - 1
    aa = _dot(a, a) - 1
    bb = _dot(b, b) - 1
    return ab / math.sqrt(aa * bb)


def _signed_angle(p, i, j, k):
    u, w = _sub(p[i], p[j]), _sub(p[k], p[j])
    return math.atan2(u[0] * w[1] - u[1] * w[0], _dot(u, w))


def _angle3(p, i, j, k):
    u, w = _sub(p[i], p[j]), _sub(p[k], p[j])
    cu = _dot(u, w) / math.sqrt(_dot(u, u) * _dot(w, w))
    return math.acos(max(-1.0, min(1.0, cu)))


def _planarity(conf, f):
    """Largest distance of a facet's vertices from their plane (Newell normal)."""
    n = [0.0, 0.0, 0.0]
    m = len(f)
    for a in range(m):
        p, q = conf[f[a]], conf[f[(a + 1) % m]]
        n[0] += (p[1] - q[1]) * (p[2] + q[2])
        n[1] += (p[2] - q[2]) * (p[0] + q[0])
        n[2] += (p[0] - q[0]) * (p[1] + q[1])
    nn = math.sqrt(_dot(n, n))
    if nn == 0:
        return float("inf")
    n = [x / nn for x in n]
    cen = [sum(conf[v][i] for v in f) / m for i in range(3)]
    return max(abs(_dot(n, _sub(conf[v], cen))) for v in f)


def check_samples(c, samples, dim, events=(), fold_angles=None, status=None, reason="", nverts=None, rel=1e-8):
    """Failures of the samples against the constraints, as messages (at most a few)."""
    errs = []
    if not samples:
        return ["no samples"]
    n = len(samples[0])
    if nverts is not None and n != nverts:
        errs.append(f"samples have {n} vertices, the scene {nverts}")
    for k, conf in enumerate(samples):
        if len(conf) != n:
            return errs + [f"sample {k} has {len(conf)} vertices, sample 0 has {n}"]
        for v, p in enumerate(conf):
            if len(p) != dim:
                return errs + [f"sample {k} vertex {v + 1} has {len(p)} coordinates, dimension {dim}"]
            if not all(isinstance(x, (int, float)) and math.isfinite(x) for x in p):
                return errs + [f"sample {k} vertex {v + 1} is not finite: {p}"]
    s0 = samples[0]
    ext = _extent(s0) or 1.0
    tol2 = rel * ext * ext
    worst = {}

    def note(what, k, val, tol):
        if val > tol and (what not in worst or val / tol > worst[what][1] / worst[what][2]):
            worst[what] = (k, val, tol)

    d0 = {e: _d2(s0[e[0]], s0[e[1]]) for e in c.dist_pairs if e != c.contract}
    ang0 = {a: _signed_angle(s0, *a) for a in c.angles2}
    ang30 = {a: _angle3(s0, *a) for a in c.angles3}
    vol0 = {s: _det([_sub(s0[v], s0[s[0]]) for v in s[1:]]) for s in c.simplices}
    cap0 = {e: _inv(s0[e[0]], s0[e[1]]) for e in c.caps}
    att0 = {(v, tuple(f)): frame_coords(s0, v, f) for v, f in c.attached}
    contacts = set()
    if c.radii is not None:
        R = c.radii
        for i in range(n):
            for j in range(i + 1, n):
                if abs(math.sqrt(_d2(s0[i], s0[j])) - (R[i] + R[j])) <= 2 * c.pack_tol * (R[i] + R[j]):
                    contacts.add((i, j))
    new_contacts = {}
    for ev in events or []:
        if ev.get("kind") == "contact" and "pair" in ev:
            pr = ev["pair"]
            new_contacts.setdefault(ev["sample"], []).append(pr)
    base_for_pairs = None
    for k, conf in enumerate(samples):
        for e, l0 in d0.items():
            note(f"distance {e[0] + 1}-{e[1] + 1}", k, abs(_d2(conf[e[0]], conf[e[1]]) - l0), tol2)
        for v in c.pinned:
            if 0 <= v < n:
                note(f"pinned vertex {v + 1} moved", k, math.sqrt(_d2(conf[v], s0[v])), 1e-12 * ext + 1e-300)
        for a, t0 in ang0.items():
            t = _signed_angle(conf, *a)
            dd = abs(math.atan2(math.sin(t - t0), math.cos(t - t0)))
            note(f"angle {a[0] + 1}-{a[1] + 1}-{a[2] + 1}", k, dd, 1e-7)
        for a, t0 in ang30.items():
            note(f"angle {a[0] + 1}-{a[1] + 1}-{a[2] + 1}", k, abs(_angle3(conf, *a) - t0), 1e-7)
        for s, v0 in vol0.items():
            v = _det([_sub(conf[u], conf[s[0]]) for u in s[1:]])
            note(f"volume of simplex {[x + 1 for x in s]}", k, abs(v - v0), rel * ext ** dim)
        for (v, f), q0 in att0.items():
            q = frame_coords(conf, v, list(f))
            if q0 is not None and q is not None:
                note(f"attached vertex {v + 1} in the frame of {[x + 1 for x in f]}", k,
                     max(abs(x - y) for x, y in zip(q, q0)), 1e-7 * max(1.0, max(abs(x) for x in q0)))
        for e, i0 in cap0.items():
            note(f"inversive distance {e[0] + 1}-{e[1] + 1}", k, abs(_inv(conf[e[0]], conf[e[1]]) - i0), 1e-7 * max(1.0, abs(i0)))
        for e in c.caps:
            for v in e:
                note(f"cap {v + 1} inside the sphere", k, max(0.0, 1.0 - _dot(conf[v], conf[v])), 0.0)
        for f in c.facets:
            note(f"facet {[x + 1 for x in f]} planarity", k, _planarity(conf, f), 1e-7 * ext)
        if c.surface:
            for v, p in enumerate(conf):
                note(f"vertex {v + 1} on the surface", k, abs(eval_expr(c.surface, *p)), rel * max(1.0, ext * ext) * 10)
        if c.radii is not None:
            R = c.radii
            if k in new_contacts:
                for pr in new_contacts[k]:
                    # pairs are numbered as in the scene; the caller passes index_base in events
                    contacts.add(tuple(sorted(pr)))
            for i in range(n):
                for j in range(i + 1, n):
                    rr = R[i] + R[j]
                    dd = math.sqrt(_d2(conf[i], conf[j]))
                    if (i, j) in contacts:
                        note(f"contact {i + 1}-{j + 1} kept", k, abs(dd - rr), 1e-8 * max(ext, rr))
                    note(f"disks {i + 1} and {j + 1} overlap", k, rr * (1 - 2 * c.pack_tol) - dd, 1e-9 * max(ext, rr))
        if fold_angles is not None and c.assign is not None and k < len(fold_angles):
            for idx, (a, ang) in enumerate(zip(c.assign, fold_angles[k])):
                if a == "M":
                    note(f"mountain crease {c.creases[idx][0] + 1}-{c.creases[idx][1] + 1} turned valley", k, ang, 1e-6)
                elif a == "V":
                    note(f"valley crease {c.creases[idx][0] + 1}-{c.creases[idx][1] + 1} turned mountain", k, -ang, 1e-6)
                elif a in "FJ" and c.interior[idx]:
                    note(f"{a} crease {c.creases[idx][0] + 1}-{c.creases[idx][1] + 1} folded", k, abs(ang), 1e-6)
    for what, (k, val, tol) in sorted(worst.items(), key=lambda w: -w[1][1] / w[1][2])[:4]:
        errs.append(f"{what}: off by {val:.3g} at sample {k} (tolerance {tol:.2g})")
    if len(worst) > 4:
        errs.append(f"... and {len(worst) - 4} more constraints off")
    last = samples[-1]
    if c.contract is not None and status == "success" and "reached its target" in (reason or ""):
        L = math.sqrt(_d2(last[c.contract[0]], last[c.contract[1]]))
        if abs(L - c.target_length) > 1e-7 * max(ext, c.target_length):
            errs.append(f"edge contraction: the last sample's edge {c.contract[0] + 1}-{c.contract[1] + 1} has length "
                        f"{L!r}, target {c.target_length!r}")
    if fold_angles is not None and status == "success" and "reached its target" in (reason or "") and fold_angles:
        fa = fold_angles[-1]
        if c.fold_crease is not None and c.fold_angle is not None:
            if abs(fa[c.fold_crease] - c.fold_angle) > 1e-5:
                errs.append(f"fold drive: crease {c.fold_crease} is at {fa[c.fold_crease]!r} degrees, target {c.fold_angle!r}")
        if c.fold_percent is not None and c.assign is not None:
            num, m = 0.0, 0
            for idx, a in enumerate(c.assign):
                if a in "MV" and c.interior[idx]:
                    num += (1 if a == "V" else -1) * fa[idx]
                    m += 1
            if m:
                pct = 100 * num / (180 * m)
                if abs(pct - c.fold_percent) > 1e-5:
                    errs.append(f"fold percent drive: the last sample is at {pct!r} %, target {c.fold_percent!r}")
    return errs


# -- files ---------------------------------------------------------------------------------

MAGIC = {
    ".png": lambda b: b.startswith(b"\x89PNG\r\n\x1a\n"),
    ".gif": lambda b: b.startswith(b"GIF8"),
    ".pdf": lambda b: b.startswith(b"%PDF"),
    ".svg": lambda b: b"<svg" in b[:4096],
    ".tex": lambda b: b"tikzpicture" in b,
    ".mp4": lambda b: b[4:8] == b"ftyp",
    ".json": lambda b: b.lstrip().startswith(b"{"),
    ".csv": lambda b: b"," in b[:200],
    ".fold": lambda b: b.lstrip().startswith(b"{"),
    ".stl": lambda b: len(b) > 84,
    ".obj": lambda b: b"v " in b,
}


def check_file(path):
    import os
    if not os.path.exists(path):
        return f"{os.path.basename(path)} was not written"
    with open(path, "rb") as f:
        b = f.read()
    if not b:
        return f"{os.path.basename(path)} is empty"
    ext = os.path.splitext(path)[1].lower()
    ok = MAGIC.get(ext)
    if ok and not ok(b):
        return f"{os.path.basename(path)} is not a {ext} file (starts {b[:16]!r})"
    if ext in (".svg", ".tex"):
        m = NONFINITE_TEXT.search(b.decode("utf-8", "replace"))
        if m:
            s = b.decode("utf-8", "replace")
            return f"{os.path.basename(path)} holds a non-finite number: ...{s[max(0, m.start() - 60):m.end() + 20]!r}"
    return None


def png_size(path):
    with open(path, "rb") as f:
        b = f.read(24)
    return int.from_bytes(b[16:20], "big"), int.from_bytes(b[20:24], "big")


def read_csv_rows(text):
    rows = list(csv.reader(io.StringIO(text)))
    return rows[0], rows[1:]


def check_csv_numbers(text, name):
    header, rows = read_csv_rows(text)
    for r, row in enumerate(rows):
        for cidx, cell in enumerate(row):
            try:
                v = float(cell)
            except ValueError:
                return header, rows, f"{name}: row {r + 1} column {header[cidx] if cidx < len(header) else cidx} is {cell!r}"
            if not math.isfinite(v):
                return header, rows, f"{name}: row {r + 1} column {header[cidx] if cidx < len(header) else cidx} is {cell!r}"
    return header, rows, None
