"""networkx and PyRigi inputs, errors as exceptions, Ctrl-C, the GIL, progress, memory, images and
Jupyter."""

import os
import resource
import signal
import threading
import time

import networkx as nx
import numpy as np
import pytest

import flexure
from conftest import EXAMPLES

K24_POS = {"a": (0.0, 0.0), "b": (0.0, 2.0), 1: (-1.0, 0.3), 2: (1.0, -0.6), 3: (-2.0, 1.4), 4: (1.5, 1.7)}


def k24():
    G = nx.Graph()
    G.add_nodes_from(K24_POS)
    G.add_edges_from((u, v) for u in ("a", "b") for v in (1, 2, 3, 4))
    return G


def test_networkx_keeps_labels():
    G = k24()
    s = flexure.from_networkx(G, K24_POS, pinned=["a"])
    assert s.labels == list(G.nodes)
    a = s.analyze()
    # K_{2,4}: 6 vertices, 8 bars, generic in the plane: 12 - 8 - 3 = 1 nontrivial flex (Whiteley's
    # counting; the realization is generic), no stress.
    assert (a.vertices, a.equations, a.nontrivial_inf_flexes, a.stress_dim) == (6, 8, 1, 0)
    p = s.track(steps=20, step_size=0.05)
    samples = p.to_pyrigi()
    assert len(samples) == 21 and set(samples[0]) == set(K24_POS)
    for conf in samples:  # every bar keeps its length along the path
        for u, v in G.edges:
            L0 = np.linalg.norm(np.subtract(K24_POS[u], K24_POS[v]))
            assert abs(np.linalg.norm(conf[u] - conf[v]) - L0) < 1e-8
    np.testing.assert_array_equal(samples[5]["a"], K24_POS["a"])  # pinned


def test_networkx_node_attribute_and_missing_position():
    G = nx.cycle_graph(4)
    for v, p in enumerate([(0, 0), (1, 0), (1, 1), (0, 1)]):
        G.nodes[v]["xy"] = p
    s = flexure.from_networkx(G, "xy")
    assert s.analyze().nontrivial_inf_flexes == 1
    del G.nodes[2]["xy"]
    with pytest.raises(flexure.SceneError) as e:
        flexure.from_networkx(G, "xy")
    assert "2" in e.value.key and "no position" in e.value.reason


class Graph(nx.Graph):
    """Stand-in for pyrigi.Graph (a networkx.Graph subclass)."""


class Framework:
    """Stand-in for pyrigi.Framework where PyRigi is not installable: its graph property and its
    realization(as_points=True, numerical=True) -> {vertex: point}."""

    def __init__(self, graph, realization):
        self._graph = graph
        self._realization = {v: np.asarray(p, dtype=float) for v, p in realization.items()}

    @property
    def graph(self):
        return self._graph

    def realization(self, as_points=False, numerical=False):
        if not as_points:
            return {v: p.reshape(-1, 1) for v, p in self._realization.items()}
        return dict(self._realization)


def test_pyrigi_framework_shape():
    G = Graph(k24())
    F = Framework(G, K24_POS)
    s = flexure.from_pyrigi(F, pinned=["a", "b"], motion={"steps": 10})
    net = flexure.from_networkx(k24(), K24_POS, pinned=["a", "b"], motion={"steps": 10})
    assert s.analyze().to_dict() == net.analyze().to_dict()
    samples = s.track().to_pyrigi()
    assert isinstance(samples, list) and all(isinstance(d, dict) for d in samples)
    assert samples[0][3].shape == (2,)


