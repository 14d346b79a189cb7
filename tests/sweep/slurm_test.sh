#!/usr/bin/env bash
# flexure sweep --slurm against a real Slurm: brings up a single-node Slurm (scripts/slurm-up:
# munged, slurmctld and slurmd started by hand on loopback ports), submits two sweeps as job
# arrays with their merge jobs, and checks that each merged result is the file a local run of
# the same sweep writes, byte for byte once the fields whose names contain "time" are taken out.
# Tears the daemons down by their pids on every exit. Needs root and nauty's geng (scripts/setup
# installs it); exit 77 (skipped) when not root.
#   tests/sweep/slurm_test.sh FLEXURE
set -euo pipefail
FLEXURE=$(readlink -f "$1")
SRC=$(cd "$(dirname "$0")/../.." && pwd)
[ "$(id -u)" -eq 0 ] || { echo "slurm test: skipped (needs root for slurmd and munged)"; exit 77; }
GENG=$(command -v nauty-geng || command -v geng) || { echo "slurm test: nauty's geng is missing (scripts/setup)"; exit 1; }

export ROOT=$(mktemp -d /tmp/flexure-slurm.XXXXXX)
WORK=$(mktemp -d /tmp/flexure-slurm-work.XXXXXX)
cleanup() {
  "$SRC/scripts/slurm-down"
  rm -rf "$ROOT" "$WORK"
}
trap cleanup EXIT
SECONDS=0
export SLURM_CONF=$("$SRC/scripts/slurm-up")
echo "slurm test: node idle after ${SECONDS} s ($SLURM_CONF)"
cd "$WORK"

# Every line with the fields whose names contain "time" removed (they are measurements), and the
# command in its provenance (a task's is not the local run's).
untimed() {
  /usr/bin/python3 -c '
import json, sys
def drop(o):
    if isinstance(o, dict):
        return {k: drop(v) for k, v in o.items() if "time" not in k and k != "command"}
    return o
for line in open(sys.argv[1]):
    print(json.dumps(drop(json.loads(line)), separators=(",", ":")))' "$1"
}

# Waits (up to 180 s) until Slurm has no job left from those given.
wait_jobs() {
  for _ in $(seq 1 900); do
    [ -z "$(squeue -h -j "$1" 2>/dev/null)" ] && return 0
    sleep 0.2
  done
  echo "slurm test: jobs $1 still queued after 180 s"; squeue; return 1
}

check() {  # name, local file, slurm file
  [ -s "$3" ] || { echo "FAIL $1: the merge job wrote nothing"; cat "$3".shards/*.log; exit 1; }
  if cmp -s <(untimed "$2") <(untimed "$3"); then
    echo "ok $1: $(($(wc -l < "$3") - 1)) items, the merged file is the local run's (time fields aside)"
  else
    echo "FAIL $1: the merged file differs from the local run"; diff <(untimed "$2") <(untimed "$3") | head -c 2000; exit 1
  fi
}

# 1. Every connected graph on 8 vertices with 13 edges, analysed in 2D: 4 array tasks.
"$GENG" -c -q 8 13:13 > g8.g6
"$FLEXURE" sweep analyze g8.g6 -o local8.jsonl --quiet
read -r array merge < <("$FLEXURE" sweep analyze g8.g6 --slurm --tasks 4 -o slurm8.jsonl | tail -1)
wait_jobs "$array,$merge"
check "graphs n=8, 4 tasks" local8.jsonl slurm8.jsonl
rigid=$(tail -1 slurm8.jsonl | /usr/bin/python3 -c 'import json,sys; print(json.load(sys.stdin)["summary"]["verdicts"]["rigid"])')
[ "$rigid" = 608 ] || { echo "FAIL: $rigid rigid graphs, Laman graphs on 8 vertices are 608 (OEIS A227117)"; exit 1; }
echo "ok 608 generically rigid, as OEIS A227117 counts the Laman graphs on 8 vertices"

# 2. geng's output on standard input, 3D, two realizations per graph, a filter: 3 tasks, at
#    most 2 at once.
"$GENG" -c -q 6 10:12 > g6.g6
"$FLEXURE" sweep analyze - --dimension 3 --realizations 2 --seed 7 \
  --where "nontrivial_inf_flexes > 0 and stress_dim > 0" -o local6.jsonl --quiet < g6.g6
read -r array merge < <("$FLEXURE" sweep analyze - --dimension 3 --realizations 2 --seed 7 \
  --where "nontrivial_inf_flexes > 0 and stress_dim > 0" --slurm --tasks 3 --max-running 2 -o slurm6.jsonl < g6.g6 | tail -1)
wait_jobs "$array,$merge"
check "stdin, 3D, 2 realizations, --where, 3 tasks" local6.jsonl slurm6.jsonl
# 3. An awkward working directory and output name (a quote, a blank, '#' and '%': issue 42):
#    sbatch takes them as its own arguments (--chdir, --output with % escaped); the logs land in
#    the shard directory under their pattern's names.
AWK="$WORK/Bob's runs #3 %x"
mkdir -p "$AWK"
cp g8.g6 "$AWK/g8.g6"
(cd "$AWK" && "$FLEXURE" sweep analyze g8.g6 -o 'local 50%.jsonl' --quiet)
read -r array merge < <(cd "$AWK" && "$FLEXURE" sweep analyze g8.g6 --slurm --tasks 2 -o 'res 50%.jsonl' | tail -1)
wait_jobs "$array,$merge"
check "awkward names, 2 tasks" "$AWK/local 50%.jsonl" "$AWK/res 50%.jsonl"
logs=$(ls "$AWK/res 50%.jsonl.shards/" | grep -c '^slurm-.*\.log$' || true)
[ "$logs" -ge 3 ] || { echo "FAIL: $logs Slurm logs in the shard directory, expected 3"; ls -la "$AWK/res 50%.jsonl.shards"; exit 1; }
echo "ok the logs of the 2 tasks and the merge are in the shard directory under their own names"
echo "slurm test: passed in ${SECONDS} s"
