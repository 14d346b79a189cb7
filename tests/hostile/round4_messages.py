"""Hostile input, fourth round (issue 62): wrong exit codes and misleading messages.
Expectations from the contract (README: exit 1 for wrong input, 3 only for an output that could
not be written; messages name file, line and column; docs/scene-format.md; issue 62), never from
what the binary does."""
import re

import __main__ as h          # run.py: h.flex, h.run, h.run_py, h.mkdir, h.write,
                              # h.expect_rc, h.Fail, h.check, h.FLEXURE, h.ROOT, h.GiB

TRIANGLE = """[system]
type = "framework"
vertices = [[0,0],[1,0],[0,1]]
edges = [[1,2],[2,3],[1,3]]
"""

MECHANISM = """[system]
type = "framework"
vertices = [[0,0],[1,0],[1,1],[0,1]]
edges = [[1,2],[2,3],[3,4],[1,4]]
pinned = [1,2]
"""


def err(r):
    return r.err.decode("utf-8", "replace")


# 1. A stress beyond the basis is wrong input (exit 1), not an output that could not be written.
def probe_msg_stress_beyond_basis():
    d = h.mkdir("r4_msg_stress_beyond")
    tri = h.write(d + "/tri.toml", TRIANGLE)
    cases = [("tri", [tri, "--stress", "0"]),                            # no stress at all
             ("k4_edge", ["k4_edge", "--stress", "1"]),                   # one stress: 0 only
             ("k4_edge --set", ["k4_edge", "--set", "render.stress=7"]),
             ("scene key", [h.write(d + "/s.toml", TRIANGLE + "[render]\nstress = 12\n")])]
    for i, (what, args) in enumerate(cases):
        out = "%s/out%d.svg" % (d, i)
        r = h.flex("render", *args, "-o", out, cwd=d, timeout=30)
        h.expect_rc(r, 1, "render %s with a stress beyond the basis" % what)
        h.check("stress" in err(r) and "could not be written" not in err(r),
                "%s: the message should name the stress, not an output: %r" % (what, err(r)[-300:]))
        h.check(not __import__("os").path.exists(out), "%s: an output was written" % what)


# 2. render.stress = -1 is the documented "none" (docs/scene-format.md: default -1: none).
def probe_msg_stress_minus_one_is_none():
    d = h.mkdir("r4_msg_stress_none")
    tri = h.write(d + "/tri.toml", TRIANGLE)
    r = h.flex("render", tri, "--set", "render.stress=-1", "-o", d + "/a.svg", cwd=d, timeout=30)
    h.expect_rc(r, 0, "render --set render.stress=-1 (the documented none)")
    s = h.write(d + "/s.toml", TRIANGLE + "[render]\nstress = -1\n")
    r = h.flex("render", s, "-o", d + "/b.svg", cwd=d, timeout=30)
    h.expect_rc(r, 0, "[render] stress = -1 in the scene")
    r = h.flex("analyze", tri, "--set", "render.stress=-2", cwd=d, timeout=30)
    h.expect_rc(r, 1, "render.stress=-2 (below -1)")
    h.check("stress" in err(r), "the refusal of -2 should name the key: %r" % err(r)[-300:])


# 3. A length's pixels are range-checked before they become an integer.
def probe_msg_width_huge_length():
    d = h.mkdir("r4_msg_width")
    cases = [('width = "1e300in"', []), ('width = "1e400in"', []), ('height = "7e19pt"', []), ('width = "9.3e18px"', []),
             ('width = "80cm"\ndpi = 2400', []), ("", ["--set", 'render.width="1e200mm"']),
             ("", ["--set", 'render.height="-1e300in"'])]
    for i, (line, extra) in enumerate(cases):
        s = h.write("%s/s%d.toml" % (d, i), TRIANGLE + "[render]\n" + line + "\n")
        r = h.flex("analyze", s, *extra, cwd=d, timeout=30)
        e = err(r)
        h.expect_rc(r, 1, "a size of %s" % (line or extra[-1]))
        h.check("9223372036854775808" not in e and "2147483648" not in e,
                "%s: an integer overflow in the message: %r" % (line or extra[-1], e[-300:]))
        h.check(re.search(r"(width|height)", e) is not None, "the message should name the key: %r" % e[-300:])
        m = re.search(r"is (-?[0-9.e+]+) px", e)
        if m:
            h.check(abs(float(m.group(1))) > 8192, "%s: the size said is %s px: %r" % (line, m.group(1), e[-300:]))


