#!/usr/bin/env python3
"""Position error RMS (over samples and bodies, each over its body's size) of islands on and off at the
scene's tol against islands off at tol/100. usage: accuracy.py POLYDYN SCENE TEND OUTDIR"""
import csv, json, math, os, subprocess, sys

pd, scene, tend, out = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4]
os.makedirs(out, exist_ok=True)
text = open(scene).read()
tol = 1e-6
for line in text.splitlines():
    if line.split()[:1] == ["tol"]:
        tol = float(line.split()[1])
tight = os.path.join(out, "tight.scene")
open(tight, "w").write("\n".join(l for l in text.splitlines() if l.split()[:1] != ["tol"]) + f"\ntol {tol / 100!r}\n")

def run(sc, islands, name):
    d = os.path.join(out, name)
    if not os.path.exists(os.path.join(d, "summary.json")):
        subprocess.run([pd, "run", sc, "--tend", tend, "--islands", islands, "--out", d], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    rows = {}
    with open(os.path.join(d, "trajectory.csv")) as f:
        for r in csv.DictReader(f):
            rows[(r["t"], r["body"])] = (float(r["x"]), float(r["y"]), float(r["z"]))
    return rows, json.load(open(os.path.join(d, "summary.json")))

ref, sref = run(tight, os.environ.get("REF_ISLANDS", "off"), "ref")
size = {b["name"]: b["size"] for b in sref["bodies"]} if "size" in sref["bodies"][0] else None
res = {}
for mode in ("off", "on"):
    rows, s = run(scene, mode, mode)
    acc, n, worst = 0.0, 0, 0.0
    for k, p in rows.items():
        q = ref[k]
        L = size[k[1]] if size else 1.0
        e = math.dist(p, q) / L
        acc += e * e
        n += 1
        worst = max(worst, e)
    c = s["counts"]
    res[mode] = dict(rms=math.sqrt(acc / n), final_max=worst, accepted=c["accepted_steps"],
                     derivatives=c["derivative_evaluations"], onset_retries=c["onset_retries"],
                     late_onsets=s["warnings"]["late_onset"], islands=s.get("island_counts"))
print(json.dumps({"scene": scene, "tend": tend, "tol": tol, "size_known": size is not None, **res}, indent=1))
