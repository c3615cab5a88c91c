"""The bench from Python: oracle, gedanken, precision, compare, cubetoss — the same rows as the command's files."""
import math
import os

import numpy as np
import pytest

import polydyn
from conftest import read_csv, run_command, scene_path

TOSSES = os.environ.get("PD_CUBETOSS_DATA", os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "data",
                                                         "cube-toss", "tosses-train.csv"))


def test_oracle_pair_depth_against_libccd():
    # two 0.1 m cubes face to face, overlapping by 1 mm along x: both methods say 1 mm
    cube = "cube 0.1 0.1 0.1"
    t = polydyn.oracle((cube, (0, 0, 0), (1, 0, 0, 0)), (cube, (0.099, 0, 0), (1, 0, 0, 0)))
    assert len(t) == 1 and t.failures == 0 and t.pairs == 1
    row = t[0]
    assert row["kind"] == "agree_overlap" and row["ours"] and row["gjk"]
    assert row["our_depth"] == pytest.approx(1e-3, abs=1e-12)  # m
    assert row["epa_depth"] == pytest.approx(row["our_depth"], abs=row["epa_bound"])
    apart = polydyn.oracle((cube, (0, 0, 0), (1, 0, 0, 0)), (cube, (0.2, 0, 0), (2, 0, 0, 0)))[0]  # q normalised
    assert apart["kind"] == "agree_separate" and apart["our_depth"] == pytest.approx(-0.1, abs=1e-12)
    assert math.isnan(apart["epa_depth"])
    with pytest.raises(polydyn.SceneError):
        polydyn.oracle(("cube 0.1", (0, 0, 0), (1, 0, 0, 0)), (cube, (0, 0, 0), (1, 0, 0, 0)))
    with pytest.raises(ValueError):
        polydyn.oracle((cube, (0, 0, 0), (0, 0, 0, 0)), (cube, (1, 0, 0), (1, 0, 0, 0)))


def test_oracle_scene_and_random():
    t = polydyn.oracle(scene=scene_path("examples", "demo.scene"), tend=0.5, sample=20)
    model = polydyn.Model(polydyn.Scene.from_file(scene_path("examples", "demo.scene")), tend=0.5, sample=20)
    bodies = model.bodies
    pairs = sum(1 for i in range(len(bodies)) for j in range(i + 1, len(bodies))
                if not (bodies[i]["fixed"] and bodies[j]["fixed"]))
    assert len(t) == 11 * pairs and t.failures == 0
    assert set(t["index"]) == set(range(11))
    r = polydyn.oracle(random=300, seed=1)
    assert len(r) == 300 and r.failures == 0  # README: no disagreement outside the touching band
    assert sum(r.kinds.values()) == 300


def test_gedanken_rows_are_results_csv(tmp_path, polydyn_command):
    run_command(polydyn_command, "gedanken", "--out", tmp_path / "cli", "--only", "a1_restitution", "--engines", "soft",
                "--jobs", "1")
    header, rows = read_csv(tmp_path / "cli" / "results.csv")
    t = polydyn.gedanken(only=["a1_restitution"], engines=["soft"], jobs=1)
    assert t.columns == header and len(t) == len(rows) == 5
    for mine, theirs in zip(t, rows):
        theirs = dict(zip(header, theirs))
        assert mine["status"] == theirs["status"] == "PASS"
        assert mine["measured"] == float(theirs["measured"])  # the same computation, to the bit
        assert mine["input"] == theirs["input"]
    assert t.summary["soft_failures"] == 0
    assert t.experiments and "a1_restitution" in str(t.experiments)
    names = [e["name"] for e in polydyn.experiments()]
    assert len(names) == 31 and "a1_restitution" in names
    with pytest.raises(ValueError):
        polydyn.gedanken(only=["no_such_experiment"])