# 4. Caption vertex numbers: the number written, or refused with its column.
def probe_msg_caption_index_wraps():
    d = h.mkdir("r4_msg_caption")
    for i, (field, col) in enumerate([("{distance:4294967297:2}", 22), ("{distance:1:18446744073709551618}", 24),
                                      ("{distance:2:-4294967295}", 24), ("{distance:99999999999999999999999:1}", 22)]):
        s = h.write("%s/s%d.toml" % (d, i), TRIANGLE + "[render]\ncaption = \"" + field + "\"\n")
        r = h.flex("analyze", s, cwd=d, timeout=30)
        h.expect_rc(r, 1, "caption %s (3 vertices)" % field)
        e = err(r)
        h.check("s%d.toml:6:%d:" % (i, col) in e,
                "caption %s: the message should point at line 6, column %d: %r" % (field, col, e[-300:]))
        h.check("out of range" in e, "caption %s: %r" % (field, e[-300:]))


# 5. Python: sample numbers are integers, never truncated.
def probe_msg_python_branch_samples_not_truncated():
    d = h.mkdir("r4_msg_python")
    code = r'''
import numpy as np, flexure
s = flexure.framework([[0,0],[1,0],[1,1],[0,1]], [[0,1],[1,2],[2,3],[0,3]], pinned=[0,1])
bad = []
def refused(what, fn, arg):
    try:
        fn()
    except (TypeError, ValueError) as e:
        if arg not in str(e):
            bad.append("%s: the error does not name %s: %s" % (what, arg, e))
        return
    except Exception as e:
        bad.append("%s: %s: %s" % (what, type(e).__name__, e))
        return
    bad.append(what + ": accepted")
refused("branch=(267.9, 3)", lambda: s.track(steps=3, branch=(267.9, 3)), "branch[0]")
refused("branch=(1, 0.5)", lambda: s.track(steps=3, branch=(1, 0.5)), "branch[1]")
refused("branch=(True, 0)", lambda: s.track(steps=3, branch=(True, 0)), "branch[0]")
refused("samples=[0.5, 1]", lambda: s.render("f.png", samples=[0.5, 1]), "samples[0]")
refused("samples=[0, 2.0]", lambda: s.render("g.png", samples=[0, 2.0]), "samples[1]")
refused("sample=1.5", lambda: s.render("h.png", sample=1.5), "sample")
p = s.track(steps=3)
refused("Path.render samples=[1, 1.7]", lambda: p.render("i.png", samples=[1, 1.7]), "samples[1]")
# numpy integers are integers
p = s.track(steps=3, branch=(np.int64(0), np.int32(0)))
print("BAD" if bad else "OK", bad)
'''
    r = h.run_py(code, d, timeout=60)
    h.expect_rc(r, 0, "python child")
    h.check(r.out.startswith(b"OK"), "Python: %s %s" % (r.out.decode()[-600:], err(r)[-300:]))


# 6. Distinct vertices are not "coincident"; a closeness refusal says which tolerance decided.
def probe_msg_not_coincident_at_large_scale():
    d = h.mkdir("r4_msg_far_apart")
    for i, verts in enumerate(["[[0,0],[1,1],[1e17,0]]", "[[1e17,1e17],[1e17,1.00000000000000016e17],[0,0]]",
                               "[[0,0,0],[1,1,1],[3e16,0,0]]"]):
        s = h.write("%s/s%d.toml" % (d, i), TRIANGLE.replace("[[0,0],[1,0],[0,1]]", verts))
        r = h.flex("analyze", s, cwd=d, timeout=30)
        e = err(r)
        if r.rc == 0:
            continue  # analysed: not called coincident
        h.expect_rc(r, 1, "vertices %s" % verts)
        h.check("coincid" not in e, "vertices %s are distinct doubles, called coincident: %r" % (verts, e[-300:]))
        h.check("1e-12" in e and "extent" in e,
                "vertices %s: the refusal should say which tolerance decided: %r" % (verts, e[-300:]))
    # Equal points still coincide.
    s = h.write(d + "/eq.toml", TRIANGLE.replace("[[0,0],[1,0],[0,1]]", "[[5,5],[5,5],[0,1]]"))
    r = h.flex("analyze", s, cwd=d, timeout=30)
    h.expect_rc(r, 1, "two equal vertices")
    h.check("coincide" in err(r), "equal vertices: %r" % err(r)[-300:])


