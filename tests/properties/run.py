#!/usr/bin/python3
"""Property-based tests of flexure's rigidity analysis against independent oracles.

    PYTHONPATH=build/python /usr/bin/python3 tests/properties/run.py [--cases-per-family N] [--seed S]
    (or --pythonpath build/python; default: build/python next to this folder)

Every case is a system built by construction (families.py) with a known answer, disguised by a
random similarity (scale 1e-3..1e3, rotation or reflection, translation; or axis-aligned with
exact coordinates; or as built), a random relabelling of the vertices and a random order of the
constraints and of the vertices inside each. flexure analyses it (`System.analyze()`; every 20th
case also `flexure analyze SCENE --json` on a 1-based scene file, which must agree with Python),
and so does the numpy oracle in oracle.py, which shares no code with flexure: the constraint
equations of the paper's appendix B, their Jacobian's rank by SVD at a clear gap, the dimension
of the type's trivial motions (SPEC.md's groups applied to the points, pins respected), and a
small predictor-corrector tracker that decides whether the system leaves its trivial orbit.

Families: frameworks (2D/3D Henneberg minimally rigid, minus an edge, plus an edge, pinned,
random graphs, large and huge (sparse) ones, and special positions: collinear triangle, vertex
on a segment, parallelogram 4-bar, Dixon's K33, parallel-bar prisms, square grids), angular
(every angle of polygons: rectangles, squares, parallelograms, rhombi, trapezoids, regular,
convex, star-shaped, huge zigzags, 0-2 pins; planar polygons in 3D; rectangle grids; all angles
of triangulations; random angle sets in 2D and 3D), volume (2D/3D area/volume Henneberg, minus
and plus a simplex, complete hypergraphs, triangulated polygons, pinned), body_hinge (triangle
strips flat or not, tetrahedron chains, planar-quad and 5-point-body chains, triangle fans
around a vertex, flat fans, random bodies, pinned) and packing (2D disk chains, straight chains,
triangles, Henneberg clusters, triangular and square lattices, contacts within the tolerance,
3D sphere chains and tetrahedra).

The checks of a case:
  counts        rigidity_rank, trivial_inf_flexes, nontrivial_inf_flexes, stress_dim, variables,
                equations and inf_rigid equal the oracle's (a case whose oracle rank gap is not
                clear is skipped and counted)
  CONTRADICTION flexure says "rigid" (or prestress_stable / second_order_rigid true) but the
                tracker moves it off its trivial orbit at residual <= 1e-10 (relative); or
                flexure says "flexible" where the oracle finds it infinitesimally rigid
  known         the construction's answer (counts and verdict) holds for flexure; a verdict of
                "unknown" where the construction is flexible or rigid is INCOMPLETE: counted, not a
                false verdict, and a failure beyond --max-incomplete (2 %) of a family's cases.
                Generic constructions (random points) are flexible exactly when the oracle finds
                a nontrivial flex. If the oracle contradicts a construction that only holds at
                generic points, the sample was not generic and the case is skipped (counted);
                if it contradicts an exact one, that is an ORACLE failure.

Every failure prints the seed, the case number, a rerun command and a reproducer (the system as
a flexure constructor call with Python literals). --inject-bug replays the known bug (angular
parallelograms reported rigid and prestress stable) on flexure's answers, to show it is caught.
The last line is `N passed, N failed`; the exit status is 1 on any failure.
"""

