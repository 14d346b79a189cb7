#!/usr/bin/python3
"""The paper's examples, made by scripts/paper and checked against the paper (docs/paper-examples.md).

    /usr/bin/python3 tests/paper/run.py --flexure build/flexure [--root .] [--keep DIR]

Runs `scripts/paper OUT --quick` with FLEXURE set to --flexure, into a temporary folder (or
--keep DIR, left in place), then checks:

- every file the paper's examples and figures need is there, not empty, of its format (PNG,
  PDF, GIF, JSON), and scripts/paper printed exactly one line per file;
- for each example, flexure's counts and verdicts (from ID.json, `analyze --json`) and its path
  (ID_path.json) against what the paper states, or against a count or closed form written here
  where the paper gives none or is wrong; each check says where its number comes from. The
  paths are checked by recomputing their constraints here (bar lengths, areas, inversive
  distances, the surface, Thales' circle), with no code from flexure;
- that every scene of scenes/paper/ is shown in docs/paper-examples.md exactly as the file is
  (the page's toml blocks marked `doc-test: file NAME`).

Standard library only. One line per check; exit 1 if any fails, 2 for a usage error.
"""

import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

# The examples: ID -> the figures scripts/paper draws for it (besides ID.txt, ID.json and
# ID_path.json, which every example has).
EXAMPLES = {
    "sec2_collinear_triangle": [],
    "appA_segment": [],
    "fig01_left_bricard_octahedron": ["fig01_left_bricard_octahedron.png", "fig01_left_bricard_octahedron.pdf",
                                      "fig01_left_bricard_octahedron.gif"],
    "fig01_fig13_hypostatic_packing": ["fig01_fig13_hypostatic_packing.png", "fig01_fig13_hypostatic_packing.pdf"],
    "fig02_left_prism_generic": ["fig02_left_prism_generic.png", "fig02_left_prism_generic.pdf"],
    "fig02_center_three_frustum": ["fig02_center_three_frustum.png", "fig02_center_three_frustum.pdf"],
    "fig02_right_fig05_left_three_prism": ["fig02_right_fig05_left_three_prism.png",
                                           "fig02_right_fig05_left_three_prism.pdf"],
    "fig05_center_k4_subdivided": ["fig05_center_k4_subdivided.png", "fig05_center_k4_subdivided.pdf"],
    "fig05_right_k4_pendant": ["fig05_right_k4_pendant.png", "fig05_right_k4_pendant.pdf"],
    "fig08_three_prism": ["fig08_three_prism.png", "fig08_three_prism.pdf", "fig08_three_prism.gif"],
    "fig09_double_watt": ["fig09_left_double_watt.png", "fig09_left_double_watt.pdf",
                          "fig09_right_double_watt_projection.png", "fig09_right_double_watt_projection.pdf",
                          "fig09_double_watt.gif"],
    "fig10_left_hyperboloid": ["fig10_left_hyperboloid.png", "fig10_left_hyperboloid.pdf", "fig10_left_hyperboloid.gif"],
    "fig10_right_thales": ["fig10_right_thales.png", "fig10_right_thales.pdf", "fig10_right_thales.gif"],
    "fig11_dodecahedron": ["fig11_left_dodecahedron.png", "fig11_left_dodecahedron.pdf",
                           "fig11_right_dodecahedron_projection.png", "fig11_right_dodecahedron_projection.pdf",
                           "fig11_dodecahedron.gif"],
    "fig12_left_bodyhinge_pyramid": ["fig12_left_bodyhinge_pyramid.png", "fig12_left_bodyhinge_pyramid.pdf"],
    "fig12_right_bodybar_cube": ["fig12_right_bodybar_cube.png", "fig12_right_bodybar_cube.pdf"],
    "fig13_left_disk_packing": ["fig13_left_disk_packing.png", "fig13_left_disk_packing.pdf"],
    "fig14_left_octahedral_volumes": ["fig14_left_octahedral_volumes.png", "fig14_left_octahedral_volumes.pdf"],
    "fig14_right_spherical_bricard": ["fig14_right_spherical_bricard.png", "fig14_right_spherical_bricard.pdf"],
}

MAGIC = {".png": b"\x89PNG\r\n\x1a\n", ".pdf": b"%PDF-", ".gif": b"GIF89a", ".json": b"{"}

