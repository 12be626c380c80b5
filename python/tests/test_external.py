"""partita.ExternalParticipant's checks before it joins a run (no MPI needed): what a program
gets wrong is a partita.UsageError or partita.Error naming it. The run itself under mpirun is the
ctest test python-external (external_tube_mpi.py)."""

import numpy as np
import pytest

partita = pytest.importorskip("partita")

from conftest import ROOT

CASE = ROOT / "examples" / "external_tube" / "tube_external.yaml"

pytestmark = pytest.mark.skipif(not getattr(partita._partita, "has_mpi", False),
                                reason="partita is built without MPI")


@pytest.fixture
def solid():
    p = partita.ExternalParticipant("solid", CASE)
    p.add_mesh(partita.Mesh("nodes", np.zeros((11, 3)), reads=[partita.Field("pressure", 1, "Pa")],
                            writes=[partita.Field("cross_section_area", 1, "m^2"),
                                    partita.Field("wall_force", 3, "N", "extensive")]))
    yield p
    p.close()


def test_writes_of_the_wrong_shape_name_or_value_are_refused(solid):
    solid.write("nodes", "cross_section_area", np.ones(11))            # (n,) for 1 component
    solid.write("nodes", "wall_force", np.ones((11, 3)))               # (n, 3) for 3
    with pytest.raises(partita.UsageError, match=r"shape \(10\), not \(11,\)"):
        solid.write("nodes", "cross_section_area", np.ones(10))
    with pytest.raises(partita.UsageError, match=r"shape \(11\), not \(11, 3\)"):
        solid.write("nodes", "wall_force", np.ones(11))
    with pytest.raises(partita.UsageError, match="declared no mesh 'nodes' that writes 'pressure'"):
        solid.write("nodes", "pressure", np.ones(11))
    area = np.ones(11)
    area[4] = np.nan
    with pytest.raises(partita.Error, match="nan at point 4"):
        solid.write("nodes", "cross_section_area", area)


def test_calls_out_of_order_are_usage_errors(solid):
    with pytest.raises(partita.UsageError, match="outside a step"):
        solid.read("nodes", "pressure")
    with pytest.raises(partita.UsageError, match="without a step"):
        solid.advance(0.01)
    with pytest.raises(partita.UsageError, match="before initialize"):
        solid.is_resuming()
    with pytest.raises(partita.UsageError, match="> 0"):
        solid.set_stable_time_step(0.0)
    with pytest.raises(partita.UsageError, match="callable"):
        solid.set_restart_writer(b"state")
    solid.close()
    with pytest.raises(partita.UsageError, match="closed"):
        solid.time()


def test_a_communicator_must_be_mpi4pys():
    with pytest.raises(partita.Error, match="mpi4py communicator"):
        partita.ExternalParticipant("solid", CASE, comm=3)
