"""A Python solver coupled with partita's native DEM under explicit coupling: the out-of-tree
example's spring-mass lid (examples/out_of_tree_adapter) written in Python
(examples/python/lid_python_oscillator.py) against the C++ oscillator, loaded as a plugin into
the partita executable, on lid_on_granules.yaml."""

import sys

import numpy as np
import pytest

partita = pytest.importorskip("partita")

from conftest import ROOT

sys.path.insert(0, str(ROOT / "examples" / "python"))
import lid_python_oscillator as lid  # noqa: E402  (registers "py-oscillator")

# 1500 windows of 10 us: the lid presses the bed and the granules carry it (about 2 s for both runs)
END = 0.015


def test_python_lid_on_granules_moves_as_the_cpp_lid(tmp_path, executable):
    plugin = lid.default_plugin()
    if not plugin.exists():
        pytest.skip(f"the oscillator plugin {plugin} is not built (tests/CMakeLists.txt builds it)")
    py = lid.run_python(tmp_path / "python", end=END)
    cpp = lid.run_cpp(tmp_path / "cpp", plugin, end=END)
    assert py.summary.windows == cpp.summary.windows == round(END / 1.0e-5)
    # The Python lid makes the C++ lid's operations in the same order on the same doubles (Python
    # floats are IEEE doubles; math.sqrt/exp/cosh/sinh are the libm functions the C++ calls; the
    # build does not contract a*b+c into FMAs), and it reads and writes the same values through
    # the same mappers: the whole coupled run is the same to the last bit, so lid.csv (the lid's
    # motion and the DEM's forces) is the same file.
    assert (tmp_path / "python" / "lid.csv").read_bytes() == (tmp_path / "cpp" / "lid.csv").read_bytes()
    z = py["lid"]["lid.z"].to_numpy()
    np.testing.assert_array_equal(z, cpp["lid"]["lid.z"].to_numpy())
    # and it did couple: the lid, pushed by its weight and the preloaded spring, went down into
    # the bed, whose contacts push back on it
    assert z[0] == pytest.approx(0.010)
    assert z[-1] < z[0] - 1.0e-4
    assert py["lid"]["granules.lid.force_z"].iloc[-1] > 0.5


def test_python_oscillator_alone_follows_the_exact_solution(tmp_path):
    # the lid's update is exact for a force held over a step: without the granules (no force)
    # and without gravity or dashpot the mass oscillates as z0 cos(w t), w = sqrt(k/m)
    s = lid.Oscillator({"mass": "2 kg", "stiffness": 50, "displacement": "10 mm"})
    s.read("mass", "force", np.zeros((1, 3)))
    w, dt = np.sqrt(50 / 2.0), 1.0e-2
    for _ in range(100):
        s.advance(dt)
    assert s.time() == pytest.approx(1.0)
    assert s.z == pytest.approx(0.010 * np.cos(w * 1.0), rel=1e-12, abs=1e-15)
    assert s.write("mass", "displacement")[0].tolist() == [0.0, 0.0, s.z]
