#!/usr/bin/env python3
"""Per Gedanken experiment, the CPU time each soft variant needs to reach the experiment's tolerance: the cheapest
point of precision.csv (`polydyn gedanken --precision`) whose error is within the tolerance (no interpolation), and
the ratios dopri / adaptive and implicit-dopri / implicit. Usage: gedanken_cost.py precision.csv > gedanken-cost.csv"""
import csv
import statistics
import sys

rows = list(csv.DictReader(open(sys.argv[1])))
variants = ["adaptive", "dopri", "implicit", "implicit-dopri"]
best = {}
for r in rows:
    if r["engine"] != "soft" or r["variant"] not in variants or r["status"] != "ok":
        continue
    if not r["error"] or not r["tolerance"] or float(r["error"]) > float(r["tolerance"]):
        continue
    key = (r["experiment"], r["variant"])
    cost = (float(r["cpu_seconds"]), int(r["steps"]), int(r["derivatives"]), r["value"])
    if key not in best or cost[0] < best[key][0]:
        best[key] = cost
experiments = sorted({r["experiment"] for r in rows if r["engine"] == "soft"})
out = csv.writer(sys.stdout, lineterminator="\n")
head = ["experiment"]
for v in variants:
    head += [v + "_cpu_s", v + "_steps", v + "_derivatives", v + "_tol"]
head += ["dopri_over_adaptive", "implicit_dopri_over_implicit"]
out.writerow(head)
ratios = {"d": [], "i": []}
reached = {v: 0 for v in variants}
for x in experiments:
    line = [x]
    for v in variants:
        b = best.get((x, v))
        if b:
            reached[v] += 1
        line += ["%.4f" % b[0], b[1], b[2], b[3]] if b else ["", "", "", ""]
    for tag, (a, bv) in (("d", ("dopri", "adaptive")), ("i", ("implicit-dopri", "implicit"))):
        if (x, a) in best and (x, bv) in best:
            q = best[(x, a)][0] / best[(x, bv)][0]
            ratios[tag].append(q)
            line.append("%.3f" % q)
        else:
            line.append("")
    out.writerow(line)
for tag, name in (("d", "dopri / adaptive"), ("i", "implicit-dopri / implicit")):
    q = ratios[tag]
    if q:
        print("# %s: median %.3f over %d experiments, cheaper on %d" % (name, statistics.median(q), len(q),
              sum(1 for v in q if v < 1.0)), file=sys.stderr)
print("# reached: " + ", ".join("%s %d" % (v, reached[v]) for v in variants), file=sys.stderr)
