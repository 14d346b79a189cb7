#!/usr/bin/env bash
# The installed tree works alone (cmake/install.cmake): the build is installed into a temporary
# prefix, the prefix is moved elsewhere (so nothing may refer to where it was installed), and the
# moved tree is run with a clean environment:
#   - bin/flexure --version, --help (its commands), catalog;
#   - no RPATH or RUNPATH naming the build tree, and no path of it in the executables or the module;
#   - a PNG through bin/flexure (the drawing runs in the installed bin/flexure-draw);
#   - an MP4 with lib/flexure/libflexure-av.so: the loader's own report (LD_DEBUG=files: the files
#     it made a link map for, i.e. loaded; the candidates it only tried are listed too) must name
#     the installed module, not the build tree's;
#   - the Slurm scripts of `sweep --slurm --dry-run` name the installed executable;
#   - the man page: `man -l` renders it without warnings, `man -M PREFIX/share/man` finds
#     flexure and flexure-draw, and it has a section for every command `flexure --help` lists;
#   - the Python package (when built): imported from the prefix, an analysis, and an MP4 through
#     the package's own copy of libflexure-av.so.
#
#   tests/install/run.sh BUILD_DIR VERSION PYTHON_MODULE
#     PYTHON_MODULE  the built module's file, or - when the build has no Python module (the
#                    package's folder under the prefix is the build's FLEXURE_INSTALL_PYTHONDIR)
# Exit status: 0 every check passed; 1 a check failed (what, on stderr); 77 skipped (the Python
# module is configured but not built: `cmake --install` needs it).
set -uo pipefail

if [ $# -ne 3 ]; then
  echo "usage: $0 BUILD_DIR VERSION PYTHON_MODULE|-" >&2
  exit 2
fi
build=$(realpath "$1")
version=$2
python_module=$3
python=/usr/bin/python3

fail() {
  echo "install test: FAILED: $*" >&2
  exit 1
}

if [ "$python_module" != "-" ] && [ ! -f "$python_module" ]; then
  echo "install test: skipped: the Python module $python_module is not built, and cmake --install" \
       "installs it (cmake --build $build builds everything)" >&2
  exit 77
fi
if [ "$python_module" != "-" ]; then
  python_dir=$(sed -n 's/^FLEXURE_INSTALL_PYTHONDIR:[A-Z]*=//p' "$build/CMakeCache.txt")
  [ -n "$python_dir" ] || fail "$build/CMakeCache.txt has no FLEXURE_INSTALL_PYTHONDIR (cmake/install.cmake sets it)"
fi
for tool in readelf man; do
  command -v "$tool" >/dev/null || fail "$tool is not installed (scripts/setup installs binutils and man-db)"
done

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
tmp=$(realpath "$tmp")
started=$(date +%s%N)

cmake --install "$build" --prefix "$tmp/installed" >"$tmp/install.log" 2>&1 ||
  fail "cmake --install $build --prefix $tmp/installed: $(tail -5 "$tmp/install.log")"
mv "$tmp/installed" "$tmp/moved"
P=$tmp/moved

man_page=share/man/man1/flexure.1.gz
[ -f "$P/$man_page" ] || man_page=share/man/man1/flexure.1
expected=(bin/flexure bin/flexure-draw lib/flexure/libflexure-av.so "$man_page" share/doc/flexure/README.md
          share/doc/flexure/docs/user-guide.md)
if [ "$python_module" != "-" ]; then
  module_name=$(basename "$python_module")
  expected+=("$python_dir/flexure/__init__.py" "$python_dir/flexure/$module_name"
             "$python_dir/flexure/libflexure-av.so")
fi
for f in "${expected[@]}"; do
  [ -f "$P/$f" ] || fail "cmake --install did not install $f (installed: $(cd "$P" && find . -type f | sort | tr '\n' ' '))"
done
for f in bin/flexure bin/flexure-draw; do
  [ -x "$P/$f" ] || fail "$f is not executable"
done

# No search path into the build tree (CMake removes the build RPATH on install).
for f in bin/flexure bin/flexure-draw lib/flexure/libflexure-av.so ${module_name:+"$python_dir/flexure/$module_name"}; do
  paths=$(readelf -d "$P/$f" | grep -E '\((RPATH|RUNPATH)\)')
  case "$paths" in
    *"$build"*) fail "$f searches the build tree for libraries: $paths" ;;
  esac
done

# No path of the build tree compiled in (issue 62: the MP4 loader's last resort was the build
# tree's libflexure-av.so, a library that would run its code wherever the build tree is now).
for f in bin/flexure bin/flexure-draw ${module_name:+"$python_dir/flexure/$module_name"}; do
  if grep -q -a -F "$build/" "$P/$f"; then
    fail "$f holds a path of the build tree $build: $(strings "$P/$f" | grep -F "$build/" | head -3 | tr '\n' ' ')"
  fi
done

# Everything below runs in a clean environment: no PATH to the build tree, no PYTHONPATH, no
# LD_LIBRARY_PATH, no FLEXURE_* variable.
mkdir "$tmp/work"
cd "$tmp/work" || fail "cannot enter $tmp/work"
run() {
  env -i HOME="$tmp/work" PATH=/usr/bin:/bin LANG=C.UTF-8 "$@"
}

out=$(run "$P/bin/flexure" --version 2>&1) || fail "bin/flexure --version exited with $?: $out"
[ "$out" = "flexure $version" ] || fail "bin/flexure --version printed '$out', not 'flexure $version'"

