"""run(), State and callbacks: shapes and units, physics, and the same numbers as `polydyn run` bit for bit."""
import os
import threading
import time

import numpy as np
import pytest

import polydyn
from conftest import CUBE_SCENE, parse_trajectory, read_csv, run_command, scene_path

G = 9.81  # m/s², the scene language's default gravity


@pytest.fixture(scope="module")
def cube_result():
    return polydyn.run(polydyn.Scene.from_string(CUBE_SCENE, name="cube.scene"))


def test_shapes_and_units(cube_result):
    r = cube_result
    s = 31  # samples at k/10 s for k = 0..30 (tend 3, sample 10)
    assert r.t.shape == (s,) and r.x.shape == (s, 1, 3) and r.q.shape == (s, 1, 4)
    assert r.v.shape == (s, 1, 3) and r.w.shape == (s, 1, 3)
    assert np.array_equal(r.t, np.arange(s) / 10.0)  # t = k / sample, that very division
    assert r.names == ["block"] and list(r.bodies) == [1]
    assert np.allclose(np.linalg.norm(r.q, axis=2), 1.0, atol=1e-12)  # unit quaternions
    assert r.x[0, 0] == pytest.approx((0, 0, 0.2))  # m, the scene's loc
    # at rest on a face: centre 0.05 m above the floor (± 20 µm: the springs sag ~0.5 µm), still
    assert abs(r.x[-1, 0, 2] - 0.05) < 20e-6
    assert np.linalg.norm(r.v[-1, 0]) < 1e-4
    assert r.completed and r.summary["engine"] == "polydyn-soft"
    assert r.trajectory.dtype.names[:3] == ("t", "body", "x") and len(r.trajectory) == s


def test_contacts_forces_sum_to_weight(cube_result):
    r = cube_result
    last = r.contacts_at(len(r.t) - 1)
    assert len(last) == 4 and not last["edge_edge"].any()  # four vertex–face contacts on a face
    assert np.all(last["fn"] >= 0)
    assert np.allclose(np.linalg.norm(last["normal"], axis=1), 1.0, atol=1e-12)
    loads = r.loads()
    assert loads.shape == (len(r.t), 1, 3)
    # the contacts carry m g = 9.81 N (1 kg) at rest
    assert loads[-1, 0] == pytest.approx((0, 0, G), abs=0.01)
    assert r.contact_offsets[-1] == len(r.contacts)


def test_arrays_are_views_of_the_recording(cube_result):
    r = cube_result
    assert r.x.base is not None and np.shares_memory(r.x, r.trajectory)
    assert np.shares_memory(r.q, r.trajectory)


def compare_with_command(result, run_dir):
    t, names, poses = parse_trajectory(os.path.join(run_dir, "trajectory.csv"))
    m = len(result.names)
    assert names == result.names * len(result.t)
    assert np.array_equal(t, np.repeat(result.t, m))
    assert np.array_equal(poses, result.poses.reshape(-1, 13))  # bit for bit: %.17g round-trips


@pytest.mark.parametrize("engine, options", [
    ("soft", {}),
    ("soft", {"stepper": "adaptive", "islands": "off"}),
    ("ode", {"variant": "native"}),
    ("bullet", {"variant": "matched"}),
])
def test_same_numbers_as_the_command(tmp_path, polydyn_command, cube_scene, engine, options):
    args = ["run", cube_scene, "--out", tmp_path / "cli", "--engine", engine, "--tend", "1.5", "--sample", "40"]
    for k, v in options.items():
        args += ["--" + k, v]
    run_command(polydyn_command, *args)
    r = polydyn.run(cube_scene, engine, tend=1.5, sample=40, **options)
    compare_with_command(r, tmp_path / "cli")
    assert len(r.t) == 61


def test_demo_scene_and_contacts_bit_for_bit(tmp_path, polydyn_command):
    scene = scene_path("examples", "demo.scene")
    run_command(polydyn_command, "run", scene, "--out", tmp_path / "cli", "--tend", "1")
    r = polydyn.run(scene, tend=1, out=tmp_path / "py")
    compare_with_command(r, tmp_path / "cli")
    # the run directory written from Python is the command's, byte for byte
    for name in ("trajectory.csv", "contacts.csv"):
        assert (tmp_path / "cli" / name).read_bytes() == (tmp_path / "py" / name).read_bytes()
    header, rows = read_csv(tmp_path / "cli" / "contacts.csv")
    assert len(rows) == len(r.contacts) > 0
    c = r.contacts
    assert np.array_equal(np.array([float(x[0]) for x in rows]), c["t"])
    assert np.array_equal(np.array([[float(v) for v in x[6:9]] for x in rows]), c["point"])
    assert np.array_equal(np.array([[float(v) for v in x[9:12]] for x in rows]), c["normal"])
    assert np.array_equal(np.array([float(x[12]) for x in rows]), c["fn"])
    assert np.array_equal(np.array([[float(v) for v in x[13:16]] for x in rows]), c["ft"])
    assert [x[3] == "EE" for x in rows] == list(c["edge_edge"])
    assert [x[16] == "slip" for x in rows] == list(c["slip"])


