"""run(): one scene in one engine, recorded into NumPy arrays (python/src/state.c fills them)."""
import json
import os
import shutil
import tempfile
import threading

import numpy as np

from . import _polydyn
from ._polydyn import Model, Scene

_layout = _polydyn.contact_layout()
#: One active contact at one sample: contacts.csv's columns (kind as edge_edge, mode as slip) plus the sample's
#: index and the geometric depth. point (m, world), normal (unit, from body_b into body_a), fn and ft (N): the
#: force body_b applies to body_a.
CONTACT_DTYPE = np.dtype({
    "names": [f[0] for f in _layout["fields"]],
    "formats": [f[2] for f in _layout["fields"]],
    "offsets": [f[1] for f in _layout["fields"]],
    "itemsize": _layout["itemsize"],
})

#: trajectory.csv's columns, body as the model's body index (Result.names gives the names).
TRAJECTORY_DTYPE = np.dtype([("t", "f8"), ("body", "i8")] + [
    (c, "f8") for c in ("x", "y", "z", "qw", "qx", "qy", "qz", "vx", "vy", "vz", "wx", "wy", "wz")])


def _in_main_thread():
    return threading.current_thread() is threading.main_thread()


def poses_array(state, out=None):
    """Every moving body's pose of a State as an (M, 13) float64 array: x (m), q (w first), v (m/s), w (rad/s).

    With ``out`` (a C-contiguous float64 array of M*13 numbers) the numbers are written there: no allocation,
    for a callback that reads every sample."""
    if out is not None:
        state.poses(out=out)
        return out
    return np.frombuffer(state.poses(), dtype=np.float64).reshape(-1, 13)


def contacts_array(state):
    """The State's active contacts as a CONTACT_DTYPE array (one record per contact, contact-id order)."""
    return np.frombuffer(state.contacts(), dtype=CONTACT_DTYPE)


def _model_of(scene, tend, sample, tol=None):
    if isinstance(scene, Model):
        if tend is not None or sample is not None or tol is not None:
            raise ValueError("tend, sample and tol apply when a scene is compiled: pass a Scene or a path")
        return scene
    if not isinstance(scene, Scene):
        scene = Scene.from_file(os.fspath(scene))
    return Model(scene, tend=tend, sample=sample, tol=tol)


class Result:
    """A recorded run.

    t: (S,) sample times, s. x (S, M, 3) m, q (S, M, 4) body → world (w first), v (S, M, 3) m/s, w (S, M, 3)
    rad/s (world): views of ``trajectory``, trajectory.csv's rows as one structured array (t, body index, x ... wz), M the moving bodies in scene order (``names``, ``bodies``: their
    names and model indices). contacts: CONTACT_DTYPE records of every sample (soft engine), in sample then
    contact-id order; ``contacts_at(k)`` those of sample k. summary: summary.json as a dict. completed: the run
    reached tend.
    """

    def __init__(self, model, engine, raw, summary):
        self.model = model
        self.engine = engine
        self.t = np.frombuffer(raw["t"], dtype=np.float64)
        #: trajectory.csv as one structured array (TRAJECTORY_DTYPE), a row per sample and moving body: the very
        #: memory the run filled, no copy
        self.trajectory = np.frombuffer(raw["poses"], dtype=TRAJECTORY_DTYPE)
        rows = np.frombuffer(raw["poses"], dtype=np.float64).reshape(len(self.t), len(model.moving), 15)
        self.poses = rows[:, :, 2:15]
        self.x = rows[:, :, 2:5]
        self.q = rows[:, :, 5:9]
        self.v = rows[:, :, 9:12]
        self.w = rows[:, :, 12:15]
        self.contacts = np.frombuffer(raw["contacts"], dtype=CONTACT_DTYPE)
        self._offsets = None
        self.summary = summary
        self.completed = raw["completed"]
        self.wall_seconds = raw["wall_seconds"]
        self.steps = raw["steps"]
        bodies = model.bodies
        self.bodies = np.array(model.moving, dtype=np.int32)
        self.names = [bodies[i]["name"] for i in model.moving]

    def __repr__(self):
        return (f"<polydyn.Result {self.engine}: {len(self.t)} samples × {len(self.names)} moving bodies, "
                f"{len(self.contacts)} contact records, completed={self.completed}>")

    @property
    def contact_offsets(self):
        """(S + 1,) indices into contacts: sample k's contacts are contacts[offsets[k]:offsets[k + 1]]."""
        if self._offsets is None:
            self._offsets = np.searchsorted(self.contacts["sample"], np.arange(len(self.t) + 1))
        return self._offsets

    def contacts_at(self, k):
        """Sample k's contacts (k < 0 counts from the end)."""
        k = range(len(self.t))[k]
        o = self.contact_offsets
        return self.contacts[o[k]:o[k + 1]]

    def loads(self):
        """(S, M, 3) the total contact force on each moving body at each sample, N (examples/embed's `load`)."""
        out = np.zeros((len(self.t), len(self.names), 3))
        c = self.contacts
        if len(c) == 0:
            return out
        moving_index = np.full(len(self.model.bodies), -1)
        moving_index[self.bodies] = np.arange(len(self.bodies))
        force = c["normal"] * c["fn"][:, None] + c["ft"]
        for column, sign in (("body_a", 1.0), ("body_b", -1.0)):
            j = moving_index[c[column]]
            keep = j >= 0
            np.add.at(out, (c["sample"][keep], j[keep]), sign * force[keep])
        return out

    def to_pandas(self):
        """The trajectory as a pandas DataFrame (pandas is not a dependency: ImportError without it)."""
        import pandas as pd
        frame = pd.DataFrame(self.trajectory)
        frame["body"] = [self.model.bodies[i]["name"] for i in frame["body"]]
        return frame

    def contacts_to_pandas(self):
        """The contacts as a pandas DataFrame with contacts.csv's column names (px ... ftz)."""
        import pandas as pd
        c = self.contacts
        columns = {name: c[name] for name in c.dtype.names if c.dtype[name].shape == ()}
        for name, prefix in (("point", "p"), ("normal", "n"), ("ft", "ft")):
            for i, axis in enumerate("xyz"):
                columns[prefix + axis] = c[name][:, i]
        return pd.DataFrame(columns)

