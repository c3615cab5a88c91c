"""Shared fixtures of the package's tests: the polydyn command of the same build, scenes, CSV readers."""
import csv
import os
import shutil
import subprocess

import numpy as np
import pytest

SOURCE_DIR = os.environ.get("PD_SOURCE_DIR", os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..")))

# examples/embed's built-in scene: a tilted 0.1 m cube (1 kg) dropped from 0.2 m onto a fixed floor
CUBE_SCENE = """\
tend 3
sample 10
cube floor grey 2 2 0.2
fixed
loc 0 0 -0.1
cube block red 0.1 0.1 0.1
loc 0 0 0.2 10 1 0 0
restitution 0.5
"""


@pytest.fixture
def cube_scene(tmp_path):
    path = tmp_path / "cube.scene"
    path.write_text(CUBE_SCENE)
    return str(path)


@pytest.fixture(scope="session")
def polydyn_command():
    """The `polydyn` command of this build (CTest sets POLYDYN), or one on PATH; the test skips without one."""
    command = os.environ.get("POLYDYN") or shutil.which("polydyn")
    if not command:
        pytest.skip("no polydyn command (set POLYDYN)")
    return command


def run_command(command, *args):
    done = subprocess.run([command, *map(str, args)], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    return done


def read_csv(path):
    """A CSV file as (header, rows of strings)."""
    with open(path, newline="") as f:
        reader = csv.reader(f)
        header = next(reader)
        return header, list(reader)


def parse_trajectory(path):
    """trajectory.csv as (t, names, (rows, 13) poses), every number parsed from its %.17g text (exact)."""
    header, rows = read_csv(path)
    assert header == "t,body,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz".split(",")
    t = np.array([float(r[0]) for r in rows])
    names = [r[1] for r in rows]
    poses = np.array([[float(v) for v in r[2:]] for r in rows])
    return t, names, poses


def scene_path(*parts):
    return os.path.join(SOURCE_DIR, "cases", *parts)
