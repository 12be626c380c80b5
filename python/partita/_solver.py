"""Solvers written in Python (docs/python.md, "A solver in Python"): the base class of partita's
Solver contract, the description of its coupling meshes and fields, and the registry of the
factories by name that the module's runs build them from."""

from __future__ import annotations

import inspect
import math
import re
from typing import Any, Callable, Dict, List, NamedTuple, Optional, Sequence, Tuple

import numpy as np

from . import _partita
from ._errors import Error


class Field(NamedTuple):
    """A field a solver reads or writes on a mesh: ``components`` 1 (arrays of shape (n,)) or 3
    ((n, 3)), its SI ``unit`` and ``kind``: "intensive" (a point value or density: displacement,
    pressure; mapped consistently) or "extensive" (an amount that adds up: force; mapped
    conservatively)."""
    name: str
    components: int = 3
    unit: str = ""
    kind: str = "intensive"


class Mesh:
    """A coupling mesh in its reference configuration: ``points`` (n, 3) [m], optional
    ``triangles`` (m, 3) point indices and ``weights`` (n,) (the area each point stands for), the
    fields the solver reads and writes on it, and whether its motion is ``prescribed`` (a driven
    body's surface that takes no load back)."""

    def __init__(self, name: str, points: Any, reads: Sequence[Field] = (),
                 writes: Sequence[Field] = (), triangles: Any = None, weights: Any = None,
                 prescribed: bool = False):
        self.name = name
        self.points = np.asarray(points, dtype=float)
        self.reads = list(reads)
        self.writes = list(writes)
        self.triangles = None if triangles is None else np.asarray(triangles, dtype=np.int32)
        self.weights = None if weights is None else np.asarray(weights, dtype=float)
        self.prescribed = bool(prescribed)


class OutputFrame(NamedTuple):
    """Where and when write_output() writes: files go under ``vtk_directory``, their names start
    with ``prefix`` (the participant's name); ``index`` is the frame number, ``time`` [s]."""
    vtk_directory: str
    prefix: str
    index: int
    time: float


class SolverContext(NamedTuple):
    """What a factory may take besides the participant's case section: the participant's name,
    the case file's folder (relative inputs), the run's output folder and the threads it may use."""
    name: str
    case_dir: str
    output_dir: str
    threads: int


class Solver:
    """partita's Solver contract in Python. Derive from it and implement meshes(), read(),
    write(), advance(), time(), save_checkpoint() and restore_checkpoint(); the others have
    defaults. The coupling core calls them in the order of docs/writing_an_adapter.md:

    - meshes() once, after the solver is built (and after receive_mesh() where it asked for
      surfaces with mesh_requests()): a list of partita.Mesh, fixed for the run;
    - for each window: save_checkpoint() (implicit schemes); per substep read(mesh, data, values)
      for each field it receives, advance(dt), write(mesh, data) for each field it sends;
      restore_checkpoint() when the window is repeated;
    - after each accepted window: monitors(), check_state(), write_output(frame) at output times.

    read() gets a read-only numpy view of the core's values, (n,) or (n, 3): valid during that
    call only (copy it, e.g. ``self.p[:] = values``, to keep it). write() returns an array of
    that shape, which the core copies; a non-finite value stops the run.

    Optional, not defined here: ``write_restart() -> bytes`` with ``read_restart(data)`` keep
    the state in restart files (without them a run with this solver writes none);
    ``interface_work(mesh) -> float`` joins the interface energy audit."""

    def meshes(self) -> List[Mesh]:
        raise NotImplementedError("meshes()")

    def read(self, mesh: str, data: str, values: np.ndarray) -> None:
        raise NotImplementedError("read()")

    def write(self, mesh: str, data: str) -> np.ndarray:
        raise NotImplementedError("write()")

    def advance(self, dt: float) -> None:
        raise NotImplementedError("advance()")

    def time(self) -> float:
        raise NotImplementedError("time()")

    def save_checkpoint(self) -> None:
        raise NotImplementedError("save_checkpoint() (an implicit scheme needs it)")

    def restore_checkpoint(self) -> None:
        raise NotImplementedError("restore_checkpoint() (an implicit scheme needs it)")

    def stable_time_step(self) -> float:
        """The largest step the solver can take now [s] (default: unconditionally stable)."""
        return math.inf

    def mesh_requests(self) -> List[Tuple[str, str]]:
        """Surfaces taken from other participants: [(name, "participant.mesh")] (default none);
        each comes to receive_mesh(name, points, triangles) before meshes() is called."""
        return []

    def receive_mesh(self, name: str, points: np.ndarray, triangles: np.ndarray) -> None:
        raise Error(f"this solver takes no meshes from other participants (asked for {name!r})")

    def monitors(self) -> Dict[str, Any]:
        """Scalars after each accepted window: {name: value} or {name: (value, "unit")}, the same
        names every time (a case's monitors record them as participant.name)."""
        return {}

    def check_state(self) -> Optional[str]:
        """A diagnosis when the state is no longer physical (the run stops with it), else None."""
        return None

    def write_output(self, frame: OutputFrame) -> Optional[List[Tuple[str, str]]]:
        """Write this frame's files under frame.vtk_directory; return [(series, file name)] for
        the .pvd series the core keeps (default: writes nothing)."""
        return None

    def finalize(self) -> None:
        """Once after the last window."""


