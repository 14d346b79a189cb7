"""Systems, analyses and paths: the Python face of flexure's pipeline.

A System is a scene document (the nested dicts a scene file reads as, vertex indices from 0).
Every computation hands its TOML text to the same scene loader and pipeline as the CLI, so a
system built here is validated, analysed, tracked and drawn exactly as its scene file would be.
"""

import base64
import copy
import decimal
import json
import numbers
import os
import sys
import tempfile

import numpy as np

from . import _flexure, _toml
from .errors import FlexureError, Interrupted, OutputError, SceneError, TooLargeError

try:
    import tomllib as _tomllib
except ImportError:  # Python < 3.11
    import tomli as _tomllib

# Keys that hold vertex numbers, by table (the scene format counts them from index_base; Python
# from 0): {"system": ("edges", "pinned", ...), "motion": (...), "render": (...)}, from the
# loader's key table (scenes/keys.cpp).
_INDEX_KEYS = _flexure.index_keys()
_TABLES = ("motion", "analysis", "render", "projection")


def _shift(v, delta):
    if isinstance(v, bool) or isinstance(v, str):
        return v
    if isinstance(v, int):
        return v + delta
    if isinstance(v, (list, tuple)):
        return [_shift(x, delta) for x in v]
    if isinstance(v, dict):  # an edge_styles or vertex_styles entry: only its vertices move
        return {k: _shift(x, delta) if k in ("edges", "vertices") else x for k, x in v.items()}
    if isinstance(v, np.ndarray) and v.dtype.kind in "iu":
        return v + delta
    return v


def _rebase(doc, delta):
    """doc with every vertex number moved by delta (a copy of the tables it touches)."""
    doc = dict(doc)
    for table, keys in _INDEX_KEYS.items():
        t = doc.get(table)
        if not isinstance(t, dict):
            continue
        t = dict(t)
        for k in keys:
            if k in t:
                t[k] = _shift(t[k], delta)
        doc[table] = t
    return doc


def _zero_based(doc):
    """A parsed scene document, counted from 0, with a catalog system resolved into its entry's
    system (and the entry's title and settings as defaults, as the loader merges them)."""
    base = doc.get("index_base", 1)
    if not isinstance(base, int) or base not in (0, 1):
        return doc  # the loader reports it
    sysdoc = doc.get("system")
    if isinstance(sysdoc, dict) and sysdoc.get("type") == "catalog":
        entry = _catalog_docs().get(sysdoc.get("name"))
        if entry is not None:
            entry = _zero_based(entry)
            merged = {k: v for k, v in doc.items() if k != "system"}
            merged = _rebase(merged, -base) if base else merged
            merged["index_base"] = 0
            merged["system"] = entry["system"]
            if "title" not in merged and "title" in entry:
                merged["title"] = entry["title"]
            for t in _TABLES:
                if isinstance(entry.get(t), dict):
                    own = merged.get(t, {})
                    if isinstance(own, dict):
                        merged[t] = {**entry[t], **own}
            return merged
    out = _rebase(doc, -base) if base else dict(doc)
    out["index_base"] = 0
    return out


_CATALOG = None


def _catalog_docs():
    global _CATALOG
    if _CATALOG is None:
        _CATALOG = {name: _tomllib.loads(text) for name, text in _flexure.catalog()}
    return _CATALOG


def _keyed(err, lines, source):
    """A loader error on generated text, as an error at the key of its line."""
    if err.file == source and err.line is not None and 0 < err.line < len(lines) and lines[err.line] is not None:
        item = getattr(err, "_item", None)  # a row of an array passed as numbers
        return SceneError(err.reason, key=lines[err.line] + (f"[{item}]" if item is not None else ""))
    return err  # another file's (a catalog entry's): its own position


class _Keyed:
    """A loaded scene (or a study of it) whose calls report scene errors at their keys: a check
    made while computing (a flex with the wrong number of coefficients) points into the
    generated text too. Loaded files keep their file, line and column."""

    def __init__(self, target, lines, source):
        self._target = target
        self._lines = lines
        self._source = source

    def __getattr__(self, name):
        attr = getattr(self._target, name)
        if not callable(attr):
            return attr

        def call(*args, **kw):
            try:
                r = attr(*args, **kw)
            except SceneError as e:
                if self._lines is None:
                    raise
                raise _keyed(e, self._lines, self._source) from None
            if isinstance(r, _flexure._Study):
                return _Keyed(r, self._lines, self._source)
            if isinstance(r, dict) and isinstance(r.get("study"), _flexure._Study):
                r["study"] = _Keyed(r["study"], self._lines, self._source)
            return r

        return call


def _merge(options, kw):
    merged = dict(options or {})
    merged.update({k: v for k, v in kw.items() if v is not None})
    return merged


def _with_table(doc, table, options):
    """doc with options (Python values, vertex numbers as doc counts them) over its [table]."""
    doc = dict(doc)
    t = doc.get(table, {})
    if not isinstance(t, dict):
        t = {}
    doc[table] = {**t, **{k: _toml._plain(v) for k, v in options.items()}}
    return doc


def _scene_text(doc):
    """The TOML text the loader reads for doc, and the key each line holds (see _keyed)."""
    text, lines = _toml.dumps(doc)
    # A first line that holds no key: the loader's whole-document errors point at line 1.
    return "# flexure scene\n" + text, [None, None] + lines[1:]


# The files each call writes, by extension, as the command line's commands take them
# (`flexure render --help`, `animate --help`, `project --help`, `track --help`): what else
# would be written as something other than its name says (render("a.jpg") as a PNG).
_WRITES = {
    "frame": ("render", ("png", "svg", "pdf", "tex", "obj", "stl"),
              ".png, .svg, .pdf, .tex (TikZ), or .obj/.stl (a solid)"),
    "animation": ("animate", ("mp4", "gif"), ".mp4 or .gif"),
    "projection": ("project", ("png", "svg", "pdf", "tex", "mp4", "gif"),
                   ".png, .svg, .pdf, .tex (TikZ), or .mp4/.gif (the animated projection)"),
    "data": ("project(data=...)", ("csv",), ".csv"),
    "path": ("write", ("json", "csv", "fold"), ".json, .csv or .fold (origami)"),
}


def _extension(name):
    """The extension of a file name, lower case, without the dot ("" for none), as the command
    line reads it: the last dot of the last path component."""
    base = os.path.basename(name)
    dot = base.rfind(".")
    return "" if dot < 0 else base[dot + 1:].lower()


