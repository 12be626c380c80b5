"""A Python program with its own time loop as one participant of a partita run over MPI
(docs/python.md, "A program with its own time loop"): partita::mpi::ExternalParticipant, the
external-code API of C++ programs, for Python."""

from __future__ import annotations

from pathlib import Path
from typing import Any, Callable, Dict, Optional, Union

import numpy as np

from . import _partita
from ._errors import Error


class ExternalParticipant:
    """Participant ``participant`` of the case ``case`` (``solver: external`` there), computed by
    this program, started beside partita under mpirun (partita first: it runs the coupling core)::

        mpirun -n 1 partita run CASE --participant OTHER : -n 1 python3 program.py

    ``set``: the case's overrides, as ``partita run --set`` (the same on every process).
    ``comm``: the communicator of the run's processes, an mpi4py communicator (default:
    MPI_COMM_WORLD, MPI initialised by the API unless mpi4py or the program did).
    ``peer_timeout`` [s]: the longest wait for the controller.

    The loop, as in C++ (coupling/mpi/include/partita/mpi/external_participant.hpp)::

        p.add_mesh(partita.Mesh("nodes", points, reads=[...], writes=[...]))
        p.write("nodes", "area", area)                    # initial values
        p.initialize()
        while p.is_coupling_ongoing():
            if p.requires_writing_checkpoint(): save the state
            dt = p.time_step_size()
            pressure = p.read("nodes", "pressure")         # at the step's end (a new array)
            ... step ...; p.write("nodes", "area", area)  # copied
            p.advance(dt)
            if p.requires_reading_checkpoint(): restore the state
        p.finalize()

    Used as a context manager (``with partita.ExternalParticipant(...) as p:``) it is closed on
    leaving: an exception in the loop ends the run on partita's side with a message naming the
    participant instead of a wait for its timeout."""

    def __init__(self, participant: str, case: Union[str, Path], set: Optional[Dict[str, Any]] = None,
                 comm: Any = None, peer_timeout: float = 600.0):
        if not getattr(_partita, "has_mpi", False):
            raise Error("partita.ExternalParticipant: this partita was built without MPI "
                        "(install libopenmpi-dev and rebuild: ./build.sh)")
        from . import _overrides
        handle = None
        if comm is not None:
            if not hasattr(comm, "py2f"):
                raise Error(f"partita.ExternalParticipant: comm must be an mpi4py communicator "
                            f"(mpi4py.MPI.Comm), not {type(comm).__name__}")
            handle = comm.py2f()
        self._p = _partita.ExternalParticipant(participant, str(case), _overrides(set), handle,
                                               float(peer_timeout))
        self.participant = participant

    # before initialize()
    def add_mesh(self, mesh: Any) -> None:
        """A coupling mesh (a partita.Mesh) with the fields the program reads and writes on it."""
        self._p.add_mesh(mesh)

    def set_stable_time_step(self, dt: float) -> None:
        """The largest step the program can take [s] (for substeps: auto); default no limit."""
        self._p.set_stable_time_step(dt)

    def set_restart_writer(self, state: Callable[[], bytes]) -> None:
        """Restart files: ``state()`` returns the program's state as bytes. Called when the run
        writes a restart file, between windows, while the program waits in advance()."""
        self._p.set_restart_writer(state)

    def initialize(self) -> None:
        """Join the run (the handshake); partita.RunStopped where the controller refuses it."""
        self._p.initialize()

    # after initialize()
    def is_resuming(self) -> bool:
        """Whether the run resumes from a restart file (partita run ... --resume DIR)."""
        return self._p.is_resuming()

    def restart_state(self) -> bytes:
        """The bytes the restart writer gave at the restart point (when is_resuming())."""
        return self._p.restart_state()

    def is_coupling_ongoing(self) -> bool:
        return self._p.is_coupling_ongoing()

    def stopped_by_signal(self) -> int:
        """Once the run has ended: the signal that stopped it after a window (0: it ran to its end)."""
        return self._p.stopped_by_signal()

    def time_step_size(self) -> float:
        """The step to take now [s] (advance() must be given it)."""
        return self._p.time_step_size()

    def time(self) -> float:
        """The time at the start of the step [s]."""
        return self._p.time()

    def requires_writing_checkpoint(self) -> bool:
        return self._p.requires_writing_checkpoint()

    def requires_reading_checkpoint(self) -> bool:
        return self._p.requires_reading_checkpoint()

    def read(self, mesh: str, data: str, relative_read_time: Optional[float] = None) -> np.ndarray:
        """An input as a new array, (n,) or (n, 3): at the end of the current step, or
        ``relative_read_time`` [s] after its start (in [0, time_step_size()])."""
        return self._p.read(mesh, data, relative_read_time)

    def write(self, mesh: str, data: str, values: Any) -> None:
        """An output at the end of the current step, (n,) or (n, 3) (copied; finite values)."""
        self._p.write(mesh, data, values)

    def set_monitor(self, name: str, value: float, unit: str = "") -> None:
        """A scalar for the case's monitors (participant.name), reported after each window."""
        self._p.set_monitor(name, float(value), unit)

    def advance(self, dt: float) -> None:
        """The step is done; waits for the next one (or the end of the run)."""
        self._p.advance(dt)

    def finalize(self) -> None:
        """After the last window (is_coupling_ongoing() false)."""
        self._p.finalize()

    def close(self) -> None:
        """Leave: a run still going ends with an error naming this participant."""
        self._p.close()

    def __enter__(self) -> "ExternalParticipant":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()
