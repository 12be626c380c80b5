import os
from pathlib import Path
from typing import Dict, List, Optional, Union

import pandas as pd

def read_csv(path: Union[str, os.PathLike[str]]) -> pd.DataFrame: ...

class Summary:
    windows: int
    iterations: int
    max_window_iterations: int
    unconverged_windows: Optional[int]
    wall_seconds: Optional[float]
    participant_seconds: Optional[Dict[str, float]]
    mapping_seconds: Optional[float]
    output_seconds: Optional[float]
    overlap_seconds: Optional[float]
    core_seconds: Optional[float]
    resumed_from: Optional[int]
    stopped_by_signal: int
    last_restart: Optional[Path]
    imbalance_warnings: Optional[int]
    energy_warnings: Optional[int]
    energy_balance_warnings: Optional[int]
    @property
    def mean_iterations(self) -> float: ...

class Result:
    output_dir: Path
    monitors: Dict[str, pd.DataFrame]
    coupling: Optional[pd.DataFrame]
    energy: Optional[pd.DataFrame]
    summary: Summary
    vtk: Dict[str, Path]
    plots: Dict[str, Path]
    probes: Dict[str, List[Path]]
    def __init__(self, output_dir: Union[str, os.PathLike[str]], summary: Optional[Summary] = ...) -> None: ...
    def __getitem__(self, monitor: str) -> pd.DataFrame: ...
