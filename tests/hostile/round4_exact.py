"""Hostile input, fourth round (issue 62): every number that reaches an exact proof is the number
written, or it is refused. Expectations from the contract (README, docs/exact.md, issue 62),
never from what the binary does: a numeral is its own exact value whatever its exponent's
spelling (TOML allows leading zeros and underscores there), a number the exact mode cannot hold is
refused with its file, line and column (exit 1), never replaced by a nearby one, no expression
aborts the process (GMP's overflow: exit 134) or costs minutes, lengths and radii are exact like
coordinates, and Python's Decimal, long double and large Fraction coordinates are taken exactly.

Each proof is checked against an independent rank computed here in fractions.Fraction."""
import json
import re
from fractions import Fraction

import __main__ as h

# ----------------------------------------------------------------------------------------------
# an independent oracle: the rigidity matrix's rank over the rationals


def _rank(rows):
    """Rank of a matrix of Fractions (Gaussian elimination)."""
    m = [[Fraction(x) for x in r] for r in rows]
    rank, cols = 0, len(m[0]) if m else 0
    for c in range(cols):
        piv = next((i for i in range(rank, len(m)) if m[i][c] != 0), None)
        if piv is None:
            continue
        m[rank], m[piv] = m[piv], m[rank]
        for i in range(len(m)):
            if i != rank and m[i][c] != 0:
                f = m[i][c] / m[rank][c]
                m[i] = [a - f * b for a, b in zip(m[i], m[rank])]
        rank += 1
    return rank


def framework_rank(points, edges):
    """The rank of the rigidity matrix of bars `edges` at rational `points` (no pins)."""
    d = len(points[0])
    rows = []
    for a, b in edges:
        row = [Fraction(0)] * (d * len(points))
        for k in range(d):
            diff = Fraction(points[a][k]) - Fraction(points[b][k])  # never int / int (a float)
            row[d * a + k] = diff
            row[d * b + k] = -diff
        rows.append(row)
    return _rank(rows)


def _analyze(d, scene, *extra, timeout=20):
    r = h.flex("analyze", scene, "--exact", "--json", *extra, cwd=d, timeout=timeout)
    return r


def _json(r, what):
    h.check(r.rc == 0, "%s: expected exit 0, got %r" % (what, r))
    try:
        return json.loads(r.out)
    except ValueError:
        raise h.Fail("%s: stdout is not JSON: %s" % (what, h.tail(r.out)))


def _triangle(y3):
    """A triangle (0,0), (1,1/2), (2, y3): collinear exactly when y3 == 1."""
    return ("[system]\ntype = \"framework\"\nvertices = [[0, 0], [1, 0.5], [2, %s]]\n"
            "edges = [[1, 2], [2, 3], [1, 3]]\n" % y3)


_NEAR_ONE = Fraction(10 ** 25 + 1, 10 ** 25)  # 1.0000000000000000000000001: its double is 1


def _expect_rank(r, want, what):
    j = _json(r, what)
    h.check(j.get("exact") is True, "%s: not an exact analysis: %s" % (what, h.tail(r.out)))
    h.check(j.get("rigidity_rank") == want,
            "%s: exact rank %r, the rationals written have rank %d" % (what, j.get("rigidity_rank"), want))
    return j


# ----------------------------------------------------------------------------------------------
# 1. the exponent's spelling never changes the number


def probe_exact_exponent_spellings():
    d = h.mkdir("r4_exact_exponent")
    want = framework_rank([(0, 0), (1, Fraction(1, 2)), (2, _NEAR_ONE)], [(0, 1), (1, 2), (0, 2)])
    h.check(want == 3, "oracle: the triangle is not collinear")
    # The same number in TOML's spellings: 5 exponent digits was read exactly, 6 or more fell
    # back to the double (1.0: a collinear triangle, a false proof of flexibility).
    for i, y in enumerate(["1.0000000000000000000000001e00000", "1.0000000000000000000000001e000000",
                           "1.0000000000000000000000001E+0000000000", "1.0000000000000000000000001e-000000000000",
                           "10.000000000000000000000001e-0_000_001", "1_0.000000000000000000000001E-00000001",
                           "0.00010000000000000000000000001e+000000004"]):
        scene = h.write(d + "/s%d.toml" % i, _triangle(y))
        _expect_rank(_analyze(d, scene), want, "y3 = %s" % y)


