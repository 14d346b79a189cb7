"""Every system type built from numpy arrays gives the same analysis and path as its example
scene: the scene written by to_scene() makes the CLI print the same JSON, byte for byte, as the
example does, and the module's own results agree with the CLI's."""

import json
import os
import shutil
import tomllib

import numpy as np
import pytest

import flexure
from conftest import EXAMPLES

# The [system] keys given as arrays: those holding vertex numbers (the module's, from the
# loader's key table), and the numbers per vertex or edge.
INDEX_KEYS = flexure._flexure.index_keys()
ARRAY_KEYS = INDEX_KEYS["system"] + ("radii", "lengths")


def example_names():
    names = []
    for f in sorted(os.listdir(EXAMPLES)):
        if not f.endswith(".toml"):
            continue
        with open(os.path.join(EXAMPLES, f), "rb") as fh:
            doc = tomllib.load(fh)
        if doc["system"]["type"] != "catalog":
            names.append(f[:-5])
    return names


def from_arrays(name):
    """The example rebuilt from arrays: its start configuration as evaluated by flexure, its
    combinatorics as 0-based integer arrays, its settings as dicts."""
    with open(os.path.join(EXAMPLES, name + ".toml"), "rb") as fh:
        doc = tomllib.load(fh)
    base = doc.get("index_base", 1)
    sysdoc = dict(doc["system"])
    typ = sysdoc.pop("type")
    loaded = flexure.load(os.path.join(EXAMPLES, name + ".toml"))
    raw_vertices = sysdoc.pop("vertices")
    # A start projected onto its surface is given as written (the projection is part of loading).
    vertices = raw_vertices if sysdoc.get("project_start") else loaded.vertices
    keys = {}
    for k, v in sysdoc.items():
        if k in ARRAY_KEYS and not isinstance(v, str):
            if k in ("radii", "lengths"):
                v = np.asarray(v, dtype=float) if all(not isinstance(x, str) for x in v) else v
            elif all(isinstance(x, list) for x in v) and len({len(x) for x in v}) > 1:
                v = [np.asarray(x, dtype=np.int64) - base for x in v]  # ragged: facets, bodies
            else:
                v = np.asarray(v, dtype=np.int64) - base
                if k != "attached" and k != "pinned" and v.ndim == 1:
                    v = v.reshape(-1, 1)
        keys[k] = v
    tables = {}
    for t in ("motion", "analysis", "render", "projection"):
        if t in doc:
            tables[t] = dict(doc[t])
    for t in tables:
        for k in INDEX_KEYS.get(t, ()):
            if k in tables[t]:
                tables[t][k] = np.asarray(tables[t][k], dtype=np.int64) - base
    if isinstance(vertices, np.ndarray):
        assert vertices.dtype == np.float64
    return flexure.system(typ, vertices, title=doc.get("title"), **tables, **keys), base


@pytest.mark.parametrize("name", example_names())
def test_built_from_arrays_matches_example(name, cli, tmp_path):
    system, base = from_arrays(name)
    system.to_scene(tmp_path / f"{name}.toml", index_base=base)
    steps = ["--set", "motion.steps=12"]
    for args in (["analyze", f"{name}.toml", "--json"], ["track", f"{name}.toml", *steps]):
        mine = cli(args, cwd=tmp_path, check=False)
        theirs = cli(args, cwd=EXAMPLES, check=False)
        if args[0] == "track":
            # The path's "scene" is each file's own text (expressions, comments' absence, key
            # order); everything else, the structure included, is the same.
            mine, theirs = json.loads(mine), json.loads(theirs)
            assert mine.pop("scene").count("[system]") == theirs.pop("scene").count("[system]") == 1
        assert mine == theirs, f"flexure {' '.join(args)} differs"

    # The module's own analysis: the CLI's JSON for its 0-based scene (only the source differs).
    zero = tmp_path / "zero"
    zero.mkdir()
    system.to_scene(zero / f"{name}.toml")
    cli_analysis = json.loads(cli(["analyze", f"{name}.toml", "--json"], cwd=zero))
    mine = system.analyze().to_dict()
    assert mine.pop("scene") == f"<flexure.{system.type}>"
    cli_analysis.pop("scene")
    # Which flexure made each, and how: the same build, a Python program and a command.
    made, cli_made = mine.pop("flexure"), cli_analysis.pop("flexure")
    assert made["command"][0] == "python" and cli_made["command"][1:] == ["analyze", f"{name}.toml", "--json"]
    assert {**made, "command": None} == {**cli_made, "command": None}
    assert mine == cli_analysis

    # Its path: the CLI's samples and summary.
    path = system.track(steps=12)  # a rigid start: one sample, stopped early, as the CLI
    cli_path_text = cli(["track", f"{name}.toml", *steps], cwd=zero, check=False)
    cli_path = json.loads(cli_path_text)
    np.testing.assert_array_equal(path.samples, np.asarray(cli_path["samples"], dtype=float))
    assert path.samples.shape == (len(cli_path["samples"]), system.num_vertices, system.dimension)
    for k in ("status", "steps_done", "seed", "max_residual", "flex", "flex_choice"):
        assert path.summary[k] == cli_path[k], k
    assert [(e.sample, e.kind, e.detail) for e in path.events] == [
        (e["sample"], e["kind"], e["detail"]) for e in cli_path["events"]]
    # The same text up to the provenance, which is last.
    mine_text, cli_text = path.json(), cli_path_text.decode()
    assert mine_text[:mine_text.index('"flexure":')] == cli_text[:cli_text.index('"flexure":')]
    assert json.loads(mine_text)["flexure"]["command"][0] == "python"


