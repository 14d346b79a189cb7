#!/usr/bin/python3
"""An independent oracle for `flexure analyze SCENE --exact --json` (issue 44: exact mode).

    /usr/bin/python3 tests/exact/run.py --flexure build/flexure [--seed S] [--cases N] [--jobs J]
    /usr/bin/python3 tests/exact/run.py --self-check          (the oracle alone, no binary)

The scenes are built here, as TOML text in a temporary folder, with answers known from the
literature, and every answer is recomputed here in exact rational arithmetic
(`fractions.Fraction`, Gaussian elimination written below). Nothing is shared with flexure: no
numpy, no sympy, no code from engine/, pipeline/ or python/.

What the oracle computes for a bar-joint framework (d = 2 or 3, pinned vertices' columns removed,
edges between two pinned vertices dropped as SPEC.md section 3 says):
  variables       d * (free vertices)
  equations       the edges left
  rigidity_rank   rank of R (row ij: p_i - p_j in i's columns, p_j - p_i in j's)
  trivial         dimension of {(A p_i + b)_{i free} : A skew, b, A p_k + b = 0 for each pin k}
  nontrivial      variables - rank - trivial;  stress_dim = equations - rank
  stresses        a basis of the left null space of R
  prestress       the stress energy Q_w(v) = sum_ij w_ij |v_i - v_j|^2 on a complement C of the
                  trivial flexes in ker R (pinned velocities 0). Decided exactly (LDL^T, Sylvester)
                  when: no nontrivial flex (true); no stress (false); one stress (Q_w or -Q_w
                  positive definite on C); one nontrivial flex (some Q_w(v) != 0). Also proved
                  true when one basis stress (or a small combination) is definite, and false when
                  some kernel vector outside the trivial flexes is isotropic for every Q_w (then
                  it is not second-order rigid either).
The verdict "rigid" must come exactly when a proof exists (infinitesimally rigid, or prestress
stable); with no stress and a nontrivial flex the realization space is a manifold larger than the
orbit: "flexible" is proved. Known flexible constructions (Dixon I, Bricard) must never be called
"rigid" or prestress stable; where the oracle cannot decide, flexure is only checked not to claim
the opposite of a known fact.

"strict" facts (decided by one exact test: counts, inf_rigid, prestress with at most one stress
or no nontrivial flex) must be reported exactly, in the top-level fields and in the certificate
(true/false, not null). Facts the oracle derives beyond those (several stresses) must not be
contradicted; null, and "unknown" for the verdict, are accepted there.

Cases: K33 on conics (circle, ellipses, hyperbolas, parabolas, a projective image; decimals,
"p/q", expressions, heights near 10^6 and beyond 2^63), the same moved off the conic by 10^-12,
Dixon's first mechanism, Bricard octahedra of type 1 and a generic octahedron, triangulated grids,
4-cycles, pinned frameworks, degenerate (collinear, coplanar) ones, seeded random frameworks in
2D and 3D (also through floating point, which must agree on the generic ones), and bad input
(an irrational coordinate; a framework on a surface).

One line per case (name, expected, got, ok), then a summary; exit status 1 on any mismatch.
"""

import argparse
import concurrent.futures
import decimal
import json
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib
from fractions import Fraction as F

# --------------------------------------------------------------------------------------------
# Exact linear algebra over the rationals
# --------------------------------------------------------------------------------------------


def rref(rows, ncols):
    """Reduced row echelon form: (nonzero rows, pivot columns)."""
    A = [list(r) for r in rows]
    piv = []
    r = 0
    nrows = len(A)
    for c in range(ncols):
        if r == nrows:
            break
        p = next((i for i in range(r, nrows) if A[i][c] != 0), None)
        if p is None:
            continue
        A[r], A[p] = A[p], A[r]
        pr = A[r]
        inv = 1 / pr[c]
        pr = [x * inv for x in pr]
        A[r] = pr
        nz = [k for k in range(c, ncols) if pr[k] != 0]
        for i in range(nrows):
            if i != r:
                row = A[i]
                f = row[c]
                if f != 0:
                    for k in nz:
                        row[k] -= f * pr[k]
        piv.append(c)
        r += 1
    return A[:r], piv


def rank(rows, ncols):
    return len(rref(rows, ncols)[1]) if rows else 0


def nullspace(rows, ncols):
    """A basis of {x : rows . x = 0}."""
    if not rows:
        return [[F(int(i == j)) for i in range(ncols)] for j in range(ncols)]
    R, piv = rref(rows, ncols)
    pivset = set(piv)
    basis = []
    for f in range(ncols):
        if f in pivset:
            continue
        v = [F(0)] * ncols
        v[f] = F(1)
        for i, pc in enumerate(piv):
            v[pc] = -R[i][f]
        basis.append(v)
    return basis


def transpose(rows, ncols):
    return [[rows[i][j] for i in range(len(rows))] for j in range(ncols)]


def matvec(rows, v):
    return [sum((a * b for a, b in zip(r, v)), F(0)) for r in rows]


def definiteness(G):
    """+1 if G is positive definite, -1 if negative definite, 0 otherwise: Gaussian elimination
    without pivoting (LDL^T); a symmetric matrix is positive definite exactly when every pivot is
    positive (Sylvester: every leading principal minor positive)."""
    n = len(G)
    if n == 0:
        return 0
    for sign in (1, -1):
        A = [[sign * x for x in r] for r in G]
        ok = True
        for k in range(n):
            if A[k][k] <= 0:
                ok = False
                break
            for i in range(k + 1, n):
                f = A[i][k] / A[k][k]
                if f != 0:
                    for j in range(k + 1, n):
                        A[i][j] -= f * A[k][j]
        if ok:
            return sign
    return 0


# --------------------------------------------------------------------------------------------
# The oracle
# --------------------------------------------------------------------------------------------


class Framework:
    """d, points (tuples of Fractions), edges (0-based pairs), pinned (0-based set), and the text
    each coordinate is written with in the scene (see coord_text)."""

    def __init__(self, d, points, edges, pinned=(), texts=None):
        self.d = d
        self.points = [tuple(F(x) for x in p) for p in points]
        self.edges = [tuple(e) for e in edges]
        self.pinned = set(pinned)
        assert all(len(p) == d for p in self.points)
        assert len(set(self.points)) == len(self.points), "coincident vertices"
        assert len({frozenset(e) for e in self.edges}) == len(self.edges), "duplicate edge"
        assert all(i != j for i, j in self.edges)
        self.texts = texts or [[coord_text(x, "auto") for x in p] for p in self.points]


def motion_fields(d, p):
    """Velocity at p of each generator of the infinitesimal Euclidean motions: d translations,
    then the rotations in each coordinate plane (a, b)."""
    out = []
    for k in range(d):
        out.append([F(int(a == k)) for a in range(d)])
    for a in range(d):
        for b in range(a + 1, d):
            v = [F(0)] * d
            v[a] = -p[b]
            v[b] = p[a]
            out.append(v)
    return out


