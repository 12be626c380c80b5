"""The result of a run: the CSV files of its output folder as pandas DataFrames, its summary and
the paths of its VTK series and plots (read from the folder, so that partita.read() of a
finished folder gives the same object as partita.run())."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path
from typing import Dict, List, Optional

import pandas as pd

_UNIT = re.compile(r"^(.*\S)\s+\[([^\]]*)\]$")


def read_csv(path) -> pd.DataFrame:
    """One CSV file of partita: the header's "name [unit]" columns become "name", and
    ``df.attrs["units"]`` maps each column to its unit ("" when it has none, e.g. iterations)."""
    df = pd.read_csv(path)
    names, units = [], {}
    for column in df.columns:
        m = _UNIT.match(column)
        name, unit = (m.group(1), m.group(2)) if m else (column, "")
        names.append(name)
        units[name] = unit
    df.columns = names
    df.attrs["units"] = units
    df.attrs["file"] = str(path)
    return df


@dataclasses.dataclass
class Summary:
    """What a run measured. From partita.run(), everything; from partita.read(), what the folder
    keeps (the windows and iterations, from coupling.csv): the times are then None."""

    windows: int = 0
    iterations: int = 0
    max_window_iterations: int = 0
    unconverged_windows: Optional[int] = None
    wall_seconds: Optional[float] = None
    #: seconds in each participant's solver, by participant
    participant_seconds: Optional[Dict[str, float]] = None
    mapping_seconds: Optional[float] = None
    output_seconds: Optional[float] = None
    overlap_seconds: Optional[float] = None
    core_seconds: Optional[float] = None
    #: the window the run resumed after (None: not resumed)
    resumed_from: Optional[int] = None
    #: the signal that stopped the run early (0: none; 2 after a KeyboardInterrupt)
    stopped_by_signal: int = 0
    #: the newest restart file written (None: none)
    last_restart: Optional[Path] = None
    imbalance_warnings: Optional[int] = None
    energy_warnings: Optional[int] = None
    energy_balance_warnings: Optional[int] = None

    @property
    def mean_iterations(self) -> float:
        return self.iterations / self.windows if self.windows else 0.0

    @classmethod
    def _from_run(cls, d: dict) -> "Summary":
        d = dict(d)
        d["resumed_from"] = d["resumed_from"] if d["resumed_from"] >= 0 else None
        d["last_restart"] = Path(d["last_restart"]) if d["last_restart"] else None
        return cls(**d)

    @classmethod
    def _from_coupling(cls, coupling: Optional[pd.DataFrame]) -> "Summary":
        if coupling is None or "iterations" not in coupling:
            return cls()
        done = coupling[coupling["window"] > 0] if "window" in coupling else coupling
        return cls(windows=int(len(done)), iterations=int(done["iterations"].sum()),
                   max_window_iterations=int(done["iterations"].max()) if len(done) else 0)


class Result:
    """A run's output folder, read.

    - ``output_dir``: the folder (a Path)
    - ``monitors``: {monitor name: DataFrame} of each ``<monitor>.csv`` (not coupling.csv,
      energy.csv, sweep.csv)
    - ``coupling``: coupling.csv (window, time, iterations, residuals, audits) or None
    - ``energy``: energy.csv (the energy balance) or None
    - ``summary``: a Summary
    - ``vtk``: {series name: path of its .pvd}
    - ``plots``: {name: path of its .png}
    - ``probes``: {probe name: [path of each frame's CSV, in time order]} (DIR/probes/; read one
      with partita.read_csv)
    Each DataFrame keeps the units of its columns in ``df.attrs["units"]``.
    """

    def __init__(self, output_dir, summary: Optional[Summary] = None):
        self.output_dir = Path(output_dir)
        if not self.output_dir.is_dir():
            from ._errors import Error
            raise Error(f"'{output_dir}' is not a folder: give the output folder of a run")
        self.monitors: Dict[str, pd.DataFrame] = {}
        self.coupling: Optional[pd.DataFrame] = None
        self.energy: Optional[pd.DataFrame] = None
        for csv in sorted(self.output_dir.glob("*.csv")):
            if csv.stem == "sweep":
                continue
            df = read_csv(csv)
            if csv.stem == "coupling":
                self.coupling = df
            elif csv.stem == "energy":
                self.energy = df
            else:
                self.monitors[csv.stem] = df
        self.summary = summary if summary is not None else Summary._from_coupling(self.coupling)
        self.vtk: Dict[str, Path] = {p.stem: p for p in sorted((self.output_dir / "vtk").glob("*.pvd"))}
        self.plots: Dict[str, Path] = {p.stem: p for p in sorted(self.output_dir.glob("*.png"))}
        self.probes: Dict[str, List[Path]] = {}
        for p in sorted((self.output_dir / "probes").glob("*.csv")):
            self.probes.setdefault(re.sub(r"_\d+$", "", p.stem), []).append(p)

    def __getitem__(self, monitor: str) -> pd.DataFrame:
        """result["reaction"]: the monitor's DataFrame (also "coupling" and "energy")."""
        if monitor == "coupling" and self.coupling is not None:
            return self.coupling
        if monitor == "energy" and self.energy is not None:
            return self.energy
        try:
            return self.monitors[monitor]
        except KeyError:
            from ._errors import Error
            raise Error(f"no monitor '{monitor}' in {self.output_dir}: it has "
                        f"{', '.join(self.monitors) or 'none'}") from None

    def __repr__(self) -> str:
        return (f"partita.Result('{self.output_dir}', monitors=[{', '.join(self.monitors)}], "
                f"windows={self.summary.windows}, iterations={self.summary.iterations})")
