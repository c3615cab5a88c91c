#!/usr/bin/env python3
"""What a looser tolerance changes in the pile of 300 at its end (README.md beside this file, "The pile of 300 at tol 1e-4").

write DIR      writes into DIR cases/bench/pile_300.scene at tol 1e-6 and 1e-4 (pile_300_tolT.scene) and, for each, three
               realizations whose boxes start up to 0.5 mm away in x and y (uniform, seeds 1, 2 and 3:
               pile_300_tolT_sS.scene): the pile is chaotic, so a single run says nothing of the spread
stats RUN_DIR  one CSV row per run directory, from its trajectory.csv's last sample and summary.json: the boxes'
               mean and 90th-percentile height of their centres (m), the median and 90th-percentile distance of their
               centres from the vertical axis (m), how many move faster than 0.05 m/s (scripts/bench-scale's rest
               threshold), how many lie flat (their own z axis within 8° of the vertical) and the energy at the end (J)

usage: reports/bench/piles/tolerance.py write DIR
       reports/bench/piles/tolerance.py stats LABEL=RUN_DIR ...
"""
import csv
import json
import math
import os
import random
import re
import statistics
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "..", "..", "..", "cases", "bench", "pile_300.scene")
TOLERANCES = ("1e-6", "1e-4")
SEEDS = (1, 2, 3)
SHIFT = 5e-4  # m: well below a box's size, far above the tolerance's effect on one step
REST_SPEED = 0.05  # m/s, as scripts/bench-scale
FLAT_COS = 0.99  # |cos| of the tilt of a box's own z axis: 8.1°


def write(out, tol, seed):
    rnd = random.Random(seed) if seed else None
    lines, fixed_next = [], False
    for line in open(SCENE).read().split("\n"):
        match = re.match(r"^loc (\S+) (\S+) (\S+)(.*)$", line)
        if match and rnd and not fixed_next:
            x = float(match.group(1)) + rnd.uniform(-SHIFT, SHIFT)
            y = float(match.group(2)) + rnd.uniform(-SHIFT, SHIFT)
            line = "loc %.6f %.6f %s%s" % (x, y, match.group(3), match.group(4))
        fixed_next = line.startswith("fixed")
        lines.append(line)
        if line.startswith("tend"):
            lines.append("tol " + tol)
    name = "pile_300_tol%s%s.scene" % (tol, "_s%d" % seed if seed else "")
    with open(os.path.join(out, name), "w") as f:
        f.write("\n".join(lines))


def stats(label, run_dir):
    last = {}
    with open(os.path.join(run_dir, "trajectory.csv")) as f:
        for row in csv.DictReader(f):
            last[row["body"]] = row
    z = sorted(float(r["z"]) for r in last.values())
    radius = sorted(math.hypot(float(r["x"]), float(r["y"])) for r in last.values())
    speeds = [math.sqrt(sum(float(r[k]) ** 2 for k in ("vx", "vy", "vz"))) for r in last.values()]
    flat = 0
    for r in last.values():
        qx, qy = float(r["qx"]), float(r["qy"])
        flat += abs(1.0 - 2.0 * (qx * qx + qy * qy)) > FLAT_COS
    with open(os.path.join(run_dir, "summary.json")) as f:
        energy = json.load(f).get("energy", {}).get("end", float("nan"))
    p90 = lambda values: values[int(0.9 * (len(values) - 1))]
    return [label, len(z), "%.4f" % statistics.mean(z), "%.4f" % p90(z), "%.4f" % statistics.median(radius),
            "%.4f" % p90(radius), sum(s > REST_SPEED for s in speeds), flat, "%.1f" % energy]


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "write":
        os.makedirs(sys.argv[2], exist_ok=True)
        for tol in TOLERANCES:
            for seed in (0,) + SEEDS:
                write(sys.argv[2], tol, seed)
    elif len(sys.argv) >= 3 and sys.argv[1] == "stats":
        out = csv.writer(sys.stdout, lineterminator="\n")
        out.writerow(["run", "bodies", "z_mean_m", "z_p90_m", "radius_median_m", "radius_p90_m", "faster_than_0.05",
                      "flat", "energy_end_J"])
        for arg in sys.argv[2:]:
            label, _, run_dir = arg.partition("=")
            out.writerow(stats(label, run_dir))
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