def _output_file(file, kind):
    """file as a path string, refused (OutputError) unless its extension is one the output of
    this kind is written as; None stays None (an image returned instead of a file)."""
    if file is None:
        return None
    file = os.fspath(file)
    name = os.fsdecode(file)
    call, extensions, text = _WRITES[kind]
    if "\0" in name:
        # The system cuts a name at its NUL: "a.csv\0.json" would be the file a.csv, written
        # as JSON. Refused before the extension is read, as open() refuses it.
        err = OutputError(f"cannot write {name!r}: a file name cannot contain a NUL byte")
        err.filename = name
        raise err
    if _extension(name) not in extensions:
        got = f"'.{_extension(name)}'" if _extension(name) else "no extension"
        err = OutputError(f"cannot write '{name}': {call} writes {text}, not {got}")
        err.filename = name
        raise err
    return file


class _Progress:
    """progress=True: a bar on stderr; a callable: called as f(stage, done, total) (return False
    to stop); False/None: nothing."""

    def __init__(self, progress):
        self.user = progress if callable(progress) else None
        self.bar = progress is True
        self.shown = False

    def __call__(self, stage, done, total):
        if self.bar and total > 0:
            width = 30
            filled = int(width * min(done, total) / total)
            sys.stderr.write(f"\r{stage:12s} [{'#' * filled}{'.' * (width - filled)}] {done}/{total}")
            sys.stderr.flush()
            self.shown = True
        if self.user is not None:
            return self.user(stage, done, total)
        return True

    def done(self):
        if self.shown:
            sys.stderr.write("\n")
            sys.stderr.flush()

    def arg(self):
        return self if (self.user or self.bar) else None


class Analysis:
    """The rigidity report of a system's start, as `System.analyze()` returns it: every field of
    `flexure analyze --json`, as attributes and items (`a.rigid`, `a["stress_dim"]`, `keys()`,
    `to_dict()`). Vertex numbers count from 0.

    The main fields (docs/scene-format.md lists them all):

    - `rigid`: `"rigid"` (proved), `"flexible"` (a nontrivial motion was found) or
      `"unknown"`; `reason` says why, in one sentence.
    - `variables`, `equations`, `rigidity_rank`: the free coordinates, the equations, and the
      rank of their Jacobian at the start (`System.jacobian()`).
    - `trivial_inf_flexes`, `nontrivial_inf_flexes`: the dimension of the Jacobian's kernel,
      split into the motions of the system's symmetry group that keep the pins and the rest;
      `stress_dim`: the equilibrium stresses, `equations - rigidity_rank`.
    - `inf_rigid`, `prestress_stable`, `second_order_rigid`: True, False, or None (not decided,
      or the theory does not apply).
    - `nontrivial_flex_basis`: a `(flexes, vertices, dimension)` array of velocities (pinned
      vertices 0); `stress_basis`: a `(stresses, equations)` array whose columns follow
      `equation_labels` (`"edge 0-1"`, ...).
    - `second_order`, `numerics`, `warnings`, `flexure`: dicts and lists of the second-order
      test, the rank decision, numerical warnings and the version that computed it.

    `str(a)` is the report `flexure analyze` prints, `a.json` the text `flexure analyze --json`
    prints for the same scene.
    """

    _ARRAYS = {"nontrivial_flex_basis", "stress_basis"}

    def __init__(self, text, report=None):
        self.json = text
        self._data = json.loads(text)
        self._report = report

    def __str__(self):
        """The report `flexure analyze` prints."""
        return self._report if self._report is not None else self.json

    def __getitem__(self, key):
        """A field by name, `a["stress_dim"]` (`KeyError` when there is none);
        `nontrivial_flex_basis` and `stress_basis` as float arrays."""
        v = self._data[key]
        if key in self._ARRAYS and v is not None:
            return np.asarray(v, dtype=float)
        return v

    def __getattr__(self, key):
        if key.startswith("_"):
            raise AttributeError(key)
        try:
            return self[key]
        except KeyError:
            raise AttributeError(f"the analysis has no field '{key}'") from None

    def __contains__(self, key):
        """Whether the analysis has the field, e.g. `"certificate" in a`."""
        return key in self._data

    def keys(self):
        """The names of the fields, in the order of `flexure analyze --json`."""
        return self._data.keys()

    def to_dict(self):
        """Every field as Python values (a new dict; lists, not arrays)."""
        return json.loads(self.json)

    @property
    def exact(self):
        """True when the counts and decisions were computed in exact rational arithmetic
        (`analyze(exact=True)`)."""
        return bool(self._data.get("exact", False))

    @property
    def certificate(self):
        """What is proved, with `analyze(exact=True)` or `analyze(certify=True)`: a dict of
        `inf_rigid`, `flexible`, `prestress_stable` (True or False: proved; None: not proved
        either way) and `reason` (with `certify=True`, when infinitesimal rigidity is proved, also
        `sigma_lower_bound`); None when nothing was asked to be proved."""
        return self._data.get("certificate")

    def __repr__(self):
        d = self._data
        return (f"<flexure.Analysis {d.get('system')}: {d.get('rigid')}, inf_rigid={d.get('inf_rigid')}, "
                f"nontrivial_inf_flexes={d.get('nontrivial_inf_flexes')}, stress_dim={d.get('stress_dim')}>")


class Event:
    """Something that happened along a path (`Path.events`): a singular point passed (kind
    `"singularity"`), a contact made in a sticky packing (`"contact"`, with the `pair` of
    balls), or two faces of an origami sheet passing through each other (`"intersection"`,
    with the `faces`). Numbers count from 0.

    At a singular point, `directions` holds the directions of the tangent cone there, and
    `direction_kinds` says for each whether the path leaves along it, came along it, or not:
    `system.track(branch=(event.sample, j))` goes on along direction `j` from there."""

    __slots__ = {
        "sample": "The sample at which it happened (an index into `Path.samples`).",
        "kind": '`"singularity"`, `"contact"` or `"intersection"`.',
        "detail": "What happened, in words (at a singular point: how it showed, or how the path left it).",
        "pair": "A contact's two balls `(i, j)`; None for the other kinds.",
        "faces": "An intersection's two faces `(f, g)`; None for the other kinds.",
        "directions": ("At a singular point, the directions of the tangent cone there: a `(directions, "
                       "vertices, dimension)` array of velocities; None where they were not looked for."),
        "direction_kinds": ('One per direction: `"path"` (the path leaves along it), `"back"` (the path came '
                            'along it) or `"other"` (another branch); empty where there are no directions.'),
    }

    def __init__(self, d):
        self.sample = d["sample"]
        self.kind = d["kind"]
        self.detail = d.get("detail", "")
        self.pair = tuple(d["pair"]) if "pair" in d else None
        self.faces = tuple(d["faces"]) if "faces" in d else None
        dirs = d.get("directions")
        self.directions = None if dirs is None else np.asarray(dirs, dtype=float)
        self.direction_kinds = tuple(d.get("direction_kinds", ()))

    def __repr__(self):
        extra = f", pair={self.pair}" if self.pair else f", faces={self.faces}" if self.faces else ""
        return f"Event(sample={self.sample}, kind={self.kind!r}{extra}, detail={self.detail!r})"


