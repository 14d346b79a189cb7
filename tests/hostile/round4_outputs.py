"""Hostile input, fourth round (issue 62): the MP4 module's loader, output writing, and
certificates counted that are not certificates. Expectations from the contract (README,
docs/user-guide.md "Where the MP4 module is loaded from" and "Sweeps", issue 62), never from what
the binary does."""
import json
import os
import shutil
import subprocess

import __main__ as h

# A libflexure-av.so planted where flexure must not look: loading it runs its constructor, which
# leaves a marker file (dlopen runs constructors before any check).
PLANTED_C = r"""
#include <stdio.h>
__attribute__((constructor)) static void planted(void) {
  FILE* f = fopen(MARKER, "w");
  if (f) { fputs("the planted libflexure-av.so was loaded\n", f); fclose(f); }
}
"""

SMALL = ["--quiet", "--set", "render.width=64", "--set", "render.height=64", "--set", "motion.steps=4"]


def planted_module(d):
    """d/libflexure-av.so whose constructor writes d/LOADED; returns the marker's path."""
    cc = shutil.which("cc") or shutil.which("gcc")
    h.check(cc is not None, "no C compiler (cc) to build the planted module: install gcc (scripts/setup does)")
    marker = os.path.join(d, "LOADED")
    src = h.write(os.path.join(d, "planted.c"), PLANTED_C)
    r = subprocess.run([cc, "-shared", "-fPIC", "-DMARKER=\"%s\"" % marker, "-o",
                        os.path.join(d, "libflexure-av.so"), src], capture_output=True, timeout=60)
    h.check(r.returncode == 0, "cc could not build the planted module: %s" % h.tail(r.stderr))
    return marker


def path_env(bin_dir, **extra):
    env = h.base_env()
    env["PATH"] = bin_dir + os.pathsep + "/usr/bin:/bin"
    env.pop("FLEXURE_AV_MODULE", None)
    env.update(extra)
    return env


def bin_with_flexure(d):
    """d/bin/flexure: a symbolic link to the real executable, as a user's ~/bin holds one."""
    b = os.path.join(d, "bin")
    os.makedirs(b, exist_ok=True)
    link = os.path.join(b, "flexure")
    if not os.path.lexists(link):
        os.symlink(h.FLEXURE, link)
    return b


def is_mp4(path):
    try:
        with open(path, "rb") as f:
            return f.read(8)[4:8] == b"ftyp"
    except OSError:
        return False


def probe_outputs_av_module_not_from_working_directory():
    # flexure started through PATH, from a working directory that holds an entry named
    # `flexure` and a libflexure-av.so: the module comes from beside the real executable only.
    d = h.mkdir("r4_outputs_av_cwd")
    b = bin_with_flexure(d)
    work = os.path.join(d, "work")
    os.makedirs(work, exist_ok=True)
    marker = planted_module(work)
    h.write(os.path.join(work, "flexure"), "not flexure\n")
    r = h.run(["flexure", "animate", "double_watt"] + SMALL + ["-o", "out.mp4"], work, timeout=30,
              env=path_env(b), what="`flexure animate` through PATH")
    h.check(not os.path.exists(marker),
            "the libflexure-av.so of the working directory was loaded (its constructor ran): %r" % r)
    h.expect_rc(r, 0, "animate through PATH with the real module beside the executable")
    h.check(is_mp4(os.path.join(work, "out.mp4")), "no MP4 written: %r" % r)


def probe_outputs_av_module_variable():
    # FLEXURE_AV_MODULE: an absolute path is the one place tried; a relative one is refused
    # (it would name a file of whatever the working directory is), before anything is loaded.
    d = h.mkdir("r4_outputs_av_variable")
    marker = planted_module(d)
    b = bin_with_flexure(d)
    r = h.run(["flexure", "animate", "double_watt"] + SMALL + ["-o", "rel.mp4"], d, timeout=30,
              env=path_env(b, FLEXURE_AV_MODULE="libflexure-av.so"), what="relative FLEXURE_AV_MODULE")
    h.check(not os.path.exists(marker), "a relative FLEXURE_AV_MODULE was loaded: %r" % r)
    h.expect_rc(r, 1, "a relative FLEXURE_AV_MODULE (wrong input)")
    h.check(b"FLEXURE_AV_MODULE" in r.err and b"absolute" in r.err,
            "the refusal does not say that FLEXURE_AV_MODULE must be absolute: %r" % r)
    h.check(not os.path.exists(os.path.join(d, "rel.mp4")), "an MP4 was written anyway")
    missing = os.path.join(d, "nowhere", "libflexure-av.so")
    r = h.run(["flexure", "animate", "double_watt"] + SMALL + ["-o", "miss.mp4"], d, timeout=30,
              env=path_env(b, FLEXURE_AV_MODULE=missing), what="FLEXURE_AV_MODULE naming no file")
    h.expect_rc(r, 3, "FLEXURE_AV_MODULE naming no file (the output cannot be written)")
    h.check(os.fsencode(missing) in r.err, "the message does not name the file tried, %s: %r" % (missing, r))
    h.check(not os.path.exists(marker), "the planted module was loaded")