def test_loaded_file_counts_from_zero():
    # double_watt.toml counts from 1; in Python, labels and bases count from 0.
    s = flexure.load(os.path.join(EXAMPLES, "double_watt.toml"))
    a = s.analyze()
    assert a.index_base == 0
    assert "edge 0-1" in " ".join(a.equation_labels) or any(l.startswith("edge 0-") for l in a.equation_labels)
    assert s["edges"].min() == 0
    assert a.nontrivial_flex_basis.shape == (a.nontrivial_inf_flexes, s.num_vertices, 2)
    assert a.stress_basis.shape == (a.stress_dim, a.equations)
    assert isinstance(a.rigidity_rank, int) and isinstance(a.numerics["sigma_max"], float)


def test_index_keys_come_from_the_loader():
    # The package rebases exactly the keys the loader's key table marks as vertex numbers.
    from flexure import _system
    assert _system._INDEX_KEYS == INDEX_KEYS
    assert {"edges", "pinned", "attached", "facets", "faces", "creases"} <= set(INDEX_KEYS["system"])
    assert not {"vertices", "radii", "lengths", "surface"} & set(INDEX_KEYS["system"])
    assert "contract_edge" in INDEX_KEYS["motion"] and "fixed_vertices" in INDEX_KEYS["render"]


def test_catalog_and_catalog_reference(tmp_path):
    names = {e.name for e in flexure.catalog()}
    assert "double_watt" in names and "k24" in names
    by_name = flexure.load("double_watt")
    ref = tmp_path / "ref.toml"
    ref.write_text('[system]\ntype = "catalog"\nname = "double_watt"\n[motion]\nsteps = 5\n')
    by_ref = flexure.load(ref)
    assert by_ref.type == "framework" and by_ref.title == by_name.title
    np.testing.assert_array_equal(by_ref.vertices, by_name.vertices)
    assert len(by_ref.track()) == 6  # its own steps, the entry's other settings


def test_options_as_keywords_and_dicts():
    s = flexure.load("double_watt")
    p1 = s.track(steps=7, step_size=0.02, seed=3)
    p2 = s.track(options={"steps": 7, "step_size": 0.02, "seed": 3})
    np.testing.assert_array_equal(p1.samples, p2.samples)
    assert p1.summary["step_size"] == 0.02 and p1.seed == 3 and len(p1) == 8
    a = s.analyze(rank_tolerance=1e-8)
    assert a.numerics["rank_tolerance"] == 1e-8
    # The system itself is unchanged.
    assert len(s.track()) == 501  # the scene's steps


def test_to_scene_round_trip(tmp_path):
    v = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    s = flexure.framework(v, np.array([[0, 1], [1, 2], [2, 3], [3, 0]]), pinned=[0, 1], title='a "square"\n',
                          motion={"steps": 20})
    f = tmp_path / "sq.toml"
    text = s.to_scene(f)
    assert f.read_text() == text
    back = flexure.load(f)
    assert back.title == 'a "square"\n'
    assert back.analyze().to_dict() | {"scene": ""} == s.analyze().to_dict() | {"scene": ""}
    np.testing.assert_array_equal(back.track().samples, s.track().samples)
    one = s.to_scene(index_base=1)
    assert "index_base = 1" in one and "[1, 2]" in one and "pinned = [1, 2]" in one


