"""Solvers written in Python (partita.Solver, partita.register_solver) coupled in process with
partita's own: the 1D tube's wall in Python against the C++ wall, and the errors of a Python
solver that raises or returns non-finite values."""

import filecmp
import sys

import numpy as np
import pandas as pd
import pytest

partita = pytest.importorskip("partita")

from conftest import CASES, ROOT

sys.path.insert(0, str(ROOT / "examples" / "python"))
import tube_python_solid  # noqa: E402  (registers "py-tube-solid")

# 30 windows: past the first pressure wave's reflection, enough to tell the accelerations apart
END = 0.3


@pytest.mark.parametrize("acceleration", ["iqn-ils", "aitken"])
def test_python_tube_wall_takes_the_iterations_of_the_cpp_wall(acceleration, tmp_path):
    # The same tube law evaluated the same way: the coupled fixed point and every iterate the
    # acceleration builds from it are the same, so each window converges after as many iterations
    py, cpp = tube_python_solid.run_both(CASES / "elastic_tube_1d" / f"{acceleration}.yaml",
                                         tmp_path, end=END)
    assert py.summary.windows == cpp.summary.windows == round(END / 0.01)
    assert (py.coupling["iterations"] > 1).all()  # implicit: every window iterates
    np.testing.assert_array_equal(py.coupling["iterations"].to_numpy(),
                                  cpp.coupling["iterations"].to_numpy())
    # the Python wall's monitors reach the case's monitor with their units
    assert py["tube"].attrs["units"]["solid.mid_area"] == "m^2"
    np.testing.assert_allclose(py["tube"]["solid.mid_area"], cpp["tube"]["solid.mid_area"],
                               rtol=1e-12)


def test_register_solver_lists_it_and_refuses_partitas_names():
    assert "py-tube-solid" in partita.solvers()
    assert "py-tube-solid" in partita._partita.solver_names()
    with pytest.raises(partita.Error, match="partita has a solver of that name"):
        partita.register_solver("tube1d-solid", tube_python_solid.TubeSolid)
    with pytest.raises(partita.Error, match="must be callable"):
        partita.register_solver("py-nothing", 3)


def test_factory_gets_the_case_section_and_context(tmp_path):
    seen = {}

    def factory(config, context):
        seen["config"], seen["context"] = config, context
        return tube_python_solid.TubeSolid(config)

    partita.register_solver("py-tube-solid-context", factory)
    partita.check(CASES / "elastic_tube_1d" / "aitken.yaml",
                  set={"participants.solid.solver": "py-tube-solid-context",
                       "participants.solid.youngs_modulus": "10 kPa",
                       "participants.solid.cells": 100})
    assert seen["config"]["solver"] == "py-tube-solid-context"
    assert seen["config"]["cells"] == 100
    assert partita.quantity(seen["config"]["youngs_modulus"], "Pa") == pytest.approx(1.0e4)
    assert seen["context"].name == "solid"
    assert seen["context"].case_dir.endswith("elastic_tube_1d")


class _FailingWall(tube_python_solid.TubeSolid):
    """The tube wall that fails in its fourth window: an exception in advance() or a NaN area."""

    def __init__(self, config, how):
        super().__init__(config)
        self.how = how

    def advance(self, dt):
        super().advance(dt)
        if self.t > 0.035:
            if self.how == "raise":
                raise RuntimeError("the wall tore at its middle node")
            self.area = self.area.copy()
            self.area[self.cells // 2] = np.nan


@pytest.mark.parametrize("how", ["raise", "nan"])
def test_a_failing_python_solver_stops_the_run_naming_it(how, tmp_path):
    name = f"py-tube-solid-{how}"
    partita.register_solver(name, lambda config: _FailingWall(config, how))
    out = tmp_path / how
    with pytest.raises(partita.Error) as caught:
        partita.run(CASES / "elastic_tube_1d" / "aitken.yaml", output=out, threads=1,
                    set={"participants.solid.solver": name, "time.end": END})
    message = str(caught.value)
    assert f"participant 'solid' (Python solver '{name}')" in message
    if how == "raise":
        assert "advance() raised RuntimeError: the wall tore at its middle node" in message
        assert "test_solver.py" in message and "in advance)" in message  # the innermost frame
    else:
        assert "write('nodes', 'cross_section_area') returned nan at point 50" in message
    # the windows before the failure are in the output folder
    coupling = pd.read_csv(out / "coupling.csv", comment="#")
    assert len(coupling) >= 3
    assert (out / "tube.csv").exists()


def test_a_solver_missing_a_method_is_refused(tmp_path):
    class NoSolver:
        pass

    partita.register_solver("py-not-a-solver", lambda config: NoSolver())
    with pytest.raises(partita.Error, match=r"Python solver 'py-not-a-solver'\): the object its "
                                            r"factory returned has no method meshes\(\)"):
        partita.check(CASES / "elastic_tube_1d" / "aitken.yaml",
                      set={"participants.solid.solver": "py-not-a-solver"})


def test_a_sweep_refuses_a_solver_registered_in_python(tmp_path):
    # a sweep's variants are partita processes, which know no solver registered in this one
    with pytest.raises(partita.CaseError, match="registered in Python, which a sweep cannot use") as caught:
        partita.sweep(CASES / "elastic_tube_1d" / "aitken.yaml", output=tmp_path,
                      over={"participants.solid.youngs_modulus": [1.0e4, 2.0e4]},
                      set={"participants.solid.solver": "py-tube-solid"})
    assert caught.value.key == "participants.solid.solver"


def test_a_python_solver_resumes_from_its_restart_bytes_bit_for_bit(tmp_path):
    # write_restart()/read_restart(): a run resumed from the restart file after window 10 ends
    # with the bytes of the uninterrupted run
    case = CASES / "elastic_tube_1d" / "iqn-ils.yaml"
    solid = {"participants.solid.solver": "py-tube-solid"}
    whole = partita.run(case, output=tmp_path / "whole", threads=1, set={**solid, "time.end": 0.2})
    partita.run(case, output=tmp_path / "cut", threads=1,
                set={**solid, "time.end": 0.1, "output.restart": {"at_end": True}})
    resumed = partita.run(case, resume=tmp_path / "cut", threads=1, set={**solid, "time.end": 0.2})
    assert resumed.summary.resumed_from == 10 and whole.summary.windows == 20
    for f in ("coupling.csv", "tube.csv"):
        assert filecmp.cmp(tmp_path / "whole" / f, tmp_path / "cut" / f, shallow=False), f


def test_a_mesh_request_of_a_python_solver_is_checked_at_its_section():
    # mesh_requests(): the core hands over another participant's surface; the tube's nodes
    # have no triangles, which the core refuses at the requesting participant's section
    class AsksForNodes(tube_python_solid.TubeSolid):
        def mesh_requests(self):
            return [("fluid_nodes", "fluid.nodes")]

    partita.register_solver("py-tube-solid-asking", AsksForNodes)
    with pytest.raises(partita.CaseError, match="has no triangles") as caught:
        partita.check(CASES / "elastic_tube_1d" / "aitken.yaml",
                      set={"participants.solid.solver": "py-tube-solid-asking"})
    assert caught.value.key == "participants.solid"
