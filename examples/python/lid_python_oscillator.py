#!/usr/bin/python3
"""A spring-mass lid on granules with the lid written in Python: the out-of-tree example's
oscillator (examples/out_of_tree_adapter/oscillator_adapter.cpp, a mass on a spring along z)
as a partita.Solver, registered as "py-oscillator" and coupled in process with partita's native
DEM in examples/out_of_tree_adapter/lid_on_granules.yaml (explicit coupling), then the same case
with the C++ oscillator loaded as a plugin into the partita executable, for comparison.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/lid_python_oscillator.py [--end T] [--plugin LIB]

LIB is the oscillator plugin built from examples/out_of_tree_adapter (its CMakeLists.txt, or
the test build's build/tests/libpartita_test_plugin_oscillator.so, the default). Without it only
the Python lid runs. Writes out/lid-python-oscillator/{python,cpp}/.

The lid takes the same steps as the C++ one in the same order (the exact solution for a force
held over the step, the same libm functions), so the two runs agree to the last bit: the same
lid.csv, row for row.
"""
import argparse
import math
import os
import subprocess
import time
from pathlib import Path

import numpy as np

import partita

ROOT = Path(__file__).resolve().parents[2]
CASE = ROOT / "examples" / "out_of_tree_adapter" / "lid_on_granules.yaml"


def default_plugin():
    """The oscillator plugin the test build makes beside the executable the module runs sweeps
    with (build/tests/libpartita_test_plugin_oscillator.so), which may not exist."""
    from partita._paths import executable
    return Path(executable).resolve().parents[1] / "tests" / "libpartita_test_plugin_oscillator.so"


class Oscillator(partita.Solver):
    """A mass on a spring along z: mesh "mass" (one point at the origin), writes "displacement"
    [m] (0, 0, z), reads "force" [N] (its z component loads the mass); optionally under gravity
    g along z and with a dashpot c to the fixed support. Monitors z, v and energy."""

    def __init__(self, config):
        # the participant's case section, with the C++ oscillator's keys and defaults
        def value(key, unit, default=None):
            if key not in config:
                if default is None:
                    raise partita.Error(f"oscillator: the key {key!r} [{unit}] is required")
                return default
            return partita.quantity(config[key], unit)

        self.m = value("mass", "kg")
        self.k = value("stiffness", "N/m")
        if self.m <= 0.0 or self.k <= 0.0:
            raise partita.Error("oscillator: mass and stiffness must be positive")
        self.g = value("gravity", "m/s^2", 0.0)
        self.c = value("damping", "N s/m", 0.0)
        if self.c < 0.0:
            raise partita.Error("oscillator: damping must not be negative")
        self.z = value("displacement", "m", 0.0)
        self.v = value("velocity", "m/s", 0.0)
        self.t = 0.0
        self.force = 0.0
        self.saved = (self.z, self.v, self.t)
        self.out = np.zeros((1, 3))

    def meshes(self):
        return [partita.Mesh("mass", np.zeros((1, 3)),
                             writes=[partita.Field("displacement", 3, "m", "intensive")],
                             reads=[partita.Field("force", 3, "N", "extensive")])]

    def read(self, mesh, data, values):
        self.force = float(values[0, 2])  # the z component of the force on the one point

    def write(self, mesh, data):
        self.out[0, 2] = self.z
        return self.out  # copied by partita

    def advance(self, dt):
        # Exact for the force held over the step, as the C++ adapter computes it (the same
        # operations in the same order): about z_eq = (F + m g) / k the motion y = z - z_eq is
        # that of a free damped oscillator, w0 = sqrt(k/m), h = c/(2m); under-, over- or
        # critically damped by the sign of d = w0^2 - h^2.
        w0 = math.sqrt(self.k / self.m)
        z_eq = (self.force + self.m * self.g) / self.k
        h = self.c / (2.0 * self.m)
        d = w0 * w0 - h * h
        C, S = 1.0, dt
        if d > 0.0:
            wd = math.sqrt(d)
            C = math.cos(wd * dt)
            S = math.sin(wd * dt) / wd
        elif d < 0.0:
            q = math.sqrt(-d)
            C = math.cosh(q * dt)
            S = math.sinh(q * dt) / q
        decay = math.exp(-h * dt)
        y = self.z - z_eq
        z = z_eq + decay * (y * C + (self.v + h * y) * S)
        self.v = decay * (self.v * C - (w0 * w0 * y + h * self.v) * S)
        self.z = z
        self.t += dt

    def time(self):
        return self.t

    def save_checkpoint(self):
        self.saved = (self.z, self.v, self.t)

    def restore_checkpoint(self):
        self.z, self.v, self.t = self.saved

    def write_restart(self):
        return np.array([self.z, self.v, self.t, self.force]).tobytes()

    def read_restart(self, data):
        self.z, self.v, self.t, self.force = (float(x) for x in np.frombuffer(data, dtype=float))

    def monitors(self):
        energy = 0.5 * self.m * self.v * self.v + 0.5 * self.k * self.z * self.z - self.m * self.g * self.z
        return {"z": (self.z, "m"), "v": (self.v, "m/s"), "energy": (energy, "J")}


partita.register_solver("py-oscillator", Oscillator, "a mass on a spring along z, in Python")


def run_python(output, end=None, threads=1):
    """lid_on_granules.yaml with the Python lid: its partita.Result."""
    overrides = {"participants.lid.solver": "py-oscillator"}
    if end is not None:
        overrides["time.end"] = end
    return partita.run(CASE, output=output, threads=threads, set=overrides)


def run_cpp(output, plugin=None, end=None, threads=1):
    """lid_on_granules.yaml with the C++ lid: the partita executable with the oscillator plugin
    (a partita process: the module does not load plugins). Its partita.Result."""
    from partita._paths import executable
    plugin = default_plugin() if plugin is None else plugin
    cmd = [executable, "run", str(CASE), "--plugin", str(plugin), "--output", str(output),
           "--threads", str(threads)]
    if end is not None:
        cmd += ["--set", f"time.end={end!r}"]
    done = subprocess.run(cmd, capture_output=True, text=True,
                          env={**os.environ, "PARTITA_LOG_LEVEL": "warn"})
    if done.returncode != 0:
        raise partita.Error(f"{' '.join(cmd)} failed: {done.stderr.strip()}")
    return partita.read(output)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--end", type=float, help="end time [s] (default: the case's, 0.04 s)")
    ap.add_argument("--plugin", type=Path, default=default_plugin(),
                    help="the C++ oscillator plugin (default: the test build's)")
    args = ap.parse_args()
    out = Path("out") / "lid-python-oscillator"
    start = time.perf_counter()
    py = run_python(out / "python", args.end)
    lid = py["lid"]
    print(f"Python lid: {py.summary.windows} windows, z from {lid['lid.z'].iloc[0]:.6g} m to "
          f"{lid['lid.z'].iloc[-1]:.6g} m, force of the granules {lid['granules.lid.force_z'].iloc[-1]:.6g} N "
          f"({time.perf_counter() - start:.1f} s)")
    if not args.plugin.exists():
        print(f"no C++ oscillator plugin at {args.plugin}: no comparison")
        return
    cpp = run_cpp(out / "cpp", args.plugin, args.end)
    same = (out / "python" / "lid.csv").read_bytes() == (out / "cpp" / "lid.csv").read_bytes()
    dz = np.abs(lid["lid.z"] - cpp["lid"]["lid.z"]).max()
    print(f"C++ lid: the same lid.csv: {same}; largest difference of z: {dz:.3g} m; output in {out}")


if __name__ == "__main__":
    main()
