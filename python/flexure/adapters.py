"""Systems from the graph libraries our users have: networkx graphs with a position mapping, and
PyRigi frameworks (duck-typed: anything with .graph and .realization(as_points=True)).
Vertex labels are kept: Path.to_pyrigi() gives samples keyed by them."""

from ._system import framework
from .errors import SceneError


def _framework_from(nodes, edges, pos, pinned, where, **kw):
    index = {}
    for i, v in enumerate(nodes):
        index[v] = i
    if not hasattr(pos, "__getitem__"):
        raise SceneError(f"positions are needed: {where} must map each node to its point ({{node: point}}), "
                         f"not {type(pos).__name__}", key=where)
    vertices = []
    for v in nodes:
        try:
            p = pos[v]
        except (KeyError, IndexError):
            raise SceneError(f"vertex {v!r} has no position", key=f"{where}[{v!r}]") from None
        try:
            vertices.append([float(x) for x in p])
        except (TypeError, ValueError):
            raise SceneError(f"the position of vertex {v!r} is not a list of numbers: {p!r}",
                             key=f"{where}[{v!r}]") from None
    bars = []
    for u, v in edges:
        if u == v:
            raise SceneError(f"the loop at {u!r} is not a bar", key=f"edges[({u!r}, {v!r})]")
        bars.append([index[u], index[v]])
    pins = []
    for v in pinned or ():
        if v not in index:
            raise SceneError(f"pinned vertex {v!r} is not in the graph", key="pinned")
        pins.append(index[v])
    return framework(vertices, bars, pins or None, labels=list(nodes), **kw)


def from_networkx(G, pos=None, pinned=None, **kw):
    """A framework from a networkx graph: its nodes are the vertices (in `G.nodes`' order, their
    labels kept in `System.labels`), its edges the bars. `pos` is `{node: point}` (e.g.
    `networkx.spring_layout`'s) or a node attribute's name (`pos="xy"`); `pos=None` takes the
    nodes' `"pos"` attribute (networkx's convention, which its drawing functions read), which
    every node must then have (else a `SceneError` at key `pos`). `pinned` lists nodes that do
    not move. Other keywords as `framework()`'s (`title`, `motion`, ...)."""
    if pos is None:
        missing = [v for v, d in G.nodes(data=True) if "pos" not in d]
        if missing:
            raise SceneError(f"positions are needed: pass pos={{node: point}}, or give every node a \"pos\" "
                             f"attribute (networkx's convention); node {missing[0]!r} has none"
                             + (f", nor have {len(missing) - 1} other(s)" if len(missing) > 1 else ""), key="pos")
        pos = "pos"
    if isinstance(pos, str):
        attr = pos
        pos = {v: d[attr] for v, d in G.nodes(data=True) if attr in d}
        where = f"G.nodes[...][{attr!r}]"
    else:
        where = "pos"
    return _framework_from(list(G.nodes), list(G.edges), pos, pinned, where, **kw)


def from_pyrigi(F, pinned=None, **kw):
    """A framework from a PyRigi `Framework` (anything with `.graph` and
    `.realization(as_points=True)`): its graph's nodes are the vertices (their labels kept in
    `System.labels`, so that `Path.to_pyrigi()` gives PyRigi's samples), its realization the
    start, numerically. `pinned` lists vertices that do not move. Other keywords as
    `framework()`'s."""
    graph = F.graph() if callable(getattr(F, "graph", None)) else F.graph
    try:
        points = F.realization(as_points=True, numerical=True)
    except TypeError:
        points = F.realization(as_points=True)
    return _framework_from(list(graph.nodes), list(graph.edges), points, pinned, "realization", **kw)
