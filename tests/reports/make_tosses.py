#!/usr/bin/env python3
"""Writes a small synthetic cube-toss file in the layout `polydyn cubetoss --data` reads (docs/validation.md, cube
tosses): N tosses of the 0.1048 m cube at 148 Hz, each thrown from 0.25–0.35 m with a spin, falling
freely until its centre is half a width above the board top (-0.0012 m), then lying still. Not
physics to compare against: a record with the right layout and plausible motion, for the tests of what
reads cubetoss results (polydyn report).

usage: make_tosses.py OUT.csv [N]"""
import math
import sys

RATE, HALF, TOP, G = 148.0, 0.0524, -0.0012, 9.81


def qmul(a, b):
    w0, x0, y0, z0 = a
    w1, x1, y1, z1 = b
    return (w0 * w1 - x0 * x1 - y0 * y1 - z0 * z1, w0 * x1 + x0 * w1 + y0 * z1 - z0 * y1,
            w0 * y1 - x0 * z1 + y0 * w1 + z0 * x1, w0 * z1 + x0 * y1 - y0 * x1 + z0 * w1)


def main():
    out, n = sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 6
    with open(out, "w") as f:
        f.write("toss,t,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz\n")
        for toss in range(1, n + 1):
            z0 = 0.25 + 0.1 * ((toss * 37) % 11) / 10
            v = (0.4 + 0.05 * toss, -0.2 + 0.03 * toss, 0.5)
            w = (3.0 - 0.4 * toss, 1.5, 0.3 * toss)
            rest_z = TOP + HALF
            # time of landing: z0 + vz t − g t²/2 = rest_z
            t_land = (v[2] + math.sqrt(v[2] ** 2 + 2 * G * (z0 - rest_z))) / G
            samples = int((t_land + 0.15) * RATE) + 1
            wn = math.sqrt(sum(c * c for c in w))
            for k in range(samples):
                t = k / RATE
                tf = min(t, t_land)
                x = (0.1 * toss + v[0] * tf, v[1] * tf, max(rest_z, z0 + v[2] * tf - 0.5 * G * tf * tf))
                h = 0.5 * wn * tf
                q = qmul((math.cos(h), *(math.sin(h) * c / wn for c in w)), (1.0, 0.0, 0.0, 0.0))
                vel = (v[0], v[1], v[2] - G * t) if t < t_land else (0.0, 0.0, 0.0)
                om = w if t < t_land else (0.0, 0.0, 0.0)
                f.write(",".join([str(toss), f"{t:.6f}"] + [repr(c) for c in (*x, *q, *vel, *om)]) + "\n")


main()