def test_edge_contraction_and_every_builder():
    sq = flexure.framework([[0, 0], [1, 0], [1, 1], [0, 1]], [[0, 1], [1, 2], [2, 3], [3, 0]])
    p = sq.track(contract_edge=[0, 1], target_length=1.2, step_size=0.01)
    d = np.linalg.norm(p.samples[-1, 0] - p.samples[-1, 1])
    assert abs(d - 1.2) < 1e-9
    tet = flexure.polytope([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    assert tet.analyze().rigid == "rigid"
    vh = flexure.volume_hypergraph([[0, 0], [1, 0], [0, 1], [1, 1]], [[0, 1, 2], [1, 3, 2]])
    assert vh.analyze().nontrivial_inf_flexes >= 1
    disks = flexure.sphere_packing([[0, 0], [2, 0], [1, 3 ** 0.5]], radius=1.0)
    assert disks.analyze().rigid == "rigid"


def test_origami_driven_fold():
    # A strip of three unit squares with two valley creases (numbered from 0 in Python): folding
    # one crease moves only its own fold; the fold percentage moves both, and the outer squares
    # pass through each other after 120 degrees.
    strip = flexure.origami([[0, 0], [1, 0], [2, 0], [3, 0], [0, 1], [1, 1], [2, 1], [3, 1]],
                            [[0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6]],
                            [[0, 1], [1, 2], [2, 3], [4, 5], [5, 6], [6, 7], [0, 4], [3, 7], [1, 5], [2, 6]],
                            assignments="BBBBBBBBVV")
    one = strip.track(fold_crease=[1, 5], fold_angle=90, steps=9)
    assert len(one) == 10
    end = one.samples[-1]  # the first square at right angles to the other two, which stay flat
    np.testing.assert_allclose([np.linalg.norm(end[0] - end[2]), np.linalg.norm(end[0] - end[3])], [2 ** 0.5, 5 ** 0.5],
                               atol=1e-9)
    both = strip.track(fold_percent=90, steps=90)
    crossing = [e for e in both.events if e.kind == "intersection"]
    assert len(crossing) == 1 and crossing[0].faces == (0, 2)


def test_graph6_and_mesh_files(cli, tmp_path):
    g = tmp_path / "k33.g6"
    g.write_text("EFz_\n")
    s = flexure.load(g)
    assert s.type == "framework" and s.num_vertices == 6 and s["from"] == str(g)
    a = s.analyze()
    assert a.rigid == "rigid" and a.nontrivial_inf_flexes == 0 and a.equations == 9  # K_{3,3}: Laman
    cli_a = json.loads(cli(["analyze", "k33.g6", "--json"], cwd=tmp_path))
    assert a.rigidity_rank == cli_a["rigidity_rank"]
    np.testing.assert_array_equal(s.vertices, np.asarray(json.loads(cli(["track", "k33.g6"], cwd=tmp_path,
                                                                        check=False))["samples"][0]))
    off = tmp_path / "cube.off"
    off.write_text("OFF\n8 6 12\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
                   "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n")
    cube = flexure.load(off)
    assert cube.type == "polytope" and cube.num_vertices == 8
    assert cube.analyze().nontrivial_inf_flexes == flexure.load("cube").analyze().nontrivial_inf_flexes
    bad = tmp_path / "bad.off"
    bad.write_text(off.read_text().replace("4 4 5 6 7", "4 4 5 6 9"))
    import subprocess
    from conftest import _exe
    r = subprocess.run([_exe(), "analyze", "bad.off"], cwd=tmp_path, capture_output=True, text=True)
    assert r.returncode == 1 and "bad.off:12:9: face vertex 9 is out of range 0..7" in r.stderr
    with pytest.raises(flexure.SceneError) as e:
        flexure.load(bad)
    assert (e.value.line, e.value.column) == (12, 9)


def test_exact_analysis_of_a_special_position():
    from fractions import Fraction as F
    # K_{3,3} with its points on the unit circle (rational points): infinitesimally flexible
    # (Bolker and Roth); one point moved off the circle by 10^-12: infinitesimally rigid, which
    # only the exact analysis can tell.
    v = [[1, 0], [F(3, 5), F(4, 5)], [0, 1], [F(-5, 13), F(12, 13)], [-1, 0], [F(8, 17), F(-15, 17)]]
    e = [[0, 1], [0, 3], [0, 5], [2, 1], [2, 3], [2, 5], [4, 1], [4, 3], [4, 5]]
    a = flexure.framework(v, e).analyze(exact=True)
    assert a.exact and a.rigidity_rank == 8 and a.nontrivial_inf_flexes == 1 and a.stress_dim == 1
    assert a.certificate["inf_rigid"] is False
    v[5][1] += F(1, 10**12)
    b = flexure.framework(v, e).analyze(exact=True)
    assert b.exact and b.inf_rigid and b.rigidity_rank == 9 and b.certificate["inf_rigid"] is True
    assert not flexure.framework(v, e).analyze().exact
    assert flexure.framework(v, e).analyze().certificate is None
    # A flat crease pattern in the plane for a sheet in space: read at z = 0.
    w = flexure.load("waterbomb_base").analyze(exact=True)
    assert w.exact and w.certificate["inf_rigid"] is False


def test_certified_track_and_start():
    # The four-bar: every sample and step certified; its start proved flexible (a regular point).
    s = flexure.framework([[0, 0], [2, 0], [2.2, 1.1], [0.3, 1.2]], [[0, 3], [1, 2], [2, 3]], pinned=[0, 1])
    p = s.track(steps=10, step_size=0.05, certify=True)
    assert p.certified is True
    assert len(p.certificate["radii"]) == 11 and all(r is not None for r in p.certificate["radii"])
    assert p.certificate["steps"] == [True] * 10
    # The certified chain from the start leaves the start's orbit: flexible, proved by the path.
    assert p.certificate["flexible"] is True
    assert s.track(steps=3).certified is None
    a = s.analyze(certify=True)
    assert a.certificate["flexible"] is True and a.certificate["inf_rigid"] is False
    t = flexure.framework([[0, 0], [1, 0], [0.3, 0.9]], [[0, 1], [1, 2], [0, 2]]).analyze(certify=True)
    assert t.certificate["inf_rigid"] is True and t.certificate["sigma_lower_bound"] > 0


def test_large_numeric_arrays_written_as_by_value():
    # Rows of plain floats and ints take a fast path (repr in C): the same text as value() writes
    # for each, including exponents, -0.0, inf, nan and mixed rows.
    from flexure import _toml

    rng = np.random.default_rng(3)
    special = [1e-05, 1e16, -0.0, 0.1, 1 / 3, 2.5e-300, 123456789.0, 7, -3, float("inf"), float("nan")]
    rows = [[special[i % len(special)], float(rng.standard_normal()) * 10.0 ** int(rng.integers(-20, 20)),
             int(rng.integers(-5, 5))] for i in range(200)]
    text, lines = _toml.dumps({"system": {"vertices": rows}})
    assert text == "\n".join(["", "[system]", "vertices = ["] + [f"  {_toml.value(r)}," for r in rows] + ["]"]) + "\n"
    assert lines[4] == "system.vertices[0]" and lines[203] == "system.vertices[199]"
    # A boolean is not a number here: the slow path writes it (true, not True).
    assert "[true, 3]" in _toml.dumps({"system": {"vertices": [[1.5, 2], [True, 3]]}})[0]


def test_arrays_go_to_the_engine_as_numbers(tmp_path):
    """numpy arrays of [system] numbers reach the engine as numbers (no scene text): the same
    system as from the scene text, errors at the key and row, the document as lists."""
    k = 30
    ij = np.array([(i, j) for i in range(k) for j in range(k)], dtype=float)
    idx = np.arange(k * k).reshape(k, k)
    e = np.concatenate([np.c_[idx[:, :-1].ravel(), idx[:, 1:].ravel()], np.c_[idx[:-1, :].ravel(), idx[1:, :].ravel()],
                        np.c_[idx[:-1, :-1].ravel(), idx[1:, 1:].ravel()]])
    s = flexure.framework(ij, e, pinned=np.array([0, 1]), lengths=np.linalg.norm(ij[e[:, 0]] - ij[e[:, 1]], axis=1))
    # The same scene through its text (what to_scene writes; loaded by the file reader).
    text = s.to_scene(tmp_path / "grid.toml")
    assert "vertices = []" not in text
    a = s.analyze()
    assert a.rigidity_rank == 2 * k * k - 4 and a.rigid == "rigid"  # two vertices pinned
    again = flexure.load(tmp_path / "grid.toml").analyze().to_dict()
    assert {**again, "scene": None} == {**a.to_dict(), "scene": None}
    doc = s.doc
    assert isinstance(doc["system"]["vertices"], list) and doc["system"]["edges"][0] == [0, 1]
    assert isinstance(doc["system"]["pinned"], list)
    # Exact: the doubles' shortest decimals, as the text path writes them.
    x = flexure.framework(ij + 0.1, e, pinned=np.array([0, 1])).analyze(exact=True)  # (the sqrt(2) lengths are not exact)
    assert x.exact and x.rigidity_rank == a.rigidity_rank
    # Errors: the key and the row, as for lists.
    bad = e.copy()
    bad[7, 1] = 10 ** 6
    for edges in (bad, bad.tolist()):
        with pytest.raises(flexure.SceneError) as err:
            flexure.framework(ij, edges)
        assert err.value.key == "system.edges[7]" and "out of range" in err.value.reason
    v = ij.copy()
    v[5, 1] = np.nan
    with pytest.raises(flexure.SceneError) as err:
        flexure.framework(v, e)
    assert err.value.key == "system.vertices[5]" and "NaN" in err.value.reason
    with pytest.raises(flexure.SceneError) as err:
        flexure.framework(ij, e, pinned=np.array([3, 3]))
    assert err.value.key == "system.pinned[1]" and "pinned twice" in err.value.reason
    with pytest.raises(flexure.SceneError) as err:
        flexure.framework(ij, e, lengths=np.full(len(e) - 1, 1.0))
    assert err.value.key == "system.lengths" and "entries" in err.value.reason
    huge = e.astype(np.int64)
    huge[2, 0] = 2 ** 60
    with pytest.raises(flexure.SceneError) as err:
        flexure.framework(ij, huge)
    assert err.value.key == "system.edges[2]"
    # Options reload the system from the same arrays.
    assert s.analyze(rank_tolerance=1e-8).rigidity_rank == a.rigidity_rank


def test_a_system_does_not_change_with_the_callers_arrays():
    v = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    e = np.array([[0, 1], [1, 2], [2, 0]])
    s = flexure.framework(v, e)
    v[1, 0] = 5.0
    e[0, 1] = 2
    got = s["vertices"]
    got[2, 1] = 7.0  # a copy: writable, the system's own stays
    np.testing.assert_array_equal(s["vertices"], [[0, 0], [1, 0], [0, 1]])
    np.testing.assert_array_equal(s["edges"], [[0, 1], [1, 2], [2, 0]])
    assert s.analyze(rank_tolerance=1e-8).rigidity_rank == 3  # reloaded from its own arrays
    np.testing.assert_array_equal(s.vertices, [[0, 0], [1, 0], [0, 1]])


def test_branches_at_the_flat_four_bar(cli, tmp_path):
    """A path's singular events carry the tangent cone's directions; track(branch=(k, j)) follows
    direction j from sample k, as `flexure track --branch k:j` does."""
    square = flexure.load("square_pinned")
    path = square.track()
    flat = [e for e in path.events if e.kind == "singularity"]
    assert len(flat) == 2
    for e in flat:
        # Two branches cross: four unit directions (4 vertices in 2D), pinned vertices still.
        assert e.directions.shape == (4, 4, 2)
        assert sorted(e.direction_kinds) == ["back", "other", "other", "path"]
        np.testing.assert_array_equal(e.directions[:, :2], 0.0)
        np.testing.assert_allclose(np.linalg.norm(e.directions.reshape(4, -1), axis=1), 1.0)
    e = flat[-1]
    j = e.direction_kinds.index("other")
    other = square.track(branch=(e.sample, j))
    cli_path = json.loads(cli(["track", "square_pinned", "--branch", f"{e.sample}:{j}"], cwd=tmp_path))
    np.testing.assert_array_equal(other.samples, np.asarray(cli_path["samples"], dtype=float))
    assert f"from sample {e.sample} along branch direction {j}" in other.summary["flex_choice"]
    with pytest.raises(flexure.SceneError, match="has 4 branch direction"):
        square.track(branch=(e.sample, 9))
    with pytest.raises(TypeError, match="branch is"):
        square.track(branch=3)
