"""The analysis's text report as str(analysis); the Jacobian (dense, sparse, labelled) and the
classical rigidity matrix of a bar framework, checked against numpy computations of their own
and against the analysis's rank."""

import re

import networkx as nx
import numpy as np
import pytest

import flexure

K24_POS = {0: (0.0, 0.0), 1: (0.0, 2.0), 2: (-1.0, 0.3), 3: (1.0, -0.6), 4: (-2.0, 1.4), 5: (1.5, 1.7)}


def classical_rigidity_matrix(points, edges):
    """Row r for bar {i, j}: p_i - p_j in i's d columns, p_j - p_i in j's (every vertex)."""
    points = np.asarray(points, dtype=float)
    n, d = points.shape
    R = np.zeros((len(edges), d * n))
    for r, (i, j) in enumerate(edges):
        R[r, d * i:d * i + d] = points[i] - points[j]
        R[r, d * j:d * j + d] = points[j] - points[i]
    return R


def rank(M):
    return int(np.linalg.matrix_rank(M))


def test_str_is_the_cli_report(cli, tmp_path):
    a = flexure.load("double_watt").analyze()
    report = cli(["analyze", "double_watt"], cwd=tmp_path).decode()
    mine = str(a)
    assert "\n" in mine and "rigidity matrix rank 14" in mine
    # The first line is the scene's title (not a file name): the same for the catalog entry
    # loaded by name. Vertex numbers appear in neither, so Python's 0-based numbering does not show.
    assert mine.splitlines()[0] == report.splitlines()[0] == "Cuspidal double Watt mechanism  (framework, 2D)"
    assert mine == report
    # repr stays the one-line summary.
    assert repr(a) == ("<flexure.Analysis framework: flexible, inf_rigid=False, nontrivial_inf_flexes=2, "
                       "stress_dim=1>")
    assert "\n" not in repr(a)


def test_str_of_an_untitled_system_names_its_source(cli, tmp_path):
    # Without a title the report's first line names the scene: the CLI its file, Python the
    # constructor; the rest is the same text.
    s = flexure.framework([[0, 0], [1, 0], [1, 1], [0, 1]], [[0, 1], [1, 2], [2, 3], [3, 0]], pinned=[0, 1])
    s.to_scene(tmp_path / "sq.toml")
    mine = str(s.analyze()).split("\n", 1)
    theirs = cli(["analyze", "sq.toml"], cwd=tmp_path).decode().split("\n", 1)
    assert mine[0] == "<flexure.framework>  (framework, 2D)" and theirs[0] == "sq.toml  (framework, 2D)"
    assert mine[1] == theirs[1] and "1 = 0 trivial + 1 nontrivial" in mine[1]


def test_jacobian_dense_sparse_and_labels():
    s = flexure.load("double_watt")
    a = s.analyze()
    J = s.jacobian()
    assert J.shape == (a.equations, a.variables) and J.dtype == float
    rows, cols, values, shape = s.jacobian(sparse=True)
    assert shape == J.shape and rows.dtype == np.int64 and cols.dtype == np.int64
    # The sparsity pattern: each entry once (a few may be 0 at the start).
    assert len(rows) == len(cols) == len(values) == len(set(zip(rows.tolist(), cols.tolist())))
    assert np.count_nonzero(values) == np.count_nonzero(J) > 0
    rebuilt = np.zeros(shape)
    rebuilt[rows, cols] = values
    np.testing.assert_array_equal(rebuilt, J)
    matrix, row_labels, column_labels = s.jacobian(labels=True)
    np.testing.assert_array_equal(matrix, J)
    assert row_labels == list(a.equation_labels)
    assert len(column_labels) == a.variables
    # Pinned vertices have no columns; every other vertex has its x and y, from 0.
    pinned = set(int(v) for v in s["pinned"])
    want = [f"{c}{v}" for v in range(s.num_vertices) if v not in pinned for c in "xy"]
    assert sorted(column_labels) == sorted(want)
    (rows2, cols2, values2, shape2), row_labels2, _ = s.jacobian(sparse=True, labels=True)
    assert shape2 == shape and row_labels2 == row_labels
    np.testing.assert_array_equal(values2, values)


@pytest.mark.parametrize("name", ["double_watt", "cube", "k24", "square_pinned", "coned_cube"])
def test_jacobian_rank_is_the_rigidity_rank(name):
    s = flexure.load(name)
    a = s.analyze()
    J = s.jacobian()
    assert J.shape == (a.equations, a.variables)
    assert rank(J) == a.rigidity_rank, name
    # The stress basis spans its left null space.
    if a.stress_dim:
        np.testing.assert_allclose(a.stress_basis @ J, 0.0, atol=1e-8)


def test_a_polytopes_jacobian_has_the_normals_columns():
    s = flexure.load("cube")
    _, rows, columns = s.jacobian(labels=True)
    # 8 vertices' coordinates, then a normal per facet (3 coordinates each), a variable of the
    # polytope's own.
    assert columns == [f"{c}{v}" for v in range(8) for c in "xyz"] + [""] * (3 * 6)
    assert any(r.startswith("facet 0") for r in rows) and any(r.startswith("edge 0-") for r in rows)
    with pytest.raises(flexure.FlexureError, match=r"jacobian\(\)"):
        s.rigidity_matrix()