class Path:
    """A tracked deformation path, as `System.track()` returns it.

    Attributes:

    - `samples`: a `(samples, vertices, dimension)` array; `samples[0]` is the start, and the
      pinned vertices are there too. `len(path)` is the number of samples.
    - `events`: the singular points, contacts and intersections passed, a list of `Event`.
    - `summary`: the fields of `flexure track`'s JSON but the samples and events (`status`,
      `reason`, `steps_requested`, `steps_done`, `seed`, `max_residual`, `residual_scale`,
      `step_size`, `rejected_steps`, `flex`, `flex_choice`, ...).
    - `system`: the `System` it was tracked from.
    - `interrupted`: True when Ctrl-C stopped it (the `partial` of an `Interrupted`).

    A path draws itself from its own samples (`render`, `animate`, `project`); in Jupyter it
    shows its animation.
    """

    def __init__(self, system, study, result):
        self.system = system
        self._study = study
        meta = json.loads(result["meta"])
        self.samples = np.asarray(result["samples"])
        self.events = [Event(e) for e in meta.pop("events")]
        self.summary = meta
        self.interrupted = bool(result["interrupted"])
        # Stopped by its progress function or Ctrl-C: the track's study stays stopped, and
        # draws nothing more (see _drawn).
        self._stopped = bool(result.get("stopped")) or self.interrupted

    status = property(lambda self: self.summary["status"],
                      doc='`"success"`, or `"stopped_early"` (then `reason` says why and where).')
    reason = property(lambda self: self.summary.get("reason", ""),
                      doc='Why the path stopped early, or ended before the steps asked for; `""` otherwise.')
    flex = property(lambda self: list(self.summary["flex"]),
                    doc="The coefficients followed, in the start's nontrivial-flex basis "
                        "(`Analysis.nontrivial_flex_basis`); empty for an edge contraction.")
    seed = property(lambda self: self.summary["seed"], doc="The tracker's seed: every random choice derives from it.")
    max_residual = property(lambda self: self.summary["max_residual"],
                            doc="The largest constraint residual over all samples.")
    certified = property(lambda self: self.summary.get("certified"),
                         doc="With `track(certify=True)`: True when every sample and every step is certified; "
                             "None otherwise.")
    certificate = property(lambda self: self.summary.get("certificate"),
                           doc="With `track(certify=True)`: a dict of `radii` (one per sample: exactly one point "
                               "of the real motion lies within this max-norm distance; None where not certified), "
                               "`steps` (one flag per step: both samples on one smooth arc) and `reason`; None "
                               "otherwise.")

    def __len__(self):
        """The number of samples, the start included."""
        return len(self.samples)

    def json(self):
        """The path as `flexure track` writes it (the same text, byte for byte)."""
        return self._study.path_json()

    def csv(self):
        """The path as `flexure track -o PATH.csv` writes it: a header, then a row
        `sample,x0,y0,...` per sample (`z` too in 3D), every vertex."""
        return self._study.path_csv()

    def write(self, file):
        """Writes the path as JSON, CSV or (origami) a multi-frame FOLD file, by the extension
        (any other is refused: `OutputError`), atomically; returns `file`. The JSON is a scene
        that `load()` and every command take."""
        return _written(self._study.write("path", _output_file(file, "path")))

    def to_pyrigi(self):
        """The samples in PyRigi's motion-sample format: a list of `{vertex: point}` dicts, keyed
        by the system's vertex labels when it has them (`System.labels`), else by 0, 1, ..."""
        labels = self.system.labels or list(range(self.samples.shape[1]))
        return [{v: np.array(p) for v, p in zip(labels, conf)} for conf in self.samples]

    def render(self, file=None, sample=0, flex=False, samples=None, options=None, **render):
        """Sample `sample` of this path drawn in the path's one view, as `System.render` draws
        it: a PNG, SVG, PDF, TikZ (.tex) or solid (.obj, .stl) file (the file name is returned),
        or without `file` an `(height, width, 4)` uint8 array; `flex=True` adds the flex arrows;
        `samples=[0, 60, 120]`: a filmstrip of those samples in one figure (a file). The
        `[render]` keys as keywords (or a dict, `options=`)."""
        file = _output_file(file, "frame")
        sample = _integer(sample, "sample")
        return _draw(self._drawn("render", _merge(options, render), "frame"), "frame", file, sample=sample, flex=flex,
                     samples=samples)

    def animate(self, file=None, options=None, **render):
        """The path as an MP4 or GIF file (by the extension; the file name is returned), or
        without `file` its frames as a `(frames, height, width, 4)` uint8 array. The `[render]`
        keys as keywords (or a dict, `options=`)."""
        file = _output_file(file, "animation")
        return _animate(self._drawn("render", _merge(options, render), "animation"), file)

    def project(self, file=None, data=None, options=None, **projection):
        """A random 2D projection of this path: a PNG, SVG, PDF, TikZ, GIF or MP4 file (the file
        name is returned; `data=` also writes the projected coordinates as CSV), or without
        `file` the plot as an `(height, width, 4)` uint8 array. The `[projection]` keys as
        keywords (or a dict, `options=`); those that track other paths (`flexes`,
        `both_directions`) are refused: `System.project` draws them."""
        file = _output_file(file, "projection")
        data = _output_file(data, "data")
        study = self._drawn("projection", _merge(options, projection), "projection")
        return _draw(study, "projection", file, data=data)

    def _drawn(self, table, options, kind):
        """The study that draws this path (as a `kind` output) with options in [table]: its own
        study without options; with options (or when the track was stopped, which stops its
        study's drawing too), the path's JSON with the options merged into its scene (as
        System._with merges a system's) loaded as a path given as SCENE, which is drawn as it
        is, not tracked again (as `flexure render PATH.json` draws it). Errors in the options
        name their keys."""
        if not options and not self._stopped:
            return self._study
        j = json.loads(self.json())
        doc = _tomllib.loads(j["scene"])
        base = doc.get("index_base", 1)
        doc = _with_table(doc, table, _rebase({table: options}, base)[table] if base else options)
        motion = doc.get("motion")
        if isinstance(motion, dict) and "certify" in motion:  # nothing to draw: not certified again
            doc["motion"] = {k: v for k, v in motion.items() if k != "certify"}
        projection = doc.get("projection") if isinstance(doc.get("projection"), dict) else {}
        render = doc.get("render") if isinstance(doc.get("render"), dict) else {}
        draws_projection = kind == "projection" or (kind == "animation" and render.get("side_by_side") is True)
        if draws_projection and ("flexes" in projection or projection.get("both_directions")):
            # A path given as SCENE is the one path the scene has: the projection's paths along
            # other flexes would be drawn as this one.
            raise FlexureError("a path's own drawings show this path only; [projection] flexes and "
                               "both_directions track other paths: draw them with system.project(...) "
                               "(or system.animate(side_by_side=True, ...))")
        j["scene"], lines = _scene_text(doc)
        with tempfile.TemporaryDirectory() as d:
            f = os.path.join(d, "path.json")
            with open(f, "w", encoding="utf-8") as fh:
                json.dump(j, fh)
            source = f + ' (its "scene")'  # the loader's name for the scene of a path JSON
            try:
                scene = _flexure.load_file(f)
            except SceneError as e:
                raise _keyed(e, lines, source) from None
        return _Keyed(scene, lines, source).study(len(self) - 1, None, _interrupt_only)

    def _repr_html_(self):
        """Jupyter's view of the path: its animation, an inline GIF."""
        with tempfile.TemporaryDirectory() as d:
            f = os.path.join(d, "path.gif")
            self._study.write("animation", f)
            with open(f, "rb") as fh:
                data = base64.b64encode(fh.read()).decode("ascii")
        return f'<img src="data:image/gif;base64,{data}" alt="flexure path"/>'

    def __repr__(self):
        s = self.summary
        return (f"<flexure.Path {s.get('status')}: {len(self.samples)} samples, "
                f"{len(self.events)} events, max residual {s.get('max_residual'):.3g}>")


