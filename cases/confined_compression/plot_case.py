#!/usr/bin/python3
"""Figures and checks of the confined compression sweep (seed 001, Figs. 1 and 2).

Usage: plot_case.py OUTPUT_DIR
Reads the sweep's variant folders OUTPUT_DIR/sigma_lim0=*/ (compression.csv,
granules_grading.csv, vtk/granules_particles_NNNNNN.vtp, vtk/granules_plate_NNNNNN.vtp) and
writes into OUTPUT_DIR
  grading.png        cumulative mass passing per size, before and after, both variants;
  configuration.png  a vertical section y = mid-box through the crushing run's granules at the
                     first and the last output frame (seed 001 Fig. 1), coloured by diameter.
Prints key=value lines (read by tests/cases/test_cases.cpp through checks.yaml; also kept in
OUTPUT_DIR/plot_case.txt, which a second call prints instead of drawing again):
  events                  breakage events of the crushing run at its end
  mass_drift              max |mass - mass(0)| / mass(0) of the crushing run (mass: restored: the
                          fragments carry the parent's mass, so round-off only)
  force_gap_before_break  max |F_crushing - F_intact| / max |F_intact| over the rows before the
                          first breakage event (the model only acts when a particle breaks: an
                          enabled but idle crushing model must not change the run)
  onset_displacement_mm, onset_force_N   plate displacement and force at the first event
"""
import csv
import glob
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from python_modules import require  # noqa: E402  (cases/python_modules.py: the missing-module check)
from vtk_file import arrays  # noqa: E402  (cases/vtk_file.py: VTK's reader, any encoding)

require("matplotlib", "vtk")
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402
from matplotlib.collections import PatchCollection  # noqa: E402
from matplotlib.patches import Circle, Rectangle  # noqa: E402


def read_csv(path):
    """column name (without the unit) -> values"""
    with open(path) as f:
        r = csv.reader(f)
        head = [h.split(" [")[0] for h in next(r)]
        rows = [row for row in r if row]
    return {h: [float(row[k]) for row in rows] for k, h in enumerate(head)}


def points(path):
    n, flat = arrays(path)["Points"]
    return [flat[i:i + n] for i in range(0, len(flat), n)]


def variants(out):
    found = sorted(glob.glob(os.path.join(out, "sigma_lim0=*")))
    if not found:
        sys.exit(f"plot_case: no variant folder sigma_lim0=* in {out}")
    runs = {}
    for d in found:
        c = read_csv(os.path.join(d, "compression.csv"))
        runs[d] = c
    # the crushing run is the one with events (or the weaker strength when none broke)
    crushing = max(runs, key=lambda d: (runs[d]["granules.breakage.events"][-1], -len(d)))
    intact = [d for d in runs if d != crushing]
    return crushing, runs[crushing], (intact[0] if intact else None), (runs[intact[0]] if intact else None)


def grading(path):
    """time -> (diameters, passing) of a grading CSV."""
    g = {}
    with open(path) as f:
        r = csv.reader(f)
        next(r)
        for t, d, p in r:
            g.setdefault(float(t), ([], []))
            g[float(t)][0].append(float(d) * 1e3)
            g[float(t)][1].append(float(p))
    return g


def plot_grading(out, crushing, intact):
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    gc = grading(os.path.join(crushing, "granules_grading.csv"))
    times = sorted(gc)
    d, p = gc[times[0]]
    ax.step(d, p, where="post", color="0.75", lw=5, label=f"before (t = {times[0] * 1e3:.0f} ms)")
    d, p = gc[times[-1]]
    ax.step(d, p, where="post", color="C3", label=f"after, crushing (t = {times[-1] * 1e3:.0f} ms)")
    if intact:
        gi = grading(os.path.join(intact, "granules_grading.csv"))
        t = sorted(gi)[-1]
        d, p = gi[t]
        ax.step(d, p, where="post", color="C0", ls="--", label=f"after, no crushing (t = {t * 1e3:.0f} ms)")
    ax.set_xscale("log")
    ax.set_xticks([0.25, 0.5, 1, 2, 3, 4])
    ax.xaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.set_xlabel("diameter [mm]")
    ax.set_ylabel("cumulative mass passing [-]")
    ax.set_ylim(0, 1.02)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="upper left")
    ax.set_title("Grading before and after the compression")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "grading.png"), dpi=120)