S3 = math.sqrt(3)


class Checker:
    def __init__(self, out):
        self.out = out
        self.failed = 0
        self.count = 0

    def check(self, name, ok, why, detail=""):
        self.count += 1
        if not ok:
            self.failed += 1
        print(f"{'ok  ' if ok else 'FAIL'} {name}: {why}" + (f"  [{detail}]" if detail and not ok else ""))

    def analysis(self, ex):
        with open(os.path.join(self.out, ex + ".json"), encoding="utf-8") as f:
            return json.load(f)

    def path(self, ex):
        with open(os.path.join(self.out, ex + "_path.json"), encoding="utf-8") as f:
            return json.load(f)

    def fields(self, ex, why, **want):
        """The analysis JSON's fields equal `want`."""
        a = self.analysis(ex)
        got = {k: a.get(k) for k in want}
        self.check(ex, got == want, f"{', '.join(f'{k} {v}' for k, v in want.items())} ({why})",
                   f"got {got}")
        return a


# -- geometry, written here (no code from flexure)

def dist(p, q):
    return math.sqrt(sum((a - b) ** 2 for a, b in zip(p, q)))


def sub(p, q):
    return [a - b for a, b in zip(p, q)]


def dot(p, q):
    return sum(a * b for a, b in zip(p, q))


def cross(u, v):
    return [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]


def trivial_count(d, l):
    """(l + 1)(2d - l)/2: the Euclidean motions of points whose affine span has dimension l."""
    return (l + 1) * (2 * d - l) // 2


def max_length_drift(path, pairs):
    """The largest change of |p_i - p_j| over the samples, for 1-based pairs."""
    s = path["samples"]
    worst = 0.0
    for i, j in pairs:
        l0 = dist(s[0][i - 1], s[0][j - 1])
        for x in s:
            worst = max(worst, abs(dist(x[i - 1], x[j - 1]) - l0))
    return worst


def line_meet(p, q, r, s):
    """The intersection of the lines pq and rs in the plane (None if parallel)."""
    d1, d2 = sub(q, p), sub(s, r)
    den = d1[0] * d2[1] - d1[1] * d2[0]
    if abs(den) < 1e-12:
        return None
    t = ((r[0] - p[0]) * d2[1] - (r[1] - p[1]) * d2[0]) / den
    return [p[0] + t * d1[0], p[1] + t * d1[1]]


def dist_to_line(x, p, q):
    d = sub(q, p)
    return abs(d[0] * (x[1] - p[1]) - d[1] * (x[0] - p[0])) / math.hypot(*d)


def in_span(v, basis):
    """The distance from v to the span of the basis (Gram-Schmidt), relative to |v|."""
    ortho = []
    for b in basis:
        w = list(b)
        for o in ortho:
            c = dot(w, o)
            w = [x - c * y for x, y in zip(w, o)]
        n = math.sqrt(dot(w, w))
        if n > 1e-12:
            ortho.append([x / n for x in w])
    r = list(v)
    for o in ortho:
        c = dot(r, o)
        r = [x - c * y for x, y in zip(r, o)]
    return math.sqrt(dot(r, r)) / math.sqrt(dot(v, v))


def rigidity_matrix(points, edges):
    """Rows p_i - p_j in i's columns, p_j - p_i in j's (1-based edges)."""
    d = len(points[0])
    rows = []
    for i, j in edges:
        row = [0.0] * (d * len(points))
        for k in range(d):
            row[d * (i - 1) + k] = points[i - 1][k] - points[j - 1][k]
            row[d * (j - 1) + k] = points[j - 1][k] - points[i - 1][k]
        rows.append(row)
    return rows


def signed_area(a, b, c):
    return ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])) / 2


def inversive(a, b):
    """Inversive distance of the caps cut from the unit sphere by the planes a.y = 1, b.y = 1:
    centre m = a/|a|, plane offset d = 1/|a| (the paper's (m, d))."""
    na, nb = math.sqrt(dot(a, a)), math.sqrt(dot(b, b))
    ma, mb = [x / na for x in a], [x / nb for x in b]
    da, db = 1 / na, 1 / nb
    return (dot(ma, mb) - da * db) / math.sqrt((1 - da * da) * (1 - db * db))


# -- the examples