def _matrix(rows, cols, values, shape, sparse, call):
    """Triplets as numpy arrays (rows, cols, values, shape), or the dense matrix they make."""
    rows = np.asarray(rows, dtype=np.int64)
    cols = np.asarray(cols, dtype=np.int64)
    values = np.asarray(values, dtype=float)
    shape = (int(shape[0]), int(shape[1]))
    if sparse:
        return rows, cols, values, shape
    try:
        dense = np.zeros(shape)
    except MemoryError:
        raise TooLargeError(f"a dense {shape[0]} x {shape[1]} matrix needs {8 * shape[0] * shape[1] / 2**30:.1f} GiB: "
                            f"{call}(sparse=True) gives its {len(values)} nonzero entries") from None
    np.add.at(dense, (rows, cols), values)
    return dense


def _written(t):
    file, summary, seconds = t
    return file


def _draw(study, kind, file, sample=0, flex=False, data=None, samples=None):
    """An output of the study (file and data checked by _output_file), or its image; `samples`:
    a filmstrip of those samples in one figure (a file)."""
    samples = _filmstrip(samples)
    if file is not None:
        return _written(study.write(kind, file, sample, flex, data if data else "", samples))
    if data is not None:
        raise ValueError("data= needs file= (the CSV is written with the plot)")
    if samples:
        raise ValueError("samples= needs file= (a filmstrip is written as a PNG, SVG, PDF or TikZ file)")
    return np.asarray(study.image(kind, sample, flex))


def _integer(v, what):
    """`v` as an int when it is an integer (int, numpy's integers: numbers.Integral), never
    truncated: a float (267.9, and 3.0 too), a string or a bool is refused (TypeError) naming
    `what` (the argument, with its index)."""
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, numbers.Integral):
        raise TypeError(f"{what} must be an integer, not {v!r} ({type(v).__name__})")
    return int(v)


def _filmstrip(samples):
    """The samples of a filmstrip as a list of ints (render --samples), [] for none."""
    if samples is None:
        return []
    if isinstance(samples, (str, bytes)) or not hasattr(samples, "__iter__"):
        raise TypeError(f"samples is a list of sample numbers, e.g. [0, 60, 120], not {samples!r}")
    out = [_integer(k, f"samples[{i}]") for i, k in enumerate(samples)]
    if any(k < 0 for k in out):
        raise ValueError(f"samples are sample numbers from 0, not {out}")
    return out


def _animate(study, file):
    if file is not None:
        _written(study.write("animation", file))
        if study.interrupted():
            raise Interrupted("interrupted while writing frames")
        return file
    frames = study.frames()
    if study.interrupted():
        raise Interrupted("interrupted while drawing frames")
    return np.stack([np.asarray(f) for f in frames]) if frames else np.zeros((0, 0, 0, 4), np.uint8)


