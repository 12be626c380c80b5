"""partita from Python: check, run, sweep and read coupled cases (DEM granules, FE structures,
the 1D tube, ...) with the run library of the ``partita`` executable, results as pandas
DataFrames. See docs/python.md.

    import partita
    r = partita.run("cases/bouncing_sphere/bouncing_sphere.yaml", output="out/sphere")
    r.monitors["sphere"]["ball.particle.1.z"]        # a DataFrame column, in r.monitors["sphere"].attrs["units"]
"""

from __future__ import annotations

import collections
import itertools
import json
import os
import sys
from pathlib import Path
from typing import Any, Callable, Dict, Iterable, List, Mapping, Optional, Sequence, Union

from . import _partita
from ._errors import CaseError, Error, InternalError, RunStopped, UsageError
from ._external import ExternalParticipant
from ._result import Result, Summary, read_csv
from ._solver import Field, Mesh, OutputFrame, Solver, SolverContext, quantity, register_solver, solvers

__all__ = ["check", "run", "read", "sweep", "read_csv", "set_log_level", "Result", "Summary",
           "Progress", "Error", "CaseError", "InternalError", "__version__", "Solver", "Mesh",
           "Field", "OutputFrame", "SolverContext", "register_solver", "solvers", "quantity",
           "ExternalParticipant", "UsageError", "RunStopped"]

#: the version of the partita libraries the module is built from (as ``partita --version``)
__version__: str = _partita.version()

#: What a progress callback receives after a window: the windows done (of ``windows``), the
#: simulated time [s] and that window's coupling iterations.
Progress = collections.namedtuple("Progress", ["window", "windows", "time", "iterations"])

PathLike = Union[str, os.PathLike]


