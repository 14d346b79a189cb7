"""flexure: continuous motions of geometric constraint systems, in Python.

    import flexure
    F = flexure.framework(vertices, edges, pinned=[0, 1])   # numpy arrays, vertices from 0
    a = F.analyze()                                         # a.rigid, a.nontrivial_inf_flexes, ...
    p = F.track(steps=200, step_size=0.02, seed=1)          # p.samples: (samples, vertices, dim)
    p.animate("motion.gif")

The same scene loader and pipeline as the `flexure` command: the same keys, defaults, checks,
numbers and files. The guide is docs/python.md, the reference docs/python-api.md, and a first
session docs/tutorial.ipynb.
"""

from . import _flexure
from ._system import (Analysis, CatalogEntry, Event, Path, System, angular_framework, body_bar, body_hinge,
                      catalog, framework, framework_on_surface, load, origami, polytope, sphere_packing,
                      spherical_disk_packing, system, volume_hypergraph)
from .adapters import from_networkx, from_pyrigi
from .errors import FlexureError, Interrupted, OutputError, SceneError, TooLargeError

__version__ = _flexure.version

__all__ = [
    "Analysis", "CatalogEntry", "Event", "Path", "System", "FlexureError", "Interrupted", "OutputError",
    "SceneError", "TooLargeError", "angular_framework", "body_bar", "body_hinge", "catalog", "framework", "framework_on_surface",
    "from_networkx", "from_pyrigi", "load", "origami", "polytope", "sphere_packing", "spherical_disk_packing", "system",
    "volume_hypergraph",
]