def rigidity_matrix(fw):
    """(R, eqs, free, col, nv): the rigidity matrix over the free coordinates (a row per edge
    that is not between two pinned vertices), its edges, the free vertices, their column
    blocks and the number of variables."""
    d, P = fw.d, fw.points
    free = [i for i in range(len(P)) if i not in fw.pinned]
    col = {v: k for k, v in enumerate(free)}
    nv = d * len(free)
    eqs = [(i, j) for (i, j) in fw.edges if not (i in fw.pinned and j in fw.pinned)]
    R = []
    for i, j in eqs:
        row = [F(0)] * nv
        for k in range(d):
            if i in col:
                row[d * col[i] + k] = P[i][k] - P[j][k]
            if j in col:
                row[d * col[j] + k] = P[j][k] - P[i][k]
        R.append(row)
    return R, eqs, free, col, nv


def analyze(fw):
    d, P, n = fw.d, fw.points, len(fw.points)
    R, eqs, free, col, nv = rigidity_matrix(fw)
    m = len(eqs)
    kernel = nullspace(R, nv)
    rk = nv - len(kernel)
    stresses = nullspace(transpose(R, nv), m) if m else []
    assert m - rk == len(stresses), "rank of R and of R^T disagree"
    for w in stresses:  # w^T R = 0
        assert all(x == 0 for x in matvec(transpose(R, nv), w)) if nv else True

    # trivial motions that fix the pins, on the free coordinates
    ng = d + d * (d - 1) // 2
    fields = [motion_fields(d, P[i]) for i in range(n)]  # fields[i][g][a]
    pin_rows = [[fields[k][g][a] for g in range(ng)] for k in sorted(fw.pinned) for a in range(d)]
    params = nullspace(pin_rows, ng)
    triv_vecs = []
    for c in params:
        v = [F(0)] * nv
        for i in free:
            for a in range(d):
                v[d * col[i] + a] = sum((c[g] * fields[i][g][a] for g in range(ng)), F(0))
        triv_vecs.append(v)
    T, _ = rref(triv_vecs, nv) if triv_vecs and nv else ([], [])
    trivial = len(T)
    # the same by the formula rank(all fields) - rank(pinned fields)
    all_rows = [[fields[k][g][a] for g in range(ng)] for k in range(n) for a in range(d)]
    if nv:
        assert trivial == rank(all_rows, ng) - (rank(pin_rows, ng) if pin_rows else 0), "trivial count"
    for t in T:  # trivial flexes are flexes
        assert all(x == 0 for x in matvec(R, t)), "a trivial motion is not in the kernel"
    nontrivial = nv - rk - trivial
    assert nontrivial >= 0

    # a complement C of the trivial flexes inside the kernel, and the kernel vectors outside T
    C = []
    cur = list(T)
    outside = []
    for v in kernel:
        if rank(cur + [v], nv) > len(cur):
            cur = rref(cur + [v], nv)[0]
            C.append(v)
        if rank(T + [v], nv) > len(T):
            outside.append(v)
    assert len(C) == nontrivial

    def form(w, a, b):
        s = F(0)
        for e, (i, j) in enumerate(eqs):
            if w[e] == 0:
                continue
            acc = F(0)
            for k in range(d):
                ai = a[d * col[i] + k] if i in col else F(0)
                aj = a[d * col[j] + k] if j in col else F(0)
                bi = b[d * col[i] + k] if i in col else F(0)
                bj = b[d * col[j] + k] if j in col else F(0)
                acc += (ai - aj) * (bi - bj)
            s += w[e] * acc
        return s

    def gram(w):
        return [[form(w, a, b) for b in C] for a in C]

    res = dict(dimension=d, vertices=n, pinned=len(fw.pinned), variables=nv, equations=m,
               rigidity_rank=rk, trivial_inf_flexes=trivial, nontrivial_inf_flexes=nontrivial,
               stress_dim=len(stresses), inf_rigid=(nontrivial == 0))
    ps = so = None
    strict = False
    note = ""
    if nontrivial == 0:
        ps, so, strict, note = True, True, True, "no nontrivial flex"
    elif not stresses:
        ps, so, strict, note = False, False, True, "no stress"
    else:
        grams = [gram(w) for w in stresses]
        if len(stresses) == 1:
            sgn = definiteness(grams[0])
            ps, strict = (sgn != 0), True
            note = "one stress, form %s" % {1: "positive definite", -1: "negative definite", 0: "not definite"}[sgn]
            if nontrivial == 1:
                so = ps
        elif nontrivial == 1:
            ps = so = any(g[0][0] != 0 for g in grams)
            note = "one flex, %d stresses" % len(stresses)
        else:
            combos = list(grams)
            for a in range(len(grams)):
                for b in range(a + 1, len(grams)):
                    for c in (1, -1, 2, -2, F(1, 2), F(-1, 2)):
                        combos.append([[x + c * y for x, y in zip(r, s)] for r, s in zip(grams[a], grams[b])])
            if any(definiteness(g) != 0 for g in combos):
                ps, so, note = True, True, "a definite combination of stresses"
            elif any(all(form(w, v, v) == 0 for w in stresses) for v in C + outside):
                ps, so, note = False, False, "a flex isotropic for every stress"
            else:
                note = "undecided (%d stresses, %d flexes)" % (len(stresses), nontrivial)
    res.update(prestress_stable=ps, second_order_rigid=so, strict=strict, note=note)
    # the verdict
    if nontrivial == 0 or (ps is True and strict):
        res["rigid_allowed"] = {"rigid"}
    elif ps is True:  # derived (several stresses): flexure may not find the combination
        res["rigid_allowed"] = {"rigid", "unknown"}
    elif not stresses:
        res["rigid_allowed"] = {"flexible"}
    elif ps is False and so is False:
        res["rigid_allowed"] = {"flexible", "unknown"}
    else:
        res["rigid_allowed"] = {"rigid", "flexible", "unknown"}
    res["flexible_proved"] = bool(nontrivial > 0 and not stresses)
    return res


# --------------------------------------------------------------------------------------------
# Writing scenes (and reading them back, to check the writing)
# --------------------------------------------------------------------------------------------


def is_decimal(q):
    den = q.denominator
    for p in (2, 5):
        while den % p == 0:
            den //= p
    return den == 1


