#!/usr/bin/python3
"""The 1D elastic tube with its solid written in Python: the wall's tube law as a partita.Solver,
registered as "py-tube-solid" and coupled in process with partita's C++ fluid (tube1d-fluid)
under the shipped case's scheme and acceleration, then the same case with the C++ solid
(tube1d-solid) for comparison: the same iteration counts per window.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/tube_python_solid.py [--case iqn-ils] [--end T]

The wall has no inertia: at every node the cross-section area follows the pressure by the tube
law a(p) = a0 ((p0 - 2 rho c^2) / (p - 2 rho c^2))^2 with c^2 = E / (2 rho r0) (what
solvers/tube1d's TubeWall computes). Writes out/tube-python-solid/<case>-{python,cpp}/.
"""
import argparse
import math
import time
from pathlib import Path

import numpy as np

import partita

ROOT = Path(__file__).resolve().parents[2]


class TubeSolid(partita.Solver):
    """The tube's wall: mesh "nodes" (the N + 1 nodes x_i = i L / N on the x axis), reads
    "pressure" [Pa], writes "cross_section_area" [m^2]; monitors mid_area and max_area."""

    def __init__(self, config):
        # the participant's case section, with tube1d-solid's keys and defaults
        self.cells = int(config.get("cells", 100))
        length = partita.quantity(config.get("length", 10.0), "m")
        modulus = partita.quantity(config.get("youngs_modulus", 1.0e4), "Pa")
        radius = partita.quantity(config.get("radius", 1.0 / math.sqrt(math.pi)), "m")
        self.density = partita.quantity(config.get("density", 1.0), "kg/m^3")
        self.a0 = partita.quantity(config.get("reference_area", 1.0), "m^2")
        self.p0 = partita.quantity(config.get("reference_pressure", 0.0), "Pa")
        p_init = partita.quantity(config.get("initial_pressure", 0.0), "Pa")
        self.c2 = modulus / (2.0 * self.density * radius)  # the Moens-Korteweg wave speed, squared
        if 2.0 * self.density * self.c2 <= p_init:
            raise ValueError(f"initial_pressure must stay below E / r0 = {modulus / radius} Pa")
        self.points = np.zeros((self.cells + 1, 3))
        self.points[:, 0] = length / self.cells * np.arange(self.cells + 1)
        self.pressure = np.full(self.cells + 1, p_init)
        self.area = self.tube_law(self.pressure)
        self.t = 0.0
        self.saved = (self.pressure.copy(), self.area.copy(), self.t)

    def tube_law(self, p):
        two_rho_c2 = 2.0 * self.density * self.c2
        q = (self.p0 - two_rho_c2) / (p - two_rho_c2)
        return self.a0 * q * q

    def meshes(self):
        return [partita.Mesh("nodes", self.points,
                             reads=[partita.Field("pressure", 1, "Pa")],
                             writes=[partita.Field("cross_section_area", 1, "m^2")])]

    def read(self, mesh, data, values):
        self.pressure[:] = values  # a view valid during this call only: copy it

    def write(self, mesh, data):
        return self.area  # copied by partita

    def advance(self, dt):
        self.area = self.tube_law(self.pressure)  # a new array: the checkpoint keeps its own
        self.t += dt

    def time(self):
        return self.t

    def save_checkpoint(self):
        self.saved = (self.pressure.copy(), self.area, self.t)

    def restore_checkpoint(self):
        p, self.area, self.t = self.saved
        self.pressure[:] = p

    def write_restart(self):
        # what evolves, as bytes partita keeps in its restart file (partita.run(case, resume=DIR))
        return np.concatenate([self.pressure, self.area, [self.t]]).tobytes()

    def read_restart(self, data):
        state = np.frombuffer(data, dtype=float)
        if state.size != 2 * (self.cells + 1) + 1:
            raise ValueError(f"the restart file holds {state.size} values, not those of {self.cells} cells")
        n = self.cells + 1
        self.pressure[:] = state[:n]
        self.area = state[n:2 * n].copy()
        self.t = float(state[-1])

    def monitors(self):
        return {"mid_area": (self.area[self.cells // 2], "m^2"), "max_area": (self.area.max(), "m^2")}


partita.register_solver("py-tube-solid", TubeSolid, "the elastic tube's wall in Python: tube law a(p)")


def run_both(case, output, end=None, threads=1):
    """The case with the Python solid and with the C++ solid: (python Result, C++ Result)."""
    overrides = {} if end is None else {"time.end": end}
    py = partita.run(case, output=Path(output) / "python", threads=threads,
                     set={**overrides, "participants.solid.solver": "py-tube-solid"})
    cpp = partita.run(case, output=Path(output) / "cpp", threads=threads, set=overrides)
    return py, cpp


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--case", default="iqn-ils", help="a case of cases/elastic_tube_1d (default iqn-ils)")
    ap.add_argument("--end", type=float, help="end time [s] (default: the case's, 1 s)")
    args = ap.parse_args()
    case = ROOT / "cases" / "elastic_tube_1d" / f"{args.case}.yaml"
    out = Path("out") / "tube-python-solid" / args.case
    start = time.perf_counter()
    py, cpp = run_both(case, out, args.end)
    same = np.array_equal(py.coupling["iterations"].to_numpy(), cpp.coupling["iterations"].to_numpy())
    print(f"{args.case}: {py.summary.windows} windows, {py.summary.iterations} iterations with the "
          f"Python solid, {cpp.summary.iterations} with the C++ solid; the same per window: {same}")
    print(f"solid's time: Python {py.summary.participant_seconds['solid']:.3f} s, "
          f"C++ {cpp.summary.participant_seconds['solid']:.3f} s; both runs {time.perf_counter() - start:.1f} s")
    mid = np.abs(py["tube"]["solid.mid_area"] - cpp["tube"]["solid.mid_area"]).max()
    print(f"largest difference of the mid area: {mid:.3g} m^2; output in {out}")


if __name__ == "__main__":
    main()