class System:
    """A geometric constraint system and its settings: one scene. Made by `framework()`,
    `polytope()`, ..., `system()`, `load()`, `from_networkx()` or `from_pyrigi()`, not
    directly. Immutable: a call with options works on a copy.

    Attributes:

    - `labels`: the vertices' names (networkx nodes, PyRigi vertices), one per vertex, or None
      (vertices are numbered from 0).

    In Jupyter a system shows a picture of its start.
    """

    def __init__(self, doc, source="<python>", labels=None, scene=None):
        self._doc = doc
        self._source = source
        self._scene = scene
        self.labels = list(labels) if labels is not None else None
        if self._scene is None:
            self._scene = self._load(self._doc)

    # -- loading
    def _load(self, doc):
        # [system] arrays of numbers go to the engine as numbers (a copy, no text): `KEY = []`
        # in the text stands for each.
        arrays = []
        sysdoc = doc.get("system")
        if isinstance(sysdoc, dict):
            plain = dict(sysdoc)
            for k, v in sysdoc.items():
                if (isinstance(v, np.ndarray) and v.dtype.kind in "iuf" and v.ndim in (1, 2) and v.size > 0
                        and not (v.dtype.kind == "f" and v.dtype.itemsize > 8)):  # long doubles: as text, exactly
                    integer = v.dtype.kind in "iu"
                    if integer and v.dtype.kind == "u" and v.max() > np.iinfo(np.int64).max:
                        continue  # beyond int64: written as text, refused by the loader
                    arrays.append((k, np.ascontiguousarray(v, dtype=np.int64 if integer else np.float64)))
                    plain[k] = []
            doc = {**doc, "system": plain}
        text, lines = _scene_text(doc)
        try:
            return _Keyed(_flexure.load_text(text, self._source, arrays), lines, self._source)
        except SceneError as e:
            raise _keyed(e, lines, self._source) from None

    def _with(self, table, options):
        """The loaded scene with options in [table] (self's when there are none)."""
        if not options:
            return self._scene
        return self._load(_with_table(self._doc, table, options))

    # -- what it is
    type = property(lambda self: self._scene.type,
                    doc='The system type, e.g. `"framework"` or `"polytope"` (a catalog entry\'s own type).')
    title = property(lambda self: self._scene.title, doc='The scene\'s title (`""` when it has none).')
    dimension = property(lambda self: self._scene.dimension, doc="2 or 3.")
    num_vertices = property(lambda self: self._scene.num_vertices, doc="The number of vertices, pinned ones too.")

    @property
    def vertices(self):
        """The start configuration, a `(vertices, dimension)` array (a framework on a surface:
        corrected onto it when `project_start` asks)."""
        return np.asarray(self._scene.vertices())

    @property
    def doc(self):
        """The scene document (a deep copy), vertex numbers from 0; arrays as lists."""
        return _listed(self._doc)

    def __getitem__(self, key):
        """A `[system]` key as given, e.g. `system["edges"]` (vertex numbers from 0); arrays of
        numbers as numpy arrays (copies)."""
        v = self._doc["system"][key]
        try:
            a = np.array(v)  # a copy: the system's own arrays stay as they were
            return a if a.dtype.kind in "iuf" else v
        except (ValueError, TypeError):
            return v

    # -- computations
    def analyze(self, options=None, **analysis):
        """The rigidity analysis of the start: an `Analysis`. The `[analysis]` keys as keywords
        (or a dict, `options=`): `rank_tolerance`, `seed`, `max_homotopy_flexes`,
        `motion_check_steps`, `exact`, `exact_budget`, `certify`. `exact=True` also computes it
        in exact rational arithmetic (coordinates as ints, decimals or `fractions.Fraction`): the
        counts, `inf_rigid` and prestress stability are then proved (`Analysis.certificate`);
        its time and memory are estimated first, and work beyond `exact_budget` CPU seconds
        (default 60) or beyond the memory there is raises `TooLargeError` with the estimate;
        `certify=True` proves what interval arithmetic can about the start as given."""
        return Analysis(*self._with("analysis", _merge(options, analysis)).analyze())

    def jacobian(self, sparse=False, labels=False):
        """The Jacobian of the system's equations at the start, over its free coordinates: the
        matrix whose rank is `analyze().rigidity_rank` (its left null space is spanned by
        `stress_basis`). Pinned vertices' coordinates are no variables; a system's own
        variables (a polytope's facet normals) are. A bar's row is the derivative of its
        squared length, `2 (p_i - p_j)`.

        A dense `(equations, variables)` float array; `sparse=True` gives the entries of its
        sparsity pattern (a few may be 0 at the start) as numpy arrays `(rows, cols, values,
        (m, n))` (`scipy.sparse.coo_array((values, (rows, cols)), shape=(m, n))` is the sparse
        matrix). `labels=True` returns `(matrix, row_labels, column_labels)`: per row its
        equation (`"edge 0-1"`, as `analyze().equation_labels` names them), per column the
        vertex coordinate it moves (`"x3"`, `"y3"`, `"z3"`; `""` for a variable of the
        system's own). Vertex numbers from 0."""
        rows, cols, values, m, n, row_labels, column_labels = self._scene.jacobian()
        matrix = _matrix(rows, cols, values, (m, n), sparse, "jacobian")
        if not labels:
            return matrix
        # The module names a system's own variables (a polytope's facet normals) as coordinates
        # of vertices past the last one: they are no vertex's.
        n_vertices = self.num_vertices
        column_labels = [c if c and int(c[1:]) < n_vertices else "" for c in column_labels]
        return matrix, list(row_labels), column_labels

    def rigidity_matrix(self, sparse=False):
        """The rigidity matrix of a bar framework at the start: one row per bar `{i, j}`, in the
        order of its edges, holding `p_i - p_j` in vertex i's columns and `p_j - p_i` in vertex
        j's, over every vertex, pinned ones too: an `(edges, dimension * vertices)` array whose
        columns are x0, y0 (z0), x1, ... (`sparse=True`: triplets, as `jacobian`'s). With no
        vertex pinned its rank is `analyze().rigidity_rank`. For frameworks (type
        `"framework"`) without attached points only: other systems' equations are not all bar
        lengths (a `FlexureError` says so), and `jacobian()` is the matrix of their
        equations."""
        if self.type != "framework":
            raise FlexureError(f"rigidity_matrix() is a bar framework's matrix (one row per bar); the equations of a "
                               f"{self.type} are not all bar lengths: jacobian() is the matrix of its equations "
                               "(labels=True names them)")
        sysdoc = self._system_as_read()
        if len(sysdoc.get("attached", ())) > 0:
            raise FlexureError("rigidity_matrix() is a bar framework's matrix (one row per bar); attached points are "
                               "held by other equations: jacobian() is the matrix of all of them (labels=True names them)")
        edges = np.asarray(sysdoc.get("edges", ()), dtype=np.int64).reshape(-1, 2)
        p = self.vertices
        n, d = p.shape
        m = len(edges)
        diff = p[edges[:, 0]] - p[edges[:, 1]]  # (bars, d)
        rows = np.repeat(np.arange(m, dtype=np.int64), 2 * d)
        cols = np.concatenate([edges[:, :1] * d + np.arange(d), edges[:, 1:] * d + np.arange(d)], axis=1).ravel()
        values = np.concatenate([diff, -diff], axis=1).ravel()
        return _matrix(rows, cols, values, (m, d * n), sparse, "rigidity_matrix")

    def _system_as_read(self):
        """The [system] table, vertex numbers from 0, with what a `from` file holds read into it
        (the scene text the engine writes into a path JSON: it needs the start analysed)."""
        sysdoc = self._doc.get("system", {})
        if "from" not in sysdoc:
            return sysdoc
        text = json.loads(self._scene.study(0, None, _interrupt_only).path_json())["scene"]
        return _zero_based(_tomllib.loads(text))["system"]

    def track(self, steps=None, step_size=None, flex=None, seed=None, contract_edge=None, target_length=None,
              fold_crease=None, fold_angle=None, fold_percent=None, certify=None, branch=None, progress=False,
              options=None):
        """The deformation path from the start: a `Path`. The `[motion]` keys as keywords (or a
        dict, `options=`); a key not given is the scene's, else its default (100 steps of 0.01).

        - `steps`, `step_size`: the samples after the start, and the distance between
          consecutive samples.
        - `flex`: `"auto"`, or coefficients in the start's nontrivial-flex basis
          (`Analysis.nontrivial_flex_basis`): the direction to start in. `seed`: every random
          choice of the tracker derives from it.
        - `contract_edge=(i, j)` with `target_length`: contract that edge instead of following
          a flex.
        - Origami: `fold_crease=(i, j)` with `fold_angle` (degrees), or `fold_percent`, drive the
          fold.
        - `certify=True`: certify every sample and step in interval arithmetic
          (`Path.certified`, `Path.certificate`).
        - `branch=(k, j)`: go on from sample k along direction j of the tangent cone there (a
          singular point's `Event.directions`).
        - `progress=True` draws a bar on stderr; a function `f(stage, done, total)` is called as
          it goes, and stops the track by returning False (the path then ends there, status
          `"stopped_early"`).

        Ctrl-C stops it and raises `Interrupted` with the path so far in `partial`."""
        if branch is not None:
            if isinstance(branch, (str, bytes)) or not hasattr(branch, "__len__") or len(branch) != 2:
                raise TypeError(f"branch is (k, j): sample k of the path and direction j there, not {branch!r}")
            branch = [_integer(branch[0], "branch[0] (the sample)"), _integer(branch[1], "branch[1] (the direction)")]
        motion = _merge(options, dict(steps=steps, step_size=step_size, flex=flex, seed=seed,
                                      contract_edge=contract_edge, target_length=target_length,
                                      fold_crease=fold_crease, fold_angle=fold_angle, fold_percent=fold_percent,
                                      certify=certify, branch=branch))
        scene = self._with("motion", motion)
        p = _Progress(progress)
        try:
            result = scene.track(p.arg() or _interrupt_only)
        finally:
            p.done()
        path = Path(self, result["study"], result)
        if path.interrupted:
            raise Interrupted(f"interrupted after {len(path.samples)} samples", partial=path)
        return path

    def _study(self, table, options, seed=None, progress=False):
        scene = self._with(table, options)
        p = _Progress(progress)
        return scene.study(None, seed, p.arg() or _interrupt_only), p

    def render(self, file=None, sample=0, flex=False, samples=None, options=None, **render):
        """One frame: the start, or sample `sample` of the path, drawn in the path's one view
        (the whole path is tracked, so that sample K is frame K of `animate()`). A PNG, SVG,
        PDF, TikZ (.tex) or solid (.obj, .stl) file (the file name is returned), or without
        `file` an `(height, width, 4)` uint8 array; another extension is refused
        (`OutputError`) before anything is computed. `flex=True` adds the flex arrows;
        `samples=[0, 60, 120]`: a filmstrip of those samples in one figure (a file), as
        `flexure render --samples 0,60,120`. The `[render]` keys as keywords (or a dict,
        `options=`), e.g. `width=400, height=300`."""
        file = _output_file(file, "frame")
        sample = _integer(sample, "sample")
        strip = _filmstrip(samples)
        scene = self._with("render", _merge(options, render))
        steps = max(sample, 0, scene.ghost, scene.motion_steps, *strip)
        study = scene.study(steps, None, _interrupt_only)
        return _draw(study, "frame", file, sample=sample, flex=flex, samples=strip)

    def animate(self, file=None, seed=None, progress=False, options=None, **render):
        """The motion as an MP4 or GIF file (by the extension; the file name is returned), or
        without `file` its frames as a `(frames, height, width, 4)` uint8 array. The `[render]`
        keys as keywords (or a dict, `options=`); `seed` and `progress` as `track`'s."""
        file = _output_file(file, "animation")
        study, p = self._study("render", _merge(options, render), seed=seed, progress=progress)
        try:
            return _animate(study, file)
        finally:
            p.done()

    def project(self, file=None, data=None, seed=None, progress=False, options=None, **projection):
        """A random 2D projection of the deformation path (or of several paths, `flexes=`): a
        PNG, SVG, PDF or TikZ file, or a GIF/MP4 animation of it (the file name is returned), or
        without `file` the plot as an `(height, width, 4)` uint8 array; `data=` also writes the
        projected coordinates as CSV. The `[projection]` keys as keywords (or a dict,
        `options=`); `seed` and `progress` as `track`'s."""
        file = _output_file(file, "projection")
        data = _output_file(data, "data")
        study, p = self._study("projection", _merge(options, projection), seed=seed, progress=progress)
        try:
            return _draw(study, "projection", file, data=data)
        finally:
            p.done()

    def to_scene(self, file=None, index_base=0):
        """The system as a scene file's text (TOML), written to `file` when given (atomically).
        Vertex numbers from `index_base` (0 or 1). A file name that flexure reads as another
        format (.off, .g6, .fold, .json, ...) is refused (`OutputError`)."""
        if index_base not in (0, 1):
            raise ValueError("index_base must be 0 or 1")
        if file is not None:
            name = os.fsdecode(os.fspath(file))
            if "\0" in name:
                err = OutputError(f"cannot write {name!r}: a file name cannot contain a NUL byte")
                err.filename = name
                raise err
            if _flexure.is_importable(name):
                err = OutputError(f"cannot write a scene to '{name}': flexure reads a .{_extension(name)} file "
                                  "as that format, not as a scene; name it .toml")
                err.filename = name
                raise err
        doc = _rebase(self._doc, index_base) if index_base else self._doc
        doc = {**doc, "index_base": index_base}
        ordered = {k: doc[k] for k in ("title", "index_base") if k in doc}
        ordered.update({k: v for k, v in doc.items() if k not in ordered})
        text, _ = _toml.dumps(ordered)
        if file is not None:
            file = os.fspath(file)
            d = os.path.dirname(os.path.abspath(file))
            fd, tmp = tempfile.mkstemp(dir=d, prefix=".flexure-", suffix=".toml")
            try:
                with os.fdopen(fd, "w", encoding="utf-8") as fh:
                    fh.write(text)
                os.replace(tmp, file)
            except BaseException:
                if os.path.exists(tmp):
                    os.unlink(tmp)
                raise
        return text

    def _repr_png_(self):
        """Jupyter's picture of the system: its start, as PNG bytes."""
        return self._scene.study(0, None, None).png(0, False)

    def __repr__(self):
        t = f" {self.title!r}" if self.title else ""
        return f"<flexure.System {self.type}{t}: {self.num_vertices} vertices in {self.dimension}D>"


