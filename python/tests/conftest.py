"""The pytest suite of the partita module. Run from the build tree (ctest runs it so):
    PYTHONPATH=build/python PARTITA_NO_PLOTS=1 /usr/bin/python3 -m pytest python/tests
Without the built module every test is skipped with the reason."""

import os
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
CASES = ROOT / "cases"

try:
    import partita  # noqa: F401
    MISSING = None
except ImportError as e:  # the module is not built, or PYTHONPATH does not name build/python
    MISSING = f"the partita module is not importable ({e}); build it and set PYTHONPATH=build/python"


def pytest_collection_modifyitems(config, items):
    if MISSING:
        for item in items:
            item.add_marker(pytest.mark.skip(reason=MISSING))


@pytest.fixture(autouse=True)
def _quiet(monkeypatch):
    monkeypatch.setenv("PARTITA_NO_PLOTS", os.environ.get("PARTITA_NO_PLOTS", "1"))
    if not MISSING:
        partita.set_log_level("warn")


@pytest.fixture
def executable():
    """The partita executable of the build the module belongs to."""
    from partita._paths import executable as exe
    if not Path(exe).exists():
        pytest.skip(f"the partita executable {exe} is not built")
    return exe


@pytest.fixture
def sphere_case(tmp_path):
    """A copy of cases/bouncing_sphere (the case file and its particle file) in tmp_path."""
    for f in ("bouncing_sphere.yaml", "sphere.data"):
        shutil.copy(CASES / "bouncing_sphere" / f, tmp_path / f)
    return tmp_path / "bouncing_sphere.yaml"
