#!/usr/bin/env python3
"""Drop a cube vertex first onto a floor in polydyn's soft engine, ODE and Bullet, at several requested
restitutions, and measure the restitution each engine delivers.

    PYTHONPATH=build/python python3 examples/python/drop_cube.py [--plot FILE.png] [--no-plot] [--check]

The cube (0.1 m, 1 kg) hangs with a body diagonal vertical, so it lands on one vertex straight below its centre of
mass: a centred impact through one contact, whose restitution is the requested e (cube and floor both request e, so
the pair's √(e·e) is e). Measured from the apex after the first bounce, exact in free flight whatever the sample
rate: e = √((apex − z_touch)/(z_drop − z_touch)), z_touch the centre's height when the vertex touches (half the
body diagonal). Prints one row per engine and requested e; --plot draws measured against requested (matplotlib);
--check exits 1 unless the soft engine delivers every requested e within 0.005 (a centred single-contact impact is
the paper's eq. (15) exactly; 0.005 is the Gedanken suite's restitution tolerance).
"""
import argparse
import math
import sys

import numpy as np

import polydyn

SIDE = 0.1  # m
Z_DROP = 0.3  # m, the centre of mass at release
Z_TOUCH = SIDE * math.sqrt(3) / 2  # m, the centre's height when the lowest vertex touches the floor
TILT_DEG = math.degrees(math.acos(1 / math.sqrt(3)))  # turns a body diagonal onto the vertical
REQUESTED = [0.2, 0.35, 0.5, 0.65, 0.8, 0.95]
ENGINES = [("soft", None), ("ode", "native"), ("ode", "matched"), ("bullet", "native"), ("bullet", "matched")]
SOFT_TOLERANCE = 0.005


def scene(e):
    return polydyn.Scene.from_string(f"""\
tend 0.5
sample 1000
cube floor grey 1 1 0.1
fixed
loc 0 0 -0.05
restitution {e}
cube cube red {SIDE} {SIDE} {SIDE}
loc 0 0 {Z_DROP} {TILT_DEG:.15f} 1 -1 0
restitution {e}
""", name=f"drop-e{e}.scene")


def measured_restitution(result, g=9.81):
    z, vz = result.x[:, 0, 2], result.v[:, 0, 2]
    k_low = int(np.argmin(z))  # the first impact: the lowest point of the first bounce
    rising = np.nonzero((vz[k_low:-1] > 0) & (vz[k_low + 1:] <= 0))[0]
    if len(rising) == 0:
        return float("nan")
    k = k_low + rising[0]
    apex = z[k] + vz[k] ** 2 / (2 * g)  # exact between samples in free flight
    return math.sqrt(max(apex - Z_TOUCH, 0.0) / (Z_DROP - Z_TOUCH))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--plot", default="restitution.png", help="the figure (default restitution.png)")
    parser.add_argument("--no-plot", action="store_true")
    parser.add_argument("--check", action="store_true")
    args = parser.parse_args()

    rows = []
    print(f"{'engine':16} {'requested':>9} {'measured':>9} {'error':>9}")
    for engine, variant in ENGINES:
        label = engine if variant is None else f"{engine}-{variant}"
        for e in REQUESTED:
            result = polydyn.run(scene(e), engine, variant=variant)
            m = measured_restitution(result)
            rows.append((label, e, m))
            print(f"{label:16} {e:9.3f} {m:9.4f} {m - e:+9.4f}")

    if not args.no_plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(5, 4.5))
        ax.plot([0, 1], [0, 1], color="grey", lw=0.8, label="requested")
        for label in dict.fromkeys(r[0] for r in rows):
            pts = [(r[1], r[2]) for r in rows if r[0] == label]
            ax.plot(*zip(*pts), marker="o", label=label)
        ax.set_xlabel("requested restitution e")
        ax.set_ylabel("measured restitution (apex after the first bounce)")
        ax.set_title("A cube dropped on a vertex")
        ax.legend()
        fig.tight_layout()
        fig.savefig(args.plot, dpi=120)
        print(f"plot: {args.plot}")

    if args.check:
        bad = [r for r in rows if r[0] == "soft" and not abs(r[2] - r[1]) <= SOFT_TOLERANCE]
        for label, e, m in bad:
            print(f"check: soft engine e = {m:.6f} for requested {e} (tolerance {SOFT_TOLERANCE})", file=sys.stderr)
        return 1 if bad else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
