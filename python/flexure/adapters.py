"""Systems from the graph libraries our users have: networkx graphs with a position mapping, and
PyRigi frameworks (duck-typed: anything with .graph and .realization(as_points=True)).
Vertex labels are kept: Path.to_pyrigi() gives samples keyed by them."""

from ._system import framework
from .errors import SceneError


def _framework_from(nodes, edges, pos, pinned, where, **kw):
    index = {}
    for i, v in enumerate(nodes):
        index[v] = i
    vertices = []
    for v in nodes:
        try:
            vertices.append([float(x) for x in pos[v]])
        except KeyError:
            raise SceneError(f"vertex {v!r} has no position", key=f"{where}[{v!r}]") from None
        except (TypeError, ValueError):
            raise SceneError(f"the position of vertex {v!r} is not a list of numbers: {pos[v]!r}",
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


def from_networkx(G, pos, pinned=None, **kw):
    """A framework from a networkx graph and {node: point} (e.g. networkx.spring_layout's, or a
    node attribute name: pos="pos"). Keywords as flexure.framework's (title, motion, ...)."""
    if isinstance(pos, str):
        attr = pos
        pos = {v: d[attr] for v, d in G.nodes(data=True) if attr in d}
        where = f"G.nodes[...][{attr!r}]"
    else:
        where = "pos"
    return _framework_from(list(G.nodes), list(G.edges), pos, pinned, where, **kw)


def from_pyrigi(F, pinned=None, **kw):
    """A framework from a PyRigi Framework (its graph and realization, numerically)."""
    graph = F.graph() if callable(getattr(F, "graph", None)) else F.graph
    try:
        points = F.realization(as_points=True, numerical=True)
    except TypeError:
        points = F.realization(as_points=True)
    return _framework_from(list(graph.nodes), list(graph.edges), points, pinned, "realization", **kw)