def check_examples(c):
    out = c.out

    # Section 2: K_3 on (0,0), (1,0), (2,0). The paper: rank 2, not infinitesimally rigid, rigid
    # (the only real solution). Points on a line: l = 1, d = 2, 3 trivial flexes.
    ex = "sec2_collinear_triangle"
    c.fields(ex, "the paper: rank 2; trivial (l+1)(2d-l)/2 = 3 for l = 1, d = 2; 6 - 2 - 3 = 1 flex; "
                 "3 - 2 = 1 stress; the paper: not inf. rigid, rigid",
             variables=6, equations=3, rigidity_rank=2, trivial_inf_flexes=trivial_count(2, 1),
             nontrivial_inf_flexes=1, stress_dim=1, inf_rigid=False, rigid="rigid")
    p = c.path(ex)
    c.check(ex, p["steps_done"] == 0, "a rigid start does not move", f"steps_done {p['steps_done']}")

    # Appendix A: one bar in R^3 has 3 translations and 2 rotations: 5 trivial flexes.
    ex = "appA_segment"
    c.fields(ex, "the paper: 5 trivial flexes = (l+1)(2d-l)/2 for l = 1, d = 3",
             variables=6, equations=1, rigidity_rank=1, trivial_inf_flexes=trivial_count(3, 1),
             nontrivial_inf_flexes=0, inf_rigid=True, rigid="rigid")

    # Figure 1 (left): Bricard's octahedron is flexible. 18 - 12 - 6 = 0: as many flexes as stresses.
    ex = "fig01_left_bricard_octahedron"
    a = c.fields(ex, "the paper: flexible; a framework in R^3 on 6 points", rigid="flexible", trivial_inf_flexes=6)
    c.check(ex, a["nontrivial_inf_flexes"] == a["stress_dim"] >= 1,
            "flexes - stresses = 18 - 12 - 6 = 0, and a flex", f"{a['nontrivial_inf_flexes']}, {a['stress_dim']}")
    p = c.path(ex)
    c.check(ex, p["steps_done"] == p["steps_requested"], "the whole path is tracked", str(p["steps_done"]))
    drift = max_length_drift(p, p["structure"]["edges"])
    c.check(ex, drift < 1e-8, "every bar keeps its length along the path (recomputed)", f"{drift:.2e}")

    # Figures 1 (right) and 13 (right): the hypostatic packing (10 spheres of radius 1/2): fewer
    # contacts than 3n - 6; not infinitesimally rigid, second-order rigid, rigid (the paper).
    ex = "fig01_fig13_hypostatic_packing"
    a = c.fields(ex, "the paper: is_inf_rigid false, is_second_order_rigid and is_rigid true",
                 vertices=10, inf_rigid=False, second_order_rigid=True, rigid="rigid")
    p = c.path(ex)
    s0 = p["samples"][0]
    contacts = sum(1 for i in range(10) for j in range(i + 1, 10) if abs(dist(s0[i], s0[j]) - 1.0) < 1e-6)
    c.check(ex, contacts == a["equations"] == 23 and contacts < 3 * 10 - 6,
            "hypostatic: 23 contacts (counted here at distance 2r) < 3n - 6 = 24",
            f"{contacts} contacts, {a['equations']} equations")

    # Figure 2 (left): the 3-prism graph turned generic. A planar 3-prism is infinitesimally
    # flexible iff the lines of its joining bars 14, 25, 36 meet in a point or are parallel.
    ex = "fig02_left_prism_generic"
    p = c.path(ex)
    s0 = p["samples"][0]
    m = line_meet(s0[0], s0[3], s0[1], s0[4])
    apart = m is None or dist_to_line(m, s0[2], s0[5]) > 1e-3
    c.check(ex, apart, "the joining bars' lines are not concurrent (computed here)")
    c.fields(ex, "so infinitesimally rigid: 12 - 9 = 3 trivial flexes, no flex, no stress",
             trivial_inf_flexes=3, nontrivial_inf_flexes=0, stress_dim=0, inf_rigid=True, rigid="rigid")

    # Figure 2 (center), section 4.4: the 3-frustum in the paper's numbering (vertex 3 corrected).
    ex = "fig02_center_three_frustum"
    a = c.fields(ex, "the paper: one flex q, one stress omega, not inf. rigid, second-order rigid; "
                     "12 - 8 - 3 = 1, 9 - 8 = 1",
                 variables=12, equations=9, rigidity_rank=8, trivial_inf_flexes=3, nontrivial_inf_flexes=1,
                 stress_dim=1, inf_rigid=False, second_order_rigid=True, rigid="rigid")
    pts = [[1, 0], [-0.5, S3 / 2], [-0.5, -S3 / 2], [2, 0], [-1, S3], [-1, -S3]]
    edges = [[1, 2], [1, 3], [1, 4], [2, 3], [2, 5], [3, 6], [4, 5], [4, 6], [5, 6]]
    omega = [2, 2, 6, 2, 6, 6, -1, -1, -1]
    q = [0, 0, 0, 0, 0, 0, 0, 2, -S3, -1, S3, -1]
    R = rigidity_matrix(pts, edges)
    rq = max(abs(dot(row, q)) for row in R)
    wr = max(abs(sum(omega[i] * R[i][k] for i in range(9))) for k in range(12))
    c.check(ex, rq < 1e-12 and wr < 1e-12,
            "the paper's q is a flex and omega a stress of this realization (R q = 0, omega R = 0, computed here)",
            f"|Rq| {rq:.1e}, |omega R| {wr:.1e}")
    st = a["stress_basis"][0]
    scale = st[6] / omega[6]
    c.check(ex, max(abs(x / scale - w) for x, w in zip(st, omega)) < 1e-9,
            "flexure's stress is the paper's omega = (2,2,6,2,6,6,-1,-1,-1), entry by entry", str(st))
    trivial = []
    for k in range(2):
        trivial.append([1.0 if t % 2 == k else 0.0 for t in range(12)])
    trivial.append([c_ for x, y in pts for c_ in (-y, x)])
    flex = [c_ for v in a["nontrivial_flex_basis"][0] for c_ in v]
    c.check(ex, in_span(q, trivial + [flex]) < 1e-9,
            "the paper's q lies in flexure's flexes (its nontrivial flex plus the rigid motions)")
    s0 = c.path(ex)["samples"][0]
    m = line_meet(s0[0], s0[3], s0[1], s0[4])
    c.check(ex, m is not None and dist_to_line(m, s0[2], s0[5]) < 1e-12,
            "the joining bars' lines meet (at the centre): not inf. rigid")

    # Figure 2 (right) and figure 5 (left): the 3-prism with parallel bars.
    ex = "fig02_right_fig05_left_three_prism"
    c.fields(ex, "the paper (figure 5): one flex and one stress; generically rigid, yet flexible",
             nontrivial_inf_flexes=1, stress_dim=1, rigid="flexible")
    p = c.path(ex)
    s0 = p["samples"][0]
    par = max(abs(cross(sub(s0[3], s0[0]) + [0], sub(s0[4 + k], s0[1 + k]) + [0])[2]) for k in range(2))
    c.check(ex, par < 1e-12, "the joining bars are parallel (computed here)")
    drift = max_length_drift(p, p["structure"]["edges"])
    c.check(ex, drift < 1e-8, "every bar keeps its length along the path", f"{drift:.2e}")

    # Figure 5 (center): K_4 with a vertex added on an edge: one flex, one stress, second-order rigid.
    ex = "fig05_center_k4_subdivided"
    c.fields(ex, "the paper: one flex, one stress, second-order rigid",
             nontrivial_inf_flexes=1, stress_dim=1, second_order_rigid=True, rigid="rigid")

    # Figure 5 (right): K_4 with a vertex and an edge added: one flex, one stress, flexible.
    ex = "fig05_right_k4_pendant"
    c.fields(ex, "the paper: one flex, one stress, flexible", nontrivial_inf_flexes=1, stress_dim=1,
             rigid="flexible")
    p = c.path(ex)
    drift = max_length_drift(p, p["structure"]["edges"])
    c.check(ex, drift < 1e-8, "every bar keeps its length along the path", f"{drift:.2e}")

    # Figure 8, section 4.5: the paper's 3-prism, pinned at 1 and 4, 2 x 30 steps of 0.01.
    ex = "fig08_three_prism"
    c.fields(ex, "as figure 5 (left): one flex, one stress, flexible", nontrivial_inf_flexes=1, stress_dim=1,
             rigid="flexible")
    p = c.path(ex)
    s = p["samples"]
    c.check(ex, p["steps_done"] == 60, "60 steps: the paper's two paths of 30", str(p["steps_done"]))
    # Closed form: the parallelogram motion turns both triangles by theta about 1 and 4; four
    # vertices at distance 1 from their pivots move, so a configuration step of 0.01 turns them
    # by 0.005 rad: theta = 0.3 at sample 60, vertex 2 at (-+sin 0.3, cos 0.3).
    x2 = s[60][1]
    c.check(ex, abs(abs(x2[0]) - math.sin(0.3)) < 1e-4 and abs(x2[1] - math.cos(0.3)) < 1e-4,
            "vertex 2 at (-+sin 0.3, cos 0.3) at sample 60 (closed form)", str(x2))
    shift = max(dist(sub(x[3 + k], x[k]), [1, 0]) for x in s for k in range(3))
    c.check(ex, shift < 1e-8, "the second triangle is the first moved by (1, 0) at every sample", f"{shift:.2e}")

    # Figure 9: the double Watt mechanism, pins 1, 6, 11, 500 steps of 0.05 (the paper's code).
    ex = "fig09_double_watt"
    a = c.fields(ex, "the paper: flexible (so not second-order rigid, which implies rigidity); "
                     "11 vertices, 3 pinned, 15 bars",
                 vertices=11, pinned=3, variables=16, equations=15, second_order_rigid=False, rigid="flexible")
    c.check(ex, a["nontrivial_inf_flexes"] - a["stress_dim"] == 16 - 15,
            "flexes - stresses = 16 - 15 = 1", f"{a['nontrivial_inf_flexes']} - {a['stress_dim']}")
    p = c.path(ex)
    c.check(ex, p["steps_done"] == 500, "500 steps, the paper's", str(p["steps_done"]))
    cusps = [e for e in p["events"] if e["kind"] == "singularity" and "cusp" in e["detail"]]
    back = cusps and math.sqrt(sum(dist(u, v) ** 2 for u, v in zip(p["samples"][0], p["samples"][cusps[0]["sample"]])))
    c.check(ex, bool(cusps) and back < 0.01,
            "the paper: a cusp, at the start (the blue pentagon): the orbit closes at a cusp within 0.01 of the start",
            f"cusps {[e['sample'] for e in cusps]}, distance {back}")
    drift = max_length_drift(p, p["structure"]["edges"])
    c.check(ex, drift < 1e-8, "every bar keeps its length along the path", f"{drift:.2e}")

    # Figure 10 (left): the four-bar on x^2 + y^2 - z^2 = 1. The paper says 2 flexes; the count
    # is 4 x 2 - 4 = 4 degrees of freedom less 1 for the rotations about the z-axis (the only
    # continuous isometries of the hyperboloid): 3.
    ex = "fig10_left_hyperboloid"
    c.fields(ex, "4 vertices x 2 - 4 bars - 1 (rotations about z) = 3 flexes (the paper says 2: "
                 "it counts 2 trivial motions)",
             trivial_inf_flexes=1, nontrivial_inf_flexes=3, stress_dim=0, rigid="flexible")
    p = c.path(ex)
    r = math.sqrt(0.5)
    paper = [[-r, -r, -1], [-1, 0, 0], [0, 1, 0], [r, r, 1]]
    f = lambda x: x[0] ** 2 + x[1] ** 2 - x[2] ** 2 - 1
    off = [f(x) for x in paper]
    c.check(ex, off == [-1.0, 0.0, 0.0, -1.0] or max(abs(a_ - b_) for a_, b_ in zip(off, [-1, 0, 0, -1])) < 1e-12,
            "the paper's vertices 1 and 4 are off the surface (f = -1)", str(off))
    E = p["structure"]["edges"]
    s0 = p["samples"][0]
    lens = max(abs(dist(s0[i - 1], s0[j - 1]) - dist(paper[i - 1], paper[j - 1])) for i, j in E)
    on = max(abs(f(x)) for smp in p["samples"] for x in smp)
    c.check(ex, lens < 1e-9, "the start is moved onto the surface with the paper's bar lengths", f"{lens:.2e}")
    c.check(ex, on < 1e-9, "every sample's vertices are on the hyperboloid (recomputed)", f"{on:.2e}")
    drift = max_length_drift(p, E)
    c.check(ex, drift < 1e-8, "every bar keeps its length along the path", f"{drift:.2e}")

    # Figure 10 (right): Thales: the right angle at 3 over the pinned diameter 1-2.
    ex = "fig10_right_thales"
    c.fields(ex, "2 free coordinates, 1 angle, both ends pinned: 1 flex, flexible",
             variables=2, equations=1, nontrivial_inf_flexes=1, rigid="flexible")
    p = c.path(ex)
    s = p["samples"]
    circle = max(abs(math.hypot(*x[2]) - 1) for x in s)
    right = max(abs(dot(sub(x[0], x[2]), sub(x[1], x[2]))) for x in s)
    c.check(ex, circle < 1e-9 and right < 1e-9, "Thales: vertex 3 on the unit circle, the angle at 3 right, "
                                                "at every sample", f"{circle:.1e}, {right:.1e}")
    arc = p["steps_done"] * 0.025
    c.check(ex, dist(s[-1][2], [1, 0]) < 0.05 and abs(arc - 3 * math.pi / 4) < 0.05,
            "it ends at vertex 2 after the arc 3 pi/4 from 135 degrees (where the angle is undefined)",
            f"{s[-1][2]}, {p['steps_done']} steps")

    # Figure 11: the regular dodecahedron; the paper: second-order rigid; its edge contracted to 75 %.
    ex = "fig11_dodecahedron"
    a = c.fields(ex, "the paper: second-order rigid, so rigid; 20 x 3 + 12 normals x 3 = 96 coordinates, "
                     "30 edges + 12 x 4 planarity + 12 normal lengths = 90 equations",
                 vertices=20, variables=96, equations=90, trivial_inf_flexes=6, inf_rigid=False,
                 second_order_rigid=True, rigid="rigid")
    c.check(ex, a["nontrivial_inf_flexes"] == a["stress_dim"],
            "flexes - stresses = 96 - 90 - 6 = 0", f"{a['nontrivial_inf_flexes']}, {a['stress_dim']}")
    p = c.path(ex)
    s = p["samples"]
    E = p["structure"]["edges"]
    c.check(ex, len(E) == 30 and [1, 9] in E, "[1, 9] is one of the 30 edges")
    c.check(ex, abs(dist(s[-1][0], s[-1][8]) - 0.75) < 1e-9 and abs(dist(s[0][0], s[0][8]) - 1) < 1e-9,
            "the paper: the edge contracted from 1 to 75 % of its length", str(dist(s[-1][0], s[-1][8])))
    drift = max_length_drift(p, [e for e in E if e != [1, 9]])
    c.check(ex, drift < 1e-8, "the other 29 edges keep their length along the path", f"{drift:.2e}")
    flat = 0.0
    for x in s:
        for fa in p["structure"]["facets"]:
            a0, a1, a2 = (x[v - 1] for v in fa[:3])
            n = cross(sub(a1, a0), sub(a2, a0))
            nn = math.sqrt(dot(n, n))
            flat = max(flat, max(abs(dot(sub(x[v - 1], a0), n)) / nn for v in fa[3:]))
    c.check(ex, flat < 1e-8, "every pentagon stays planar along the path (recomputed)", f"{flat:.2e}")

    # Figure 12 (left): five triangles hinged around an apex: 10 edges on 6 points in R^3.
    ex = "fig12_left_bodyhinge_pyramid"
    c.fields(ex, "18 - 10 - 6 = 2 flexes (a spherical five-bar), no stress", variables=18, equations=10,
             nontrivial_inf_flexes=2, stress_dim=0, rigid="flexible")
    # Figure 12 (right): two rigid squares and four parallel bars: the bars' lines span 3
    # dimensions of line space, so 6 - 3 = 3 flexes of the top panel and 4 - 3 = 1 stress.
    ex = "fig12_right_bodybar_cube"
    c.fields(ex, "4 parallel bars through a square's corners span 3 line-space dimensions: 3 flexes, 1 stress",
             nontrivial_inf_flexes=3, stress_dim=1, rigid="flexible")
    for ex in ("fig12_left_bodyhinge_pyramid", "fig12_right_bodybar_cube"):
        p = c.path(ex)
        pairs = {tuple(sorted((u, v))) for fa in p["structure"]["facets"] for u in fa for v in fa if u != v}
        drift = max_length_drift(p, sorted(pairs))
        c.check(ex, drift < 1e-8, "every body keeps all its distances along the path (recomputed)", f"{drift:.2e}")

    # Figure 13 (left): four unit disks, disk 1 pinned: 2 flexes (the paper).
    ex = "fig13_left_disk_packing"
    c.fields(ex, "the paper: 2 flexes; 3 contacts on 6 coordinates less the rotation about disk 1",
             equations=3, trivial_inf_flexes=1, nontrivial_inf_flexes=2, stress_dim=0, rigid="flexible")
    p = c.path(ex)
    paper = [[0, 0], [7 / 4, -math.sqrt(15 / 16)], [7 / 2, 0], [7 / 2 + math.sqrt(2), math.sqrt(2)]]
    s = p["samples"]
    c.check(ex, max(dist(u, v) for u, v in zip(s[0], paper)) < 1e-12, "the start is the paper's centres")
    c.check(ex, all(abs(dist(paper[k], paper[k + 1]) - 2) < 1e-12 for k in range(3)),
            "the paper's consecutive centres are 2 apart: 3 contacts (computed here)")
    overlap = min(dist(x[i], x[j]) for x in s for i in range(4) for j in range(i + 1, 4))
    c.check(ex, overlap > 2 - 1e-7, "no two disks overlap along the path", f"closest {overlap}")
    drift = max_length_drift(p, [[1, 2], [2, 3], [3, 4]])
    c.check(ex, drift < 1e-8, "the first contacts stay closed (sticky)", f"{drift:.2e}")

    # Figure 14 (left): the octahedral volume hypergraph, inner triangle 4, 5, 6 pinned: flexible.
    ex = "fig14_left_octahedral_volumes"
    c.fields(ex, "the paper: flexible; 6 free coordinates - 4 areas = 2 flexes, none trivial with a triangle pinned",
             variables=6, equations=4, trivial_inf_flexes=0, nontrivial_inf_flexes=2, stress_dim=0, rigid="flexible")
    p = c.path(ex)
    s = p["samples"]
    area = max(abs(signed_area(*(x[v - 1] for v in t)) - signed_area(*(s[0][v - 1] for v in t)))
               for x in s for t in p["structure"]["simplices"])
    c.check(ex, area < 1e-9, "every triangle keeps its signed area along the path (recomputed)", f"{area:.2e}")
    c.check(ex, p["steps_done"] > 0, "it moves", str(p["steps_done"]))

    # Figure 14 (right): six caps of angular radius 45 degrees centred on +-e_x, +-e_y, +-e_z, with
    # the 12 contacts of an octahedron's graph (DeformationPaths.jl's list): flexible (the paper).
    # The Moebius maps keeping the pinned cap are a 3-dimensional group.
    ex = "fig14_right_spherical_bricard"
    a = c.fields(ex, "the paper: flexible; the Moebius maps keeping cap 1 are 3 trivial flexes",
                 variables=15, equations=12, trivial_inf_flexes=3, rigid="flexible")
    c.check(ex, a["nontrivial_inf_flexes"] == a["stress_dim"] >= 1,
            "flexes - stresses = 15 - 12 - 3 = 0, and a flex", f"{a['nontrivial_inf_flexes']}, {a['stress_dim']}")
    p = c.path(ex)
    s = p["samples"]
    E = p["structure"]["edges"]
    # Inversive distance (m.m' - d d')/sqrt((1 - d^2)(1 - d'^2)) with d = 1/sqrt(2): -1 for caps
    # 90 degrees apart (tangent: the paper's +-1), (-1 - 1/2)/(1/2) = -3 for opposite caps.
    want = {(i, j): (-3.0 if dot(s[0][i - 1], s[0][j - 1]) < 0 else -1.0) for i, j in E}
    start = max(abs(inversive(s[0][i - 1], s[0][j - 1]) - want[(i, j)]) for i, j in E)
    c.check(ex, len(E) == 12 and sorted(want.values()).count(-1.0) == 10 and start < 1e-9,
            "12 contacts: 10 tangent caps (inversive distance -1) and 2 opposite pairs (-3), computed here",
            f"{start:.2e}")
    drift = max(abs(inversive(x[i - 1], x[j - 1]) - inversive(s[0][i - 1], s[0][j - 1])) for x in s for i, j in E)
    c.check(ex, drift < 1e-8 and p["steps_done"] > 0, "the inversive distances stay constant along the path",
            f"{drift:.2e}")

    # Rigid examples: the path stops at the start.
    for ex in ("appA_segment", "fig01_fig13_hypostatic_packing", "fig02_left_prism_generic",
               "fig02_center_three_frustum", "fig05_center_k4_subdivided"):
        p = c.path(ex)
        c.check(ex, p["steps_done"] == 0 and p["status"] == "stopped_early", "rigid: the path stays at the start",
                f"{p['status']}, {p['steps_done']}")


