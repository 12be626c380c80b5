#!/usr/bin/python3
"""Seed 001, Fig. 4 from Python: the hollow box of cases/hollow_box filled with granules, swept
over the granules' Young's modulus (2 MPa ... 2 GPa) with partita.sweep, the empty box as the
reference with partita.run, and the figure drawn with matplotlib from the returned DataFrames:
the opposite wall's displacement along its centre line, divided by the box length, at the end of
the load (left), and the force the granules put on the far wall against the modulus (right).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/hollow_box_sweep.py [--jobs 2] [--end T]

About 25 s of runs with --jobs 2 on 2 quiet cores (70 s on a shared machine; the four variants
and the empty box); --end T
shortens them (e.g. --end 0.02 for a look in a few seconds; the load then has not been applied
yet). Writes out/hollow-box-python/ (the variants, sweep.csv) and fig4_python.png there.
"""
import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import partita  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
CASE = ROOT / "cases" / "hollow_box" / "hollow_box.yaml"
EMPTY = ROOT / "cases" / "hollow_box" / "empty_box.yaml"
MODULUS = "participants.granules.materials.granule.youngs_modulus"
L = 0.040  # the box's length along x [m]


def centre_line(result):
    """z and u_x / L along the probe of the opposite wall, at its last frame."""
    frame = partita.read_csv(result.probes["box_centre"][-1])
    return frame["z"] * 1e3, frame["displacement_x"] / L


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--jobs", type=int, default=2, help="variants at once (default 2)")
    ap.add_argument("--end", type=float, default=None, help="time.end of every run [s] (default: the case's 0.07)")
    ap.add_argument("--output", default="out/hollow-box-python", help="output folder")
    args = ap.parse_args()
    out = Path(args.output)
    shorter = {"time.end": args.end} if args.end else {}

    moduli = ["2 MPa", "20 MPa", "200 MPa", "2 GPa"]
    sweep = partita.sweep(CASE, over={MODULUS: moduli}, labels={MODULUS: "E"}, jobs=args.jobs,
                          output=out, set=shorter, plots=False)
    print(sweep[["E", "status", "far_wall_force_N", "far_wall_mean_ux_m"]].to_string(index=False))
    empty = partita.run(EMPTY, output=out / "empty", set=shorter, plots=False)

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.5))
    for _, row in sweep[sweep["status"] == "ok"].iterrows():
        z, u = centre_line(partita.read(row["folder"]))
        left.plot(u, z, marker=".", label=f"E = {row['E']}")
    z, u = centre_line(empty)
    left.plot(u, z, "k--", label="empty box")
    left.set_xlabel("displacement of the opposite wall / L [-]")
    left.set_ylabel("position along the centre line z [mm]")
    left.legend()
    ok = sweep[sweep["status"] == "ok"]
    pascal = {"MPa": 1e6, "GPa": 1e9}
    e_pa = [float(v.split()[0]) * pascal[v.split()[1]] for v in ok["E"]]
    right.semilogx(e_pa, ok["far_wall_force_N"], "o-")
    right.set_xlabel("granules' Young's modulus [Pa]")
    right.set_ylabel("force of the granules on the far wall [N]")
    for ax in (left, right):
        ax.grid(True, alpha=0.3)
    fig.suptitle("Hollow box filled with granules, 500 kPa on one end (seed 001, Fig. 4)")
    fig.tight_layout()
    png = out / "fig4_python.png"
    fig.savefig(png, dpi=120)
    print(f"figure: {png}")


if __name__ == "__main__":
    main()
