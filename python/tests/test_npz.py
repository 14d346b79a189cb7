"""[system] from = "FILE.npz": the arrays NumPy writes (numpy.savez, savez_compressed; every
dtype and order it can give) read as the same system as the scene text with the arrays written
out; bad files and bad arrays refused at the `from` key, naming the array and its row."""

import json
import subprocess

import numpy as np
import pytest

import flexure
from conftest import _exe


def grid(k=40):
    """A k x k triangulated grid (10^3-10^4 vertices): vertices (float) and edges (0-based)."""
    ij = np.array([(i, j) for i in range(k) for j in range(k)], dtype=float)
    ij += 0.01 * np.random.default_rng(7).standard_normal(ij.shape)
    idx = np.arange(k * k).reshape(k, k)
    e = np.concatenate([np.c_[idx[:, :-1].ravel(), idx[:, 1:].ravel()], np.c_[idx[:-1, :].ravel(), idx[1:, :].ravel()],
                        np.c_[idx[:-1, :-1].ravel(), idx[1:, 1:].ravel()]])
    return ij, e


HEAD = 'title = "grid"\nindex_base = 0\n[system]\ntype = "framework"\n'


def analyze(path):
    r = subprocess.run([_exe(), "analyze", str(path), "--json"], capture_output=True, text=True)
    return r.returncode, (json.loads(r.stdout) if r.returncode == 0 else None), r.stderr


def without_scene(j):
    """The analysis without the scene's name, nor the command in its provenance (both name the file)."""
    return {k: v for k, v in j.items() if k not in ("scene", "flexure")}


def test_npz_reads_as_the_scene_text(tmp_path):
    v, e = grid()
    text = flexure.framework(v, e, pinned=[0, 1], title="grid").to_scene()
    (tmp_path / "text.toml").write_text(text)
    rc, want, err = analyze(tmp_path / "text.toml")
    assert rc == 0, err
    forms = {
        "savez": lambda f: np.savez(f, vertices=v, edges=e),
        "savez_compressed": lambda f: np.savez_compressed(f, vertices=v, edges=e),
        "fortran order, int32": lambda f: np.savez(f, vertices=np.asfortranarray(v), edges=np.asfortranarray(e.astype(np.int32))),
        "big-endian, uint16": lambda f: np.savez(f, vertices=v.astype(">f8"), edges=e.astype(">u2")),
        "pinned in the file": lambda f: np.savez(f, vertices=v, edges=e, pinned=np.array([0, 1], dtype=np.int8)),
    }
    for name, write in forms.items():
        write(tmp_path / "grid.npz")
        pinned = "" if "pinned" in name else "pinned = [0, 1]\n"
        (tmp_path / "npz.toml").write_text(HEAD + 'from = "grid.npz"\n' + pinned)
        rc, got, err = analyze(tmp_path / "npz.toml")
        assert rc == 0, (name, err)
        assert without_scene(got) == without_scene(want), name
    # Python loads it too, from another working directory (the file is next to the scene).
    s = flexure.load(tmp_path / "npz.toml")
    assert s.num_vertices == len(v) and s.analyze().rigidity_rank == want["rigidity_rank"]
    # The path JSON's scene holds the system it read: the arrays, no `from`.
    out = tmp_path / "path.json"
    (tmp_path / "npz.toml").write_text(HEAD + 'from = "grid.npz"\n[motion]\nsteps = 1\n')  # (pinned in the file)
    r = subprocess.run([_exe(), "track", str(tmp_path / "npz.toml"), "-o", str(out)], capture_output=True)
    assert r.returncode in (0, 2), r.stderr  # 2: the grid is rigid, the path stops at its start
    scene = json.loads(out.read_text())["scene"]
    assert "from" not in scene and "vertices = [" in scene and "edges = [" in scene


def test_npz_errors(tmp_path):
    v, e = grid(12)

    def error(text, **arrays):
        np.savez(tmp_path / "g.npz", **arrays)
        (tmp_path / "s.toml").write_text(HEAD + text)
        rc, _, err = analyze(tmp_path / "s.toml")
        assert rc == 1, err
        return err

    bad = e.copy()
    bad[7, 1] = 500
    err = error('from = "g.npz"\n', vertices=v, edges=bad)
    assert "s.toml:5:8: g.npz, edges[7][1]: edge vertex 500 is out of range" in err
    err = error('from = "g.npz"\n', vertices=v, edges=e.astype(float))
    assert "g.npz, edges[0][0]: edge vertex must be an integer" in err
    err = error('from = "g.npz"\n', vertices=v, edges=e, weights=np.ones(3))
    assert "holds the array 'weights'" in err
    err = error('from = "g.npz"\n', vertices=v.ravel(), edges=e)
    assert "vertices has 1 dimension(s)" in err
    err = error('from = "g.npz"\nedges = [[0, 1]]\n', vertices=v, edges=e)
    assert "edges is given both here and in g.npz" in err
    vv = v.copy()
    vv[3, 0] = np.inf
    err = error('from = "g.npz"\n', vertices=vv, edges=e)
    assert "g.npz, vertices[3]: a number is infinite" in err
    np.savez(tmp_path / "o.npz", vertices=np.array([None, 1], dtype=object), edges=e)
    (tmp_path / "s.toml").write_text(HEAD + 'from = "o.npz"\n')
    rc, _, err = analyze(tmp_path / "s.toml")
    assert rc == 1 and "cannot read 'o.npz'" in err and "Python objects" in err
    data = (tmp_path / "g.npz").read_bytes()
    for cut in (len(data) // 2, 30, 0):
        (tmp_path / "c.npz").write_bytes(data[:cut])
        (tmp_path / "s.toml").write_text(HEAD + 'from = "c.npz"\n')
        rc, _, err = analyze(tmp_path / "s.toml")
        assert rc == 1 and "cannot read 'c.npz'" in err, err
    damaged = bytearray(data)
    damaged[len(damaged) // 3] ^= 0xFF  # inside the data: the checksum
    (tmp_path / "d.npz").write_bytes(bytes(damaged))
    (tmp_path / "s.toml").write_text(HEAD + 'from = "d.npz"\n')
    rc, _, err = analyze(tmp_path / "s.toml")
    assert rc == 1 and "cannot read 'd.npz'" in err, err
    (tmp_path / "s.toml").write_text(HEAD + 'from = "missing.npz"\n')
    rc, _, err = analyze(tmp_path / "s.toml")
    assert rc == 1 and "cannot read 'missing.npz'" in err