def _interrupt_only(stage, done, total):
    return True


# -- making systems


def _listed(doc):
    """A deep copy of doc with numpy arrays as lists (what a TOML reader gives)."""
    if isinstance(doc, dict):
        return {k: _listed(v) for k, v in doc.items()}
    if isinstance(doc, list):
        return [_listed(v) for v in doc]
    if isinstance(doc, np.ndarray):
        return doc.tolist()
    return copy.deepcopy(doc)


def _frozen(a):
    """A read-only copy of the array a (a system is immutable: not changed through the caller's
    array)."""
    a = np.array(a)
    a.setflags(write=False)
    return a


def _numbers(v):
    """v as a (read-only) numpy array when it is a rectangular array of real numbers (1 or 2
    dimensions), else as it is (expression strings, Fractions, ragged lists)."""
    if isinstance(v, (str, bytes, bool)) or v is None:
        return v
    try:
        a = np.asarray(v)
    except (ValueError, TypeError, OverflowError):
        return _toml._plain(v)
    if a.dtype.kind in "iuf" and a.ndim in (1, 2) and a.size > 0:
        return _exact_floats(a)
    return _toml._plain(v)


def _exact_floats(a):
    """A float or integer array as a read-only array when its values are doubles (the engine's
    numbers); a long double array whose values are not all doubles as nested lists of its
    scalars, which the scene text writes exactly (`_toml.value`): never rounded."""
    if a.dtype.kind == "f" and a.dtype.itemsize > 8:
        d = a.astype(np.float64)
        with np.errstate(invalid="ignore"):
            if not np.array_equal(d.astype(a.dtype), a, equal_nan=True):
                return a.tolist()  # numpy long double scalars
        return _frozen(d)
    return _frozen(a)