def check_files(c, printed):
    want = []
    for ex, figs in EXAMPLES.items():
        want += [ex + ".txt", ex + ".json", ex + "_path.json"] + figs
    have = sorted(os.listdir(c.out))
    missing = [f for f in want if f not in have]
    c.check("files", not missing, f"all {len(want)} files written", f"missing {missing}")
    empty = [f for f in want if f in have and os.path.getsize(os.path.join(c.out, f)) == 0]
    c.check("files", not empty, "none empty", f"empty {empty}")
    bad = []
    for f in want:
        ext = os.path.splitext(f)[1]
        if f in have and ext in MAGIC:
            with open(os.path.join(c.out, f), "rb") as h:
                if not h.read(8).startswith(MAGIC[ext]):
                    bad.append(f)
    c.check("files", not bad, "each file is of its format (PNG, PDF, GIF, JSON headers)", f"bad {bad}")
    names = sorted(os.path.basename(l) for l in printed)
    c.check("files", names == sorted(want), "scripts/paper prints one line per file",
            f"printed {len(names)} lines for {len(want)} files")
    for ex in EXAMPLES:
        with open(os.path.join(c.out, ex + ".txt"), encoding="utf-8") as h:
            first = h.readline()
        if "(" not in first:
            c.check(ex, False, "the report starts with the title line", first)


