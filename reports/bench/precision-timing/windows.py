#!/usr/bin/env python3
"""What a timing of a short work-precision run reads, by its length: from the CPU times of consecutive runs of one
soft point (pd_bench_span's CSV on stdin), each timing being the runs taken back to back until they add up to at
least T of CPU time (gedanken/timing.c), their cost per run. Prints, per T, the timings' count, least, median,
largest and largest/least.
usage: pd_bench_span SCENE --tol T --repeats 1000 --no-record | windows.py LABEL"""
import csv
import statistics
import sys

label = sys.argv[1]
runs = [float(r["cpu_seconds"]) for r in csv.DictReader(sys.stdin)]
for window in (0.0, 0.001, 0.002, 0.005, 0.01, 0.02, 0.05):
    costs, total, count = [], 0.0, 0
    for cpu in runs:
        total += cpu
        count += 1
        if total >= window:
            costs.append(total / count)
            total, count = 0.0, 0
    if len(costs) >= 3:
        print(f"{label},{window * 1e3:g},{len(costs)},{min(costs):.4g},{statistics.median(costs):.4g},{max(costs):.4g},"
              f"{max(costs) / min(costs):.3f}")