def section(ax, vtp, plate_vtp, y0, box, norm, cmap):
    x = points(vtp)
    r = arrays(vtp)["radius"][1]
    circles, colours = [], []
    for c, rad in zip(x, r):
        dy = c[1] - y0
        if abs(dy) < rad:
            circles.append(Circle((c[0] * 1e3, c[2] * 1e3), (rad * rad - dy * dy) ** 0.5 * 1e3))
            colours.append(2e3 * rad)
    pc = PatchCollection(circles, cmap=cmap, norm=norm, edgecolor="k", linewidth=0.3)
    pc.set_array(colours)
    ax.add_collection(pc)
    ax.add_patch(Rectangle((0, 0), box[0] * 1e3, box[2] * 1e3, fill=False, lw=1.5))
    if plate_vtp:
        z = min(p[2] for p in points(plate_vtp)) * 1e3
        ax.add_patch(Rectangle((0, z), box[0] * 1e3, 2.0, color="0.6"))
    ax.set_xlim(-0.5, box[0] * 1e3 + 0.5)
    ax.set_ylim(-0.5, box[2] * 1e3 + 0.5)
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    return pc, len(circles), len(x)


def plot_configuration(out, crushing):
    files = sorted(glob.glob(os.path.join(crushing, "vtk", "granules_particles_*.vtp")))
    plates = sorted(glob.glob(os.path.join(crushing, "vtk", "granules_plate_*.vtp")))
    if not files:
        return
    box = (0.020, 0.020, 0.020)
    radii = arrays(files[0])["radius"][1] + arrays(files[-1])["radius"][1]
    norm = matplotlib.colors.Normalize(vmin=2e3 * min(radii), vmax=2e3 * max(radii))
    cmap = plt.get_cmap("viridis")
    fig, axes = plt.subplots(1, 2, figsize=(9.0, 5.0), sharey=True, layout="constrained")
    for ax, k, what in ((axes[0], 0, "start"), (axes[1], -1, "end")):
        pc, cut, n = section(ax, files[k], plates[k] if plates else None, 0.5 * box[1], box, norm, cmap)
        t = int(os.path.basename(files[k]).split("_")[-1].split(".")[0])
        ax.set_title(f"{what} (frame {t}): {n} particles\n{cut} cut by the section")
    axes[0].set_ylabel("z [mm]")
    fig.suptitle("Section y = 10 mm through the crushing run (plate in grey)")
    fig.colorbar(pc, ax=axes, label="particle diameter [mm]", shrink=0.9)
    fig.savefig(os.path.join(out, "configuration.png"), dpi=120)


def main(argv):
    if len(argv) != 2:
        sys.exit(__doc__)
    out = argv[1]
    crushing, c, intact, i = variants(out)
    # the case test runs this once per check: the figures and lines of a first call are reused
    # while the run's CSV is older than them
    summary = os.path.join(out, "plot_case.txt")
    csv_time = os.path.getmtime(os.path.join(crushing, "compression.csv"))
    if os.path.exists(summary) and os.path.getmtime(summary) > csv_time:
        with open(summary) as f:
            print(f.read(), end="")
        return
    lines = []
    events = c["granules.breakage.events"]
    mass = c["granules.mass"]
    lines.append(f"events={events[-1]:.0f}")
    lines.append(f"mass_drift={max(abs(m - mass[0]) for m in mass) / mass[0]:.3e}")
    first = next((k for k, e in enumerate(events) if e > 0), len(events))
    if first < len(events):
        lines.append(f"onset_displacement_mm={-1e3 * c['plate.bottom.displacement_z'][first]:.4g}")
        lines.append(f"onset_force_N={c['plate.bottom.force_z'][first]:.4g}")
    if i is not None:
        fi = i["granules.plate.force_z"]
        fc = c["granules.plate.force_z"]
        rows = min(first, len(fi), len(fc))
        scale = max(abs(f) for f in fi[:rows]) if rows else 1.0
        gap = max((abs(a - b) for a, b in zip(fc[:rows], fi[:rows])), default=0.0) / scale
        lines.append(f"force_gap_before_break={gap:.3e}")
        lines.append(f"rows_before_break={rows}")
    plot_grading(out, crushing, intact)
    plot_configuration(out, crushing)
    text = "".join(line + "\n" for line in lines)
    with open(summary, "w") as f:
        f.write(text)
    print(text, end="")


if __name__ == "__main__":
    main(sys.argv)