def probe_outputs_track_json_non_utf8_scene_name():
    # Other JSON writers replace bytes that are not UTF-8; the path JSON must be written too.
    d = h.mkdir("r4_outputs_track_json")
    name = b"tri\xff\xfe.toml"
    h.write(os.path.join(os.fsencode(d), name).decode("utf-8", "surrogateescape"),
            'title = "triangle"\n[system]\ntype = "framework"\nvertices = [[0,0],[1,0],[0.3,0.9]]\n'
            'edges = [[1,2],[2,3]]\n[motion]\nsteps = 3\n')
    out = os.path.join(d, "path.json")
    r = h.run([h.FLEXURE, "track", name, "-o", "path.json"], d, timeout=20, what="track -o path.json")
    h.expect_rc(r, 0, "track of a scene whose file name is not UTF-8, -o path.json")
    h.check(os.path.exists(out), "path.json was not written: %r" % r)
    with open(out, "rb") as f:
        data = f.read()
    try:
        j = json.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as e:
        raise h.Fail("path.json is not valid UTF-8 JSON: %s" % e)
    h.check(len(j.get("samples", [])) == 4, "path.json has %d samples, not 4" % len(j.get("samples", [])))


PY_NUL = r"""
import os, sys, flexure
p = flexure.load("double_watt").track(steps=3)
bad = []
for name in ("a.csv\0.json", "b.json\0.csv", "c.json\0"):
    try:
        p.write(name)
        bad.append("%r: written" % name)
    except (flexure.OutputError, ValueError) as e:
        if "NUL" not in str(e) and "null" not in str(e):
            bad.append("%r: refused without saying why: %s" % (name, e))
    except Exception as e:
        bad.append("%r: %s: %s" % (name, type(e).__name__, e))
left = sorted(os.listdir("."))
if left:
    bad.append("files written: %r" % left)
print("\n".join(bad))
sys.exit(1 if bad else 0)
"""


def probe_outputs_python_nul_in_file_name():
    # The system cuts a name at its NUL: "a.csv\0.json" must not become the file a.csv holding
    # JSON (nor any file): refused like open() refuses it.
    d = h.mkdir("r4_outputs_python_nul")
    r = h.run_py(PY_NUL, d, timeout=30, what="Path.write with a NUL in the name")
    h.check(r.rc == 0, "Path.write with a NUL in the file name: %s %s" % (h.tail(r.out), h.tail(r.err)))


# The certificates: a rigid triangle, K4 with a pendant edge (flexible with a stress: its verdict
# cannot be proved in floating point, "certified": false), a 4-cycle (flexible, provable), K3,3
# (generically rigid), in turn.
def cert_graphs():
    k4_pendant = h.graph6(5, h.complete(4) + [(0, 4)])
    return [h.graph6(3, h.complete(3)), k4_pendant, h.graph6(4, h.cycle(4)),
            h.graph6(6, h.kmn(3, 3)), k4_pendant, h.graph6(4, h.cycle(4))]


def forged(line):
    return line.replace('"certified":false', '"certified":true')


def certified_of(lines):
    return sum(1 for l in lines if json.loads(l).get("certified") is True)


def summary_of(path):
    return h.read_jsonl(path)[-1]["summary"]