import argparse
import collections
import os
import sys
import time
import traceback

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases-per-family", type=int, default=3000,
                    help="default 3000 (5 families: about 90 s of CPU on this 2-core machine)")
    ap.add_argument("--seed", type=int, default=20261127)
    ap.add_argument("--max-incomplete", type=float, default=0.02,
                    help="the share of a family's cases that may be 'unknown' where the construction knows the answer")
    ap.add_argument("--pythonpath", default=None, help="where the flexure module is (e.g. build/python)")
    ap.add_argument("--families", default=None, help="comma-separated subset of the families")
    ap.add_argument("--case", type=int, default=None, help="run only this case number (with --families)")
    ap.add_argument("--show", type=int, default=3, help="failures printed in full per failure class")
    ap.add_argument("-v", "--verbose", action="store_true")
    ap.add_argument("--cli-every", type=int, default=20,
                    help="every k-th case also goes through `flexure analyze SCENE --json` with a 1-based scene "
                         "file (0: never)")
    ap.add_argument("--flexure-exe", default=os.path.join(HERE, "..", "..", "build", "flexure"))
    ap.add_argument("--inject-bug", action="store_true",
                    help="self-test: make angular parallelograms look 'rigid' and check that the run fails")
    return ap.parse_args()


args = parse_args()
if args.pythonpath:
    sys.path.insert(0, os.path.abspath(args.pythonpath))
else:
    guess = os.path.join(HERE, "..", "..", "build", "python")
    if os.path.isdir(guess) and not os.environ.get("PYTHONPATH"):
        sys.path.insert(0, os.path.abspath(guess))

import numpy as np  # noqa: E402

import flexure  # noqa: E402
from families import FAMILIES, disguise  # noqa: E402
from oracle import Model  # noqa: E402

MAX_TRACKED = 400  # larger systems (the huge variants) rely on their construction's answer alone
COUNT_FIELDS = [("rigidity_rank", "rank"), ("trivial_inf_flexes", "trivial"),
                ("nontrivial_inf_flexes", "nontrivial"), ("stress_dim", "stress"),
                ("variables", "variables"), ("equations", "equations")]


def flexure_system(case):
    V = case.vertices.tolist()
    pinned = case.pinned or None
    if case.kind == "framework":
        return flexure.framework(V, case.keys["edges"], pinned)
    if case.kind == "angular_framework":
        return flexure.angular_framework(V, case.keys["angles"], pinned)
    if case.kind == "volume_hypergraph":
        return flexure.volume_hypergraph(V, case.keys["simplices"], pinned)
    if case.kind == "body_hinge":
        return flexure.body_hinge(V, case.keys["bodies"], pinned)
    if case.kind == "sphere_packing":
        return flexure.sphere_packing(V, radii=case.keys["radii"], pinned=pinned)
    raise ValueError(case.kind)


def oracle_model(case):
    k = case.keys
    if case.kind == "framework":
        return Model("framework", case.vertices, case.pinned, edges=k["edges"])
    if case.kind == "angular_framework":
        return Model("angular_framework", case.vertices, case.pinned, angles=k["angles"])
    if case.kind == "volume_hypergraph":
        return Model("volume_hypergraph", case.vertices, case.pinned, simplices=k["simplices"])
    if case.kind == "body_hinge":
        return Model("body_hinge", case.vertices, case.pinned, bodies=k["bodies"])
    if case.kind == "sphere_packing":
        return Model("sphere_packing", case.vertices, case.pinned, edges=k["edges"])
    raise ValueError(case.kind)


def packing_contacts(case, tol=1e-6):
    """The contact graph from the geometry (docs: |gap| <= tolerance * (r_i + r_j) touch), and
    whether some pair's gap is too close to the tolerance to tell (0.7 to 1.5 tolerances)."""
    P, R = case.vertices, np.asarray(case.keys["radii"])
    n = len(P)
    D = np.linalg.norm(P[:, None, :] - P[None, :, :], axis=2)
    S = R[:, None] + R[None, :]
    G = np.abs(D - S) / S
    iu = np.triu_indices(n, 1)
    g = G[iu]
    contacts = {(int(i), int(j)) for i, j, x in zip(iu[0], iu[1], g) if x <= tol}
    ambiguous = bool(np.any((g > 0.7 * tol) & (g < 1.5 * tol)))
    return contacts, ambiguous