def _vertices(vertices):
    try:
        kind = np.asarray(vertices).dtype.kind
    except (ValueError, TypeError, OverflowError):
        kind = "O"
    if kind == "c" or (kind == "O" and any(isinstance(x, complex) for row in vertices for x in np.ravel(row))):
        # numpy would drop the imaginary parts (with a warning); a framework's points are real.
        raise TypeError("vertices must be real coordinates, not complex numbers")
    try:
        exact = np.asarray(vertices)
        if kind == "f" and exact.dtype.itemsize > 8 and exact.ndim == 2:
            kept = _exact_floats(exact)  # long doubles: kept exactly unless they are doubles
            if isinstance(kept, list):
                return kept
        a = np.asarray(vertices, dtype=float)
    except OverflowError:  # an integer beyond double (2**1100)
        raise SceneError("a coordinate is too large (beyond the range of a double)", key="system.vertices") from None
    except (ValueError, TypeError):
        return [list(v) for v in vertices]  # expression strings: the loader evaluates them
    if a.ndim != 2:
        raise SceneError(f"vertices must be a (vertices, dimension) array, not of shape {a.shape}",
                         key="system.vertices")
    if kind == "O" and any(_inexact_as_double(x) for row in vertices for x in row):
        # fractions.Fraction, decimal.Decimal, numpy long doubles, ...: kept, and written exactly
        # ("p/q", the Decimal's numeral: _toml.value), so that analyze(exact=True) proves things
        # about the numbers given, not about their doubles.
        return [[x if _inexact_as_double(x) else float(x) for x in row] for row in vertices]
    return _frozen(a)


def _inexact_as_double(x):
    """True for a number whose double is not the number itself (or may not be): Fractions,
    Decimals, long doubles and other reals that are not floats or integers."""
    if isinstance(x, (bool, np.bool_, numbers.Integral, float)):
        return False
    if isinstance(x, np.floating) and x.dtype.itemsize <= 8:
        return False
    return isinstance(x, (numbers.Real, decimal.Decimal))


def _index_list(v):
    if isinstance(v, str):
        return v
    try:
        a = np.asarray(v)
    except ValueError:  # ragged (numpy >= 1.24): facets or bodies of different sizes
        return [_index_list(x) for x in v]
    if a.dtype.kind in "iu" or (a.dtype.kind == "f" and a.size and np.all(a == np.round(a))):
        return _frozen(a.astype(np.int64)) if a.ndim in (1, 2) and a.size else a.astype(np.int64).tolist()
    if a.dtype.kind == "O":  # ragged: facets, bodies
        return [np.asarray(x).astype(np.int64).tolist() for x in v]
    return _toml._plain(v)


def system(type, vertices, *, title=None, motion=None, analysis=None, render=None, projection=None, output=None,
           labels=None, **keys):
    """A system of any type: `type` as a scene's `[system] type` (`"framework"`, `"polytope"`,
    ...), `vertices` its start as a `(vertices, dimension)` array, and the type's other
    `[system]` keys as keywords, with vertex numbers from 0 (docs/scene-format.md lists them).

    `title` and the tables `motion`, `analysis`, `render` and `projection` (dicts of their
    keys) and `output` (a list of dicts, one per `[[output]]`) are the scene's; `labels`, one
    per vertex, name the vertices (`System.labels`). Each type's own function (`framework()`,
    `polytope()`, ...) takes these keywords too. A wrong value raises a `SceneError` at its key;
    a `(dimension, vertices)` matrix is refused with a hint to pass its transpose."""
    sysdoc = {"type": type, "vertices": _vertices(vertices)}
    for k, v in keys.items():
        if v is None:
            continue
        try:
            if k in _INDEX_KEYS["system"]:
                v = _index_list(v)
            sysdoc[k] = v if isinstance(v, np.ndarray) else _numbers(v)
        except OverflowError:  # e.g. a vertex number 2**70: beyond 64-bit integers
            raise SceneError("a number is too large (beyond 64-bit integers)", key=f"system.{k}") from None
    doc = {}
    if title is not None:
        doc["title"] = title
    doc["index_base"] = 0
    doc["system"] = sysdoc
    for name, t in (("motion", motion), ("analysis", analysis), ("render", render), ("projection", projection)):
        if t:
            doc[name] = {k: _toml._plain(v) for k, v in t.items()}
    if output:
        doc["output"] = [{k: _toml._plain(v) for k, v in o.items()} for o in output]
    try:
        return System(doc, source=f"<flexure.{type}>", labels=labels)
    except SceneError as e:
        hint = _transpose_hint(sysdoc["vertices"], e)
        if hint is None:
            raise
        raise SceneError(e.reason + hint, key=e.key, file=e.file, line=e.line, column=e.column) from None


def _transpose_hint(vertices, err):
    """What to add to a vertices error when the array reads as points in columns (Julia's,
    MATLAB's convention): (d, n) with d = 2 or 3 rows and n > 3 columns, a shape no system type
    takes as it is (no vertex has more than 3 coordinates); None otherwise."""
    if not (err.key or "").startswith("system.vertices"):
        return None
    try:
        shape = np.shape(vertices)
    except ValueError:  # ragged
        return None
    if len(shape) == 2 and shape[0] in (2, 3) and shape[1] > 3:
        return "; it looks like a (dimension x vertices) matrix: pass its transpose (vertices.T)"
    return None


def framework(vertices, edges, pinned=None, *, lengths=None, attached=None, **kw):
    """A bar-joint framework in 2D or 3D: the bars keep their lengths.

    `vertices` is the start, a `(vertices, dimension)` array; `edges` an `(m, 2)` integer array
    of bars (vertex numbers from 0); `pinned` the vertices that do not move. `lengths`, one per
    edge, are lengths that the start must have (checked). `attached` rows `[v, a, b]` (or `[v,
    a, b, c]`) hold vertex v in the frame of a and b (and c) where it is at the start: a coupler
    point, a point of a ternary link. Other keywords as `system()`'s (`title`, `motion`, ...)."""
    return system("framework", vertices, edges=edges, pinned=pinned, lengths=lengths, attached=attached, **kw)


def framework_on_surface(vertices, edges, surface, pinned=None, *, project_start=None, **kw):
    """A framework in 3D whose vertices stay on the surface f(x, y, z) = 0: `surface` is the
    expression f, e.g. `"x^2 + y^2 - z^2 - 1"`. `project_start=True` corrects the start onto the
    surface, keeping the bar lengths. Its trivial motions are the surface's isometries. Other
    arguments as `framework()`'s."""
    return system("framework_on_surface", vertices, edges=edges, surface=surface, pinned=pinned,
                  project_start=project_start, **kw)


