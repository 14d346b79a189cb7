#!/usr/bin/env bash
# The layers depend one way: each folder may include only the folders listed for it (and
# itself). Fails naming every include that points upwards.
set -uo pipefail
cd "$(dirname "$0")/.."
declare -A allowed=(
  [engine]="engine"
  [render]="render"
  [scenes]="scenes engine render/color.h"
  [present]="present scenes engine render"
  [pipeline]="pipeline present scenes engine render"
  [sweep]="sweep pipeline present scenes engine"
  [viewer]="viewer pipeline present scenes engine render"
  [cli]="cli sweep viewer pipeline present scenes engine render"
)
bad=0
checked=0
for layer in "${!allowed[@]}"; do
  # Subfolders too (scenes/systems/).
  for f in $(find "$layer" -name '*.h' -o -name '*.cpp' | sort); do
    while IFS= read -r inc; do
      checked=$((checked + 1))
      ok=0
      for a in ${allowed[$layer]}; do
        case "$inc" in "$a"/*|"$a") ok=1 ;; esac
      done
      if [ $ok -eq 0 ]; then echo "$f includes \"$inc\": $layer may include only ${allowed[$layer]}"; bad=1; fi
    done < <(grep -o '^#include "[^"]*"' "$f" | sed 's/#include "\(.*\)"/\1/' | grep '/')
  done
done
[ $checked -gt 100 ] || { echo "only $checked includes checked: the layout moved?"; exit 1; }
echo "$checked includes checked"
exit $bad