def test_errors_carry_key_and_reason(tmp_path):
    v = [[0, 0], [1, 0], [1, 1], [0, 1]]
    with pytest.raises(flexure.SceneError) as e:
        flexure.framework(v, [[0, 1], [1, 2], [2, 7]])
    assert e.value.key == "system.edges[2]"
    assert "out of range" in e.value.reason and "0..3" in e.value.reason
    assert isinstance(e.value, ValueError)

    sq = flexure.framework(v, [[0, 1], [1, 2], [2, 3], [3, 0]])
    with pytest.raises(flexure.SceneError) as e:
        sq.track(step_size=-1)
    assert e.value.key == "motion.step_size"
    with pytest.raises(flexure.SceneError) as e:
        sq.track(flex=[1, 2, 3])
    assert e.value.key == "motion.flex"
    with pytest.raises(flexure.SceneError) as e:
        sq.analyze(rank_tolerence=1e-8)
    assert e.value.key == "analysis.rank_tolerence" and "did you mean 'rank_tolerance'" in e.value.reason
    with pytest.raises(flexure.SceneError) as e:
        flexure.framework([[0, 0], [1, float("nan")]], [[0, 1]])
    assert e.value.key == "system.vertices[1]" and "NaN" in e.value.reason
    with pytest.raises(flexure.SceneError) as e:
        flexure.framework(np.zeros((3, 2, 2)), [[0, 1]])
    assert e.value.key == "system.vertices"
    with pytest.raises(flexure.SceneError) as e:
        flexure.system("frame_work", v, edges=[[0, 1]])
    assert e.value.key == "system.type" and "framework" in e.value.reason

    bad = tmp_path / "bad.toml"
    bad.write_text('[system]\ntype = "framework"\nvertices = [[0, 0], [1, 0]]\nedges = [[1, 3]]\n')
    with pytest.raises(flexure.SceneError) as e:
        flexure.load(bad)
    assert (e.value.file, e.value.line, e.value.column) == (str(bad), 4, 14)
    with pytest.raises(flexure.SceneError):
        flexure.load(tmp_path / "missing.toml")
    with pytest.raises(flexure.OutputError):
        sq.render(tmp_path / "no" / "such" / "dir" / "x.png")


def test_a_path_json_loads_as_its_scene(tmp_path):
    s = flexure.load("double_watt")
    p = s.track(steps=30)
    p.write(tmp_path / "p.json")
    back = flexure.load(tmp_path / "p.json")
    assert back.analyze().to_dict()["rigidity_rank"] == s.analyze().to_dict()["rigidity_rank"]
    np.testing.assert_array_equal(back.track(steps=30).samples, p.samples)
    # Its vector figures too.
    back.render(tmp_path / "p.svg", sample=10)
    assert (tmp_path / "p.svg").read_text().startswith("<?xml")


def test_ctrl_c_keeps_the_path():
    s = flexure.load("double_watt")
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    with pytest.raises(flexure.Interrupted) as e:
        s.track(steps=5_000_000, step_size=0.001)
    timer.join()
    assert isinstance(e.value, KeyboardInterrupt)
    p = e.value.partial
    assert 1 < len(p) < 5_000_001 and p.status == "stopped_early"
    assert p.max_residual < 1e-8
    # what was kept is a real path: consecutive samples a step apart
    gaps = np.linalg.norm((p.samples[1:] - p.samples[:-1]).reshape(len(p) - 1, -1), axis=1)
    assert np.all(gaps < 0.01)


def test_progress_function_stops_and_gil_is_released():
    s = flexure.load("double_watt")
    seen = []

    def progress(stage, done, total):
        seen.append((stage, done, total))
        return done < 300

    p = s.track(steps=2000, step_size=0.001, progress=progress)
    assert seen and seen[0][0] == "tracking" and seen[0][2] == 2000
    assert p.status == "stopped_early" and len(p) < 2001

    # Another thread runs while a track does.
    counter = [0]
    stop = threading.Event()

    def count():
        while not stop.is_set():
            counter[0] += 1

    t = threading.Thread(target=count)
    t.start()
    s.track(steps=3000, step_size=0.001)
    stop.set()
    t.join()
    assert counter[0] > 1000


def test_no_memory_growth_over_10000_calls():
    v = np.array([[np.cos(t), np.sin(t)] for t in np.linspace(0, 2 * np.pi, 10, endpoint=False)])
    edges = np.array([[i, (i + 1) % 10] for i in range(10)] + [[i, (i + 3) % 10] for i in range(10)])

    def once():
        s = flexure.framework(v, edges, pinned=[0])
        a = s.analyze()
        assert a.vertices == 10
        s.track(steps=2)

    for _ in range(500):
        once()
    rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    for _ in range(10_000):
        once()
    rss1 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    assert rss1 - rss0 < 8 * 1024, f"max RSS grew by {rss1 - rss0} KiB over 10,000 calls"


