"""Scene and Model: parsing, compiling, and bad input raising SceneError (FILE:LINE:COL: message), never a crash."""
import subprocess
import sys

import numpy as np
import pytest

import polydyn
from conftest import CUBE_SCENE


def test_scene_from_string_and_file_agree(cube_scene):
    a = polydyn.Scene.from_string(CUBE_SCENE, name="cube.scene")
    b = polydyn.Scene.from_file(cube_scene)
    assert a.names == b.names == ["floor", "block"]
    assert a.settings == b.settings
    assert a.settings["tend"] == 3.0 and a.settings["sample"] == 10.0
    assert a.path == "cube.scene" and b.path == cube_scene


def test_model_mass_properties_in_si_units():
    model = polydyn.Model(polydyn.Scene.from_string(CUBE_SCENE))
    floor, block = model.bodies
    assert floor["fixed"] and not block["fixed"]
    assert model.moving == (1,)
    # a 0.1 m cube of water: 1 kg, inertia m a²/6 about every axis through its centre
    assert block["mass"] == pytest.approx(1.0, rel=1e-12)
    assert block["volume"] == pytest.approx(1e-3, rel=1e-12)
    inertia = np.array(block["inertia"])
    assert np.allclose(inertia, np.eye(3) * 1.0 * 0.01 / 6, rtol=1e-12, atol=1e-18)
    assert block["x0"] == pytest.approx((0, 0, 0.2))
    pair = model.pair_contact(1, 0)
    assert pair["restitution"] == pytest.approx(np.sqrt(0.5 * 0.5), rel=1e-12)
    with pytest.raises(IndexError):
        model.pair_contact(0, 0)


def test_model_overrides_like_the_command():
    scene = polydyn.Scene.from_string(CUBE_SCENE)
    model = polydyn.Model(scene, tend=0.5, sample=200)
    assert model.settings["tend"] == 0.5 and model.settings["sample"] == 200
    assert scene.settings["tend"] == 3.0  # the scene itself is unchanged
    with pytest.raises(ValueError):
        polydyn.Model(scene, tend=-1)
    with pytest.raises(ValueError):
        polydyn.Model(scene, sample=float("nan"))


@pytest.mark.parametrize("text, line, col, words", [
    ("cube a red 1 1\n", 1, 1, "expects 5 arguments"),
    ("tend 1\n\ncube a red 1 1 x\n", 3, 16, "number"),
    ("frobnicate 3\n", 1, 1, "unknown"),
    ("mu 0.3\n", 1, 1, "object"),
    ("cube a red 1 1 1\ncube a red 1 1 1\n", 2, 6, "duplicate"),
    ("\x00\x01\x02binary", 1, 1, ""),
])
def test_bad_scene_raises_with_location(text, line, col, words):
    with pytest.raises(polydyn.SceneError) as info:
        polydyn.Scene.from_string(text, name="bad.scene")
    e = info.value
    assert e.file == "bad.scene" and e.line == line
    assert str(e) == f"bad.scene:{e.line}:{e.col}: {e.message}"
    assert words.lower() in e.message.lower()
    assert isinstance(e, ValueError)


def test_compile_errors_carry_the_objects_line():
    # two cubes overlapping at t = 0: refused by pd_model_compile at the second object's line
    text = "cube a red 1 1 1\ncube b red 1 1 1\nloc 0.5 0 0\n"
    with pytest.raises(polydyn.SceneError) as info:
        polydyn.Model(polydyn.Scene.from_string(text, name="overlap.scene"))
    assert info.value.file == "overlap.scene" and info.value.line >= 1
    assert str(info.value).startswith("overlap.scene:")


def test_missing_file(tmp_path):
    with pytest.raises(polydyn.SceneError) as info:
        polydyn.Scene.from_file(str(tmp_path / "none.scene"))
    assert info.value.line == 0 and "none.scene" in str(info.value)


def test_junk_never_crashes_the_interpreter():
    # random bytes and truncations of a valid scene: every one parses or raises SceneError, in a child interpreter
    # whose exit status would show a crash
    code = """
import random, polydyn
from conftest import CUBE_SCENE
rng = random.Random(7)
for i in range(3000):
    n = rng.randrange(0, 200)
    if i % 2:
        text = bytes(rng.randrange(256) for _ in range(n)).decode("latin-1")
    else:
        text = CUBE_SCENE[: rng.randrange(len(CUBE_SCENE))] + "".join(rng.choice(" 0123456789.-e\\n#x") for _ in range(n // 10))
    try:
        polydyn.Model(polydyn.Scene.from_string(text))
    except polydyn.SceneError:
        pass
print("ok")
"""
    import os
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([os.path.dirname(__file__), os.environ.get("PYTHONPATH", "")]))
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, env=env)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "ok"
