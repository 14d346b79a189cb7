"""Drawing calls: unknown output extensions refused before any computation, with the extensions
the call writes; a Path drawn with render and projection keys as System draws it, from its own
samples (not tracked again)."""

import os
import re

import numpy as np
import pytest

import flexure

SQUARE = [[0, 0], [1, 0], [1, 1], [0, 1]]
SQUARE_EDGES = [[0, 1], [1, 2], [2, 3], [3, 0]]


def four_bar(**kw):
    """A pinned four-bar (one degree of freedom), 40 steps by default."""
    return flexure.framework([[0, 0], [2, 0], [2.2, 1.1], [0.3, 1.2]], [[0, 3], [1, 2], [2, 3]], pinned=[0, 1],
                             motion={"steps": 40, "step_size": 0.02, **kw.pop("motion", {})}, **kw)


def listing(d):
    return sorted(os.listdir(d))


def test_unknown_extensions_are_refused_before_any_computation(tmp_path):
    # A flex of 3 coefficients for a square of 4 flexes: loading accepts it, tracking refuses it
    # (motion.flex). A refused extension must be reported first: nothing is tracked.
    bad = flexure.framework(SQUARE, SQUARE_EDGES, motion={"flex": [1, 2, 3]})
    with pytest.raises(flexure.SceneError) as e:
        bad.render(tmp_path / "a.png")
    assert e.value.key == "motion.flex"  # (so the calls below would compute, and fail, if they did)
    calls = []

    def progress(stage, done, total):
        calls.append(stage)
        return True

    cases = [
        (lambda f: bad.render(f), "a.jpg", "render", [".png", ".svg", ".pdf", ".tex", ".obj", ".stl"]),
        (lambda f: bad.render(f, sample=3, width=100), "a", "render", [".png", ".tex"]),
        (lambda f: bad.animate(f, progress=progress), "a.avi", "animate", [".mp4", ".gif"]),
        (lambda f: bad.project(f, progress=progress), "a.jpeg", "project", [".png", ".svg", ".pdf", ".mp4", ".gif"]),
        (lambda f: bad.project(tmp_path / "p.png", data=f), "p.txt", "project(data=...)", [".csv"]),
    ]
    for call, name, what, extensions in cases:
        with pytest.raises(flexure.OutputError) as e:
            call(tmp_path / name)
        message = str(e.value)
        assert str(tmp_path / name) in message and what in message, message
        for ext in extensions:
            assert ext in message, (ext, message)
        assert e.value.filename == str(tmp_path / name)
        assert isinstance(e.value, OSError) and isinstance(e.value, flexure.FlexureError)
    assert calls == []
    assert listing(tmp_path) == []


def test_a_path_refuses_unknown_extensions_before_drawing(tmp_path):
    p = four_bar().track()
    # A misspelt render key is a SceneError once the scene is loaded with it: the file name is
    # checked before (OutputError), and so before anything is loaded or drawn.
    for call in (lambda f: p.render(f, widht=10), lambda f: p.animate(f, widht=10),
                 lambda f: p.project(f, line_widht=1)):
        with pytest.raises(flexure.OutputError) as e:
            call(tmp_path / "x.bmp")
        assert "x.bmp" in str(e.value)
    with pytest.raises(flexure.OutputError) as e:
        p.write(tmp_path / "p.txt")
    assert ".json" in str(e.value) and ".csv" in str(e.value) and ".fold" in str(e.value)
    assert listing(tmp_path) == []
    # The extension is read as the command line reads it: case aside, the last dot of the name.
    assert p.render(tmp_path / "A.PNG", sample=3) == str(tmp_path / "A.PNG")
    assert (tmp_path / "A.PNG").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    p.write(tmp_path / "p.CSV")
    assert (tmp_path / "p.CSV").read_text().startswith("sample")
    (tmp_path / "d.svg").mkdir()
    with pytest.raises(flexure.OutputError) as e:
        p.render(tmp_path / "d.svg" / "frame")
    assert "no extension" in str(e.value)