def test_images_match_the_cli(cli, tmp_path):
    s = flexure.load(os.path.join(EXAMPLES, "double_watt.toml"))
    img = s.render(sample=10, width=300, height=200)
    assert img.shape == (200, 300, 4) and img.dtype == np.uint8
    assert len(np.unique(img.reshape(-1, 4), axis=0)) > 10  # something is drawn
    s.render(tmp_path / "py.png", sample=10)
    # Python numbers vertices from 0, in pictures too: the CLI draws the same on the 0-based scene.
    s.to_scene(tmp_path / "dw.toml")
    cli(["render", "dw.toml", "--sample", "10", "-o", "cli.png"], cwd=tmp_path)
    assert (tmp_path / "py.png").read_bytes() == (tmp_path / "cli.png").read_bytes()

    small = s.track(steps=6)
    frames = small.animate()
    assert frames.shape[0] == 7 and frames.shape[3] == 4
    small.animate(tmp_path / "p.gif")
    assert (tmp_path / "p.gif").read_bytes()[:6] == b"GIF89a"
    plot = s.project()
    assert plot.ndim == 3 and plot.shape[2] == 4
    out = s.project(tmp_path / "proj.png", data=tmp_path / "proj.csv", seed=4)
    assert os.path.exists(out) and (tmp_path / "proj.csv").read_text().startswith("path,sample")


def test_jupyter_reprs():
    s = flexure.framework([[0, 0], [1, 0], [1, 1], [0, 1]], [[0, 1], [1, 2], [2, 3], [3, 0]],
                          render={"width": 160, "height": 160}, motion={"steps": 4})
    assert s._repr_png_()[:8] == b"\x89PNG\r\n\x1a\n"
    html = s.track()._repr_html_()
    assert html.startswith('<img src="data:image/gif;base64,R0lGOD')  # GIF89a


def test_networkx_pos_attribute_when_no_positions_are_given():
    G = nx.cycle_graph(4)
    square = {0: (0, 0), 1: (1, 0), 2: (1, 1), 3: (0, 1)}
    nx.set_node_attributes(G, square, "pos")  # networkx's convention (nx.draw reads it)
    want = flexure.from_networkx(G, square).analyze().to_dict()
    for s in (flexure.from_networkx(G, None), flexure.from_networkx(G)):
        np.testing.assert_array_equal(s.vertices, [square[v] for v in G.nodes])
        assert s.analyze().to_dict() == want
    del G.nodes[2]["pos"]
    for pos in (None, 5):
        with pytest.raises(flexure.SceneError) as e:  # not a TypeError
            flexure.from_networkx(G, pos)
        assert e.value.key == "pos" and "positions are needed" in e.value.reason
    with pytest.raises(flexure.SceneError) as e:
        flexure.from_networkx(G)
    assert "pos=" in e.value.reason and '"pos" attribute' in e.value.reason and "node 2" in e.value.reason
    # A position that is no list of numbers names the node.
    with pytest.raises(flexure.SceneError) as e:
        flexure.from_networkx(G, {**square, 3: 7})
    assert e.value.key == "pos[3]" and "not a list of numbers" in e.value.reason


def test_a_transposed_vertex_matrix_gets_a_hint():
    points = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 1.5]])
    edges = [[0, 1], [1, 2], [2, 3], [3, 0], [2, 4], [3, 4]]
    hint = "it looks like a (dimension x vertices) matrix: pass its transpose (vertices.T)"
    for columns in (points.T, np.c_[points, np.ones(5)].T, points.T.tolist()):
        with pytest.raises(flexure.SceneError) as e:
            flexure.framework(columns, edges)
        assert e.value.key.startswith("system.vertices") and hint in e.value.reason
        assert e.value.reason.startswith("a vertex has 5 coordinates")  # the loader's message first
    assert flexure.framework(points.T.T, edges).num_vertices == 5
    # No hint where the shape is not wrong as it is: (2, 3) is two points in 3D (here the edges
    # are out of range), (5, 4) has no reading as points in columns, nor does an error elsewhere.
    for vertices, bad in ((points[:3].T, "system.edges"), (np.zeros((5, 4)), "system.vertices"),
                          (points.T, "system.type")):
        with pytest.raises(flexure.SceneError) as e:
            flexure.system("frame_work" if bad == "system.type" else "framework", vertices, edges=edges)
        assert e.value.key.startswith(bad) and "transpose" not in e.value.reason, (vertices.shape, e.value)