def probe_outputs_sweep_forged_certified_resume():
    # A rerun takes over the lines its output holds; one edited to say "certified": true must
    # not raise the count of certified results, and the summary says how many were taken over.
    d = h.mkdir("r4_outputs_certified_resume")
    h.write_g6(os.path.join(d, "G.g6"), cert_graphs())
    args = ["sweep", "analyze", "G.g6", "--certify", "--threads", "1", "--seed", "3"]
    r = h.flex(*args, "-o", "full.jsonl", cwd=d, timeout=30)
    h.expect_rc(r, 0, "the genuine sweep")
    with open(os.path.join(d, "full.jsonl")) as f:
        lines = f.read().splitlines()[:-1]
    h.check(len(lines) == 6, "the genuine sweep has %d item lines, not 6" % len(lines))
    genuine_rest = certified_of(lines[3:])
    claims = certified_of(forged(l) for l in lines[:3])
    h.check(claims > certified_of(lines[:3]), "nothing to forge: the first 3 lines are all certified")
    h.write(os.path.join(d, "cut.jsonl"), "".join(forged(l) + "\n" for l in lines[:3]))
    r = h.flex(*args, "-o", "cut.jsonl", cwd=d, timeout=30)
    h.expect_rc(r, 0, "the rerun of a cut output with forged lines")
    s = summary_of(os.path.join(d, "cut.jsonl"))
    h.check(s.get("certified") == genuine_rest,
            "the rerun counts %r certified where it computed %d certificates (3 lines forged): %s"
            % (s.get("certified"), genuine_rest, json.dumps(s)[:400]))
    h.check(s.get("certified_unverified") == claims,
            "the summary does not say that %d certificates were taken over unverified: %s" % (claims, json.dumps(s)[:400]))
    h.check(b"not verified" in r.out, "the printed summary does not say that claims were not verified: %s" % h.tail(r.out))
    # The whole output read back: nothing this run certified.
    r = h.flex(*args, "-o", "cut.jsonl", cwd=d, timeout=30)
    h.expect_rc(r, 0, "the rerun of a complete output")
    h.check(b"; 0 certified" in r.out, "a rerun that computed nothing prints certificates: %s" % h.tail(r.out))


def probe_outputs_sweep_forged_certified_merge():
    # The merge takes over every shard's lines: forging one must not change the count of
    # certified results, which the merge has not verified.
    d = h.mkdir("r4_outputs_certified_merge")
    h.write_g6(os.path.join(d, "G.g6"), cert_graphs())
    for k in (0, 1):
        r = h.flex("sweep", "analyze", "G.g6", "--certify", "--threads", "1", "--slice", "%d/2" % k,
                   "-o", "s%d.jsonl" % k, cwd=d, timeout=30)
        h.expect_rc(r, 0, "shard %d/2" % k)
    r = h.flex("sweep", "merge", "s0.jsonl", "s1.jsonl", "-o", "genuine.jsonl", cwd=d, timeout=20)
    h.expect_rc(r, 0, "the merge of the genuine shards")
    genuine = summary_of(os.path.join(d, "genuine.jsonl"))
    with open(os.path.join(d, "s0.jsonl")) as f:
        s0 = f.read().splitlines()
    h.check(forged("\n".join(s0[:-1])) != "\n".join(s0[:-1]), "nothing to forge in shard 0: every line is certified")
    claims = certified_of(forged(l) for l in s0[:-1])
    with open(os.path.join(d, "s1.jsonl")) as f:
        claims += certified_of(f.read().splitlines()[:-1])
    h.write(os.path.join(d, "s0.jsonl"), "".join(forged(l) + "\n" for l in s0[:-1]) + s0[-1] + "\n")
    r = h.flex("sweep", "merge", "s0.jsonl", "s1.jsonl", "-o", "merged.jsonl", cwd=d, timeout=20)
    h.expect_rc(r, 0, "the merge of a forged shard")
    s = summary_of(os.path.join(d, "merged.jsonl"))
    h.check(s.get("certified") == genuine.get("certified") and (s.get("certified") or 0) == 0,
            "the merge counts %r certified (the genuine shards: %r), none of which it verified"
            % (s.get("certified"), genuine.get("certified")))
    h.check(s.get("certified_unverified") == claims,
            "the merged summary does not say that %d certificates were taken over unverified: %s"
            % (claims, json.dumps(s)[:400]))
    h.check(b"not verified" in r.out, "the merge's report does not say the claims were not verified: %s" % h.tail(r.out))


HEAVY = []
LIGHT = [probe_outputs_av_module_not_from_working_directory, probe_outputs_av_module_variable,
         probe_outputs_track_json_non_utf8_scene_name, probe_outputs_python_nul_in_file_name,
         probe_outputs_sweep_forged_certified_resume, probe_outputs_sweep_forged_certified_merge]