def probe_exact_exponent_bulk_array():
    # The same through the fast reader of large arrays (>= 16 KB): 800 pinned vertices after the
    # triangle (no variables); the triangle's rank decides.
    d = h.mkdir("r4_exact_bulk")
    rows = ["[0, 0]", "[1, 0.5]", "[2, 1.0000000000000000000000001e-0000000]"]
    rows += ["[%d.25, %d.5]" % (10 + i, 20 + i % 7) for i in range(800)]
    text = ("[system]\ntype = \"framework\"\nvertices = [\n  " + ",\n  ".join(rows) + ",\n]\n"
            "edges = [[1, 2], [2, 3], [1, 3]]\npinned = [%s]\n" % ", ".join(str(4 + i) for i in range(800)))
    h.check(len(text) > 16 * 1024, "the array is not large enough for the bulk reader")
    scene = h.write(d + "/s.toml", text)
    _expect_rank(_analyze(d, scene), 3, "a bulk vertices array")


def probe_exact_exponent_beyond_range_refused():
    d = h.mkdir("r4_exact_range")
    # 1e-200000 became 0 (a coincident or collinear point, a false proof); beyond the exact mode's
    # numbers it is refused at its place, exit 1.
    for i, y in enumerate(["1e-200000", "1e-00000000000000200000", "-7.5E-0000000000400000",
                           "3e-99999999999999999999999", "1.5e-1_000_000"]):
        scene = h.write(d + "/s%d.toml" % i, "[system]\ntype = \"framework\"\nvertices = [[0, 0], [2, 0], [1, %s]]\n"
                        "edges = [[1, 2], [2, 3], [1, 3]]\n" % y)
        r = _analyze(d, scene)
        h.expect_rc(r, 1, "coordinate %s in exact mode" % y)
        h.check(re.search(rb"s%d\.toml:3:\d+:" % i, r.err) is not None,
                "coordinate %s: the error does not name s%d.toml:3:COLUMN: %s" % (y, i, h.tail(r.err)))
        h.check(b"limit" in r.err or b"too large" in r.err,
                "coordinate %s: the error does not say it is too large: %s" % (y, h.tail(r.err)))


def probe_exact_set_value_read_exactly():
    # A --set value has its text: read exactly too (it was the double's shortest decimal, 1).
    d = h.mkdir("r4_exact_set")
    scene = h.write(d + "/s.toml", _triangle("1"))
    want = framework_rank([(0, 0), (1, Fraction(1, 2)), (2, _NEAR_ONE)], [(0, 1), (1, 2), (0, 2)])
    for y in ["1.0000000000000000000000001", "1.0000000000000000000000001e-0000000"]:
        r = _analyze(d, scene, "--set", "system.vertices=[[0, 0], [1, 0.5], [2, %s]]" % y)
        _expect_rank(r, want, "--set y3 = %s" % y)
    r = _analyze(d, scene, "--set", "system.vertices=[[0, 0], [1, 0.5], [2, 1e-0000300000]]")
    h.expect_rc(r, 1, "--set with a coordinate beyond the exact mode's numbers")


# ----------------------------------------------------------------------------------------------
# 2. rational expressions: bounded before every operation, never an abort