def test_precision_rows_are_precision_csv(tmp_path, polydyn_command):
    run_command(polydyn_command, "gedanken", "--out", tmp_path / "cli", "--only", "a1_restitution", "--engines", "soft",
                "--jobs", "1", "--precision", "--repeats", "1")
    header, rows = read_csv(tmp_path / "cli" / "precision.csv")
    p = polydyn.precision(tmp_path / "py", only=["a1_restitution"], engines=["soft"], jobs=1, repeats=1)
    assert p.columns == header and len(p) == len(rows) > 10
    assert [r["setting"] for r in p] == [r[header.index("setting")] for r in rows]
    mine = p["measured"]
    theirs = np.array([float(r[header.index("measured")]) for r in rows])
    assert np.array_equal(mine, theirs)
    assert (tmp_path / "py" / "precision.csv").exists() and p.out == str(tmp_path / "py")
    assert len(p.results) == 5


def test_compare_metrics(tmp_path):
    scene = tmp_path / "cube.scene"
    from conftest import CUBE_SCENE
    scene.write_text(CUBE_SCENE)
    t = polydyn.compare(str(scene), engines=["soft", "ode"], variants=["native"], tend=1)
    assert t.status == 0
    assert [(r["engine"], r["variant"]) for r in t] == [("soft", "reference"), ("soft", "implicit"), ("ode", "native")]
    soft = t.where(engine="soft", variant="implicit")[0]
    assert soft["pos_err_final"] < 1e-2  # within a hundredth of the body size of the tighter run
    assert math.isnan(t[0]["pos_err_final"])  # the reference has no error against itself
    assert t.runs
    with pytest.raises(polydyn.CommandError) as info:
        polydyn.compare(str(scene), engines=["soft", "nonsense"])
    assert info.value.status == 2


def test_cubetoss_free_flight(tmp_path):
    # a recorded "toss" that is exact free fall (g = 9.81 m/s², no spin) for 12 camera frames at 148 Hz, well above
    # the board: every engine must follow it to integration accuracy
    rows = ["toss,t,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz"]
    for k in range(12):
        t = k / 148.0
        rows.append(f"7,{t:.6f},0.1,0.2,{0.3 + 0.5 * t - 4.905 * t * t!r},1,0,0,0,0,0,{0.5 - 9.81 * t!r},0,0,0")
    data = tmp_path / "free.csv"
    data.write_text("\n".join(rows) + "\n")
    t = polydyn.cubetoss(data, engines=["soft", "ode"], tosses="all", jobs=1)
    assert list(t["engine"]) == ["soft", "ode"] and list(t["status"]) == ["ok", "ok"]
    assert t["samples"][0] == 12
    assert t.where(engine="soft")[0]["pos_err_end"] < 1e-6  # cube widths: 0.1 µm
    assert np.all(t["rot_err_end_rad"] < 1e-9)
    data.write_text("toss,t,x\n1,0,0\n")
    with pytest.raises(polydyn.CommandError) as info:
        polydyn.cubetoss(data)
    assert info.value.status == 2


@pytest.mark.skipif(not os.path.exists(TOSSES), reason=f"no cube-toss data at {TOSSES}")
def test_cubetoss_rows(tmp_path):
    t = polydyn.cubetoss(TOSSES, engines=["soft"], tosses="1,3", jobs=1)
    assert t.columns[:6] == ["toss", "split", "engine", "variant", "params", "status"]
    assert list(t["toss"]) == [1, 3] and set(t["status"]) == {"ok"}
    assert np.all(t["pos_err_end"] >= 0) and np.all(t["rot_err_end_rad"] <= math.pi)
    assert len(t.summary) > 0


def test_tables_convert():
    t = polydyn.oracle(random=20, seed=3)
    rec = t.to_records()
    assert len(rec) == 20 and rec.our_depth.dtype == np.float64
    assert t["our_depth"].shape == (20,)
    pd = pytest.importorskip("pandas")
    frame = t.to_pandas()
    assert list(frame.columns) == t.columns and len(frame) == 20
    r = polydyn.run(scene_path("examples", "demo.scene"), tend=0.2)
    assert len(r.to_pandas()) == len(r.t) * len(r.names)
    assert isinstance(frame, pd.DataFrame)