def decimal_text(q):
    """The exact decimal expansion of q (whose denominator divides a power of 10)."""
    assert is_decimal(q)
    k = 0
    while (q * 10 ** k).denominator != 1:
        k += 1
    k = max(k, 1)
    n = abs(q.numerator * 10 ** k // q.denominator)
    s = str(n).rjust(k + 1, "0")
    return ("-" if q < 0 else "") + s[:-k] + "." + s[-k:]


def coord_text(q, style, rng=None):
    """TOML text of the coordinate q: 'auto' (integer, else "p/q"), 'frac' ("p/q"), 'dec' (a TOML
    decimal literal), 'decstr' ("0.25"), 'expr' ("a/b + c/d")."""
    q = F(q)
    if style == "dec" and is_decimal(q):
        return decimal_text(q)
    if style == "decstr" and is_decimal(q):
        return '"%s"' % decimal_text(q)
    if style == "expr":
        rng = rng or random.Random(q.numerator ^ q.denominator)
        a = F(rng.randint(-9, 9), rng.randint(1, 7))
        b = q - a
        op = "+" if b >= 0 else "-"
        b = abs(b)
        at = str(a.numerator) if a.denominator == 1 else "%d/%d" % (a.numerator, a.denominator)
        bt = str(b.numerator) if b.denominator == 1 else "%d/%d" % (b.numerator, b.denominator)
        if a < 0:
            at = "(%s)" % at
        return '"%s %s %s"' % (at, op, bt)
    if q.denominator == 1 and style != "frac" and abs(q) < 2 ** 53:
        return str(q.numerator)
    return '"%d/%d"' % (q.numerator, q.denominator)


def styled(points, styles, rng=None):
    """Texts for the points with a style per coordinate (a list of lists, or one style)."""
    out = []
    for i, p in enumerate(points):
        row = []
        for k, x in enumerate(p):
            s = styles if isinstance(styles, str) else styles[i][k] if isinstance(styles[i], (list, tuple)) else styles[i]
            row.append(coord_text(x, s, rng))
        out.append(row)
    return out


def scene_text(fw, title, index_base=1, stype="framework", extra_system=""):
    b = index_base
    verts = "[" + ", ".join("[" + ", ".join(t) + "]" for t in fw.texts) + "]"
    edges = "[" + ", ".join("[%d, %d]" % (i + b, j + b) for i, j in fw.edges) + "]"
    lines = ['title = "%s"' % title]
    if index_base != 1:
        lines.append("index_base = %d" % index_base)
    lines += ["", "[system]", 'type = "%s"' % stype, "vertices = " + verts, "edges = " + edges]
    if fw.pinned:
        lines.append("pinned = [%s]" % ", ".join(str(i + b) for i in sorted(fw.pinned)))
    if extra_system:
        lines.append(extra_system)
    return "\n".join(lines) + "\n"


_TOK = re.compile(r"\s*(?:(\d+(?:\.\d+)?)|(.))")


def eval_rational(text):
    """A rational expression (+ - * / parentheses, integers, decimals) as a Fraction."""
    toks = []
    for num, op in _TOK.findall(text):
        toks.append(("n", F(decimal.Decimal(num))) if num else ("o", op))
    toks = [t for t in toks if not (t[0] == "o" and t[1].isspace())]
    pos = [0]

    def peek():
        return toks[pos[0]] if pos[0] < len(toks) else ("e", None)

    def take():
        t = peek()
        pos[0] += 1
        return t

    def expr():
        v = term()
        while peek() in (("o", "+"), ("o", "-")):
            v = v + term() if take()[1] == "+" else v - term()
        return v

    def term():
        v = unary()
        while peek() in (("o", "*"), ("o", "/")):
            v = v * unary() if take()[1] == "*" else v / unary()
        return v

    def unary():
        if peek() == ("o", "-"):
            take()
            return -unary()
        if peek() == ("o", "+"):
            take()
            return unary()
        t = take()
        if t[0] == "n":
            return t[1]
        if t == ("o", "("):
            v = expr()
            assert take() == ("o", ")")
            return v
        raise ValueError("not a rational expression: %r" % text)

    v = expr()
    if pos[0] != len(toks):
        raise ValueError("trailing text in %r" % text)
    return v


def check_scene_roundtrip(text, fw, index_base=1):
    """The scene written says what the oracle analyses: read it back (decimals exactly)."""
    doc = tomllib.loads(text, parse_float=decimal.Decimal)
    sysd = doc["system"]
    got = [tuple(eval_rational(x) if isinstance(x, str) else F(x) for x in p) for p in sysd["vertices"]]
    assert got == fw.points, "scene writer: vertices differ"
    b = doc.get("index_base", 1)
    assert b == index_base
    assert [tuple(x - b for x in e) for e in sysd["edges"]] == fw.edges
    assert {x - b for x in sysd.get("pinned", [])} == fw.pinned


# --------------------------------------------------------------------------------------------
# Constructions
# --------------------------------------------------------------------------------------------

K33_EDGES = [(i, j) for i in range(3) for j in range(3, 6)]


def circle_point(t):
    t = F(t)
    return ((1 - t * t) / (1 + t * t), 2 * t / (1 + t * t))


def k33(points, texts=None, styles="auto", rng=None):
    texts = texts or styled(points, styles, rng)
    return Framework(2, points, K33_EDGES, texts=texts)


def conic_value(coeffs, p):
    a, b, c, d, e, f = coeffs
    x, y = p
    return a * x * x + b * x * y + c * y * y + d * x + e * y + f


def conic_through(points):
    """The conic through 6 points, if there is one (a nonzero coefficient vector), else None."""
    rows = [[x * x, x * y, y * y, x, y, F(1)] for x, y in points]
    ns = nullspace(rows, 6)
    return ns[0] if ns else None


def k33_cases():
    """(name, framework, on_conic) for K33 on conics, and moved off them by 10^-12."""
    out = []
    eps = F(1, 10 ** 12)
    # the unit circle, small heights, mixed "p/q" and integers
    circ = [F(3, 5), F(4, 5)], [F(-5, 13), F(12, 13)], [F(8, 17), F(-15, 17)], \
           [F(-7, 25), F(-24, 25)], [F(20, 29), F(21, 29)], [F(-1), F(0)]
    circ = [tuple(p) for p in circ]
    out.append(("k33_circle", k33(circ), True))
    # the unit circle in decimals only (denominators 5^k): binary floating point is not on it
    dec = [(F("0.6"), F("0.8")), (F("-0.28"), F("0.96")), (F("0.936"), F("-0.352")),
           (F("-0.8432"), F("-0.5376")), (F("0.352"), F("0.936")), (F("-0.6"), F("0.8"))]
    sty = [["dec", "dec"], ["decstr", "dec"], ["dec", "decstr"], ["dec", "dec"], ["decstr", "decstr"], ["dec", "dec"]]
    out.append(("k33_circle_decimals", k33(dec, styles=sty), True))
    # an axis ellipse x^2/4 + y^2/9 = 1, points as expressions of rationals
    ell = [(2 * x, 3 * y) for x, y in circ]
    out.append(("k33_ellipse_expr", k33(ell, styles="expr", rng=random.Random(5)), True))
    # a rotated, shifted ellipse: a rational affine image of the circle
    aff = [(2 * x + y / 3 + F(1, 7), -x / 2 + 3 * y - 2) for x, y in circ]
    out.append(("k33_ellipse_affine", k33(aff), True))
    # the hyperbola x^2 - y^2 = 1, both branches
    hyp = [((t + 1 / t) / 2, (t - 1 / t) / 2) for t in (F(2), F(3, 7), F(-5, 4), F(-1, 3), F(9, 2), F(-11, 6))]
    out.append(("k33_hyperbola", k33(hyp), True))
    # the hyperbola xy = 1
    hyp2 = [(t, 1 / t) for t in (F(1, 2), F(3), F(-2, 5), F(-7), F(11, 3), F(-13, 8))]
    out.append(("k33_hyperbola_xy", k33(hyp2, styles=[["frac", "decstr"] if is_decimal(1 / t) else "frac" for t in (F(1, 2), F(3), F(-2, 5), F(-7), F(11, 3), F(-13, 8))]), True))
    # the parabola y = x^2
    par = [(x, x * x) for x in (F(-3), F(-1, 2), F(1, 3), F(2), F(5, 7), F(-11, 4))]
    out.append(("k33_parabola", k33(par), True))
    # a projective image of the unit circle (a general conic), as expressions
    def proj(p):
        x, y = p
        w = x / 5 + y / 7 + 3
        return ((2 * x - y + 1) / w, (x + 3 * y - F(1, 2)) / w)
    pro = [proj(p) for p in circ]
    out.append(("k33_projective_conic", k33(pro, styles="expr", rng=random.Random(7)), True))
    # large heights on the circle: numerators and denominators near 10^6
    big = [circle_point(F(a, b)) for a, b in ((1234, 987), (-2021, 1999), (3, 1543), (1777, -1201), (3012, 1777), (-1511, 877))]
    out.append(("k33_circle_height1e6", k33(big), True))
    # large heights on the parabola: x with numerator and denominator near 10^6 (y near 10^12)
    bigpar = [(x, x * x) for x in (F(1000003, 999983), F(-1299709, 1000033), F(104729, 1299721),
                                    F(-7, 1000037), F(2750159, 1234577), F(-999979, 3000017))]
    out.append(("k33_parabola_height1e6", k33(bigpar), True))
    # the same moved off the conic by 10^-12, in several notations
    moved = [tuple(p) for p in circ]
    moved[0] = (moved[0][0] + eps, moved[0][1])
    t = styled(moved, "auto")
    t[0][0] = decimal_text(moved[0][0])  # 0.600000000001 as a TOML decimal literal
    out.append(("k33_circle_off_1e-12_literal", k33(moved, texts=t), False))
    md = list(dec)
    md[1] = (md[1][0], md[1][1] - eps)
    out.append(("k33_decimals_off_1e-12_decstr", k33(md, styles="decstr"), False))
    mb = list(big)
    mb[4] = (mb[4][0] + eps, mb[4][1])  # a "p/q" string whose numerator exceeds 2^63
    assert mb[4][0].numerator > 2 ** 63 or mb[4][0].denominator > 2 ** 63
    out.append(("k33_height1e6_off_1e-12_bigfrac", k33(mb), False))
    mp = list(bigpar)
    mp[2] = (mp[2][0], mp[2][1] + eps)
    t = styled(mp, "auto")
    y = bigpar[2][1]
    t[2][1] = '"%d/%d + 1/1000000000000"' % (y.numerator, y.denominator)
    out.append(("k33_parabola_off_1e-12_expr", k33(mp, texts=t), False))
    mh = list(hyp)
    mh[5] = (mh[5][0], mh[5][1] - eps)
    out.append(("k33_hyperbola_off_1e-12", k33(mh), False))
    for name, fw, on in out:
        assert (conic_through(fw.points) is not None) == on, name
    return out


def dixon1(xs, ys, styles="auto"):
    pts = [(F(x), F(0)) for x in xs] + [(F(0), F(y)) for y in ys]
    return Framework(2, pts, K33_EDGES, texts=styled(pts, styles))


def octahedron(pts, styles="auto"):
    # a, a', b, b', c, c' = 0..5; every pair but the antipodal ones
    edges = [(i, j) for i in range(6) for j in range(i + 1, 6) if not (i // 2 == j // 2)]
    return Framework(3, pts, edges, texts=styled(pts, styles))


def bricard1(a, b, c, styles="auto"):
    pts = []
    for p in (a, b, c):
        p = tuple(F(x) for x in p)
        pts += [p, (-p[0], -p[1], p[2])]
    return octahedron(pts, styles)


def rational_rotation(d, rng):
    """A rational orthogonal matrix: the Cayley transform (I - S)^-1 (I + S) of a rational skew S."""
    S = [[F(0)] * d for _ in range(d)]
    for a in range(d):
        for b in range(a + 1, d):
            S[a][b] = F(rng.randint(-4, 4), rng.randint(1, 3))
            S[b][a] = -S[a][b]
    I = [[F(int(a == b)) for b in range(d)] for a in range(d)]
    A = [[I[a][b] - S[a][b] for b in range(d)] + [I[a][b] + S[a][b] for b in range(d)] for a in range(d)]
    Rr, piv = rref(A, 2 * d)
    assert piv == list(range(d))
    Q = [row[d:] for row in Rr]
    for a in range(d):
        for b in range(d):
            assert sum(Q[k][a] * Q[k][b] for k in range(d)) == int(a == b)
    return Q


def disguise(fw, rng):
    """The framework under a rational rotation, a scaling and a translation."""
    d = fw.d
    Q = rational_rotation(d, rng)
    s = F(rng.randint(1, 9), rng.randint(1, 9))
    t = [F(rng.randint(-9, 9), rng.randint(1, 5)) for _ in range(d)]
    pts = [tuple(s * sum(Q[a][k] * p[k] for k in range(d)) + t[a] for a in range(d)) for p in fw.points]
    return Framework(d, pts, fw.edges, fw.pinned)


def grid(n):
    """The triangulated n x n grid of unit squares: (n+1)^2 vertices, edges right, up and one
    diagonal per square."""
    idx = lambda i, j: i * (n + 1) + j
    pts = [(F(i), F(j)) for i in range(n + 1) for j in range(n + 1)]
    edges = []
    for i in range(n + 1):
        for j in range(n + 1):
            if i < n:
                edges.append((idx(i, j), idx(i + 1, j)))
            if j < n:
                edges.append((idx(i, j), idx(i, j + 1)))
            if i < n and j < n:
                edges.append((idx(i, j), idx(i + 1, j + 1)) if (i + j) % 2 == 0 else (idx(i + 1, j), idx(i, j + 1)))
    return Framework(2, pts, edges)


def square(diag=False, pinned=()):
    pts = [(0, 0), (1, 0), (1, 1), (0, 1)]
    edges = [(0, 1), (1, 2), (2, 3), (0, 3)] + ([(0, 2)] if diag else [])
    return Framework(2, pts, edges, pinned)


def random_rational(rng, lo=-9, hi=9, dens=(1, 1, 2, 3, 4, 5)):
    return F(rng.randint(lo, hi), rng.choice(dens))


def random_framework(rng, d, n, kind):
    """kind: generic, collinear (2D), coplanar (3D), collinear3 (3D)."""
    pts = []
    if kind == "collinear":
        base = (random_rational(rng), random_rational(rng))
        dirn = (random_rational(rng, 1, 5), random_rational(rng))
    elif kind == "collinear3":
        base = tuple(random_rational(rng) for _ in range(3))
        dirn = (random_rational(rng, 1, 5), random_rational(rng), random_rational(rng))
    elif kind == "coplanar":
        a, b, c = random_rational(rng, -3, 3), random_rational(rng, -3, 3), random_rational(rng)
    while len(pts) < n:
        if kind == "generic":
            p = tuple(random_rational(rng) for _ in range(d))
        elif kind in ("collinear", "collinear3"):
            t = random_rational(rng, -6, 6)
            p = tuple(x + t * y for x, y in zip(base, dirn))
        else:
            x, y = random_rational(rng), random_rational(rng)
            p = (x, y, a * x + b * y + c)
        if p not in pts:
            pts.append(p)
    # a random spanning tree, then more edges (around the generic count d n - d(d+1)/2)
    order = list(range(n))
    rng.shuffle(order)
    edges = set()
    for k in range(1, n):
        i, j = order[k], order[rng.randrange(k)]
        edges.add((min(i, j), max(i, j)))
    full = n * (n - 1) // 2
    target = min(full, max(n - 1, d * n - d * (d + 1) // 2 + rng.randint(-3, 3)))
    allpairs = [(i, j) for i in range(n) for j in range(i + 1, n)]
    rng.shuffle(allpairs)
    for e in allpairs:
        if len(edges) >= target:
            break
        edges.add(e)
    edges = sorted(edges)
    rng.shuffle(edges)
    edges = [e if rng.random() < 0.5 else (e[1], e[0]) for e in edges]
    r = rng.random()
    npin = 0 if r < 0.6 else 1 if r < 0.8 else 2 if r < 0.95 else 3
    pinned = set(rng.sample(range(n), min(npin, n - 1)))
    styles = [[rng.choice(["auto", "auto", "frac", "dec", "decstr", "expr"]) for _ in range(d)] for _ in range(n)]
    return Framework(d, pts, edges, pinned, texts=styled(pts, styles, rng))


# --------------------------------------------------------------------------------------------
# Cases and comparison
# --------------------------------------------------------------------------------------------

COUNTS = ["variables", "equations", "rigidity_rank", "trivial_inf_flexes", "nontrivial_inf_flexes", "stress_dim"]
SHORT = dict(variables="var", equations="eq", rigidity_rank="rank", trivial_inf_flexes="triv",
             nontrivial_inf_flexes="flex", stress_dim="stress")


class Case:
    def __init__(self, name, fw=None, known_flexible=False, literature=None, float_too=False,
                 index_base=1, kind="exact", text=None, expect=None, group=""):
        self.name, self.fw, self.known_flexible = name, fw, known_flexible
        self.literature = literature or {}  # counts the literature fixes (self-check)
        self.float_too, self.index_base, self.kind = float_too, index_base, kind
        self.text, self.expect, self.group = text, expect, group
        self.oracle = None


def build_cases(seed, ncases):
    cases = []
    # 1, 2: K33 on conics, and moved off them
    k33s = k33_cases()
    for name, fw, on in k33s:
        lit = dict(rigidity_rank=8, nontrivial_inf_flexes=1, stress_dim=1) if on else \
            dict(rigidity_rank=9, nontrivial_inf_flexes=0, stress_dim=0)
        if not on and cases[-1].group == "1 conic":
            cases.append(Case("k33_circle_rotated_scaled", disguise(k33s[0][1], random.Random(2)),
                              literature=dict(rigidity_rank=8, nontrivial_inf_flexes=1, stress_dim=1), group="1 conic"))
        cases.append(Case(name, fw, literature=lit, group="1 conic" if on else "2 off conic"))
    # 3: Dixon's first mechanism
    cases.append(Case("dixon1", dixon1([1, 3, -2], [2, -1, 5]), known_flexible=True, group="3 dixon"))
    cases.append(Case("dixon1_rational", dixon1([F(1, 3), F(-7, 2), F(5, 4)], [F(2, 9), F(-11, 5), F(13, 6)], "frac"),
                      known_flexible=True, group="3 dixon"))
    cases.append(Case("dixon1_decimals", dixon1([F("0.5"), F("-1.25"), F("2.2")], [F("0.75"), F("-3.1"), F("1.6")], "dec"),
                      known_flexible=True, group="3 dixon"))
    # 4: Bricard octahedra of type 1, a generic octahedron
    bric = dict(variables=18, equations=12, rigidity_rank=11, trivial_inf_flexes=6, nontrivial_inf_flexes=1, stress_dim=1)
    a, b, c = (3, 1, -1), (1, -2, 2), (-1, -1, -3)
    cases.append(Case("bricard1", bricard1(a, b, c), known_flexible=True, literature=bric, group="4 octahedra"))
    cases.append(Case("bricard1_rational", bricard1((F(7, 3), F(2, 5), F(-1, 2)), (F(-3, 4), F(5, 2), F(4, 3)),
                                                    (F(1, 6), F(-9, 7), F(-5, 2)), "frac"),
                      known_flexible=True, literature=bric, group="4 octahedra"))
    cases.append(Case("bricard1_decimals", bricard1((F("1.5"), F("0.25"), F("-2.5")), (F("-0.75"), F("1.2"), F("0.4")),
                                                    (F("0.1"), F("-1.9"), F("1.05")), "dec"),
                      known_flexible=True, literature=bric, group="4 octahedra"))
    cases.append(Case("bricard1_rotated_scaled", disguise(bricard1(a, b, c), random.Random(3)), known_flexible=True,
                      literature=bric, group="4 octahedra"))
    g = bricard1(a, b, c)
    pts = list(g.points)
    pts[1] = (pts[1][0] + F(1, 3), pts[1][1], pts[1][2] + F(1, 5))
    lit_oct = dict(variables=18, equations=12, rigidity_rank=12, trivial_inf_flexes=6, nontrivial_inf_flexes=0, stress_dim=0)
    cases.append(Case("octahedron_generic", octahedron(pts), literature=lit_oct, float_too=True, group="4 octahedra"))
    cases.append(Case("octahedron_regular", octahedron([(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]),
                      literature=lit_oct, float_too=True, group="4 octahedra"))
    # 5: grids, squares, pinned frameworks, degenerate ones
    for n in range(3, 7):
        V = (n + 1) ** 2
        lit = dict(variables=2 * V, rigidity_rank=2 * V - 3, trivial_inf_flexes=3, nontrivial_inf_flexes=0)
        cases.append(Case("grid_%dx%d" % (n, n), grid(n), literature=lit, float_too=True, group="5 grids"))
    cases.append(Case("square_4cycle", square(), known_flexible=True,
                      literature=dict(rigidity_rank=4, trivial_inf_flexes=3, nontrivial_inf_flexes=1, stress_dim=0),
                      float_too=True, group="5 small"))
    cases.append(Case("square_diagonal", square(diag=True), literature=dict(rigidity_rank=5, nontrivial_inf_flexes=0),
                      float_too=True, group="5 small"))
    cases.append(Case("square_pinned_edge_dropped", square(pinned=(0, 1)), known_flexible=True,
                      literature=dict(variables=4, equations=3, rigidity_rank=3, trivial_inf_flexes=0, nontrivial_inf_flexes=1),
                      float_too=True, group="5 pinned"))
    gp = grid(3)
    cases.append(Case("grid_3x3_pinned_2", Framework(2, gp.points, gp.edges, {0, 15}),
                      literature=dict(variables=28, trivial_inf_flexes=0, nontrivial_inf_flexes=0), float_too=True, group="5 pinned"))
    cases.append(Case("fourbar_pinned_rational", Framework(2, [(0, 0), (F(7, 2), 0), (F(9, 2), F(5, 3)), (F(1, 3), F(11, 4))],
                                                           [(0, 3), (3, 2), (2, 1)], {0, 1}, texts=None),
                      known_flexible=True, literature=dict(variables=4, equations=3, trivial_inf_flexes=0, nontrivial_inf_flexes=1),
                      float_too=True, group="5 pinned"))
    tet = [(0, 0, 0), (2, 0, 0), (0, 3, 0), (0, 0, 1), (1, 1, 1)]
    cases.append(Case("3d_one_pin_rotations", Framework(3, tet, [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3), (4, 0), (4, 1)], {0}),
                      literature=dict(trivial_inf_flexes=3, nontrivial_inf_flexes=1), float_too=True, group="5 pinned"))
    cases.append(Case("3d_two_pins_axis", Framework(3, tet, [(0, 2), (0, 3), (1, 2), (1, 3), (2, 3), (4, 2), (4, 3), (4, 0)], {0, 1}),
                      literature=dict(trivial_inf_flexes=1), float_too=True, group="5 pinned"))
    cases.append(Case("collinear_triangle", Framework(2, [(0, 0), (1, 0), (3, 0)], [(0, 1), (1, 2), (0, 2)]),
                      literature=dict(rigidity_rank=2, trivial_inf_flexes=3, nontrivial_inf_flexes=1, stress_dim=1,
                                      prestress_stable=True), group="5 degenerate"))
    cases.append(Case("collinear_path_3d", Framework(3, [(1, 2, 3), (2, 4, 6), (F(5, 2), 5, F(15, 2))], [(0, 1), (1, 2)]),
                      literature=dict(rigidity_rank=2, trivial_inf_flexes=5, nontrivial_inf_flexes=2, stress_dim=0),
                      group="5 degenerate"))
    # 6, 8: random frameworks
    rng = random.Random(seed)
    for k in range(ncases):
        d = 2 if k % 2 == 0 else 3
        n = rng.randint(5, 8)
        kind = "generic"
        if k % 5 == 4:
            kind = "collinear" if d == 2 else rng.choice(["coplanar", "coplanar", "collinear3"])
        fw = random_framework(rng, d, n, kind)
        ib = 0 if rng.random() < 0.2 else 1
        cases.append(Case("random_%02d_%dd_n%d_%s%s" % (k, d, n, kind, "_base0" if ib == 0 else ""), fw,
                          float_too=(kind == "generic"), index_base=ib, group="6 random"))
    # 7: bad input
    bad = k33([(F(3, 5), F(4, 5)), (F(-5, 13), F(12, 13)), (F(8, 17), F(-15, 17)),
               (F(-7, 25), F(-24, 25)), (F(20, 29), F(21, 29)), (F(-1), F(0))])
    for expr in ("sqrt(2)", "pi/4", "1 + exp(1)"):
        fw = Framework(2, bad.points, bad.edges, texts=[list(t) for t in bad.texts])
        fw.texts[2][1] = '"%s"' % expr
        cases.append(Case("irrational_%s" % re.sub(r"\W+", "_", expr).strip("_"), fw, kind="bad_exact", group="7 bad input"))
    surf = Framework(3, [(1, 0, 0), (0, 1, 0), (-1, 0, 0), (0, -1, 0)], [(0, 1), (1, 2), (2, 3), (0, 3)])
    cases.append(Case("framework_on_surface", surf, kind="surface", group="7 bad input"))
    return cases


def run(flexure, path, exact, timeout):
    cmd = [flexure, "analyze", path, "--json"] + (["--exact"] if exact else [])
    t0 = time.time()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return dict(rc="timeout", out="", err="timed out after %ss" % timeout, js=None, secs=timeout)
    js = None
    try:
        js = json.loads(p.stdout)
    except ValueError:
        a, b = p.stdout.find("{"), p.stdout.rfind("}")
        if a >= 0 and b > a:
            try:
                js = json.loads(p.stdout[a:b + 1])
            except ValueError:
                pass
    return dict(rc=p.returncode, out=p.stdout, err=p.stderr, js=js, secs=time.time() - t0)


def fmt_bool(x):
    return {True: "T", False: "F", None: "?"}.get(x, repr(x))


def expected_line(o):
    s = " ".join("%s=%s" % (SHORT[k], o[k]) for k in COUNTS)
    s += " ps=%s%s rigid=%s" % (fmt_bool(o["prestress_stable"]), "" if o["strict"] or o["prestress_stable"] is None else "(derived)",
                                "|".join(sorted(o["rigid_allowed"])))
    return s


def got_line(js):
    if not isinstance(js, dict):
        return "(no JSON)"
    s = " ".join("%s=%s" % (SHORT[k], js.get(k, "-")) for k in COUNTS)
    cert = js.get("certificate")
    cs = ""
    if isinstance(cert, dict):
        cs = " cert=%s/%s/%s" % tuple(fmt_bool(cert.get(k, "-")) for k in ("inf_rigid", "flexible", "prestress_stable"))
    return s + " ps=%s rigid=%s%s" % (fmt_bool(js.get("prestress_stable", "-")), js.get("rigid", "-"), cs)


def compare_exact(case, js):
    """The list of problems with flexure's exact analysis of a framework."""
    o = case.oracle
    bad = []
    if not isinstance(js, dict):
        return ["no JSON object on stdout"]

    def want(key, value):
        if key not in js:
            bad.append("%s missing" % key)
        elif js[key] != value or type(js[key]) is not type(value):
            bad.append("%s=%r, expected %r" % (key, js[key], value))

    want("exact", True)
    if js.get("system", "framework") != "framework":
        bad.append("system=%r" % js.get("system"))
    for k in ["dimension", "vertices", "pinned"] + COUNTS + ["inf_rigid"]:
        want(k, o[k])
    ps = o["prestress_stable"]
    gps = js.get("prestress_stable", "missing")
    if ps is not None:
        if o["strict"]:
            want("prestress_stable", ps)
        elif gps is not None and gps != ps:
            bad.append("prestress_stable=%r contradicts the oracle's %r (%s)" % (gps, ps, o["note"]))
    if case.known_flexible and gps is True:
        bad.append("prestress_stable true on a flexible construction")
    so = o["second_order_rigid"]
    gso = js.get("second_order_rigid")
    if so is not None and gso is not None and gso != so:
        bad.append("second_order_rigid=%r contradicts the oracle's %r" % (gso, so))
    if case.known_flexible and gso is True:
        bad.append("second_order_rigid true on a flexible construction")
    rigid = js.get("rigid")
    allowed = set(o["rigid_allowed"])
    if case.known_flexible:
        allowed -= {"rigid"}
    if rigid not in allowed:
        bad.append("rigid=%r, expected %s" % (rigid, " or ".join(sorted(allowed))))
    cert = js.get("certificate")
    if not isinstance(cert, dict):
        bad.append("certificate missing")
        return bad
    for k in ("inf_rigid", "flexible", "prestress_stable"):
        if k not in cert:
            bad.append("certificate.%s missing" % k)
        elif cert[k] not in (True, False, None):
            bad.append("certificate.%s=%r" % (k, cert[k]))
    if not isinstance(cert.get("reason"), str):
        bad.append("certificate.reason is not a string")
    if cert.get("inf_rigid") is not o["inf_rigid"]:
        bad.append("certificate.inf_rigid=%r, expected %r (exact rank)" % (cert.get("inf_rigid"), o["inf_rigid"]))
    cps = cert.get("prestress_stable")
    if ps is not None:
        if o["strict"] and cps is not ps:
            bad.append("certificate.prestress_stable=%r, expected %r (%s)" % (cps, ps, o["note"]))
        elif cps is not None and cps != ps:
            bad.append("certificate.prestress_stable=%r contradicts %r" % (cps, ps))
    if case.known_flexible and cps is True:
        bad.append("certificate.prestress_stable true on a flexible construction")
    cf = cert.get("flexible")
    if o["flexible_proved"] and cf is not True:
        bad.append("certificate.flexible=%r: no stress and a nontrivial flex is a proof of flexibility" % cf)
    if o["inf_rigid"] or (ps is True and o["strict"]):
        if cf is not False:
            bad.append("certificate.flexible=%r, but rigidity is proved (%s)" % (cf, o["note"]))
    elif ps is True and cf is True:
        bad.append("certificate.flexible true, but the oracle proves it prestress stable")
    if case.known_flexible and cf is False:
        bad.append("certificate.flexible false on a flexible construction")
    # flexure's own answers must agree with each other
    if rigid == "rigid" and cf is True:
        bad.append("rigid but certificate.flexible true")
    if cert.get("inf_rigid") is True and js.get("inf_rigid") is False:
        bad.append("certificate.inf_rigid contradicts inf_rigid")
    return bad


def compare_float(case, js):
    o = case.oracle
    if not isinstance(js, dict):
        return ["no JSON object on stdout (floating point)"]
    bad = []
    if js.get("exact") is True:
        bad.append("floating-point run says exact: true")
    for k in COUNTS + ["inf_rigid"]:
        if js.get(k) != o[k]:
            bad.append("float %s=%r, exact %r" % (k, js.get(k), o[k]))
    return bad


def self_check(cases):
    """The oracle against the literature, no binary."""
    failures = 0
    t0 = time.time()
    for c in cases:
        if c.kind != "exact":
            continue
        o = c.oracle
        probs = []
        for k, v in c.literature.items():
            if o[k] != v:
                probs.append("%s=%r, literature %r" % (k, o[k], v))
        if c.known_flexible:
            # the stress energy vanishes on the tangent of a motion: never prestress stable
            if o["prestress_stable"] is not False:
                probs.append("prestress_stable=%r on a flexible construction" % o["prestress_stable"])
        if c.group.startswith("5 grids") and not o["inf_rigid"]:
            probs.append("grid not infinitesimally rigid")
        # Maxwell: rank + stresses = equations, rank + kernel = variables
        if o["rigidity_rank"] + o["stress_dim"] != o["equations"]:
            probs.append("Maxwell count")
        status = "ok" if not probs else "FAIL: " + "; ".join(probs)
        failures += bool(probs)
        print("%-40s %s  [%s]  %s" % (c.name, expected_line(o), o["note"], status))
    # the form does not depend on the complement of the trivial flexes: Bricard and K33 on a conic
    # with the flex shifted by trivial motions give the same value
    for c in cases:
        if c.name in ("bricard1", "k33_circle", "collinear_triangle", "dixon1", "random_00_2d_n8_generic"):
            ok, msg = check_form_invariance(c.fw)
            print("%-40s %s  %s" % ("form_invariance_" + c.name, msg, "ok" if ok else "FAIL"))
            failures += not ok
    # the oracle's pieces on small known inputs
    D = lambda rows: definiteness([[F(x) for x in r] for r in rows])
    units = [D([[2, 1], [1, 2]]) == 1, D([[1, 2], [2, 1]]) == 0, D([[-1, 0], [0, -3]]) == -1,
             D([[0, 0], [0, 1]]) == 0, D([[1, 0], [0, 0]]) == 0, D([[F(1, 3)]]) == 1,
             rank([[F(1), F(2)], [F(2), F(4)]], 2) == 1, len(nullspace([[F(1), F(1), F(1)]], 3)) == 2,
             conic_through([circle_point(t) for t in (0, 1, 2, 3, 4, 5)]) is not None,
             conic_through([(0, 0), (1, 0), (0, 1), (1, 1), (2, 3), (3, 7)]) is None]
    print("%-40s definiteness, rank, null space, conic test on known inputs  %s" % ("units", "ok" if all(units) else "FAIL %r" % units))
    failures += not all(units)
    # the answers do not change under a rational rotation (Cayley), scaling and translation
    bad = []
    for c in cases:
        if c.kind != "exact" or not (c.name.startswith(("k33", "dixon", "bricard", "octahedron", "collinear")) or c.name.startswith("random_0")):
            continue
        g = disguise(c.fw, random.Random(c.name))
        o2 = analyze(g)
        if any(o2[k] != c.oracle[k] for k in COUNTS + ["prestress_stable", "second_order_rigid"]):
            bad.append(c.name)
    print("%-40s counts and prestress unchanged by a rational rotation, scaling and translation  %s"
          % ("similarity_invariance", "ok" if not bad else "FAIL " + ", ".join(bad)))
    failures += bool(bad)
    # every scene written reads back (decimals exactly) as the framework the oracle analysed
    for c in cases:
        if c.kind == "exact":
            check_scene_roundtrip(scene_text(c.fw, c.name, index_base=c.index_base), c.fw, c.index_base)
    print("%-40s every scene's text reads back as the oracle's framework  ok" % "scene_roundtrip")
    # the conic test agrees with Bolker-Roth on random 6-point sets (rank 8 iff on a conic)
    rng = random.Random(12345)
    agree = 0
    for k in range(40):
        if k % 2 == 0:  # on a random conic through 5 random points: solve for the 6th on a line
            pts = [circle_point(random_rational(rng, -20, 20, (1, 2, 3, 7))) for _ in range(12)]
            pts = list(dict.fromkeys(pts))[:6]
            M = [[F(rng.randint(-5, 5), rng.randint(1, 4)) for _ in range(2)] for _ in range(2)]
            if M[0][0] * M[1][1] - M[0][1] * M[1][0] == 0:
                M = [[F(1), F(0)], [F(0), F(1)]]
            pts = [(M[0][0] * x + M[0][1] * y + 1, M[1][0] * x + M[1][1] * y - 2) for x, y in pts]
        else:
            pts = list(dict.fromkeys((random_rational(rng), random_rational(rng)) for _ in range(12)))[:6]
        if len(pts) < 6:
            continue
        perm = list(range(6))
        rng.shuffle(perm)
        fw = Framework(2, [pts[i] for i in perm], K33_EDGES)
        o = analyze(fw)
        on = conic_through(fw.points) is not None
        if (o["rigidity_rank"] == 8) == on and o["rigidity_rank"] in (8, 9):
            agree += 1
        else:
            print("bolker_roth mismatch at", fw.points, o["rigidity_rank"], on)
            failures += 1
    print("%-40s %d random K33 (half on conics): rank 8 exactly on a conic  %s" % ("bolker_roth_random", agree,
                                                                                    "ok" if failures == 0 else ""))
    print("self-check: %d failures, %.1f s" % (failures, time.time() - t0))
    return failures


def check_form_invariance(fw):
    """Q(v + t) = Q(v) for trivial t, and Q(v, t) = 0 (the cross term vanishes on a flex)."""
    d, P = fw.d, fw.points
    o = analyze(fw)
    R, eqs, free, col, nv = rigidity_matrix(fw)
    if not o["stress_dim"]:
        return True, "no stress"
    w = nullspace(transpose(R, nv), len(eqs))[0]
    ker = nullspace(R, nv)

    def Q(a, b):
        s = F(0)
        for e, (i, j) in enumerate(eqs):
            for k in range(d):
                ai = a[d * col[i] + k] if i in col else 0
                aj = a[d * col[j] + k] if j in col else 0
                bi = b[d * col[i] + k] if i in col else 0
                bj = b[d * col[j] + k] if j in col else 0
                s += w[e] * (ai - aj) * (bi - bj)
        return s

    triv = []
    for g in range(d + d * (d - 1) // 2):
        v = []
        for i in free:
            v += motion_fields(d, P[i])[g]
        triv.append(v)
    worst = max((abs(Q(a, t)) for a in ker for t in triv), default=0)
    return worst == 0, "max |Q_w(flex, trivial)| = %s over a kernel basis and every motion generator" % worst


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--flexure", help="the flexure binary")
    ap.add_argument("--seed", type=int, default=44, help="random frameworks' seed (default 44)")
    ap.add_argument("--cases", type=int, default=40, help="random frameworks (default 40)")
    ap.add_argument("--jobs", type=int, default=2, help="binary runs at once (default 2)")
    ap.add_argument("--timeout", type=float, default=60, help="seconds per run of the binary")
    ap.add_argument("--only", default=None, help="a regular expression: run the cases whose name matches")
    ap.add_argument("--keep", default=None, help="write the scenes to this folder and keep them")
    ap.add_argument("--self-check", action="store_true", help="run the oracle alone against the literature")
    args = ap.parse_args()

    t0 = time.time()
    print("exact oracle: seed %d, %d random cases" % (args.seed, args.cases))
    cases = build_cases(args.seed, args.cases)
    if args.only:
        cases = [c for c in cases if re.search(args.only, c.name)]
    for c in cases:
        if c.kind == "exact":
            c.oracle = analyze(c.fw)
    print("oracle: %d cases in %.1f s" % (len(cases), time.time() - t0))
    if args.self_check:
        sys.exit(1 if self_check(cases) else 0)
    if not args.flexure or not os.access(args.flexure, os.X_OK):
        print("no flexure binary: %r (give --flexure PATH, or --self-check)" % args.flexure)
        sys.exit(1)
    flexure = os.path.abspath(args.flexure)

    folder = args.keep or tempfile.mkdtemp(prefix="flexure-exact-")
    os.makedirs(folder, exist_ok=True)
    try:
        jobs = []  # (case, mode, path)
        for c in cases:
            path = os.path.join(folder, c.name + ".toml")
            if c.kind == "surface":
                c.text = scene_text(c.fw, c.name, stype="framework_on_surface", extra_system='surface = "x^2 + y^2 - z^2 - 1"')
            else:
                c.text = scene_text(c.fw, c.name, index_base=c.index_base)
                if c.kind == "exact":
                    check_scene_roundtrip(c.text, c.fw, c.index_base)
            with open(path, "w") as f:
                f.write(c.text)
            c.path = path
            jobs.append((c, "exact", path))
            if c.float_too or c.kind in ("bad_exact", "surface"):
                jobs.append((c, "float", path))

        with concurrent.futures.ThreadPoolExecutor(max(1, args.jobs)) as ex:
            futs = {(c.name, mode): ex.submit(run, flexure, path, mode == "exact", args.timeout) for c, mode, path in jobs}
            results = {k: f.result() for k, f in futs.items()}

        failures = 0
        group = None
        for c in cases:
            if c.group != group:
                group = c.group
                print("-- %s" % group)
            r = results[(c.name, "exact")]
            tag = "%5.2fs" % r["secs"]
            if c.kind == "exact":
                probs = []
                if r["rc"] != 0:
                    probs.append("exit status %s: %s" % (r["rc"], r["err"].strip()[-300:]))
                probs += compare_exact(c, r["js"])
                exp, got = expected_line(c.oracle), got_line(r["js"])
                if (c.name, "float") in results:
                    rf = results[(c.name, "float")]
                    if rf["rc"] != 0:
                        probs.append("floating point: exit status %s: %s" % (rf["rc"], rf["err"].strip()[-300:]))
                    else:
                        probs += compare_float(c, rf["js"])
                        got += " | float " + " ".join("%s=%s" % (SHORT[k], (rf["js"] or {}).get(k, "-"))
                                                      for k in ("rigidity_rank", "nontrivial_inf_flexes", "stress_dim"))
            elif c.kind == "bad_exact":
                exp = "exit 1, %s:LINE:COL naming the line of the vertices; floating point exits 0" % os.path.basename(c.path)
                probs = []
                msg = r["err"] + r["out"]
                m = re.search(re.escape(os.path.basename(c.path)) + r":(\d+):(\d+)", msg)
                vline = 1 + c.text.splitlines().index(next(l for l in c.text.splitlines() if l.startswith("vertices")))
                if r["rc"] != 1:
                    probs.append("exit status %s, expected 1" % r["rc"])
                if not m:
                    probs.append("no FILE:LINE:COLUMN in %r" % msg.strip()[:300])
                elif int(m.group(1)) != vline:
                    probs.append("line %s, the coordinate is on line %d" % (m.group(1), vline))
                rf = results[(c.name, "float")]
                if rf["rc"] != 0:
                    probs.append("without --exact the scene should be accepted: exit %s: %s" % (rf["rc"], rf["err"].strip()[-200:]))
                got = "exit %s, %s" % (r["rc"], (msg.strip().splitlines() or [""])[0][:160])
            else:  # surface
                exp = "exit 1 with a reason on stderr; floating point exits 0"
                probs = []
                if r["rc"] != 1:
                    probs.append("exit status %s, expected 1" % r["rc"])
                if not r["err"].strip():
                    probs.append("nothing on stderr")
                rf = results[(c.name, "float")]
                if rf["rc"] != 0:
                    probs.append("without --exact the scene should be accepted: exit %s: %s" % (rf["rc"], rf["err"].strip()[-200:]))
                got = "exit %s, %s" % (r["rc"], (r["err"].strip().splitlines() or [""])[0][:160])
            ok = not probs
            failures += not ok
            print("%-34s expected: %s | got: %s | %s | %s" % (c.name, exp, got, tag, "ok" if ok else "MISMATCH"))
            if not ok:
                for p in probs:
                    print("      - %s" % p)
                print("      scene %s%s:" % (c.path, "" if args.keep else " (removed)"))
                text = c.text if len(c.text) < 3000 else c.text[:3000] + "...\n"
                for line in text.splitlines():
                    print("        | " + line)
    finally:
        if not args.keep:
            shutil.rmtree(folder, ignore_errors=True)
    print("summary: %d cases, %d passed, %d failed (seed %d, %.1f s)" % (len(cases), len(cases) - failures, failures,
                                                                         args.seed, time.time() - t0))
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
