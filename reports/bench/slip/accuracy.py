#!/usr/bin/env python3
"""Largest position and velocity difference, over every sample and body, between two runs' trajectory.csv."""
import csv, sys
def load(path):
    rows = {}
    with open(path) as f:
        for r in csv.DictReader(f):
            rows[(r['t'], r['body'])] = r
    return rows
a, b = load(sys.argv[1]), load(sys.argv[2])
dx = dv = 0.0
for k, ra in a.items():
    rb = b.get(k)
    if rb is None: continue
    dx = max(dx, max(abs(float(ra[c]) - float(rb[c])) for c in 'x y z'.split()))
    dv = max(dv, max(abs(float(ra[c]) - float(rb[c])) for c in 'vx vy vz'.split()))
print(f"max|dx| {dx:.3e} m  max|dv| {dv:.3e} m/s")