def packing_valid(case):
    P0, R = case.vertices, np.asarray(case.keys["radii"])
    touching = {tuple(sorted(e)) for e in case.keys["edges"]}
    pairs = [(i, j) for i in range(len(P0)) for j in range(i + 1, len(P0)) if (i, j) not in touching]

    I = np.array([p[0] for p in pairs], dtype=int)
    J = np.array([p[1] for p in pairs], dtype=int)

    def valid(P):
        return bool(np.all(np.linalg.norm(P[I] - P[J], axis=1) >= R[I] + R[J])) if len(I) else True
    return valid


def inject_bug(case, fx):
    """--inject-bug: replay the known bug on flexure's answer (angular quadrilaterals with parallel
    opposite sides reported rigid and prestress stable), to show that the checks catch it."""
    if case.kind == "angular_framework" and len(case.vertices) == 4 and case.dim == 2:
        P = case.vertices
        a, b = P[1] - P[0], P[2] - P[3]
        if abs(a[0] * b[1] - a[1] * b[0]) <= 1e-9 * np.linalg.norm(a) * np.linalg.norm(b):
            fx = dict(fx, rigid="rigid", prestress_stable=True, reason="injected: prestress stable")
    return fx


def scene_toml(case):
    """The case as a scene file with the default index_base = 1."""
    def num(x):
        return repr(float(x))
    V = ", ".join("[" + ", ".join(num(c) for c in p) + "]" for p in case.vertices)
    lines = ["[system]", f'type = "{case.kind}"', f"vertices = [{V}]"]
    for key in ("edges", "angles", "simplices", "bodies"):
        if key in case.keys and not (key == "edges" and case.kind == "sphere_packing"):
            rows = ", ".join("[" + ", ".join(str(i + 1) for i in row) + "]" for row in case.keys[key])
            lines.append(f"{key} = [{rows}]")
    if case.kind == "sphere_packing":
        lines.append("radii = [" + ", ".join(num(r) for r in case.keys["radii"]) + "]")
    if case.pinned:
        lines.append("pinned = [" + ", ".join(str(i + 1) for i in case.pinned) + "]")
    return "\n".join(lines) + "\n"


class CliUnavailable(Exception):
    pass


def cli_analyze(case):
    import json
    import subprocess
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "case.toml")
        with open(path, "w") as fh:
            fh.write(scene_toml(case))
        for attempt in range(4):
            try:
                p = subprocess.run([args.flexure_exe, "analyze", path, "--json"], capture_output=True, text=True,
                                   timeout=120)
                break
            except OSError:  # the executable is being relinked by a build: wait for it
                if attempt == 3:
                    raise CliUnavailable()
                time.sleep(3)
        if p.returncode != 0:
            raise RuntimeError(f"exit {p.returncode}: {p.stderr.strip()[:300]}")
        return json.loads(p.stdout)


class Result:
    def __init__(self):
        self.failures = []  # (class, message)
        self.incomplete = None  # "unknown" where the construction knows the answer (not a false verdict)
        self.skipped = None
        self.notes = []
        self.verdict = None
        self.moved = False