def test_threads_give_the_same_numbers():
    scene = scene_path("examples", "demo.scene")
    one = polydyn.run(scene, tend=0.6)
    two = polydyn.run(scene, tend=0.6, threads=2)
    assert np.array_equal(one.poses, two.poses)
    with pytest.raises(ValueError):
        polydyn.run(scene, tend=0.6, threads=2, islands="off")


def test_bad_options():
    scene = polydyn.Scene.from_string(CUBE_SCENE)
    for bad in ({"engine": "mujoco"}, {"stepper": "euler"}, {"onsets": "late"}, {"islands": "maybe"},
                {"threads": 0}, {"engine": "soft", "variant": "matched"}, {"engine": "ode", "stepper": "fixed"},
                {"engine": "bullet", "ode_friction": "aligned"}, {"engine": "ode", "variant": "soft"}):
        with pytest.raises(ValueError):
            polydyn.run(scene, **bad)
    with pytest.raises(ValueError):
        polydyn.run(polydyn.Model(scene), tend=1)  # a compiled model's settings are fixed
    with pytest.raises(polydyn.SceneError):
        polydyn.run("/nonexistent/x.scene")


def test_callback_every_sample_and_stop():
    scene = polydyn.Scene.from_string(CUBE_SCENE)
    times, heights = [], []

    def every(state):
        times.append(state.t)
        heights.append(polydyn.poses_array(state)[0, 2])

    r = polydyn.run(scene, callback=every)
    assert times == list(r.t) and heights == list(r.x[:, 0, 2])

    def stop_at_one(state):
        return state.t < 1.0

    r = polydyn.run(scene, callback=stop_at_one)
    assert r.t[-1] == 1.0 and not r.completed

    def fail(state):
        if state.t > 0.5:
            raise ZeroDivisionError("from the callback")

    with pytest.raises(ZeroDivisionError):
        polydyn.run(scene, callback=fail)

    kept = []
    polydyn.run(scene, callback=kept.append)
    with pytest.raises(RuntimeError):
        kept[0].t  # a callback's State is valid during the call only


def test_state_stepping_matches_one_run():
    scene = polydyn.Scene.from_string(CUBE_SCENE)
    model = polydyn.Model(scene)
    whole = polydyn.run(model)
    state = polydyn.State(model)
    out = np.empty((1, 13))
    seen = []

    def read(s):
        polydyn.poses_array(s, out=out)  # no allocation per sample
        seen.append(out.copy())
        return None

    for t_end in (0.5, 1.2, 3.0):  # stopped on sample times and resumed: the same numbers as one call
        assert state.advance(t_end, read)
    assert state.t == 3.0
    assert np.array_equal(np.array(seen)[:, 0, :], whole.poses[:, 0, :])
    contacts = polydyn.contacts_array(state)
    assert np.array_equal(contacts["fn"], whole.contacts_at(len(whole.t) - 1)["fn"])
    assert state.energy() < model.bodies[1]["mass"] * G * 0.2  # dissipated from the drop height
    assert state.warnings == {"step_at_minimum": 0, "non_finite_step": 0, "late_onset": 0}
    assert state.counters["accepted"] > 0
    with pytest.raises(ValueError):
        state.advance(1.0)  # back in time
    state.reset()
    assert state.t == 0.0


def test_gil_released_while_c_runs():
    # While a run is in C a Python thread keeps running: its clock readings cover the run's window with no gap of half
    # the window. A run that held the GIL would leave one gap as long as its C part (nearly the whole window), whatever
    # the load; a count of loop turns would depend on how long the run takes. Sleep off and 30 s simulated so that the
    # C part dominates the window (a cube asleep at rest would cost next to nothing).
    scene = polydyn.Scene.from_string("sleep off\n" + CUBE_SCENE.replace("tend 3\n", "tend 30\n"))
    stamps = []
    done = threading.Event()

    def reader():
        while not done.is_set():
            stamps.append(time.perf_counter())

    thread = threading.Thread(target=reader)
    thread.start()
    while not stamps:  # the reader is running before the window opens
        time.sleep(0.001)
    t0 = time.perf_counter()
    polydyn.run(scene, sample=1000, contacts=False)
    t1 = time.perf_counter()
    done.set()
    thread.join()
    inside = [t0] + [s for s in stamps if t0 < s < t1] + [t1]
    largest_gap = max(b - a for a, b in zip(inside, inside[1:]))
    assert largest_gap < 0.5 * (t1 - t0), (largest_gap, t1 - t0)


def test_runs_in_parallel_threads_agree():
    scene = polydyn.Scene.from_string(CUBE_SCENE)
    model = polydyn.Model(scene)  # one read-only model shared by every thread
    results = [None] * 4

    def work(i):
        results[i] = polydyn.run(model)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results[1:]:
        assert np.array_equal(r.poses, results[0].poses)


def test_summary_matches_the_command(tmp_path, polydyn_command, cube_scene):
    import json
    run_command(polydyn_command, "run", cube_scene, "--out", tmp_path / "cli")
    cli = json.loads((tmp_path / "cli" / "summary.json").read_text())
    r = polydyn.run(cube_scene)
    # every field but the wall-clock timing
    assert set(r.summary) == set(cli)
    for key in set(cli) - {"timing"}:
        assert r.summary[key] == cli[key], key
