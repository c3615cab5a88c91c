#!/usr/bin/env python3
"""Variants of cases/bench/pile_1000.scene for the "at rest by 3 s" question (README.md beside this file).

Writes, into DIR (default: the current directory), the pile of 1 000 with the same boxes, turns and material as
scripts/bench-scenes writes it, but
  pile_1000_side16_floor10.scene  16 x 16 boxes a layer (4 layers, the top one 1.05 m up instead of 2.85 m) on a
                                  10 x 10 m floor
  pile_1000_side10_floor12.scene  the same grid as pile_1000 (10 layers) on a 12 x 12 m floor
both with tend 3.

usage: reports/bench/piles/variants.py [DIR]
"""
import importlib.machinery
import importlib.util
import os
import random
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
GENERATOR = os.path.join(HERE, "..", "..", "..", "scripts", "bench-scenes")


def load_generator(out):
    """scripts/bench-scenes as a module (its helpers: floor, grid, turn, write), writing into out. Loading it writes its
    own scenes, which go to a scratch directory."""
    loader = importlib.machinery.SourceFileLoader("bench_scenes", GENERATOR)
    spec = importlib.util.spec_from_loader("bench_scenes", loader)
    module = importlib.util.module_from_spec(spec)
    argv = sys.argv
    with tempfile.TemporaryDirectory() as scratch:
        sys.argv = [GENERATOR, scratch]
        try:
            loader.exec_module(module)
        finally:
            sys.argv = argv
    module.OUT = out
    return module


def variant(gen, n, side, floor_size, tend=3.0):
    rng = random.Random(1000 + n)  # the same turns as the scene's
    lines = [f"tend {tend}", "sample 100"]
    material = ["mu 0.5", "restitution 0.5"]
    gen.floor(lines, floor_size, material)
    for k, (x, y, z) in enumerate(gen.grid(n, 0.3, side)):
        lines += [f"cube b{k} tan 0.2 0.15 0.1", f"loc {x:.4f} {y:.4f} {z:.4f}  {gen.turn(rng)}", *material]
    gen.write(f"pile_{n}_side{side}_floor{floor_size}.scene",
              [f"pile_{n}.scene's boxes, {side} x {side} a layer, on a {floor_size} x {floor_size} m floor"], lines)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "."
    gen = load_generator(out)
    variant(gen, 1000, 16, 10)
    variant(gen, 1000, 10, 12)


if __name__ == "__main__":
    main()