def test_rigidity_matrix_is_the_classical_one():
    G = nx.complete_bipartite_graph(2, 4)
    F = flexure.from_networkx(G, K24_POS)
    edges = [list(e) for e in G.edges]
    R = F.rigidity_matrix()
    points = np.array([K24_POS[v] for v in range(6)])
    want = classical_rigidity_matrix(points, edges)
    assert R.shape == (8, 12)
    np.testing.assert_allclose(R, want, rtol=0, atol=1e-15)
    rows, cols, values, shape = F.rigidity_matrix(sparse=True)
    dense = np.zeros(shape)
    dense[rows, cols] = values
    np.testing.assert_array_equal(dense, R)
    # Unpinned: its rank is the analysis's; the Jacobian of the squared lengths is twice it,
    # column by column as the labels say.
    a = F.analyze()
    assert rank(R) == a.rigidity_rank == 8
    J, row_labels, column_labels = F.jacobian(labels=True)
    assert row_labels == [f"edge {i}-{j}" for i, j in edges]
    for c, label in enumerate(column_labels):
        axis, v = "xyz".index(label[0]), int(label[1:])
        np.testing.assert_allclose(J[:, c], 2 * want[:, 2 * v + axis], rtol=0, atol=1e-14)


def test_rigidity_matrix_keeps_pinned_vertices_and_every_bar():
    # The pinned square: the bar between the two pinned vertices is no equation of the analysis
    # (nothing moves it), but it is a row of the rigidity matrix, which has every vertex's columns.
    s = flexure.load("square_pinned")
    edges = s["edges"].tolist()
    pinned = s["pinned"].tolist()
    assert [0, 1] in edges or [1, 0] in edges
    assert sorted(pinned) == [0, 1]
    R = s.rigidity_matrix()
    np.testing.assert_allclose(R, classical_rigidity_matrix(s.vertices, edges), rtol=0, atol=1e-15)
    assert R.shape == (len(edges), 2 * s.num_vertices)
    assert s.jacobian().shape[0] == len(edges) - 1


@pytest.mark.parametrize("dimension", [2, 3])
def test_rigidity_rank_of_generic_frameworks(dimension):
    # Random (generic) realizations of a triangle, K_{3,3}, K_{3,4} and K_5, unpinned: the rank
    # of the classical matrix is the analysis's (2D: 3, 9, 11, 7; 3D: 3, 9, 12, 9).
    rng = np.random.default_rng(5 + dimension)
    graphs = [nx.cycle_graph(3), nx.complete_bipartite_graph(3, 3), nx.complete_bipartite_graph(3, 4),
              nx.complete_graph(5)]
    for G in graphs:
        points = rng.standard_normal((G.number_of_nodes(), dimension))
        edges = [list(e) for e in G.edges]
        F = flexure.framework(points, edges)
        R = F.rigidity_matrix()
        np.testing.assert_allclose(R, classical_rigidity_matrix(points, edges), rtol=0, atol=1e-12)
        assert rank(R) == F.analyze().rigidity_rank, (dimension, G)
        assert rank(F.jacobian()) == F.analyze().rigidity_rank


def test_rigidity_matrix_of_a_framework_read_from_a_file(tmp_path):
    # A graph6 file's framework has no edges in its scene document: they come from the file.
    g = tmp_path / "k33.g6"
    g.write_text("EFz_\n")
    s = flexure.load(g)
    R = s.rigidity_matrix()
    assert R.shape == (9, 12)
    a = s.analyze()
    assert rank(R) == a.rigidity_rank == 9
    edges = [[int(x) for x in re.match(r"edge (\d+)-(\d+)", l).groups()] for l in a.equation_labels]
    np.testing.assert_allclose(R, classical_rigidity_matrix(s.vertices, edges), rtol=0, atol=1e-15)


def test_rigidity_matrix_refuses_other_systems():
    for s in (flexure.load("cube"),
              flexure.framework_on_surface([[1, 0, 0], [0, 1, 0]], [[0, 1]], "x^2 + y^2 - z^2 - 1"),
              flexure.angular_framework([[0, 0], [1, 0], [0, 1]], [[1, 0, 2]]),
              flexure.sphere_packing([[0, 0], [2, 0], [1, 3 ** 0.5]], radius=1.0)):
        with pytest.raises(flexure.FlexureError) as e:
            s.rigidity_matrix()
        assert "jacobian()" in str(e.value) and s.type in str(e.value)
        assert s.jacobian().shape[0] == s.analyze().equations
    attached = flexure.framework([[0, 0], [1, 0], [0.5, 1], [0.5, 0.3]], [[0, 1], [1, 2], [2, 0]],
                                 attached=[[3, 0, 1, 2]])
    with pytest.raises(flexure.FlexureError, match="attached"):
        attached.rigidity_matrix()