def test_accepted_extensions_write_their_format(tmp_path):
    p = four_bar().track()
    heads = {"svg": b"<?xml", "pdf": b"%PDF", "png": b"\x89PNG"}
    for ext, head in heads.items():
        p.render(tmp_path / f"f.{ext}", sample=5)
        assert (tmp_path / f"f.{ext}").read_bytes().startswith(head), ext
    p.render(tmp_path / "f.tex", sample=5)
    assert "tikzpicture" in (tmp_path / "f.tex").read_text()
    p.animate(tmp_path / "a.gif")
    assert (tmp_path / "a.gif").read_bytes()[:6] == b"GIF89a"


def test_to_scene_refuses_names_read_as_other_formats(tmp_path):
    s = four_bar()
    for name in ("s.off", "s.g6", "s.fold", "s.stl", "s.json"):
        with pytest.raises(flexure.OutputError) as e:
            s.to_scene(tmp_path / name)
        assert name in str(e.value) and ".toml" in str(e.value)
    assert listing(tmp_path) == []
    s.to_scene(tmp_path / "s.scene")  # any other name is read as a scene (TOML)
    back = flexure.load(tmp_path / "s.scene")
    np.testing.assert_array_equal(back.vertices, s.vertices)


def test_a_path_takes_render_keys_as_the_system_does():
    s = four_bar()
    p = s.track()
    assert len(p) == 41
    keys = dict(width=240, height=160, background="#ffeedd")
    # The same picture as System.render's, which tracks the same path (the scene's settings).
    mine = p.render(sample=12, **keys)
    assert mine.shape == (160, 240, 4)
    np.testing.assert_array_equal(mine, s.render(sample=12, **keys))
    np.testing.assert_array_equal(p.render(sample=12, options=keys), mine)
    assert not np.array_equal(p.render(sample=12, width=240, height=160), mine)  # the background
    np.testing.assert_array_equal(p.render(sample=12), s.render(sample=12))  # no keys: as before
    frames = p.animate(width=120, height=90)
    assert frames.shape == (41, 90, 120, 4)
    np.testing.assert_array_equal(frames, s.animate(width=120, height=90))
    # A frame is framed on the whole path, a still on its sample: the same figure, other pixels.
    still = p.render(sample=12, width=120, height=90)
    assert still.shape == frames[12].shape
    assert not np.array_equal(still, frames[12])
    # Projection keys on Path.project.
    plot = p.project(line_width=9)
    np.testing.assert_array_equal(plot, s.project(line_width=9))
    assert not np.array_equal(plot, p.project())


def test_a_path_is_drawn_from_its_own_samples():
    # A path stopped early (by its progress function) is drawn as it is: not tracked again
    # (which would go on to 2000 steps).
    w = flexure.load("double_watt")
    s = flexure.framework(w.vertices, w["edges"], w["pinned"], render={"width": 64, "height": 48})
    p = s.track(steps=2000, step_size=0.001, progress=lambda stage, done, total: done < 300)
    assert p.status == "stopped_early" and len(p) < 2001
    frames = p.animate(background="#ffeedd")
    assert frames.shape == (len(p), 48, 64, 4)
    np.testing.assert_array_equal(frames, p.animate(options={"background": "#ffeedd"}))
    # Without keys too (the track's own study stopped with it and would draw nothing more).
    plain = p.animate()
    assert plain.shape == frames.shape and not np.array_equal(plain, frames)
    np.testing.assert_array_equal(p.render(sample=len(p) - 1), plain[-1])


def test_path_render_key_errors_name_the_key():
    p = four_bar().track()
    with pytest.raises(flexure.SceneError) as e:
        p.render(widht=100)
    assert e.value.key == "render.widht" and "did you mean 'width'" in e.value.reason
    with pytest.raises(flexure.SceneError) as e:
        p.animate(width=-3)
    assert e.value.key == "render.width"
    with pytest.raises(flexure.SceneError) as e:
        p.project(line_width="thick")
    assert e.value.key == "projection.line_width"


