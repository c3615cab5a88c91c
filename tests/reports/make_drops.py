#!/usr/bin/env python3
"""Writes a small synthetic planar-drop file in the layout `polydyn cubetoss --data` reads (docs/planar-drops.md):
N drops of the 0.06 m square at 250 Hz, 200 samples each, falling flat from 0.10-0.15 m above the surface
(at z = 0.0005 m) while sliding sideways, bouncing with restitution 0.5 (instantly, in closed form) until the
record ends. Not physics to compare against: a record with the right layout and bounces, for the tests of
what reads planar-drop results.

usage: make_drops.py OUT.csv [N]"""
import math
import sys

RATE, HALF, TOP, G, E, SAMPLES = 250.0, 0.03, 0.0005, 9.81, 0.5, 200
REST_SPEED = 1e-3  # m/s: a bounce slower than this ends the bouncing (it would lift the block 0.05 µm)


def main():
    out, n = sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 4
    with open(out, "w") as f:
        f.write("drop,t,x,z,th,vx,vz,vth\n")
        for drop in range(1, n + 1):
            h0 = 0.10 + 0.05 * ((drop * 7) % 5) / 4
            vx = -0.2 + 0.1 * drop
            times, speeds = [math.sqrt(2 * h0 / G)], []
            speeds.append(E * G * times[0])
            while times[-1] < SAMPLES / RATE and speeds[-1] > REST_SPEED:  # the bounces' times converge
                times.append(times[-1] + 2 * speeds[-1] / G)
                speeds.append(E * speeds[-1])
            speeds[-1] = 0.0  # then it rests
            for k in range(SAMPLES):
                t = k / RATE
                if t < times[0]:
                    h, vz = h0 - 0.5 * G * t * t, -G * t
                else:
                    b = max(i for i in range(len(times)) if times[i] <= t)
                    u = t - times[b]
                    h, vz = max(0.0, speeds[b] * u - 0.5 * G * u * u), speeds[b] - G * u
                f.write(f"{drop},{t:.6f},{-0.3 + vx * t:.17g},{TOP + HALF + h:.17g},0,{vx:.17g},{vz:.17g},0\n")


if __name__ == "__main__":
    main()