def check_case(case, rng, via_cli=False):
    res = Result()
    model = oracle_model(case)
    if case.kind == "sphere_packing":
        contacts, ambiguous = packing_contacts(case)
        if ambiguous:
            res.skipped = "packing contacts ambiguous"
            return res, None, None, None
        if contacts != {tuple(sorted(e)) for e in case.keys["edges"]}:
            res.failures.append(("ORACLE", "the construction's contacts are not the geometry's"))
            return res, None, None, None
    orc = model.counts()
    if orc["trivial_in_kernel"] > 1e-8:
        res.failures.append(("ORACLE", f"oracle self-check: trivial flexes not in kernel ({orc['trivial_in_kernel']:.1e})"))
    if not orc["clear"]:
        res.skipped = (f"oracle rank gap unclear (kept {orc['sigma_kept_min']:.1e}, "
                       f"dropped {orc['sigma_dropped_max']:.1e})")
        return res, orc, None, None
    known = dict(case.known)
    if known.get("generic"):
        # generic realization: the Jacobian has locally constant rank, the realization space is a
        # manifold there, so the system is flexible exactly when a nontrivial flex exists
        known["verdict"] = "flexible" if orc["nontrivial"] > 0 else "rigid"
    for key in ("rank", "trivial", "nontrivial", "stress"):
        if key in known and known[key] != orc[key]:
            if known.get("exact"):
                res.failures.append(("ORACLE", f"oracle {key}={orc[key]} but the construction gives {known[key]}"))
            else:
                res.skipped = f"non-generic sample: oracle {key}={orc[key]}, construction {known[key]}"
                return res, orc, None, None

    try:
        a = flexure_system(case).analyze()
        fx = {k: a[k] for k in ("variables", "equations", "rigidity_rank", "trivial_inf_flexes",
                                 "nontrivial_inf_flexes", "stress_dim", "inf_rigid", "prestress_stable",
                                 "second_order_rigid", "rigid")}
        fx["reason"] = a["reason"] if "reason" in a else None
    except Exception as e:  # noqa: BLE001
        res.failures.append(("flexure raised", f"{type(e).__name__}: {e}"))
        return res, orc, None, None
    if via_cli:
        try:
            cj = cli_analyze(case)
            for k in ("variables", "equations", "rigidity_rank", "trivial_inf_flexes", "nontrivial_inf_flexes",
                      "stress_dim", "inf_rigid", "rigid"):
                if cj.get(k) != fx[k]:
                    res.failures.append(("CLI differs from Python", f"{k}: CLI (1-based scene) {cj.get(k)}, "
                                                                   f"Python {fx[k]}"))
        except CliUnavailable:
            res.notes.append("CLI unavailable (the executable could not be started)")
        except Exception as e:  # noqa: BLE001
            res.failures.append(("CLI failed", f"{type(e).__name__}: {e}"))
    if args.inject_bug:
        fx = inject_bug(case, fx)

    res.verdict = fx["rigid"]
    # (i) counts
    free = set(known.get("free_fields", []))
    for fk, ok in COUNT_FIELDS:
        if fk not in free and fx[fk] != orc[ok]:
            res.failures.append((f"count {fk}", f"{fk}: flexure {fx[fk]}, oracle {orc[ok]}"))
    if fx["inf_rigid"] != (orc["nontrivial"] == 0):
        res.failures.append(("count inf_rigid", f"inf_rigid: flexure {fx['inf_rigid']}, oracle {orc['nontrivial'] == 0}"))

    # (ii) contradictions
    track = None
    if orc["nontrivial"] > 0 and orc["variables"] <= MAX_TRACKED:
        valid = packing_valid(case) if case.kind == "sphere_packing" else None
        h = 0.01 if case.kind == "sphere_packing" else 0.015
        big = orc["variables"] > 200
        track = model.track(rng, orc["rank"], steps=2 if big else 4, h=h, valid=valid, max_basis=2 if big else 6)
        moved = track[0]
        res.moved = moved
        if moved:
            if fx["rigid"] == "rigid":
                res.failures.append(("CONTRADICTION rigid-but-moves",
                                     f"flexure says rigid ({fx['reason']}) but the oracle tracker moved it off the "
                                     f"trivial orbit: invariant change {track[1]:.2e} at residual {track[2]:.1e}"))
            if fx["prestress_stable"] is True:
                res.failures.append(("CONTRADICTION prestress-stable-but-moves",
                                     f"flexure says prestress_stable=true but the tracker moved it "
                                     f"(change {track[1]:.2e}, residual {track[2]:.1e})"))
            if fx["second_order_rigid"] is True:
                res.failures.append(("CONTRADICTION second-order-rigid-but-moves",
                                     f"flexure says second_order_rigid=true but the tracker moved it "
                                     f"(change {track[1]:.2e}, residual {track[2]:.1e})"))
        elif known.get("verdict") == "flexible":
            res.notes.append(f"oracle tracker inconclusive: {track[3]} (change {track[1]:.1e})")
    elif orc["nontrivial"] == 0 and fx["rigid"] == "flexible":
        res.failures.append(("CONTRADICTION flexible-but-inf-rigid",
                             f"flexure says flexible ({fx['reason']}) but the oracle finds it infinitesimally rigid"))

    # (iii) the construction's answer
    for key, fk in (("rank", "rigidity_rank"), ("trivial", "trivial_inf_flexes"),
                    ("nontrivial", "nontrivial_inf_flexes"), ("stress", "stress_dim")):
        if key in known and fk not in free and fx[fk] != known[key]:
            res.failures.append((f"known {fk}", f"construction: {fk}={known[key]}, flexure {fx[fk]}"))
    if "verdict" in known and fx["rigid"] != known["verdict"]:
        msg = f"construction: {known['verdict']}, flexure says {fx['rigid']!r} ({fx['reason']})"
        if fx["rigid"] == "unknown":
            # Not a false verdict (SPEC: "unknown" is an answer), but a missed one: counted, and a
            # failure when a family has more than --max-incomplete of them.
            res.incomplete = msg
        else:
            res.failures.append((f"WRONG VERDICT: {fx['rigid']!r} where the construction is {known['verdict']}", msg))
    return res, orc, fx, track


