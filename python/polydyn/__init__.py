"""polydyn from Python: the soft contact engine, the reference engines and the validation bench.

The package is a thin layer over polydyn's C libraries (the extension ``polydyn._polydyn``): scenes are parsed,
compiled and run by the same code as the ``polydyn`` command, with the GIL released while C runs, and results
arrive as NumPy arrays viewed on the memory C filled. Units are SI throughout (m, kg, s, N, rad).

    import polydyn
    r = polydyn.run("cases/examples/demo.scene", tend=1.0)
    r.x[-1]          # centre of mass of every moving body at the last sample, m
    r.summary        # summary.json as a dict

See docs/python.md.
"""
from ._polydyn import Model, Scene, SceneError, State, engine_version
from ._run import CONTACT_DTYPE, Result, contacts_array, poses_array, run
from ._table import Table
from ._bench import CommandError, compare, cubetoss, experiments, gedanken, oracle, precision

__version__ = engine_version
__all__ = [
    "CONTACT_DTYPE", "CommandError", "Model", "Result", "Scene", "SceneError", "State", "Table", "compare",
    "contacts_array", "cubetoss", "experiments", "gedanken", "oracle", "poses_array", "precision", "run",
]
