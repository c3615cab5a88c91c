#!/usr/bin/env python3
"""The fixed RK4 stepper's stability warning (docs/integration.md, "Steppers"): `polydyn run --stepper fixed` warns
on stderr, once, when the step exceeds ω h ≤ 2.5 for the scene's stiffest contact (ω = 2π / summary.json's
contact_period_min), and not when it is within it; a run at a step within the bound, given with --step, finishes
(exit 0, completed) with a finite trajectory. cases/examples/demo.scene's dt (1e-3 s) is 2.6 times its bound.

usage: test_fixed_step.py POLYDYN SOURCE_DIR
"""
import csv
import json
import math
import os
import re
import subprocess
import sys
import tempfile

PD, SRC = sys.argv[1], sys.argv[2]
SCENE = os.path.join(SRC, "cases", "examples", "demo.scene")
STABLE_OMEGA_STEP = 2.5  # ω h of the engine's RK4 stability bound (PD_STABLE_STEP_OMEGA, engine/include/polydyn/model.h)
# The warning prints the bound with 6 significant digits.
PRINTED_REL = 1e-5
# Within the bound by a margin: the bound counts one contact, and the demo's bodies land on several at once.
STEP_FRACTION = 0.75
WARNING = re.compile(r"warning: the fixed step ([0-9.e+-]+) s exceeds RK4's stability bound ([0-9.e+-]+) s")

failures = []


def check(name, ok):
    print(("ok   " if ok else "FAIL ") + name)
    if not ok:
        failures.append(name)


def run(args):
    p = subprocess.run([PD] + args, capture_output=True, text=True)
    return p.returncode, p.stderr


with tempfile.TemporaryDirectory(prefix="pd_test_fixed_step.") as scratch:
    # The scene's dt: the warning, once, with the bound that summary.json's shortest contact period gives.
    out = os.path.join(scratch, "default")
    rc, err = run(["run", SCENE, "--stepper", "fixed", "--out", out])
    found = WARNING.findall(err)
    check("the scene's dt: one warning", len(found) == 1)
    check("the scene's dt: the warning names --step", "--step" in err)
    check("the scene's dt: a run directory is written either way (exit 0 or 1)",
          rc in (0, 1) and os.path.isfile(os.path.join(out, "summary.json")))
    if not found or not os.path.isfile(os.path.join(out, "summary.json")):
        print(err)
        sys.exit(1)
    step, bound = float(found[0][0]), float(found[0][1])
    with open(os.path.join(out, "summary.json")) as f:
        period = json.load(f)["contact_period_min"]
    expected = STABLE_OMEGA_STEP * period / (2.0 * math.pi)
    print(f"dt {step} s, bound {bound} s, contact_period_min {period} s")
    check("the bound is omega h = 2.5 at contact_period_min", abs(bound - expected) <= PRINTED_REL * expected)
    check("the scene's dt exceeds the bound", step > bound)
    check_out = subprocess.run([PD, "check", SCENE], capture_output=True, text=True).stdout
    line = re.search(r"fixed step  at most ([0-9.e+-]+) s .*dt exceeds it", check_out)
    check("polydyn check: the same bound, dt exceeds it", line is not None and float(line.group(1)) == bound)

    # A step within the bound: no warning, a complete run, every number finite.
    within = f"{STEP_FRACTION * bound:.3g}"
    out = os.path.join(scratch, "within")
    rc, err = run(["run", SCENE, "--stepper", "fixed", "--step", within, "--out", out])
    check(f"--step {within}: no warning", "warning" not in err)
    check(f"--step {within}: exit 0", rc == 0)
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    check(f"--step {within}: completed", summary.get("completed") is True)
    with open(os.path.join(out, "trajectory.csv")) as f:
        rows = list(csv.reader(f))[1:]
    finite = all(math.isfinite(float(v)) for row in rows for v in row[:1] + row[2:])  # row[1]: the body's name
    times = [float(row[0]) for row in rows]
    check(f"--step {within}: {len(rows)} finite trajectory rows", len(rows) > 0 and finite)
    check(f"--step {within}: the trajectory reaches tend", abs(max(times) - summary["settings"]["tend"]) < 1e-9)
    check(f"--step {within}: summary.json's stepper rk4-fixed with dt {within}",
          summary["stepper"] == "rk4-fixed" and summary["settings"]["dt"] == float(within))

    # --step sets the soft engine's step only for the fixed stepper: elsewhere it is bad input.
    rc, err = run(["run", SCENE, "--step", within, "--out", os.path.join(scratch, "refused")])
    check("--step without --stepper fixed: exit 2", rc == 2 and "--step" in err)

print(f"{len(failures)} failed")
sys.exit(1 if failures else 0)