_factories: Dict[str, Callable[..., Any]] = {}


def register_solver(name: str, factory: Callable[..., Any], doc: str = "") -> None:
    """Make ``name`` a solver that a case names as ``solver: name`` in the module's runs and
    checks (not in sweeps, whose variants are partita processes). ``factory(config)`` or
    ``factory(config, context)`` builds the solver: ``config`` the participant's case section as
    a dict (scalars as int, float, bool or str; "20 kPa" stays a str), ``context`` a
    SolverContext. Registering a name again replaces its factory; a name of partita's own
    solvers is an Error."""
    if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z0-9_.+-]+", name):
        raise Error(f"register_solver: the name {name!r} must be a non-empty word of letters, "
                    "digits, '-', '_', '.' or '+'")
    if not callable(factory):
        raise Error(f"register_solver({name!r}): the factory must be callable (a class or a "
                    "function returning a partita.Solver)")
    _partita.add_solver(name, doc)
    _factories[name] = factory


def quantity(value: Any, unit: str) -> float:
    """A value of a case section in SI: a number as it is, a text with a unit ("20 kPa", "2 mm")
    converted as partita reads the keys of its own solvers; an Error when it is neither."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return float(value)
    if isinstance(value, str):
        return _partita.quantity(value, unit)
    raise Error(f"quantity: {value!r} is not a number or a text with a unit of {unit}")


def solvers() -> List[str]:
    """The names of the solvers registered from Python."""
    return list(_partita.python_solver_names())


def _takes_context(factory: Callable[..., Any]) -> bool:
    try:
        params = inspect.signature(factory).parameters.values()
    except (TypeError, ValueError):
        return False
    # factory(config, context), factory(config, *args) or factory(config, context=None)
    params = list(params)
    positional = [p for p in params if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    required = [p for p in positional if p.default is p.empty]
    return (len(required) >= 2 or any(p.kind == p.VAR_POSITIONAL for p in params)
            or any(p.name == "context" for p in positional[1:]))


def _build(name: str, participant: str, config: dict, case_dir: str, output_dir: str,
           threads: int) -> Any:
    """Called by the run (under the GIL) for each participant whose solver is ``name``."""
    factory = _factories[name]
    if _takes_context(factory):
        return factory(config, SolverContext(participant, case_dir, output_dir, threads))
    return factory(config)


_INT = re.compile(r"[-+]?[0-9]+")


def _scalar(text: str) -> Any:
    """A YAML scalar's text as Python: bool, int, float, None or the text itself."""
    low = text.lower()
    if low in ("true", "false"):
        return low == "true"
    if low in ("null", "~"):
        return None
    if _INT.fullmatch(text):
        return int(text)
    try:
        return float(text)
    except ValueError:
        return text