def check_doc(c, root):
    doc = os.path.join(root, "docs", "paper-examples.md")
    with open(doc, encoding="utf-8") as f:
        text = f.read()
    shown = {}
    for m in re.finditer(r"<!-- doc-test: file (\S+) -->\n```toml\n(.*?)```\n", text, re.S):
        shown[m.group(1)] = m.group(2)
    scenes = sorted(f for f in os.listdir(os.path.join(root, "scenes", "paper")) if f.endswith(".toml"))
    for name in scenes:
        with open(os.path.join(root, "scenes", "paper", name), encoding="utf-8") as f:
            body = f.read()
        c.check("docs/paper-examples.md", shown.get(name) == body,
                f"shows scenes/paper/{name} exactly as the file is")
    extra = sorted(set(shown) - set(scenes))
    c.check("docs/paper-examples.md", not extra, "shows no scene that scenes/paper/ lacks", str(extra))


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--flexure", required=True, help="the flexure executable")
    ap.add_argument("--root", default=os.path.dirname(os.path.dirname(here)), help="the source tree")
    ap.add_argument("--keep", help="make the files into this folder and leave them there")
    ap.add_argument("--timeout", type=float, default=300)
    args = ap.parse_args()
    root = os.path.abspath(args.root)
    tmp = None
    if args.keep:
        out = os.path.abspath(args.keep)
        shutil.rmtree(out, ignore_errors=True)
    else:
        tmp = tempfile.mkdtemp(prefix="flexure-paper-")
        out = os.path.join(tmp, "out")
    try:
        t0 = time.time()
        env = dict(os.environ, FLEXURE=os.path.abspath(args.flexure), LC_ALL="C.UTF-8")
        p = subprocess.run([os.path.join(root, "scripts", "paper"), out, "--quick"], env=env,
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=args.timeout)
        printed = p.stdout.decode("utf-8", "replace").splitlines()
        print(f"scripts/paper {out} --quick: exit {p.returncode}, {len(printed)} lines, {time.time() - t0:.1f} s")
        if p.returncode != 0:
            sys.stdout.write(p.stderr.decode("utf-8", "replace"))
            print("FAIL scripts/paper exited", p.returncode)
            return 1
        c = Checker(out)
        check_files(c, printed)
        check_examples(c)
        check_doc(c, root)
        print(f"{c.count - c.failed} of {c.count} checks passed, {time.time() - t0:.1f} s")
        return 1 if c.failed else 0
    finally:
        if tmp:
            shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