# 7. Certificate reasons say what is true.
def probe_msg_certificate_one_sample():
    d = h.mkdir("r4_msg_cert_one")
    for i, body in enumerate([MECHANISM + "[motion]\nsteps = 0\n",
                              MECHANISM.replace("[0,1]]\npinned", "[0,1]]\npinned") + "[motion]\nsteps = 0\nstep_size = 0.3\n"]):
        s = h.write("%s/s%d.toml" % (d, i), body)
        r = h.flex("track", s, "--certify", "-o", "%s/p%d.json" % (d, i), cwd=d, timeout=30)
        h.expect_rc(r, 0, "track --certify of a one-sample path")
        j = __import__("json").load(open("%s/p%d.json" % (d, i)))
        reason = (j.get("certificate") or {}).get("reason", "")
        h.check("each step" not in reason and "step certified" not in reason,
                "a one-sample path has no steps, its certificate says %r" % reason)
        h.check("sample" in reason, "the certificate should say what was certified: %r" % reason)


def probe_msg_certificate_bound_not_distance():
    d = h.mkdir("r4_msg_cert_bound")
    s = h.write(d + "/s.toml", "[system]\ntype = \"framework\"\nvertices = [[0,0],[1e16,0],[1e16,1e16],[0,1e16]]\n"
                "edges = [[1,2],[2,3],[3,4],[1,4]]\npinned = [1,2]\n[motion]\nsteps = 4\nstep_size = 1e14\n")
    r = h.flex("track", s, "--certify", "-o", d + "/p.json", cwd=d, timeout=60)
    h.expect_rc(r, (0, 2), "track --certify of a four-bar at scale 1e16")
    text = r.out.decode("utf-8", "replace") + err(r)
    h.check("singular point: the sliced Jacobian is singular" not in text,
            "a regular four-bar at scale 1e16 is called singular: %r" % text[-400:])
    h.check(not re.search(r"is about [0-9.e+-]+ from the curve", text),
            "a bound is called a distance: %r" % text[-400:])
    # An exact start (integer coordinates, residual 0) of an ill-conditioned ladder beyond the
    # dense test's size: the sparse norm test's bound is not the sample's distance from the curve.
    for cells in (499, 350):
        pts, edges = [], []
        for i in range(cells + 1):
            pts += [[0, i], [1, i]]
        for i in range(cells):
            edges += [[2 * i, 2 * i + 2], [2 * i + 1, 2 * i + 3], [2 * i + 2, 2 * i + 3]] + ([[2 * i, 2 * i + 3]] if i else [])
        s = h.write("%s/ladder%d.toml" % (d, cells), "index_base = 0\n[system]\ntype = \"framework\"\nvertices = %s\n"
                    "edges = %s\npinned = [0,1]\n[motion]\nsteps = 0\n" % (pts, edges))
        r = h.flex("track", s, "--certify", "-o", "%s/ladder%d.json" % (d, cells), cwd=d, timeout=60)
        h.expect_rc(r, (0, 2), "track --certify of a ladder of %d cells" % cells)
        text = r.out.decode("utf-8", "replace") + err(r)
        h.check(not re.search(r"(is|be) about [0-9.e+-]+ from the curve", text),
                "ladder %d: a bound is called a distance: %r" % (cells, text[-400:]))


