#!/usr/bin/env python3
"""Compares two output directories of a polydyn batch command byte for byte, except the measured times.

usage: same_outputs.py DIR_A DIR_B

The same files must exist in both, with the same bytes, except (docs/commands.md):
  - CSV columns named wall_seconds, cpu_seconds, wall_per_sim_second or cpu_per_sim_second, and CSV rows whose quantity is one of
    them (cubetoss's summary.csv): their other fields must be the same strings;
  - in JSON files the "timing" line of a run's summary.json and the value of "wall_seconds" (sweep's
    reference.json).
Prints each difference; exits 1 when there is one, 0 otherwise.
"""
import csv
import io
import os
import re
import sys

TIMING = {"wall_seconds", "cpu_seconds", "wall_per_sim_second", "cpu_per_sim_second"}


def files(root):
    found = set()
    for folder, _, names in os.walk(root):
        for name in names:
            found.add(os.path.relpath(os.path.join(folder, name), root))
    return found


def without_timing_csv(data):
    rows = list(csv.reader(io.StringIO(data.decode("utf-8"), newline="")))
    if not rows:
        return rows
    keep = [i for i, name in enumerate(rows[0]) if name not in TIMING]
    return [[row[i] for i in keep if i < len(row)] for row in rows if not TIMING.intersection(row)]


def without_timing_json(data):
    text = data.decode("utf-8")
    text = re.sub(r'"wall_seconds": [^,}\n]*', '"wall_seconds": _', text)
    return [line for line in text.split("\n") if '"timing"' not in line]


def same(path_a, path_b, name):
    with open(path_a, "rb") as f:
        a = f.read()
    with open(path_b, "rb") as f:
        b = f.read()
    if a == b:
        return True
    if name.endswith(".csv"):
        return without_timing_csv(a) == without_timing_csv(b)
    if name.endswith(".json"):
        return without_timing_json(a) == without_timing_json(b)
    return False


def main():
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    a, b = sys.argv[1], sys.argv[2]
    fa, fb = files(a), files(b)
    differences = 0
    for name in sorted(fa ^ fb):
        print(f"only in {a if name in fa else b}: {name}")
        differences += 1
    for name in sorted(fa & fb):
        if not same(os.path.join(a, name), os.path.join(b, name), name):
            print(f"differs beyond the measured times: {name}")
            differences += 1
    print(f"{len(fa & fb)} files compared, {differences} differences")
    return 1 if differences else 0


if __name__ == "__main__":
    sys.exit(main())
