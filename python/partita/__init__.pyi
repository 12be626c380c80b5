# Type stubs of the partita package (docs/python.md).
import os
from pathlib import Path
from typing import Any, Callable, Dict, Mapping, NamedTuple, Optional, Sequence, Union

import pandas as pd

from ._errors import (CaseError as CaseError, Error as Error, InternalError as InternalError,
                      RunStopped as RunStopped, UsageError as UsageError)
from ._external import ExternalParticipant as ExternalParticipant
from ._result import Result as Result, Summary as Summary, read_csv as read_csv
from ._solver import (Field as Field, Mesh as Mesh, OutputFrame as OutputFrame, Solver as Solver,
                      SolverContext as SolverContext, quantity as quantity,
                      register_solver as register_solver, solvers as solvers)

__version__: str

class Progress(NamedTuple):
    window: int
    windows: int
    time: float
    iterations: int

PathLike = Union[str, os.PathLike[str]]

def set_log_level(level: str) -> None: ...
def check(case: PathLike, set: Optional[Mapping[str, Any]] = ...) -> Dict[str, Any]: ...
def run(case: PathLike, output: Optional[PathLike] = ..., threads: Optional[int] = ...,
        set: Optional[Mapping[str, Any]] = ..., resume: Optional[PathLike] = ...,
        plots: Optional[bool] = ...,
        progress: Union[None, bool, Callable[[Progress], Any]] = ...,
        poll: float = ...) -> Result: ...
def read(output_dir: PathLike) -> Result: ...
def sweep(case: PathLike, over: Optional[Mapping[str, Sequence[Any]]] = ...,
          results: Optional[Sequence[Mapping[str, str]]] = ..., jobs: int = ...,
          threads: Optional[int] = ..., output: Optional[PathLike] = ...,
          set: Optional[Mapping[str, Any]] = ..., labels: Optional[Mapping[str, str]] = ...,
          plots: Optional[bool] = ..., log_level: str = ..., poll: float = ...) -> pd.DataFrame: ...
