"""The bench from Python: the interference oracle, the Gedanken suite and its work-precision runs, the cube tosses
and the engine comparison, each by the C code the `polydyn` command runs (python/src/bench.c)."""
import json
import os
import shutil
import tempfile

from . import _polydyn
from ._run import _in_main_thread, _model_of
from ._table import Table

ENGINES = ("soft", "ode", "bullet")


class CommandError(RuntimeError):
    """A batch command refused its input or failed: ``status`` is its exit status (1 failure, 2 bad input); the
    command's message went to stderr."""

    def __init__(self, command, status):
        super().__init__(f"polydyn {command} exited with status {status} (its message is on stderr)")
        self.command = command
        self.status = status


def _oracle_table(raw):
    return Table(raw["columns"], raw["rows"], kinds=raw["kinds"], failures=raw["failures"], in_band=raw["in_band"],
                 pairs=raw["pairs"])


def oracle(a=None, b=None, *, scene=None, random=None, seed=1, tend=None, sample=None):
    """Our interference test against libccd's GJK, MPR and EPA (refcheck/include/pdref/oracle.h).

    oracle(a, b): one pair, each a (spec, x, q) with spec a scene object without name and colour ("cube 0.1 0.1
    0.1", "sphere 2 0.1 0.1 0.1", "hull x y z ..."), x the shape frame's origin (m) and q its orientation (w first).
    oracle(scene=...): the soft engine's run of a scene, every pair of bodies at every output sample. oracle(random=N,
    seed=S): N random pairs, as `polydyn oracle --random N --seed S`.

    Returns a Table, one row per pair checked: verdicts (ours, gjk, mpr), depths in m (our_depth > 0 overlapping,
    < 0 minus a gap's lower bound; epa_depth and mpr_depth NaN when libccd gave none), kind (agree_overlap, ...),
    touching (inside the band), scale and size (m). Its attributes: kinds (counts by kind), failures (verdicts that
    differ from GJK outside the touching band), in_band, pairs."""
    chosen = sum(x is not None for x in (a, scene, random))
    if chosen != 1 or (a is None) != (b is None):
        raise ValueError("give a pair (a, b), scene=... or random=N")
    if a is not None:
        return _oracle_table(_polydyn.oracle_pair(a[0], tuple(a[1]), tuple(a[2]), b[0], tuple(b[1]), tuple(b[2])))
    if scene is not None:
        return _oracle_table(_polydyn.oracle_scene(_model_of(scene, tend, sample), _in_main_thread()))
    return _oracle_table(_polydyn.oracle_random(int(random), int(seed), _in_main_thread()))


def experiments():
    """The Gedanken catalogue: one dict per experiment (name, group, title, quantity, unit, kind, ...)."""
    return _polydyn.gedanken_experiments()


def _suite(out, only, engines, fast, jobs, precision, repeats):
    temporary = None
    if out is None:
        temporary = tempfile.mkdtemp(prefix="polydyn-gedanken-")
        out = os.path.join(temporary, "out")
    out = os.fspath(out)
    try:
        summary = _polydyn.gedanken(out, None if only is None else list(only), list(engines), fast=fast, jobs=jobs,
                                    precision=precision, repeats=repeats, catch_interrupt=_in_main_thread())
        results = Table.read_csv(os.path.join(out, "results.csv"), summary=summary,
                                 out=None if temporary else out)
        with open(os.path.join(out, "experiments.json"), encoding="utf-8") as f:
            results.experiments = json.load(f)
        points = Table.read_csv(os.path.join(out, "precision.csv"), summary=summary,
                                out=None if temporary else out) if precision else None
    finally:
        if temporary is not None:
            shutil.rmtree(temporary, ignore_errors=True)
    return results, points


def gedanken(out=None, *, only=None, engines=ENGINES, fast=False, jobs=2):
    """Runs the Gedanken experiments (`polydyn gedanken`) and returns results.csv as a Table (the same columns:
    experiment, group, title, engine, variant, quantity, unit, input, measured, expected, error, tolerance, status,
    ...). only: experiment names (experiments() lists them); fast: the CI subset; jobs: worker processes. out: keep
    the directory the suite writes (results.csv, experiments.json, series/, runs/); by default a temporary one,
    removed. table.summary: rows, soft_failures, wall_seconds; table.experiments: experiments.json."""
    return _suite(out, only, engines, fast, jobs, False, 1)[0]