# 8. A contraction's certificate: a bounded human line, the whole in the JSON.
def probe_msg_contraction_certify_line():
    d = h.mkdir("r4_msg_contraction")
    s = h.write(d + "/s.toml", MECHANISM + "[motion]\ncontract_edge = [3,4]\ntarget_length = 0.2\nstep_size = 0.0005\n")
    r = h.flex("track", s, "--certify", "-o", d + "/p.json", cwd=d, timeout=60)
    h.expect_rc(r, (0, 2), "track --certify of an edge contraction")
    longest = max((len(x) for x in r.out.split(b"\n")), default=0)
    h.check(longest <= 2000, "a stdout line of %d bytes" % longest)
    longest = max((len(x) for x in r.err.split(b"\n")), default=0)
    h.check(longest <= 2000, "a stderr line of %d bytes" % longest)


# 9. Messages quote a bounded excerpt of what was written.
def probe_msg_long_expression_excerpt():
    d = h.mkdir("r4_msg_excerpt")
    big = "1+" * 300000 + "foo"
    cases = [TRIANGLE.replace("[[0,0],[1,0],[0,1]]", '[[0,0],[1,0],[0,"%s"]]' % big),
             TRIANGLE.replace("[[0,0],[1,0],[0,1]]", '[[0,0],[1,0],[0,"%s"]]' % ("(" * 300000 + "1")),
             TRIANGLE + '[render]\ncaption = "{%s}"\n' % ("x" * 500000),
             TRIANGLE + '[render]\nbackground = "%s"\n' % ("y" * 500000),
             TRIANGLE + '[render]\nwidth = "%sin"\n' % ("9" * 400000),
             TRIANGLE.replace("[[0,0],[1,0],[0,1]]", '[[0,0],[1,0],[0,"%s"]]' % ("1+" * 100000 + "sqrt(2)"))]
    for i, text in enumerate(cases):
        s = h.write("%s/s%d.toml" % (d, i), text)
        r = h.flex("analyze", s, *(["--exact"] if "sqrt" in text else []), cwd=d, timeout=30)
        h.expect_rc(r, 1, "case %d (a long value)" % i)
        h.check(len(r.err) < 2000, "case %d: a %d-byte message: %r" % (i, len(r.err), err(r)[:300]))
        h.check(("s%d.toml:" % i) in err(r), "case %d: the message names no file: %r" % (i, err(r)[:300]))


# 10. A [sweep] with too many combinations is refused before any axis is made.
def probe_msg_sweep_product_before_axes():
    d = h.mkdir("r4_msg_sweep")
    for i, sweep in enumerate(['"motion.seed" = "1..10000000"\n"motion.steps" = "1..1000"\n',
                               '"analysis.seed" = "linspace(1, 2, 9000000)"\n"motion.seed" = "0..200"\n',
                               '"motion.seed" = "1..10000000"\n"motion.steps" = [1,2,3,4,5,6,7,8,9,10,11,12,13,14,'
                               '15,16,17,18,19,20,21,22,23,24,25,26,27,28,29,30,31,32,33,34,35,36,37,38,39,40,41,'
                               '42,43,44,45,46,47,48,49,50,51,52,53,54,55,56,57,58,59,60,61,62,63,64,65,66,67,68,'
                               '69,70,71,72,73,74,75,76,77,78,79,80,81,82,83,84,85,86,87,88,89,90,91,92,93,94,95,'
                               '96,97,98,99,100,101]\n']):
        s = h.write("%s/s%d.toml" % (d, i), TRIANGLE + "[sweep]\n" + sweep)
        r = h.flex("sweep", "analyze", s, "-o", "%s/o%d.jsonl" % (d, i), cwd=d, timeout=30, mem=300 << 20)
        h.expect_rc(r, 1, "a [sweep] of more than 10^9 combinations")
        h.check("10^9 combinations" in err(r), "case %d: refused for another reason: %r" % (i, err(r)[-300:]))
        h.check(r.dt < 2.0, "case %d: refused after %.1f s (values made before the product was checked)" % (i, r.dt))


HEAVY = []
LIGHT = [probe_msg_stress_beyond_basis, probe_msg_stress_minus_one_is_none, probe_msg_width_huge_length,
         probe_msg_caption_index_wraps, probe_msg_python_branch_samples_not_truncated,
         probe_msg_not_coincident_at_large_scale, probe_msg_certificate_one_sample,
         probe_msg_certificate_bound_not_distance, probe_msg_contraction_certify_line,
         probe_msg_long_expression_excerpt, probe_msg_sweep_product_before_axes]