def angular_framework(vertices, angles, pinned=None, **kw):
    """An angular framework: each row `[i, j, k]` of `angles` keeps the angle at j between the
    lines to i and to k. Its trivial motions are the similarities. Other arguments as
    `framework()`'s."""
    return system("angular_framework", vertices, angles=angles, pinned=pinned, **kw)


def polytope(vertices, facets="hull", pinned=None, **kw):
    """A polytope in 3D: its edges keep their lengths and its facets stay planar. `facets` are
    cyclic vertex lists, or `"hull"`: the facets of the vertices' convex hull. Other arguments
    as `framework()`'s."""
    return system("polytope", vertices, facets=facets, pinned=pinned, **kw)


def body_hinge(vertices, bodies, pinned=None, **kw):
    """A body-hinge framework: each of `bodies` (a list of vertex lists) is rigid, and vertices
    that bodies share are hinges. Other arguments as `framework()`'s."""
    return system("body_hinge", vertices, bodies=bodies, pinned=pinned, **kw)


def body_bar(vertices, bodies, bars, pinned=None, **kw):
    """A body-bar framework: rigid `bodies` (vertex lists) joined by `bars`, an `(m, 2)` array
    of vertex pairs whose distances are kept. Other arguments as `framework()`'s."""
    return system("body_bar", vertices, bodies=bodies, bars=bars, pinned=pinned, **kw)


def origami(vertices, faces, creases, assignments=None, pinned=None, **kw):
    """Rigid origami: planar panels hinged at creases. `faces` are the panels' vertex cycles,
    counterclockwise; `creases` every edge of the sheet, creases and boundary; `assignments` a
    string of one letter per crease (B boundary, M mountain, V valley, F flat, U unassigned, J
    join: FOLD's `edges_assignment`), mountains and valleys keeping their sense. A FOLD file
    loads with `flexure.load("sheet.fold")`; `track(fold_percent=...)` or
    `track(fold_crease=..., fold_angle=...)` drives the fold. Other arguments as
    `framework()`'s."""
    return system("origami", vertices, faces=faces, creases=creases, assignments=assignments, pinned=pinned, **kw)


def sphere_packing(vertices, radii=None, pinned=None, *, radius=None, tolerance=None, **kw):
    """A sticky packing of disks (2D) or spheres (3D) centred at `vertices`: pairs that touch
    at the start (a gap of at most `tolerance * (r_i + r_j)`, default 1e-6) keep touching, and
    new contacts stick. `radii`, one per ball, or one `radius` for all. Other arguments as
    `framework()`'s."""
    return system("sphere_packing", vertices, radii=radii, radius=radius, tolerance=tolerance, pinned=pinned, **kw)


def spherical_disk_packing(vertices, contacts, pinned=None, **kw):
    """Caps on the unit sphere: each vertex is a 3D point `a` with `|a| > 1`, standing for the
    cap that the plane `a.y = 1` cuts off; each pair in `contacts` keeps its inversive distance.
    Its trivial motions are the Moebius transformations. Other arguments as `framework()`'s."""
    return system("spherical_disk_packing", vertices, contacts=contacts, pinned=pinned, **kw)


def volume_hypergraph(vertices, simplices, pinned=None, **kw):
    """A volume hypergraph: each row of `simplices` (d + 1 vertices: triangles in 2D,
    tetrahedra in 3D) keeps its signed volume. Its trivial motions are the equi-affine maps.
    Other arguments as `framework()`'s."""
    return system("volume_hypergraph", vertices, simplices=simplices, pinned=pinned, **kw)


def load(path):
    """A system from a file or the catalog: a scene file (TOML), a catalog name
    (`"double_watt"`), a path JSON written by `flexure track` or `Path.write` (the scene it
    holds), or any other file the command line takes as SCENE (FOLD, graph6/sparse6, an edge
    list, node-link JSON, an OFF, OBJ or STL mesh). Vertex numbers count from 0 whatever the
    file's `index_base`. Errors (`SceneError`) name the file, line and column."""
    path = os.fspath(path)
    scene = _flexure.load_file(path)
    path_json = _path_json_scene(path)
    if path_json is not None:
        raw = _tomllib.loads(path_json)
    elif _flexure.is_importable(path) and os.path.exists(path):
        # A graph6/sparse6 file or a mesh: the scene [system] from = FILE, as the CLI reads it.
        raw = {"title": os.path.basename(path), "system": {"from": os.path.abspath(path)}}
    else:
        text = _flexure.read_scene_file(path) if os.path.exists(path) else _catalog_text(path)
        raw = _tomllib.loads(text)
    # The file as read when it counts vertices from 0 and is no catalog reference; else (None)
    # the 0-based document is loaded, so that every label and vertex number counts from 0.
    sysdoc = raw.get("system")
    catalog_ref = isinstance(sysdoc, dict) and sysdoc.get("type") == "catalog"
    as_read = _Keyed(scene, None, path) if raw.get("index_base", 1) == 0 and not catalog_ref else None
    return System(_zero_based(raw), source=path, scene=as_read)


def _path_json_scene(path):
    """The scene text of a path JSON (None for any other file)."""
    if not path.lower().endswith(".json") or not os.path.isfile(path):
        return None
    import json
    try:
        with open(path, encoding="utf-8") as f:
            j = json.load(f)
    except (ValueError, OSError):
        return None
    if isinstance(j, dict) and isinstance(j.get("scene"), str) and "samples" in j:
        return j["scene"]
    return None


def _catalog_text(name):
    name = name[8:] if name.startswith("catalog:") else name
    for n, text in _flexure.catalog():
        if n == name:
            return text
    raise FlexureError(f"no catalog entry '{name}'")


class CatalogEntry(tuple):
    """One built-in system, as `catalog()` lists it: a tuple `(name, title, type)`."""

    __slots__ = ()

    def __new__(cls, name, title, type):
        return tuple.__new__(cls, (name, title, type))

    name = property(lambda self: self[0], doc='The name that `load()` takes, e.g. `"double_watt"`.')
    title = property(lambda self: self[1], doc="The entry's title.")
    type = property(lambda self: self[2], doc='The system type, e.g. `"framework"`.')

    def __repr__(self):
        return f"CatalogEntry(name={self.name!r}, type={self.type!r}, title={self.title!r})"


def catalog():
    """The built-in systems (the example scenes of `flexure catalog`): a list of `CatalogEntry`,
    by name. `flexure.load(entry.name)` loads one."""
    out = []
    for name, doc in _catalog_docs().items():
        sysdoc = doc.get("system", {})
        out.append(CatalogEntry(name, doc.get("title", ""), sysdoc.get("type", "")))
    return out