def precision(out=None, *, only=None, engines=ENGINES, fast=False, jobs=2, repeats=4):
    """The work-precision runs of `polydyn gedanken --precision`: every quantitative experiment at every setting of
    each engine's accuracy knob, its error against the closed form and its cost. Returns precision.csv as a Table
    (the same columns: experiment, kind, engine, variant, setting, value, input, quantity, unit, measured, expected,
    error, relative, tolerance, ...); its attribute ``results`` holds results.csv. repeats: timings per point, each
    the run repeated back to back to a minimum of CPU time, the least kept: `--repeats`, with the CLI's default."""
    results, points = _suite(out, only, engines, fast, jobs, True, repeats)
    points.results = results
    return points


def _command(name, args, out, read):
    temporary = None
    if out is None:
        temporary = tempfile.mkdtemp(prefix=f"polydyn-{name}-")
        out = os.path.join(temporary, "out")
    out = os.fspath(out)
    try:
        status = _polydyn.command([name] + [str(a) for a in args] + ["--out", out])
        if status == 130:
            raise KeyboardInterrupt
        if status not in (0, 1) or not os.path.isdir(out):
            raise CommandError(name, status)
        result = read(out)
        result.status = status
        result.out = None if temporary else out
        return result
    finally:
        if temporary is not None:
            shutil.rmtree(temporary, ignore_errors=True)


def _path_of(scene):
    path = getattr(scene, "path", scene)
    if not os.path.exists(os.fspath(path)):
        raise ValueError(f"{path}: compare needs a scene file (or a directory of scenes)")
    return os.fspath(path)


def compare(scene, out=None, *, engines=ENGINES, variants=("native", "matched"), step=None, tend=None, sample=None,
            jobs=1):
    """`polydyn compare`: the scene in each engine and variant against the soft engine at a 100× tighter tolerance.
    Returns metrics.csv as a Table (one row per run: pose errors, energy and momentum drift, penetration,
    restitution of each bounce, cost); table.runs: compare.json's list. status 1: the soft run failed."""
    args = [_path_of(scene), "--engines", ",".join(engines), "--variants", ",".join(variants), "--jobs", jobs]
    for flag, value in (("--step", step), ("--tend", tend), ("--sample", sample)):
        if value is not None:
            args += [flag, repr(float(value))]

    def read(out):
        table = Table.read_csv(os.path.join(out, "metrics.csv"))
        path = os.path.join(out, "compare.json")
        if os.path.exists(path):
            with open(path, encoding="utf-8") as f:
                table.runs = json.load(f)
        return table

    return _command("compare", args, out, read)


def cubetoss(data, out=None, *, engines=("soft",), tosses="test", variant=None, step=None, tol=None, jobs=2,
             runs=False, params=()):
    """`polydyn cubetoss`: recorded tosses of a real cube (data: the CSV, docs/validation.md) simulated and judged.
    Returns per_toss.csv as a Table (toss, split, engine, variant, params, status, samples, duration_s,
    pos_err_end, pos_err_rms, rot_err_end_rad, rot_err_rms_rad, ...); table.summary: summary.csv. runs: also keep
    every run directory (only useful with out). params: --params values ("ENGINE=FILE" or "FILE")."""
    args = ["--data", os.fspath(data), "--engines", ",".join(engines), "--tosses", tosses, "--jobs", jobs]
    if variant is not None:
        args += ["--variant", variant]
    if step is not None:
        args += ["--step", repr(float(step))]
    if tol is not None:
        args += ["--tol", repr(float(tol))]
    for p in params:
        args += ["--params", p]
    if not runs:
        args.append("--no-runs")

    def read(out):
        table = Table.read_csv(os.path.join(out, "per_toss.csv"))
        table.summary = Table.read_csv(os.path.join(out, "summary.csv"))
        return table

    return _command("cubetoss", args, out, read)
