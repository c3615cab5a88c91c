"""A report's replay data files (FILE-replays/NAME: `polydynReplay(NAME, FILES);`), for the report tests."""
import json
import os
import struct

TRAJECTORY_FLOAT32 = range(9, 15)  # vx..wz: the viewer keeps them as float32, the rest as float64


def read_replay(folder, name):
    """The FILES object of the replay data file NAME in folder (asserts the file's one statement)."""
    with open(os.path.join(folder, name), encoding="utf-8") as f:
        text = f.read()
    head = f"polydynReplay({json.dumps(name)}, "
    assert text.startswith(head) and text.endswith(");\n"), f"{name}: {text[:80]}"
    return json.loads(text[len(head):-3])


def float32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


def same_trajectory(short, full):
    """True when the report's trajectory text holds the values of trajectory.csv as the viewer keeps them:
    the same lines and names, each number equal as float64 (float32 for the velocities)."""
    a, b = short.split("\n"), full.split("\n")
    if len(a) != len(b) or a[0] != b[0]:
        return False
    for la, lb in zip(a[1:], b[1:]):
        if la == lb:
            continue
        fa, fb = la.split(","), lb.split(",")
        if len(fa) != len(fb) or fa[1:2] != fb[1:2]:
            return False
        for k in range(len(fa)):
            if k == 1:
                continue
            x, y = float(fa[k]), float(fb[k])
            if (float32(x) != float32(y)) if k in TRAJECTORY_FLOAT32 else (x != y):
                return False
    return True
