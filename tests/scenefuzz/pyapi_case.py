"""One Python-API case of the scene fuzzer, in its own interpreter (so that a crash of the module is
seen as the death of this process, not of the fuzzer).

    PYTHONPATH=BUILD/python /usr/bin/python3 pyapi_case.py SCENE.toml OUTDIR PLAN.json

PLAN.json: {"steps": [...], "sample": K, "construct": {...} or null}. Prints "STEP name" on stderr
before each step (the last one names the step a crash happened in) and one JSON object on stdout:
{"results": {step: {...}}, "errors": {step: "Type: message"}}.
"""

import json
import math
import os
import sys
import traceback

import numpy as np

import flexure


def step(name):
    sys.stderr.write("STEP " + name + "\n")
    sys.stderr.flush()


def finite_array(a):
    a = np.asarray(a, dtype=float)
    return bool(np.all(np.isfinite(a)))


def main():
    scene, outdir, plan_file = sys.argv[1], sys.argv[2], sys.argv[3]
    with open(plan_file) as f:
        plan = json.load(f)
    res, errs = {}, {}
    S = path = None
    k = plan.get("sample", 0)

    def run(name, fn):
        step(name)
        try:
            r = fn()
            res[name] = r if r is not None else True
            return True
        except flexure.SceneError as e:
            errs[name] = f"SceneError: {e} (key={getattr(e, 'key', None)!r})"
        except flexure.Interrupted as e:
            errs[name] = f"Interrupted: {e}"
        except Exception as e:  # noqa: BLE001 - everything is reported
            errs[name] = f"{type(e).__name__}: {e}\n{traceback.format_exc(limit=3)}"
        return False

    def do_load():
        nonlocal S
        S = flexure.load(scene)
        return {"type": S.type, "dimension": S.dimension, "num_vertices": S.num_vertices}

    def do_vertices():
        return {"finite": finite_array(S.vertices), "shape": list(np.asarray(S.vertices).shape)}

    def do_analyze():
        a = S.analyze()
        return {"json": a.json}

    def do_track():
        nonlocal path
        path = S.track()
        return {"shape": list(path.samples.shape), "finite": finite_array(path.samples),
                "max_residual": path.max_residual, "status": path.status, "summary": path.summary,
                "samples": path.samples.tolist() if path.samples.size <= 20000 else None,
                "events": [{"sample": e.sample, "kind": e.kind} for e in path.events]}

    def out(name):
        return os.path.join(outdir, name)

    steps = plan["steps"]
    if not run("load", do_load):
        print(json.dumps({"results": res, "errors": errs}))
        return
    for s in steps:
        if s == "analyze":
            run(s, do_analyze)
        elif s == "vertices":
            run(s, do_vertices)
        elif s == "track":
            run(s, do_track)
        elif path is None and s in ("write_csv", "write_json", "path_project", "path_render", "path_animate"):
            continue
        elif s == "write_csv":
            run(s, lambda: path.write(out("py_path.csv")))
        elif s == "write_json":
            run(s, lambda: path.write(out("py_path.json")))
        elif s == "path_project":
            run(s, lambda: path.project(out("py_path_projection.png"), data=out("py_path_projection.csv")))
        elif s == "path_render":
            run(s, lambda: path.render(out("py_path_frame.png"), sample=min(k, len(path.samples) - 1)))
        elif s == "path_animate":
            run(s, lambda: path.animate(out("py_path.gif")))
        elif s == "render":
            run(s, lambda: S.render(out("py_frame.png")))
        elif s == "render_array":
            run(s, lambda: {"shape": list(np.asarray(S.render(width=64, height=64)).shape)})
        elif s == "project":
            run(s, lambda: S.project(out("py_projection.png")))
        elif s == "project_array":
            run(s, lambda: {"shape": list(np.asarray(S.project()).shape)})
        elif s == "construct":
            c = plan["construct"]

            def do_construct():
                T = flexure.system(c["type"], c["vertices"], motion=c.get("motion"), render=c.get("render"),
                                   projection=c.get("projection"), **c["keys"])
                p = T.track()
                r = {"shape": list(p.samples.shape), "finite": finite_array(p.samples), "max_residual": p.max_residual,
                     "status": p.status, "samples": p.samples.tolist() if p.samples.size <= 20000 else None}
                step("construct_project")
                p.project(out("py_construct_projection.png"))
                return r
            run(s, do_construct)
        elif s == "track_kwargs":
            kw = plan["track_kwargs"]

            def do_track_kwargs():
                if "contract_edge" in kw:
                    kw["contract_edge"] = tuple(kw["contract_edge"])
                if "fold_crease" in kw:
                    kw["fold_crease"] = tuple(kw["fold_crease"])
                p = S.track(**kw)
                r = {"shape": list(p.samples.shape), "finite": finite_array(p.samples), "max_residual": p.max_residual,
                     "status": p.status}
                step("track_kwargs_project")
                p.project(out("py_kwargs_projection.png"))
                return r
            run(s, do_track_kwargs)
    print(json.dumps({"results": res, "errors": errs}))


if __name__ == "__main__":
    main()