def probe_exact_expression_power_bounded():
    d = h.mkdir("r4_exact_power")
    for i, expr in enumerate(["(((1/10)^10000)^10000)^10000", "((1/10)^10000)^10000", "(2/3)^-300000",
                              "((7^90000) * (7^90000))", "1 + (5^-60000 - 3^90000)", "((10^9999)^9999)^-9999"]):
        scene = h.write(d + "/s%d.toml" % i,
                        "[system]\ntype = \"framework\"\nvertices = [[0, 0], [1, 0], [2, \"%s\"]]\n"
                        "edges = [[1, 2], [2, 3], [1, 3]]\n" % expr)
        r = _analyze(d, scene, timeout=10)
        h.expect_rc(r, 1, "coordinate \"%s\" in exact mode" % expr)
        h.check(r.dt < 5, "coordinate \"%s\": %.1f s before the refusal" % (expr, r.dt))
        h.check(re.search(rb"s%d\.toml:3:\d+:" % i, r.err) is not None and b"limit" in r.err,
                "coordinate \"%s\": no position or no limit in %s" % (expr, h.tail(r.err)))
        # Without --exact the double evaluator takes it (0, or refused): never a signal, no hang.
        r = h.flex("analyze", scene, "--json", cwd=d, timeout=10)
        h.check(r.rc in (0, 1), "coordinate \"%s\" in double mode: %r" % (expr, r))


def probe_exact_expression_within_limit():
    # Large but sensible numbers still work: 2^-100000 above the x axis is not collinear.
    d = h.mkdir("r4_exact_power_ok")
    scene = h.write(d + "/s.toml", "[system]\ntype = \"framework\"\n"
                    "vertices = [[0, 0], [1, \"1/2\"], [2, \"1 + 2^-100000\"]]\n"
                    "edges = [[1, 2], [2, 3], [1, 3]]\n")
    _expect_rank(_analyze(d, scene, timeout=20), 3, "y3 = 1 + 2^-100000")


# ----------------------------------------------------------------------------------------------
# 3. lengths and radii exact


def probe_exact_lengths_rational():
    d = h.mkdir("r4_exact_lengths")
    pts = [(Fraction(0), Fraction(0)), (Fraction(3, 10), Fraction(0)), (Fraction(0), Fraction(2, 5))]
    edges = [(0, 1), (1, 2), (0, 2)]
    want = framework_rank(pts, edges)
    cases = [
        ('[[0, 0], ["3/10", 0], [0, "2/5"]]', '["3/10", "1/2", "2/5"]'),
        ('[[0, 0], [0.3, 0], [0, 0.4]]', '[0.3, 0.5, 0.4]'),
        ('[[0, 0], [0.3, 0], [0, 0.4]]', '[3e-0000001, 0.5, "4/10"]'),
    ]
    for i, (verts, lengths) in enumerate(cases):
        scene = h.write(d + "/s%d.toml" % i, "[system]\ntype = \"framework\"\nvertices = %s\n"
                        "edges = [[1, 2], [2, 3], [1, 3]]\nlengths = %s\n" % (verts, lengths))
        j = _expect_rank(_analyze(d, scene), want, "lengths %s" % lengths)
        h.check(j.get("inf_rigid") is True, "lengths %s: the 3-4-5 triangle not proved inf. rigid" % lengths)
    # A degenerate (collinear) triangle with its lengths: rank 2, one stress.
    scene = h.write(d + "/c.toml", "[system]\ntype = \"framework\"\nvertices = [[0, 0], [0.1, 0], [0.3, 0]]\n"
                    "edges = [[1, 2], [2, 3], [1, 3]]\nlengths = [0.1, 0.2, 0.3]\n")
    want = framework_rank([(0, 0), (Fraction(1, 10), 0), (Fraction(3, 10), 0)], edges)
    j = _expect_rank(_analyze(d, scene), want, "the collinear triangle with lengths")
    h.check(j.get("stress_dim") == 1, "the collinear triangle: stress_dim %r, not 1" % j.get("stress_dim"))
    # Lengths that do not hold exactly are refused at their place, never analysed.
    scene = h.write(d + "/off.toml", "[system]\ntype = \"framework\"\n"
                    "vertices = [[0, 0], [\"3/10 + 10^-40\", 0], [0, 0.4]]\n"
                    "edges = [[1, 2], [2, 3], [1, 3]]\nlengths = [0.3, 0.5, 0.4]\n")
    r = _analyze(d, scene)
    h.expect_rc(r, 1, "lengths that the rational coordinates do not have")
    h.check(b"off.toml:" in r.err, "no file named: %s" % h.tail(r.err))