def test_a_paths_projection_of_other_flexes_is_refused():
    # A Path holds one path: the projection's paths along other flexes are tracked by
    # System.project, not drawn from it.
    w = flexure.load("double_watt")
    s = flexure.framework(w.vertices, w["edges"], w["pinned"], motion={"steps": 20},
                          projection={"flexes": [[1, 0], [0, 1]]})
    p = s.track()
    for call in (lambda: p.project(line_width=2), lambda: p.animate(side_by_side=True, width=200, height=100),
                 lambda: w.track(steps=20).project(both_directions=True)):
        with pytest.raises(flexure.FlexureError, match=r"system\.project"):
            call()
    assert p.animate(width=50, height=40).shape == (21, 40, 50, 4)  # the animation alone draws this path
    assert p.project().ndim == 3  # without keys: the track's own projection, its other paths tracked


def test_a_filmstrip_from_python_is_the_command_lines(cli, tmp_path):
    """render(file, samples=[...]): several samples in one figure, as `flexure render --samples`."""
    keys = dict(width=200, height=150)
    W = flexure.load("double_watt")
    mine = tmp_path / "mine.svg"
    assert W.render(mine, samples=[0, 50, 100], **keys) == str(mine)
    cli(["render", "double_watt", "--samples", "0,50,100", "--set", "render.width=200", "--set", "render.height=150",
         "-o", "theirs.svg"], cwd=tmp_path)
    svg = mine.read_text()
    assert 'width="600" height="150"' in svg  # three panels side by side
    theirs = (tmp_path / "theirs.svg").read_text()
    # The same figure; the parts' ids count vertices as each scene does (Python from 0).
    ids = re.compile(r' id="((?:p\d+-)?[a-z-]+?)-(\d+)(?:-(\d+))?"')
    from_one = ids.sub(lambda m: ' id="%s-%d%s"' % (m[1], int(m[2]) + 1, "-%d" % (int(m[3]) + 1) if m[3] else ""), svg)
    assert from_one == theirs
    assert 'id="bar-0-1"' in svg and 'id="bar-1-2"' in theirs
    # A path's filmstrip: its own samples.
    path = W.track()  # the whole path: drawn in the same view
    assert path.render(tmp_path / "p.svg", samples=[0, 50, 100], **keys) == str(tmp_path / "p.svg")
    assert (tmp_path / "p.svg").read_text() == svg
    with pytest.raises(ValueError, match="samples= needs file="):
        W.render(samples=[0, 1])
    with pytest.raises(TypeError, match="samples is a list"):
        W.render(tmp_path / "x.svg", samples=5)


def test_parts_in_their_own_look_and_a_stress(tmp_path):
    # Edges and vertices counted from 0 in Python (the ids too), as inline tables in [render].
    s = flexure.framework(SQUARE, SQUARE_EDGES + [[0, 2]])
    out = str(tmp_path / "parts.svg")
    s.render(out, edge_styles=[{"edges": [(2, 0)], "color": "red3", "dash": True, "label": "d"}],
             vertex_styles=[{"vertices": [3], "size": 80, "label": "P"}])
    text = open(out).read()
    assert 'id="bar-0-2"' in text and "stroke-dasharray" in text and ">d</text>" in text
    assert ">P</text>" in text and ">3</text>" not in text
    with pytest.raises(flexure.SceneError) as e:
        s.render(str(tmp_path / "x.svg"), edge_styles=[{"edges": [(1, 3)]}])
    assert "[1, 3] is not a bar" in str(e.value)
    # K4 on the square has one stress, by hand: w on the sides and -w on the diagonals
    # (equilibrium at a corner: w (1, 0) + w (0, 1) - w (1, 1) = 0).
    k4 = flexure.framework(SQUARE, SQUARE_EDGES + [[0, 2], [1, 3]])
    out = str(tmp_path / "stress.svg")
    k4.render(out, stress=0)
    text = open(out).read()
    sides = [text.count(f'id="bar-{a}-{b}"') for a, b in SQUARE_EDGES]
    assert sides == [1, 1, 1, 1]
    colour = {m[0]: m[1] for m in re.findall(r'<line class="bar" id="([^"]+)"[^>]*stroke="(#[0-9A-F]{6})"', text)}
    assert {colour["bar-0-1"], colour["bar-1-2"], colour["bar-2-3"], colour["bar-3-0"]} == {colour["bar-0-1"]}
    assert colour["bar-0-2"] == colour["bar-1-3"] != colour["bar-0-1"]
    assert {colour["bar-0-1"], colour["bar-0-2"]} == {"#CD0000", "#1F77B4"}
