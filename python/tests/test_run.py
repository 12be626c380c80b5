"""partita.check, run and read: what the executable does, results as DataFrames."""

import filecmp
import math
import os
import signal
import subprocess
import sys
import time

import pytest

partita = pytest.importorskip("partita")

from conftest import CASES


def test_version_is_the_executables(executable):
    out = subprocess.run([executable, "--version"], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == f"partita {partita.__version__}"


@pytest.mark.parametrize("case", ["uniaxial_compaction/steel.yaml", "elastic_tube_1d/iqn-ils.yaml",
                                  "bouncing_sphere/bouncing_sphere.yaml"])
def test_check_of_shipped_cases(case):
    info = partita.check(CASES / case)
    assert info["name"]
    assert info["external_participants"] == []


def test_bouncing_sphere_rebounds_to_e_squared(sphere_case, tmp_path, executable):
    # restitution e = 0.5: the sphere rises again to e^2 = 0.25 of its drop height (energy:
    # v' = e v, h' = v'^2 / 2g), within the 2 % the case's own check allows
    r = partita.run(sphere_case, output=tmp_path / "py", threads=1)
    df = r.monitors["sphere"]
    assert df.attrs["units"]["ball.particle.1.z"] == "m"
    assert df.attrs["units"]["time"] == "s"
    radius = 0.005
    z, vz = df["ball.particle.1.z"].to_numpy(), df["ball.particle.1.vz"].to_numpy()
    hit = next(k for k in range(1, len(vz)) if vz[k - 1] < 0.0 <= vz[k])
    fall = next(k for k in range(hit + 1, len(vz)) if vz[k] < 0.0)
    ratio = (z[hit:fall + 1].max() - radius) / (z[0] - radius)
    assert ratio == pytest.approx(0.25, rel=0.02)
    # the summary: every window once (explicit: one iteration each), the time in the participant
    windows = round(0.25 / 1.0e-4)
    assert r.summary.windows == windows and r.summary.iterations == windows
    assert set(r.summary.participant_seconds) == {"ball"}
    assert r.summary.wall_seconds >= r.summary.participant_seconds["ball"]
    assert len(r.coupling) == windows and r.coupling.attrs["units"]["iterations"] == ""
    assert "ball_particles" in r.vtk and r.vtk["ball_particles"].exists()
    # read() of the folder gives the same frames
    again = partita.read(r.output_dir)
    assert again.monitors.keys() == r.monitors.keys()
    for name in r.monitors:
        assert again.monitors[name].equals(r.monitors[name])
        assert again.monitors[name].attrs["units"] == r.monitors[name].attrs["units"]
    assert again.coupling.equals(r.coupling)
    assert again.summary.windows == windows and again.summary.iterations == windows
    # the executable writes the same bytes into its folder
    subprocess.run([executable, "run", str(sphere_case), "--output", str(tmp_path / "cli"),
                    "--threads", "1", "--log-level", "warn", "--no-plots"], check=True)
    for f in ("coupling.csv", "sphere.csv"):
        assert filecmp.cmp(tmp_path / "py" / f, tmp_path / "cli" / f, shallow=False), f


def test_steel_plate_carries_the_applied_load_and_its_weight(tmp_path):
    # seed 000 shortened as the case's checks.yaml does: the force of the granules on the plate
    # equals the applied pressure on the plate plus the plate's weight (static equilibrium)
    r = partita.run(CASES / "uniaxial_compaction" / "steel.yaml", output=tmp_path,
                    set={"participants.plate.mesh.box.cells": [10, 10, 1], "time.end": 0.02})
    df = r["reaction"]
    assert df.attrs["units"]["granules.plate.force_z"] == "N"
    side, thickness = 0.020, 0.001
    expected = 10e3 * side**2 + 7850 * side**2 * thickness * 9.81
    last = df.tail(max(1, len(df) // 5))
    assert last["granules.plate.force_z"].mean() == pytest.approx(expected, rel=0.015)
    assert last["plate.bottom.force_z"].mean() == pytest.approx(expected, rel=0.015)


def test_case_error_names_file_line_and_key(sphere_case):
    lines = sphere_case.read_text().splitlines()
    n = next(i for i, l in enumerate(lines) if "particles: {material: steel" in l)
    lines[n] = lines[n].replace("material: steel", "materail: steel")
    sphere_case.write_text("\n".join(lines) + "\n")
    with pytest.raises(partita.CaseError) as e:
        partita.check(sphere_case)
    assert e.value.file == str(sphere_case)
    assert e.value.line == n + 1
    assert e.value.key == "participants.ball.particles.materail"
    assert "did you mean 'material'" in str(e.value)
    assert str(e.value).startswith(f"{sphere_case}:{n + 1}:")
    # the same from run(), before anything is written
    with pytest.raises(partita.CaseError):
        partita.run(sphere_case, output=sphere_case.parent / "out")
    assert not (sphere_case.parent / "out").exists()


def test_errors_without_a_key_and_from_set(tmp_path, sphere_case):
    with pytest.raises(partita.Error) as e:
        partita.check(tmp_path / "none.yaml")
    assert not isinstance(e.value, partita.CaseError) and "none.yaml" in str(e.value)
    with pytest.raises(partita.CaseError) as e:
        partita.check(sphere_case, set={"time.end": -1})
    assert e.value.key == "time.end" and "partita.check(set={'time.end'" in str(e.value)
    with pytest.raises(partita.Error):
        partita.run(sphere_case, set={"time": [1, 2]})


def test_ctrl_c_stops_after_the_window_and_the_run_resumes_bit_for_bit(sphere_case, tmp_path):
    # a KeyboardInterrupt (here raised by SIGINT from the progress callback) stops the run as
    # Ctrl-C stops the executable's: the window ends, a restart file, complete CSV files; the
    # resumed run then ends with the bytes of an uninterrupted one
    end = {"time.end": 0.05, "output.restart": {"every_windows": 100}}
    whole = partita.run(sphere_case, output=tmp_path / "whole", set=end)
    calls = []

    def interrupt(p):
        calls.append(p)
        if len(calls) == 1:
            os.kill(os.getpid(), signal.SIGINT)

    with pytest.raises(KeyboardInterrupt) as e:
        partita.run(sphere_case, output=tmp_path / "cut", set=end, progress=interrupt, poll=0.001)
    cut = e.value.result
    assert cut.summary.stopped_by_signal == signal.SIGINT
    assert 0 < cut.summary.windows < whole.summary.windows
    assert len(cut.coupling) == cut.summary.windows  # every finished window's row, no partial one
    assert cut.summary.last_restart is not None and cut.summary.last_restart.exists()
    resumed = partita.run(sphere_case, resume=tmp_path / "cut", set=end)
    assert resumed.summary.resumed_from == cut.summary.windows
    for f in ("coupling.csv", "sphere.csv"):
        assert filecmp.cmp(tmp_path / "whole" / f, tmp_path / "cut" / f, shallow=False), f


def test_progress_reaches_the_last_window(sphere_case, tmp_path):
    seen = []
    r = partita.run(sphere_case, output=tmp_path, set={"time.end": 0.02}, progress=seen.append)
    assert seen and seen[-1].window == seen[-1].windows == r.summary.windows
    assert [p.window for p in seen] == sorted(p.window for p in seen)


def test_an_exception_of_the_progress_callback_stops_the_run_and_is_raised(sphere_case, tmp_path):
    class Enough(Exception):
        pass

    def stop(p):
        raise Enough("enough")

    with pytest.raises(Enough) as e:
        partita.run(sphere_case, output=tmp_path, set={"time.end": 0.05}, progress=stop, poll=0.001)
    r = e.value.result
    assert r.summary.stopped_by_signal == signal.SIGINT
    assert r.summary.windows < round(0.05 / 1.0e-4)
    assert len(r.coupling) == r.summary.windows


_SLOW_RUN = r"""
import sys, time
import partita
sys.path.insert(0, sys.argv[1])
import tube_python_solid

class SlowWall(tube_python_solid.TubeSolid):
    def advance(self, dt):  # a window of about 20 iterations takes 2 s
        super().advance(dt)
        time.sleep(0.1)

partita.register_solver("py-slow-wall", SlowWall)
def progress(p):
    print("window", p.window, flush=True)
partita.run(sys.argv[2], output=sys.argv[3], set={"participants.solid.solver": "py-slow-wall"},
            progress=progress, poll=0.01)
"""


def test_a_second_ctrl_c_during_the_clean_stop_ends_the_process_as_the_cli_does(tmp_path):
    # the executable's SIGINT handler is reset after the first signal (SA_RESETHAND): a second
    # Ctrl-C while the run finishes its window ends the process at once, killed by SIGINT
    from conftest import ROOT
    child = subprocess.Popen([sys.executable, "-c", _SLOW_RUN, str(ROOT / "examples" / "python"),
                              str(CASES / "elastic_tube_1d" / "iqn-ils.yaml"), str(tmp_path / "out")],
                             stdout=subprocess.PIPE, text=True)
    try:
        assert child.stdout.readline().startswith("window")  # the run is under way
        child.send_signal(signal.SIGINT)                       # the clean stop: the window goes on
        time.sleep(0.3)
        assert child.poll() is None
        start = time.monotonic()
        child.send_signal(signal.SIGINT)
        assert child.wait(timeout=30) == -signal.SIGINT
        assert time.monotonic() - start < 1.0                  # not after the window's end
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
