"""partita.sweep: the variants of a sweep given in Python, one DataFrame of values and results."""

import math

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