def run(scene, engine="soft", *, variant=None, tend=None, sample=None, stepper=None, threads=1, onsets=None,
        islands=None, step=None, ode_friction=None, contacts=True, callback=None, out=None):
    """Runs a scene to its tend in one engine and returns a Result.

    scene: a Scene, a Model, or a scene file's path. engine: "soft" (polydyn's), "ode" or "bullet" (the same
    compiled model in a reference engine: variant "native" or "matched", step in s). tend (s), sample (Hz): override
    the scene's, as `polydyn run --tend --sample`. Soft engine only: stepper ("implicit", "adaptive", "fixed",
    "embedded", "dopri", "implicit-dopri"), onsets ("bounded", the default, "auto", "pair", "exact": docs/events.md), islands ("on", "off"),
    threads (with islands on). contacts: record
    every sample's contacts (soft engine; the reference engines report none). callback(state): called at every
    output sample with a read-only State; returning False stops the run. out: also write the run directory there,
    the same bytes as `polydyn run --out` (summary.json's timing aside).

    The GIL is released while the engine runs. Ctrl-C (in the main thread) stops the run at its next sample and
    raises KeyboardInterrupt; a run directory being written is removed."""
    model = _model_of(scene, tend, sample)
    catch = _in_main_thread()
    options = dict(engine=engine, variant=variant, step=step if step is not None else 0.0, ode_friction=ode_friction,
                   stepper=stepper, onsets=onsets, islands=islands, threads=threads, contacts=bool(contacts),
                   callback=callback, catch_interrupt=catch)
    if engine == "soft":
        raw = _polydyn.run(model, out=None if out is None else os.fspath(out), **options)
        summary = json.loads(raw["summary"]) if raw["summary"] is not None else None
        return Result(model, engine, raw, summary)
    temporary = None
    if out is None:
        temporary = tempfile.mkdtemp(prefix="polydyn-")
        out = os.path.join(temporary, "run")
    try:
        raw = _polydyn.run(model, out=os.fspath(out), **options)
        path = os.path.join(os.fspath(out), "summary.json")
        summary = None
        if os.path.exists(path):
            with open(path, encoding="utf-8") as f:
                summary = json.load(f)
    finally:
        if temporary is not None:
            shutil.rmtree(temporary, ignore_errors=True)
    return Result(model, engine, raw, summary)
