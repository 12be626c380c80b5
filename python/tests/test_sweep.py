"""partita.sweep: the variants of a sweep given in Python, one DataFrame of values and results."""

import math
import subprocess

import pytest

partita = pytest.importorskip("partita")


def test_sweep_over_restitution_gives_the_rebound_speed(sphere_case, tmp_path, executable):
    # the sphere hits the plane at sqrt(2 g h) (h = 0.1 m) and leaves it at e times that speed:
    # the largest upward velocity of each variant is e sqrt(2 g h)
    key = "participants.ball.interactions[0].restitution"
    restitutions = [0.3, 0.6]
    df = partita.sweep(sphere_case, over={key: restitutions}, jobs=2, output=tmp_path / "sweep",
                       set={"time.end": 0.2},
                       results=[{"name": "rebound_speed", "monitor": "sphere",
                                 "column": "ball.particle.1.vz", "of": "max"}])
    assert list(df["restitution"]) == restitutions
    assert list(df["status"]) == ["ok", "ok"]
    impact = math.sqrt(2 * 9.81 * 0.1)
    for e, v in zip(df["restitution"], df["rebound_speed"]):
        assert v == pytest.approx(e * impact, rel=0.02)
    # each variant's folder reads as a run
    for folder in df["folder"]:
        r = partita.read(folder)
        assert r.summary.windows == round(0.2 / 1.0e-4)
    assert (tmp_path / "sweep" / "sweep.csv").exists()


def test_sweep_refuses_a_value_its_key_does_not_take(sphere_case, tmp_path):
    # checked before any variant runs (as partita run does), naming the key and the value
    with pytest.raises(partita.Error) as e:
        partita.sweep(sphere_case, over={"participants.ball.interactions[0].restitution": [0.5, 2.0]},
                      output=tmp_path / "bad")
    assert "participants.ball.interactions[0].restitution" in str(e.value)
    assert "2.0" in str(e.value)
    assert not (tmp_path / "bad").exists()


def test_a_swept_value_error_is_a_case_error_at_its_key(sphere_case, tmp_path):
    # over= given in Python: the CaseError names the key, the value and where it was given
    key = "participants.ball.materials.steel.youngs_modulus"
    with pytest.raises(partita.CaseError) as e:
        partita.sweep(sphere_case, over={key: ["200 GPa", "-3 GPa"]}, output=tmp_path / "bad")
    assert e.value.key == key
    assert e.value.file == "partita.sweep(over=...)"
    assert "the swept value -3 GPa" in e.value.detail and "0 < value" in e.value.detail
    assert str(e.value).startswith(f"partita.sweep(over=...): key '{key}': ")


def test_a_swept_value_of_the_case_file_is_located_as_the_cli_locates_it(sphere_case, tmp_path, executable):
    # the case file's own sweep section: file, line and key of the bad value, and the message
    # the executable prints after "partita: error: "
    text = sphere_case.read_text() + (
        "sweep:\n"
        "  parameters:\n"
        "    - key: participants.ball.interactions[0].friction\n"
        "      values: [0.3, -0.5]\n")
    sphere_case.write_text(text)
    line = text.splitlines().index("      values: [0.3, -0.5]") + 1
    with pytest.raises(partita.CaseError) as e:
        partita.sweep(sphere_case, output=tmp_path / "bad")
    assert e.value.file == str(sphere_case)
    assert e.value.line == line
    assert e.value.key == "participants.ball.interactions[0].friction"
    assert "the swept value -0.5" in e.value.detail
    cli = subprocess.run([executable, "run", str(sphere_case), "-o", str(tmp_path / "cli")],
                         capture_output=True, text=True)
    assert cli.returncode != 0
    printed = [ln for ln in cli.stderr.splitlines() if ln.startswith("partita: error: ")]
    assert printed and printed[-1] == "partita: error: " + str(e.value)
