"""Hostile input, fourth round (issue 62): bounded exact work, and GMP and FLINT never abort.
Expectations from the contract (README, docs/exact.md, issue 62), never from what the binary
does: the exact mode's time and memory are estimated before the work starts, and work beyond
`[analysis] exact_budget` (CPU seconds, default 60) or beyond the memory the process can have
is refused at once with the estimate, the budget and how to raise it (exit 1); a raised budget
lets the work run; Ctrl-C stops `analyze(exact=True)` in Python within a second; an exact
analysis under a memory cap ends with exit 0 or with exit 1 and a message about memory, nothing
on stdout then, never a signal (FLINT printed its message on stdout and aborted; GMP aborted)."""
import random
import time

import __main__ as h


def _random_framework(n, seed, per_vertex=2.0, digits=4):
    """n vertices at random 4-digit decimals, per_vertex * n distinct random bars (flexible,
    with stresses: the exact rank needs FLINT's dense elimination)."""
    rnd = random.Random(seed)
    V = [[round(rnd.random(), digits), round(rnd.random(), digits)] for _ in range(n)]
    E = set()
    while len(E) < int(per_vertex * n):
        a, b = rnd.randrange(n), rnd.randrange(n)
        if a != b:
            E.add((min(a, b) + 1, max(a, b) + 1))
    return V, sorted(E)


def _scene(n, seed, analysis=""):
    V, E = _random_framework(n, seed)
    return ('title = "random %d"\n[system]\ntype = "framework"\nvertices = [%s]\nedges = [%s]\n%s'
            % (n, ",".join("[%r,%r]" % tuple(v) for v in V), ",".join("[%d,%d]" % e for e in E),
               ("[analysis]\n" + analysis + "\n") if analysis else ""))


def probe_budget_exact_refused_with_estimate():
    d = h.mkdir("r4_budget_refused")
    # the case: 900 vertices, 31 KB, 353 s and 2.9 GB before
    big = h.write(d + "/r900.toml", _scene(900, 62))
    t0 = time.time()
    r = h.flex("analyze", big, "--exact", "--json", cwd=d, timeout=30)
    dt = time.time() - t0
    h.expect_rc(r, 1, "analyze --exact of a random 900-vertex framework (default budget)")
    err = r.err.decode(errors="replace")
    h.check(dt < 10, "the refusal came after %.1f s: it must come before the work" % dt)
    h.check(r.out == b"", "stdout on a refusal: %r" % h.tail(r.out))
    h.check("r900.toml" in err, "the message does not name the file: %r" % err[-400:])
    h.check("exact_budget" in err and "CPU" in err and "memory" in err,
            "the message says neither the estimate (CPU, memory) nor how to raise the budget: %r" % err[-400:])
    # a budget in the scene refuses a smaller case too, and --set raises it
    small = h.write(d + "/r120.toml", _scene(120, 5, "exact_budget = 0.001"))
    r = h.flex("analyze", small, "--exact", cwd=d, timeout=20)
    h.expect_rc(r, 1, "analyze --exact of a 120-vertex framework with exact_budget = 0.001")
    err = r.err.decode(errors="replace")
    h.check("exact_budget" in err and "0.001" in err, "the refusal does not say the budget: %r" % err[-400:])
    r = h.flex("analyze", small, "--exact", "--json", "--set", "analysis.exact_budget=100", cwd=d, timeout=30)
    h.expect_rc(r, 0, "analyze --exact --set analysis.exact_budget=100 of the 120-vertex framework")
    h.check(b'"exact": true' in r.out, "no exact analysis in the JSON: %r" % h.tail(r.out))
    for bad in ("0", "-5", "nan", "abc"):
        r = h.flex("analyze", small, "--exact", "--set", "analysis.exact_budget=" + bad, cwd=d, timeout=20)
        h.expect_rc(r, 1, "--set analysis.exact_budget=%s" % bad)
        h.check(b"exact_budget" in r.err, "exact_budget=%s: the message does not name the key: %r"
                % (bad, h.tail(r.err)))


PY_EXACT = r'''
import sys, time, random
import flexure
n = %d
rnd = random.Random(62)
V = [[round(rnd.random(), 4), round(rnd.random(), 4)] for _ in range(n)]
E = set()
while len(E) < 2 * n:
    a, b = rnd.randrange(n), rnd.randrange(n)
    if a != b:
        E.add((min(a, b), max(a, b)))
s = flexure.framework(V, sorted(E))
print("start", flush=True)
t = time.time()
try:
    s.analyze(exact=True, exact_budget=10000)
    print("done %%.3f" %% (time.time() - t), flush=True)
except KeyboardInterrupt:
    print("interrupted %%.3f" %% (time.time() - t), flush=True)
    sys.exit(0)
'''


def probe_budget_python_ctrl_c_exact():
    d = h.mkdir("r4_budget_ctrl_c")
    # 500 vertices: FLINT's dense elimination takes 10 s and more (one call before)
    p, lines, t = h.grid_child(d, PY_EXACT % 500)

    def err():
        return h.grid_err(d)
    try:
        ts, _ = h.wait_line(lines, "start", 20)
        h.check(ts, "the framework was not built within 20 s (%s)" % err())
        time.sleep(2.5)  # the double analysis, then into the exact elimination
        h.check(p.poll() is None, "the child ended before the signal (%s; %s)" % (lines, err()))
        late = h.interrupt_child(p, t, lines, 10.0, err)
        h.check(late <= 1.0, "KeyboardInterrupt came %.2f s after SIGINT" % late)
    finally:
        h.killgroup(p)
        p.wait()
        t.join(2)


def probe_budget_exact_under_memory_cap():
    d = h.mkdir("r4_budget_memcap")
    # 80 vertices: the dense elimination, the bases and the second-order step run (about 1 s);
    # under the caps below the allocation that fails is one of GMP's or FLINT's (seen in gdb)
    scene = h.write(d + "/r80.toml", _scene(80, 7))
    # the process's own size first (the cap is on the address space)
    base = h.flex("analyze", scene, "--json", cwd=d, timeout=30)
    h.expect_rc(base, 0, "analyze of the 80-vertex framework")
    problems = []
    # caps from too small to start up to enough: every run ends with 0, or 1 and a message
    # about memory with nothing on stdout, never a signal, never FLINT's message on stdout
    for mb in (60, 80, 100, 120, 200):
        r = h.run([h.FLEXURE, "analyze", scene, "--exact", "--json"], d, timeout=30, mem=mb << 20,
                  allow_signal=True)
        err = r.err.decode(errors="replace")
        if r.rc < 0:
            problems.append("%d MB: killed by %s (%s)" % (mb, h.signame(r.rc), err[-200:]))
        elif r.rc == 0:
            if b'"exact": true' not in r.out:
                problems.append("%d MB: exit 0 without the exact analysis" % mb)
        elif r.rc == 1:
            if r.out:
                problems.append("%d MB: stdout on failure: %r" % (mb, h.tail(r.out, 120)))
            if "memory" not in err:
                problems.append("%d MB: exit 1 without a message about memory: %r" % (mb, err[-200:]))
        else:
            problems.append("%d MB: exit %d (%s)" % (mb, r.rc, err[-200:]))
        if b"FLINT" in r.out or b"GNU MP" in r.out:
            problems.append("%d MB: FLINT/GMP's message on stdout" % mb)
    h.check(not problems, "; ".join(problems))


HEAVY = [probe_budget_python_ctrl_c_exact, probe_budget_exact_under_memory_cap]
LIGHT = [probe_budget_exact_refused_with_estimate]