def probe_exact_packing_radius():
    d = h.mkdir("r4_exact_packing")
    sq = [(0, 0), (Fraction(1, 5), 0), (Fraction(1, 5), Fraction(1, 5)), (0, Fraction(1, 5))]
    contacts = [(0, 1), (1, 2), (2, 3), (0, 3)]
    want = framework_rank(sq, contacts)
    for i, radius in enumerate(["radius = 0.1", "radii = [0.1, 0.1, 0.1, 0.1]", 'radius = "1/10"',
                                "radii = [1e-0000001, \"1/10\", 0.1, 0.10]"]):
        scene = h.write(d + "/s%d.toml" % i, "[system]\ntype = \"sphere_packing\"\n"
                        "vertices = [[0, 0], [0.2, 0], [0.2, 0.2], [0, 0.2]]\n%s\n" % radius)
        j = _expect_rank(_analyze(d, scene), want, "a square of disks, %s" % radius)
        h.check(j.get("nontrivial_inf_flexes") == 1 and j.get("stress_dim") == 0,
                "a square of 4 disks: %r nontrivial flexes, %r stresses (want 1, 0)"
                % (j.get("nontrivial_inf_flexes"), j.get("stress_dim")))
    # Three collinear disks: 2 contacts, rank 2.
    scene = h.write(d + "/line.toml", "[system]\ntype = \"sphere_packing\"\n"
                    "vertices = [[0, 0], [0.2, 0], [0.4, 0]]\nradius = 0.1\n")
    _expect_rank(_analyze(d, scene), framework_rank([(0, 0), (Fraction(1, 5), 0), (Fraction(2, 5), 0)],
                                                    [(0, 1), (1, 2)]), "three disks in a row")


# ----------------------------------------------------------------------------------------------
# 4. Python: every real converted exactly


_PY_TRIANGLE = r"""
import decimal, fractions, sys
import numpy as np
import flexure
def rank(vertices):
    a = flexure.framework(vertices, [[0, 1], [1, 2], [0, 2]]).analyze(exact=True)
    assert a.exact, "not exact"
    return a.rigidity_rank
D = decimal.Decimal
out = []
# 1 + 10^-25 (Decimal), 1 + 2^-60 (long double): not collinear, though their doubles are.
out.append(rank([[0, 0], [1, D("0.5")], [2, D("1.0000000000000000000000001")]]))
out.append(rank([[D(0), D(0)], [D(1), D("0.5")], [D(2), D("100000000000000000000000001E-26")]]))
ld = np.array([[0, 0], [1, 0.5], [2, 1]], dtype=np.longdouble)
ld[2, 1] += np.longdouble(2) ** -60
out.append(rank(ld) if ld[2, 1] != 1 else 3)
mixed = [[0, 0], [1, 0.5], [2, ld[2, 1]]]
out.append(rank(mixed) if ld[2, 1] != 1 else 3)
# Fraction of 1000-digit integers: taken, exactly.
F = fractions.Fraction
out.append(rank([[0, 0], [1, 0], [0, F(10**1000 + 1, 10**1000)]]))
out.append(rank([[0, 0], [1, F(1, 2)], [2, F(10**400 + 1, 10**400)]]))
# and collinear ones stay collinear
out.append(rank([[0, 0], [1, D("0.5")], [2, D("1.000")]]))
print(out)
"""


def probe_exact_python_reals():
    if not h.PYTHONPATH:
        return
    d = h.mkdir("r4_exact_python")
    r = h.run_py(_PY_TRIANGLE, d, timeout=60)
    h.expect_rc(r, 0, "Python exact reals")
    h.check(r.out.strip().splitlines()[-1:] == [b"[3, 3, 3, 3, 3, 3, 2]"],
            "Python: the exact ranks of triangles given as Decimal, long double and Fraction are %s, "
            "want [3, 3, 3, 3, 3, 3, 2]" % h.tail(r.out))


HEAVY = []
LIGHT = [probe_exact_exponent_spellings, probe_exact_exponent_bulk_array, probe_exact_exponent_beyond_range_refused,
         probe_exact_set_value_read_exactly, probe_exact_expression_power_bounded,
         probe_exact_expression_within_limit, probe_exact_lengths_rational, probe_exact_packing_radius,
         probe_exact_python_reals]
