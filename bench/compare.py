#!/usr/bin/env python3
"""Compares bench/run's figures with the benchmark tables of docs/benchmarks.md (a report, not a
test: the machine is shared, and its speed varies between days).

For each row of a table in docs/benchmarks.md (every table of that page; in a file with a
"## Benchmarks" section, such as an older README, the tables of that section) whose first cell
names a case that a benchmark printed (the line starts with the same words; a case named in
several tables is taken from the first), the first time in the row (its first "N s" or "N ms";
a range "A-B s" counts as B) is compared with the first CPU time of that line. Cases more than
20 % slower are listed first and loudly.

    bench/compare.py BENCH_OUTPUT [TABLES]

TABLES defaults to docs/benchmarks.md beside this script's bench/ folder. A README.md without
benchmark tables (the tables moved to docs/benchmarks.md) is read as the docs/benchmarks.md
beside it, so that `bench/compare.py OUT README.md` keeps working.
"""

import os
import re
import sys

TIME = re.compile(r"(?<![\w.])(\d+(?:\.\d+)?)(?:-(\d+(?:\.\d+)?))? ?(s|ms)\b")


def seconds(m):
    value = float(m.group(2) or m.group(1))
    return value / 1000.0 if m.group(3) == "ms" else value


def normal(text):
    return re.sub(r"\s+", " ", text.strip().lower())


def table_rows(path):
    """(first cell, first time in seconds) of every benchmark table row of the file."""
    with open(path, encoding="utf-8") as f:
        lines = f.readlines()
    # An older README: the tables of its "## Benchmarks" section only. docs/benchmarks.md: all.
    section = any(line.strip() == "## Benchmarks" for line in lines)
    rows, inside = [], not section
    for line in lines:
        if section and line.startswith("## "):
            inside = line.strip() == "## Benchmarks"
        if inside and line.startswith("| ") and not line.startswith("|---"):
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            for cell in cells[1:]:
                m = TIME.search(cell)
                if m:
                    rows.append((cells[0], seconds(m)))
                    break
    return rows


def bench_time(line):
    m = re.search(r"(\d+(?:\.\d+)?) ?(s|ms) CPU", line) or TIME.search(line)
    if not m:
        return None
    value = float(m.group(1))
    return value / 1000.0 if m.group(2) == "ms" else value


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    lines = [l.rstrip("\n") for l in open(sys.argv[1], encoding="utf-8", errors="replace")]
    default = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "docs", "benchmarks.md")
    path = sys.argv[2] if len(sys.argv) > 2 else default
    rows = table_rows(path)
    if not rows and os.path.basename(path) == "README.md":
        beside = os.path.join(os.path.dirname(os.path.abspath(path)), "docs", "benchmarks.md")
        if os.path.exists(beside):
            print("compare: %s has no benchmark tables; reading %s" % (path, beside), file=sys.stderr)
            path, rows = beside, table_rows(beside)
    if not rows:
        sys.exit("compare: no benchmark table rows in %s" % path)
    slower, other, seen = [], [], set()
    for name, documented in rows:
        key = normal(name)
        if key in seen:  # the first table that names a case is its own (later ones compare it)
            continue
        seen.add(key)
        for line in lines:
            if normal(line).startswith(key):
                now = bench_time(line[len(name):] if line.startswith(name) else line)
                if now is None or documented <= 0:
                    break
                ratio = now / documented
                entry = "%-60s table %9.4f s  now %9.4f s  %5.2fx" % (name[:60], documented, now, ratio)
                (slower if ratio > 1.2 else other).append(entry)
                break
    if slower:
        print("MORE THAN 20 %% SLOWER THAN %s (%d of %d cases compared):" % (os.path.relpath(path), len(slower), len(rows)))
        for e in slower:
            print("  " + e)
    print("within 20 %% or faster (%d cases):" % len(other))
    for e in other:
        print("  " + e)


if __name__ == "__main__":
    main()
