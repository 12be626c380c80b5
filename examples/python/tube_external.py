#!/usr/bin/python3
"""The 1D elastic tube's wall as an external Python program with its own time loop
(partita.ExternalParticipant, the external-code API), beside partita's fluid under mpirun: what
examples/external_tube/main.cpp does in C++, on the same case.

    mpirun -n 1 build/app/partita run examples/external_tube/tube_external.yaml --participant fluid : \\
           -n 1 env PYTHONPATH=build/python /usr/bin/python3 examples/python/tube_external.py \\
                examples/external_tube/tube_external.yaml [--set KEY=VALUE ...]

(with partita's --set options repeated here; partita must be the first process; --mpi4py joins
through mpi4py's COMM_WORLD.) The wall has no
inertia: each step it reads the pressure at the nodes and writes the cross-section area of the
tube law a(p) = a0 ((p0 - 2 rho c^2) / (p - 2 rho c^2))^2, c^2 = E / (2 rho r0), with the
defaults of partita's tube1d-solid, evaluated as the C++ program does: the run's coupling.csv
and tube.csv are byte for byte those of the case run in one process (854 iterations over 100
windows). Its state in restart files is the area; partita run ... --resume DIR resumes it.
"""
import argparse
import math
import sys

import numpy as np

import partita

# The defaults of partita's tube1d-solid (and of the preCICE tutorial).
CELLS, LENGTH, MODULUS, DENSITY = 100, 10.0, 10000.0, 1.0
RADIUS, A0, P0 = 1.0 / math.sqrt(math.pi), 1.0, 0.0


def area_of(p):
    """The tube law at pressures p (an array): the operations of main.cpp's Wall::area_of."""
    two_rho_c2 = 2.0 * DENSITY * (MODULUS / (2.0 * DENSITY * RADIUS))
    q = (P0 - two_rho_c2) / (p - two_rho_c2)
    return A0 * q * q


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("case", help="the case (its participant 'solid' is solver: external)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="partita run's --set options, the same on both sides")
    ap.add_argument("--mpi4py", action="store_true",
                    help="join through mpi4py's COMM_WORLD (MPI initialised by mpi4py, Debian's "
                         "python3-mpi4py) instead of letting partita initialise MPI")
    args = ap.parse_args()
    overrides = dict(o.split("=", 1) for o in args.set)

    x = np.zeros((CELLS + 1, 3))
    x[:, 0] = LENGTH / CELLS * np.arange(CELLS + 1)
    area = area_of(np.zeros(CELLS + 1))
    comm = None
    if args.mpi4py:
        from mpi4py import MPI
        comm = MPI.COMM_WORLD
    with partita.ExternalParticipant("solid", args.case, set=overrides, comm=comm) as solid:
        solid.add_mesh(partita.Mesh("nodes", x, reads=[partita.Field("pressure", 1, "Pa")],
                                    writes=[partita.Field("cross_section_area", 1, "m^2")]))
        solid.write("nodes", "cross_section_area", area)  # the initial value
        solid.set_monitor("mid_area", area[CELLS // 2], "m^2")
        # restart files: the area as bytes (called while this program waits in advance())
        solid.set_restart_writer(lambda: area.tobytes())
        solid.initialize()
        if solid.is_resuming():
            state = np.frombuffer(solid.restart_state(), dtype=float)
            if state.size != area.size:
                sys.exit(f"tube_external.py: the restart point holds {state.size} values, not the "
                         f"{area.size} of this wall's area")
            area[:] = state
            print(f"tube_external.py: resumed at t = {solid.time():g} s", flush=True)

        saved = area.copy()
        while solid.is_coupling_ongoing():
            if solid.requires_writing_checkpoint():
                saved[:] = area
            dt = solid.time_step_size()
            pressure = solid.read("nodes", "pressure")
            area[:] = area_of(pressure)  # in place: the restart writer's lambda sees it
            solid.write("nodes", "cross_section_area", area)
            solid.set_monitor("mid_area", area[CELLS // 2], "m^2")
            solid.advance(dt)
            if solid.requires_reading_checkpoint():
                area[:] = saved
        solid.finalize()
        if solid.stopped_by_signal():
            print(f"tube_external.py: stopped by signal {solid.stopped_by_signal()} "
                  "(resume with partita run ... --resume DIR)", flush=True)
            return 128 + solid.stopped_by_signal()
    print("tube_external.py: finished", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