def _yaml(value: Any, nested: bool = False) -> str:
    """A Python value as YAML flow text (what `partita run --set KEY=VALUE` takes). Strings go
    as they are (YAML reads "20 kPa" and "0.5" as --set does), quoted inside a list or map where
    they hold a character of YAML's flow syntax."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, os.PathLike):
        value = os.fspath(value)
    if isinstance(value, str):
        if nested and (any(c in value for c in "[]{},#&*!|>'\"%@`") or ": " in value
                       or value != value.strip() or value == ""):
            return json.dumps(value)
        return value
    if isinstance(value, Mapping):
        return "{" + ", ".join(f"{_yaml(str(k), True)}: {_yaml(v, True)}" for k, v in value.items()) + "}"
    if hasattr(value, "tolist"):  # numpy arrays and scalars
        return _yaml(value.tolist(), nested)
    if isinstance(value, Iterable):
        return "[" + ", ".join(_yaml(v, True) for v in value) + "]"
    raise Error(f"set: the value {value!r} has no YAML form (give a number, string, list or dict)")


def _overrides(set: Optional[Mapping[str, Any]]) -> List[str]:
    if set is None:
        return []
    if not isinstance(set, Mapping):
        raise Error("set: give a dict {'key.path[i].key': value}, e.g. {'time.end': 0.01}")
    return [f"{k}={_yaml(v)}" for k, v in set.items()]


def set_log_level(level: str) -> None:
    """The level of partita's log on stderr: trace, debug, info (default), warn, error, critical,
    off (as ``partita --log-level``; the environment variable PARTITA_LOG_LEVEL sets the start)."""
    _partita.set_log_level(level)


def check(case: PathLike, set: Optional[Mapping[str, Any]] = None) -> dict:
    """Validate a case completely without running it (``partita check``): parse, validate and
    build every participant, mapper and scheme. Raises CaseError (``.file``, ``.line``, ``.key``)
    on the first problem; returns {"name", "output_dir", "external_participants"}."""
    return _partita.check(os.fspath(case), _overrides(set))


def _progress_bar(p: Progress) -> None:
    width = 30
    done = int(width * p.window / p.windows) if p.windows else width
    end = "\n" if p.window >= p.windows else ""
    sys.stderr.write(f"\rpartita [{'#' * done}{'.' * (width - done)}] window {p.window}/"
                     f"{p.windows}  t = {p.time:.6g} s{end}")
    sys.stderr.flush()


def run(case: PathLike, output: Optional[PathLike] = None, threads: Optional[int] = None,
        set: Optional[Mapping[str, Any]] = None, resume: Optional[PathLike] = None,
        plots: Optional[bool] = None,
        progress: Union[None, bool, Callable[[Progress], Any]] = None,
        poll: float = 0.2) -> Result:
    """Run a case as ``partita run CASE --no-sweep`` does: the same output folder (``output``,
    default out/<case name>/ under the current folder) and the same files (CSV, VTK, PNG plots
    unless ``plots=False`` or PARTITA_NO_PLOTS=1, restart files, the case's output.scripts).

    threads: OpenMP threads of the solvers (default: all cores; the results do not depend on
    it). set: {"key.path": value} as --set. resume: the folder of a run to continue from its
    newest restart file (as --resume; the output goes there).
    progress: a callable given a Progress after windows (called on this thread, at most every
    ``poll`` seconds), or True for a progress bar on stderr.

    The run releases the GIL. Ctrl-C (KeyboardInterrupt) ends it as SIGINT ends the executable's
    run: the current window finishes, a restart file is written (where the case writes them),
    every CSV file is flushed; then the KeyboardInterrupt is raised with the result in
    ``.result``. An exception raised by the progress callback stops the run the same way.
    Errors: CaseError at a key of the case, Error otherwise."""
    if resume is not None and output is not None and Path(output).resolve() != Path(resume).resolve():
        raise Error(f"run: resume={resume} continues in its own folder; give output={resume} or leave output out")
    callback = _progress_bar if progress is True else (progress or None)
    wrapped = None if callback is None else (lambda w, n, t, i: callback(Progress(w, n, t, i)))
    out = _partita.run(os.fspath(case), os.fspath(output or resume or ""),
                       0 if threads is None else int(threads), _overrides(set),
                       os.fspath(resume or ""), plots is False, wrapped, float(poll))
    result = Result(out["output_dir"], Summary._from_run(out["summary"]))
    raised = out["exception"]
    if raised is not None:
        raised.result = result
        if isinstance(raised, KeyboardInterrupt) and not raised.args:
            raised.args = (f"partita: stopped after window {result.summary.windows}; output in "
                           f"{result.output_dir}" + (f"; continue with partita.run({os.fspath(case)!r}, "
                           f"resume={os.fspath(result.output_dir)!r})" if result.summary.last_restart else ""),)
        raise raised
    return result


def read(output_dir: PathLike) -> Result:
    """A finished (or stopped) run's folder read into a Result, as run() returns it; the summary
    holds what the folder keeps (windows and iterations from coupling.csv; no times)."""
    return Result(output_dir)


def sweep(case: PathLike, over: Optional[Mapping[str, Sequence[Any]]] = None,
          results: Optional[Sequence[Mapping[str, str]]] = None, jobs: int = 1,
          threads: Optional[int] = None, output: Optional[PathLike] = None,
          set: Optional[Mapping[str, Any]] = None, labels: Optional[Mapping[str, str]] = None,
          plots: Optional[bool] = None, log_level: str = "info", poll: float = 0.2):
    """Run a sweep as ``partita run CASE --jobs N`` does (each variant a ``partita`` process into
    DIR/<label>=<value>/, DIR/sweep.csv and sweep.png) and return sweep.csv as one DataFrame:
    a row per variant with its folder (column "folder", a Path: partita.read() it), the swept
    values, "status" ("ok" or the error) and each result.

    over: {key path: values}, the full factorial (the first key varies slowest); None: the case
    file's own sweep section. results: [{"name", "monitor", "column", "of": final|max|min|mean}]
    (default: the case's). labels: {key path: label} (default: the key's last name). The swept
    columns hold the values as given here (over=), else their YAML text."""
    overrides = _overrides(set)
    given: Dict[str, Sequence[Any]] = {}
    if over is not None:
        if not isinstance(over, Mapping) or not over:
            raise Error("sweep: over= is a dict {'key.path': [values, ...]} with at least one key")
        params = []
        for key, values in over.items():
            values = list(values)
            label = (labels or {}).get(key)
            item = {"key": key, "values": values}
            if label:
                item["label"] = label
            params.append(item)
            given[label or key.rsplit(".", 1)[-1].replace("[", "_").replace("]", "")] = values
        overrides.append("sweep.parameters=" + _yaml(params))
    if results is not None:
        overrides.append("sweep.results=" + _yaml(list(results)))
    from ._paths import executable
    out = _partita.sweep(os.fspath(case), os.fspath(output or ""), int(jobs),
                         0 if threads is None else int(threads), overrides, plots is False,
                         os.environ.get("PARTITA_EXECUTABLE", executable), log_level, float(poll))
    if out["exception"] is not None:
        raise out["exception"]
    import pandas as pd
    folder = Path(out["output_dir"])
    df = pd.read_csv(folder / "sweep.csv", dtype={"status": str})
    df.insert(0, "folder", [folder / v for v in df["variant"]])
    if given:
        combos = list(itertools.product(*given.values()))
        for j, label in enumerate(given):
            if label in df and len(combos) == len(df):
                df[label] = [c[j] for c in combos]
    df.attrs["file"] = str(folder / "sweep.csv")
    df.attrs["output_dir"] = str(folder)
    return df
