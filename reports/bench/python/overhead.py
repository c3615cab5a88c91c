#!/usr/bin/env python3
"""What the Python package costs over the command line (reports/bench/python/README.md).

    overhead.py runs N SCENE DIR     N runs of SCENE by polydyn.run(SCENE, out=DIR): the work of `polydyn run SCENE
                                     --out DIR` (parse, compile, run, write the run directory), from one interpreter
    overhead.py read SAMPLES REPEATS a single cube run sampled SAMPLES times, then, REPEATS times, the time to hand its
                                     trajectory to NumPy (polydyn.Result: t, x, q, v, w and the structured trajectory
                                     as arrays), and that plus one pass over every height (the largest z); prints one
                                     CSV row of medians
"""
import os
import statistics
import sys
import time

import polydyn

CUBE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "cube_1s.scene")  # 1 simulated second


def runs(n, scene, out):
    for _ in range(n):
        polydyn.run(scene, out=out)


def read(samples, repeats):
    # tend 1 s, so the sample rate is the number of samples less one (t = k / sample for k = 0 .. sample)
    model = polydyn.Model(polydyn.Scene.from_file(CUBE), sample=samples - 1)
    raw = polydyn._polydyn.run(model, contacts=False)
    handover, reading = [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        r = polydyn.Result(model, "soft", raw, None)
        t1 = time.perf_counter()
        top = r.x[:, 0, 2].max()
        t2 = time.perf_counter()
        handover.append(t1 - t0)
        reading.append(t2 - t0)
    assert len(r.t) == samples and abs(top - 0.2) < 1e-12  # dropped from rest at 0.2 m
    print("samples,handover_ms,handover_and_pass_over_z_ms,c_run_s")
    print(f"{samples},{1e3 * statistics.median(handover):.4f},{1e3 * statistics.median(reading):.2f},"
          f"{raw['wall_seconds']:.3f}")


if __name__ == "__main__":
    if sys.argv[1] == "runs":
        runs(int(sys.argv[2]), sys.argv[3], sys.argv[4])
    elif sys.argv[1] == "read":
        read(int(sys.argv[2]), int(sys.argv[3]))
    else:
        sys.exit(__doc__)
