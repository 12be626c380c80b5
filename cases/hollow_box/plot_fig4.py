#!/usr/bin/python3
"""Seed 001, Fig. 4: the displacement of the opposite wall along its centre line, divided by the
box length L, over the position along the line: one curve per particle Young's modulus (the
variants of the hollow_box.yaml sweep) and the empty box (empty_box.yaml) as the reference.

Usage: plot_fig4.py SWEEP_DIR [EMPTY_DIR] [PNG]
       (defaults: out/hollow-box, out/hollow-box-empty, SWEEP_DIR/fig4.png)
Reads the last frame of DIR/probes/box_centre_NNNNNN.csv of each variant (DIR/E=*/) and of the
empty box, and DIR/E=*/wall.csv (forces on the inner faces). Prints key=value lines: per variant
the centre displacement / L at the end and before the load (t = 10 ms: the filling's own
pressure), the largest displacement / L, and the share of the applied load that the far wall
receives from the granules at the end (far_share = F_far,x / (p A))."""
import csv
import glob
import os
import re
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from python_modules import require  # noqa: E402  (cases/python_modules.py: the missing-module check)

L = 0.040              # box length along x [m]
LOAD = 500e3 * 0.030 * 0.030  # pressure x area of the outer end face [N]
BEFORE_LOAD_FRAME = 1  # probe frame at t = 10 ms, the start of the ramp (output every 10 ms)


def last_probe(d, frame=-1):
    """z and u_x along the probe at the last frame (or frame number `frame`)."""
    files = sorted(glob.glob(os.path.join(d, "probes", "box_centre_*.csv")))
    if not files:
        sys.exit(f"no probe files in {d}/probes (run the case first)")
    with open(files[frame]) as f:
        rows = list(csv.DictReader(f))
    z = [float(r["z [m]"]) for r in rows]
    ux = [float(r["displacement_x [m]"]) for r in rows]
    return z, ux


def final_row(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k.split(" [")[0]: float(v) for k, v in rows[-1].items()}


def modulus(folder):
    """'E=200MPa' -> 2e8 (for sorting and labels)."""
    m = re.match(r"E=([0-9.eE+-]+)\s*([kMG]?)Pa", os.path.basename(folder))
    scale = {"": 1.0, "k": 1e3, "M": 1e6, "G": 1e9}
    return float(m.group(1)) * scale[m.group(2)] if m else float("nan")


def main():
    require("matplotlib")
    sweep = sys.argv[1] if len(sys.argv) > 1 else "out/hollow-box"
    empty = sys.argv[2] if len(sys.argv) > 2 else "out/hollow-box-empty"
    png = sys.argv[3] if len(sys.argv) > 3 else os.path.join(sweep, "fig4.png")
    variants = sorted(glob.glob(os.path.join(sweep, "E=*")), key=modulus)
    curves = []
    for v in variants:
        z, ux = last_probe(v)
        name = os.path.basename(v)
        _, before = last_probe(v, BEFORE_LOAD_FRAME)
        curves.append((f"E = {name[2:]}", z, ux, before))
        centre = ux[len(ux) // 2]
        key = name.replace("=", "_").replace(".", "p")
        print(f"{key}_centre_ux_over_L={centre / L:.6e}")
        print(f"{key}_centre_ux_over_L_before_load={before[len(ux) // 2] / L:.6e}")
        print(f"{key}_max_ux_over_L={max(ux) / L:.6e}")
        wall = os.path.join(v, "wall.csv")
        if os.path.exists(wall):
            r = final_row(wall)
            print(f"{key}_far_share={r['box.far.force_x'] / LOAD:.6e}")
    if os.path.isdir(empty):
        z, ux = last_probe(empty)
        curves.append(("empty box", z, ux, None))
        print(f"empty_centre_ux_over_L={ux[len(ux) // 2] / L:.6e}")
        print(f"empty_max_ux_over_L={max(ux) / L:.6e}")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8.6, 4.4))
    for label, z, ux, before in curves:
        style = dict(color="black", linestyle="--") if label == "empty box" else {}
        line, = ax.plot([1e3 * x for x in z], [u / L for u in ux], marker=".", label=label, **style)
        if before is not None:  # the filling's own pressure, before the load
            ax.plot([1e3 * x for x in z], [u / L for u in before], color=line.get_color(),
                    linestyle=":", linewidth=1.0)
    ax.plot([], [], color="0.4", linestyle=":", linewidth=1.0, label="(dotted: before the load)")
    ax.set_xlabel("position along the centre line of the opposite wall, z [mm]")
    ax.set_ylabel("displacement u_x / L [-]")
    ax.set_title("Hollow box, 500 kPa on one end: load transfer by the granules")
    ax.ticklabel_format(axis="y", style="sci", scilimits=(0, 0))
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=9, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)  # beside
    fig.tight_layout()
    fig.savefig(png, dpi=130, bbox_inches="tight")
    print(f"wrote {png}")


if __name__ == "__main__":
    main()