help=$(run "$P/bin/flexure" --help 2>&1) || fail "bin/flexure --help exited with $?: $help"
commands=$(printf '%s\n' "$help" | sed -n '/^Subcommands:$/,/^$/s/^  \([a-z][a-z-]*\) .*/\1/p')
[ -n "$commands" ] || fail "bin/flexure --help lists no commands under 'Subcommands:': $help"
for c in analyze track render animate sweep catalog; do
  grep -qx "$c" <<<"$commands" || fail "bin/flexure --help does not list '$c' (it lists: $(echo $commands))"
done

catalog=$(run "$P/bin/flexure" catalog 2>&1) || fail "bin/flexure catalog exited with $?: $catalog"
grep -q '^double_watt ' <<<"$catalog" || fail "bin/flexure catalog does not list double_watt: $(head -3 <<<"$catalog")..."

small=(--quiet --set render.width=200 --set render.height=200)
out=$(run "$P/bin/flexure" render double_watt "${small[@]}" -o frame.png 2>&1) ||
  fail "bin/flexure render double_watt -o frame.png exited with $?: $out"
[ "$(head -c 8 frame.png | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a" ] ||
  fail "bin/flexure render wrote no PNG: $(ls -l frame.png 2>&1)"

out=$(run LD_DEBUG=files LD_DEBUG_OUTPUT="$tmp/ld-animate" "$P/bin/flexure" animate double_watt "${small[@]}" \
      --set motion.steps=10 -o motion.mp4 2>&1) ||
  fail "bin/flexure animate double_watt -o motion.mp4 exited with $?: $out"
[ "$(head -c 8 motion.mp4 | tail -c 4)" = "ftyp" ] || fail "bin/flexure animate wrote no MP4: $(ls -l motion.mp4 2>&1)"
loaded=$(cat "$tmp"/ld-animate.* | sed -n 's/.*file=\([^ ]*libflexure-av\.so\) .*generating link map.*/\1/p' | sort -u)
[ "$loaded" = "$P/lib/flexure/libflexure-av.so" ] ||
  fail "bin/flexure animate loaded '$loaded' as its MP4 module, not the installed $P/lib/flexure/libflexure-av.so"

printf 'EFz_\n' >k33.g6
out=$(run "$P/bin/flexure" sweep analyze k33.g6 --slurm --dry-run --tasks 2 -o result.jsonl 2>&1) ||
  fail "bin/flexure sweep --slurm --dry-run exited with $?: $out"
grep -qE "^'?$P/bin/flexure'? sweep analyze" <<<"$out" ||
  fail "the Slurm array script does not run the installed $P/bin/flexure: $out"

# The man page renders, with a section per command, and is found where man looks under a prefix.
page=$(run MANWIDTH=100 man -l "$P/$man_page" 2>&1) || fail "man -l $man_page exited with $?: $page"
warnings=$(run MANWIDTH=100 man --warnings -l "$P/$man_page" 2>&1 >/dev/null)
[ -z "$warnings" ] || fail "man --warnings -l $man_page: $warnings"
grep -q '^       flexure, flexure-draw - ' <<<"$page" || fail "the man page's NAME is not 'flexure, flexure-draw - ...': $(printf '%s\n' "$page" | head -5)"
for c in $commands; do
  grep -qx "   $c" <<<"$page" || fail "the man page has no section for the command '$c'"
done
for name in flexure flexure-draw; do
  found=$(run MANWIDTH=100 man -M "$P/share/man" "$name" 2>&1 | head -1) || true
  case "$found" in
    FLEXURE\(1\)*) ;;
    *) fail "man -M PREFIX/share/man $name does not show flexure(1): $found" ;;
  esac
done

if [ "$python_module" != "-" ]; then
  out=$(run LD_DEBUG=files LD_DEBUG_OUTPUT="$tmp/ld-python" PYTHONPATH="$P/$python_dir" "$python" -c '
import sys
import flexure
import flexure._flexure
prefix = sys.argv[1]
for m in (flexure, flexure._flexure):
    if not m.__file__.startswith(prefix + "/"):
        sys.exit(f"{m.__name__} was imported from {m.__file__}, not from the prefix {prefix}")
a = flexure.load("double_watt").analyze()
if a.rigid != "flexible":
    sys.exit(f"double_watt from the installed package: {a.rigid}, not flexible")
flexure.load("double_watt").track(steps=10).animate("python.mp4", width=200, height=200)
' "$P" 2>&1) || fail "the installed Python package (PYTHONPATH=PREFIX/$python_dir): $out"
  [ "$(head -c 8 python.mp4 | tail -c 4)" = "ftyp" ] || fail "the installed Python package wrote no MP4"
  loaded=$(cat "$tmp"/ld-python.* | sed -n 's/.*file=\([^ ]*libflexure-av\.so\) .*generating link map.*/\1/p' | sort -u)
  [ "$loaded" = "$P/$python_dir/flexure/libflexure-av.so" ] ||
    fail "the installed Python package loaded '$loaded' as its MP4 module, not $P/$python_dir/flexure/libflexure-av.so"
fi

size=$(du -sk "$P" | cut -f1)
elapsed=$((($(date +%s%N) - started) / 1000000))
echo "install test: passed: installed ${size} KB into a prefix, moved it, and ran it from there (${elapsed} ms)"
