#!/usr/bin/env python3
"""Summarises probe files (probe-main.patch, probe.patch: PD_SLIP_PROBE=FILE) into rows of tightness.csv.

Each probe row is one trial step: `refused` (a stick-slip change asked for a halving) or, with probe.patch, `left`
(its changes left inside the step; `floor` here when its bound exceeded tol: the halvings had reached their floor),
with probe-main.patch `ordinary` (any accepted step not cut). e is the true error of the trial's result against the
same step in 64 RK4 substeps, in the error norm; bound is the stick-slip bound the engine formed; pinf (probe-main
only) the bound this branch adopts, formed beside main's; clamp > 0 when a contact's normal force crossed zero in
the step (a release). Usage: analyse.py LABEL=FILE ... > tightness.csv
"""
import csv
import sys


def quantiles(values):
    v = sorted(values)
    n = len(v)
    if n == 0:
        return [0, "", "", "", "", ""]
    return [n, v[n // 2], v[int(0.9 * n)], v[int(0.99 * n)], v[-1], sum(x > 2.0 for x in v) / n]


def kind(row):
    if row["kind"] == "left" and float(row["bound"]) > float(row["tol"]):
        return "floor"
    return row["kind"]


def main():
    out = csv.writer(sys.stdout, lineterminator="\n")
    out.writerow(["run", "steps", "release_in_step", "measure", "n", "p50", "p90", "p99", "max", "share_above_2"])
    for arg in sys.argv[1:]:
        label, path = arg.split("=", 1)
        rows = list(csv.DictReader(open(path)))
        for k in ("refused", "left", "floor", "ordinary"):
            for release in (False, True):
                sel = [r for r in rows if kind(r) == k and (int(r.get("clamp", "0")) > 0) == release]
                if not sel:
                    continue
                tol = float(sel[0]["tol"])
                measures = {"e/tol": [float(r["e"]) / tol for r in sel]}
                if k != "ordinary":
                    measures["e/bound"] = [float(r["e"]) / float(r["bound"]) for r in sel if float(r["bound"]) > 0]
                if k == "refused" and any(float(r.get("pinf", "0")) > 0 for r in sel):
                    measures["e/new_bound"] = [float(r["e"]) / float(r["pinf"]) for r in sel if float(r["pinf"]) > 0]
                    left = [r for r in sel if 0 < float(r["pinf"]) <= tol]
                    measures["e/tol where new_bound<=tol"] = [float(r["e"]) / tol for r in left]
                for name, values in measures.items():
                    out.writerow([label, k, int(release), name] + [f"{x:.4g}" if isinstance(x, float) else x
                                                                   for x in quantiles(values)])


if __name__ == "__main__":
    main()