def fmt_case(fam, i, seed, case, res, orc, fx, track):
    lines = []
    for cls, msg in res.failures:
        lines.append(f"FAIL [{fam}/{case.variant}] seed={seed} case={i} ({cls}): {msg}")
    if fx is not None:
        lines.append("  flexure: " + ", ".join(f"{k}={fx[k]}" for k in fx if k != "reason") + f"; reason: {fx['reason']}")
    if orc is not None:
        lines.append("  oracle:  " + ", ".join(f"{k}={orc[k]}" for k in ("variables", "equations", "rank", "trivial",
                                                                         "nontrivial", "stress"))
                     + (f", tracker moved={track[0]} (change {track[1]:.2e}, residual {track[2]:.1e}, {track[3]})"
                        if track else ""))
    lines.append(f"  known:   {case.known}")
    lines.append(f"  rerun:   run.py --seed {seed} --families {fam} --case {i} -v")
    rep = f"{case.reproducer()}.analyze()"
    if len(rep) > 3000 and args.case is None:
        rep = rep[:600] + f" ... [{len(rep)} characters: the rerun command with --case prints it in full]"
    lines.append(f"  reproducer: {rep}")
    return "\n".join(lines)


def main():
    fams = list(FAMILIES) if not args.families else args.families.split(",")
    seed = args.seed
    print(f"flexure property tests: seed={seed} cases-per-family={args.cases_per_family} "
          f"module={os.path.dirname(flexure.__file__)}")
    t0 = time.process_time()
    w0 = time.time()
    passed = failed = 0
    classes = collections.OrderedDict()
    lines = []
    incomplete_examples = []
    for fi, fam in enumerate(fams):
        stats = collections.Counter()
        skip_reasons = collections.Counter()
        t_fx = 0.0
        rng_ids = [args.case] if args.case is not None else range(args.cases_per_family)
        for i in rng_ids:
            rng = np.random.default_rng([seed, list(FAMILIES).index(fam), i])
            try:
                case = disguise(FAMILIES[fam](rng), rng)
            except Exception:  # noqa: BLE001
                stats["harness_error"] += 1
                lines.append(f"HARNESS ERROR [{fam}] seed={seed} case={i}:\n{traceback.format_exc()}")
                failed += 1
                continue
            stats["cases"] += 1
            s = time.process_time()
            try:
                via_cli = bool(args.cli_every) and i % args.cli_every == 0 and os.path.exists(args.flexure_exe)
                res, orc, fx, track = check_case(case, rng, via_cli)
                if via_cli:
                    stats["via_cli"] += 1
            except Exception:  # noqa: BLE001
                res, orc, fx, track = Result(), None, None, None
                res.failures.append(("harness error", traceback.format_exc()))
            t_fx += time.process_time() - s
            if res.verdict:
                stats["v_" + res.verdict] += 1
            if res.moved:
                stats["moved"] += 1
            if any(not n.startswith("CLI") for n in res.notes):
                stats["tracker_inconclusive"] += 1
            if any(n.startswith("CLI") for n in res.notes):
                stats["cli_unavailable"] += 1
            if res.notes:
                if args.verbose:
                    print(f"note [{fam}/{case.variant}] case={i}: {'; '.join(res.notes)}")
            if res.failures:
                failed += 1
                stats["failed"] += 1
                if any(c.startswith("CONTRADICTION") for c, _ in res.failures):
                    stats["contradictions"] += 1
                text = fmt_case(fam, i, seed, case, res, orc, fx, track)
                key = (fam, case.variant.split("_n")[0].split("_b")[0], tuple(sorted({c for c, _ in res.failures})))
                classes.setdefault(key, []).append((i, text))
            elif res.incomplete:
                passed += 1
                stats["incomplete"] += 1
                if len(incomplete_examples) < args.show:
                    incomplete_examples.append(f"INCOMPLETE [{fam}/{case.variant}] seed={seed} case={i}: {res.incomplete}\n"
                                               f"  reproducer: {case.reproducer()}.analyze()")
            elif res.skipped:
                stats["skipped"] += 1
                skip_reasons[res.skipped.split(":")[0].split(" (")[0]] += 1
            else:
                passed += 1
                stats["agreed"] += 1
            if args.verbose:
                print(fmt_case(fam, i, seed, case, res, orc, fx, track) if (res.failures or args.case is not None)
                      else f"ok [{fam}/{case.variant}] case={i}" + (f" skipped: {res.skipped}" if res.skipped else ""))
        extra = f" ({'; '.join(f'{k}: {v}' for k, v in skip_reasons.items())})" if skip_reasons else ""
        print(f"{fam:11s} cases={stats['cases']} agreed={stats['agreed']} skipped={stats['skipped']}{extra} "
              f"contradictions={stats['contradictions']} failed={stats['failed']} incomplete={stats['incomplete']} "
              f"tracker_inconclusive={stats['tracker_inconclusive']} | flexure verdicts rigid/flexible/unknown="
              f"{stats['v_rigid']}/{stats['v_flexible']}/{stats['v_unknown']}, tracker moved {stats['moved']}, "
              f"via CLI {stats['via_cli']}"
              + (f" (CLI could not be started {stats['cli_unavailable']}x)" if stats["cli_unavailable"] else "")
              + f", cpu {t_fx:.1f}s", flush=True)
        if stats["incomplete"] > args.max_incomplete * max(stats["cases"], 1):
            failed += 1
            lines.append(f"TOO MANY INCOMPLETE [{fam}]: {stats['incomplete']} of {stats['cases']} cases 'unknown' where the "
                         f"construction knows the answer (more than {args.max_incomplete:.0%})")
    if classes:
        print(f"\nFAILURE CLASSES ({len(classes)}), at most {args.show} shown in full each:")
        for (fam, var, cls), texts in classes.items():
            print(f"\n== {fam}/{var}: {', '.join(cls)}: {len(texts)} case(s)")
            for _, t in texts[:args.show]:
                print(t)
            if len(texts) > args.show:
                rest = [i for i, _ in texts[args.show:]]
                print(f"  ... and {len(rest)} more of this class (seed {seed}, rerun with --families {fam} --case N -v): "
                      f"N = {' '.join(str(i) for i in rest)}")
    for l in incomplete_examples:
        print(l)
    for l in lines:
        print(l)
    print(f"\ncpu {time.process_time() - t0:.1f}s, wall {time.time() - w0:.1f}s, seed {seed}")
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
