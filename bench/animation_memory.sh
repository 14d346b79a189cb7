#!/usr/bin/env bash
# Peak memory (maximum resident set size, by /usr/bin/time -v) of `flexure animate` writing a
# 1,000-frame 1000x1000 animation of the double Watt, as GIF and as MP4. Target: under 400 MB
# each (frames stream through the encoder; a GIF's palette pass keeps at most 128 MB of frames).
#   bench/animation_memory.sh [build/flexure]
set -euo pipefail
bin=${1:-build/flexure}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
for ext in gif mp4; do
  /usr/bin/time -v "$bin" animate double_watt --quiet --set motion.steps=999 --set render.width=1000 \
    --set render.height=1000 --set render.gif_size=1000 --set render.fps=50 -o "$dir/a.$ext" \
    >"$dir/out" 2>"$dir/time"
  kb=$(sed -n 's/.*Maximum resident set size (kbytes): //p' "$dir/time")
  cpu=$(awk -F': ' '/User time/ {u=$2} /System time/ {s=$2} END {printf "%.1f", u + s}' "$dir/time")
  printf 'animate double_watt %s 1000x1000 1000 frames | peak memory %4d MB | CPU %s s | %s\n' \
    "${ext^^}" $((kb / 1024)) "$cpu" "$(stat -c %s "$dir/a.$ext" | awk '{printf "%.1f MB file", $1 / 1048576}')"
done
