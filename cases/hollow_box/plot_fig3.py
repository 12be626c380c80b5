#!/usr/bin/python3
"""Seed 001, Fig. 3: the granules confined in the hollow box, initial (left) and final (right)
configuration. The granules are drawn as spheres to scale (front half, y < 15 mm, so that the
inside shows); the box as the wire frame of its outer and inner (cavity) edges. Final: each
granule coloured by how far it moved under the load [um].

Usage: plot_fig3.py INITIAL.data FINAL.data [PNG]
       (e.g. cases/hollow_box/settled.data out/hollow-box/E=2GPa/granules.data fig3.png)
Reads particle files (LAMMPS data, as partita writes them: id type diameter density x y z)."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from python_modules import require  # noqa: E402  (cases/python_modules.py: the missing-module check)

OUTER = ((0.0, 0.0, 0.0), (0.040, 0.030, 0.030))
INNER = ((0.001, 0.001, 0.001), (0.039, 0.029, 0.029))


def read(path):
    atoms, section = {}, None
    with open(path) as f:
        next(f)
        for line in f:
            s = line.split("#")[0].strip()
            if not s:
                continue
            if s[0].isalpha():
                section = s.split()[0]
                continue
            if section == "Atoms":
                v = s.split()
                atoms[int(v[0])] = (float(v[2]), float(v[4]), float(v[5]), float(v[6]))
    return atoms


def box_edges(ax, lo, hi, **style):
    import itertools
    for a, b in itertools.combinations(itertools.product(*zip(lo, hi)), 2):
        if sum(x != y for x, y in zip(a, b)) == 1:
            ax.plot(*[[1e3 * a[k], 1e3 * b[k]] for k in range(3)], **style)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    require("matplotlib", "numpy")
    first, last = read(sys.argv[1]), read(sys.argv[2])
    png = sys.argv[3] if len(sys.argv) > 3 else "fig3.png"
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    fig = plt.figure(figsize=(12, 5.2))
    moved = {i: 1e6 * np.linalg.norm(np.subtract(last[i][1:], first[i][1:])) for i in last if i in first}
    for k, (atoms, title) in enumerate([(first, "initial (settled)"), (last, "final (500 kPa on x = 0)")]):
        ax = fig.add_subplot(1, 2, k + 1, projection="3d")
        ids = [i for i in atoms if atoms[i][2] < 0.015]
        xyz = np.array([atoms[i][1:] for i in ids]) * 1e3
        d = np.array([atoms[i][0] for i in ids]) * 1e3
        size = (d * 9.0) ** 2  # marker area ~ diameter^2 at this figure scale
        if k == 0:
            sc = ax.scatter(xyz[:, 0], xyz[:, 1], xyz[:, 2], s=size, c=xyz[:, 2], cmap="viridis",
                            depthshade=True, edgecolors="k", linewidths=0.2)
            fig.colorbar(sc, ax=ax, shrink=0.6, label="z [mm]")
        else:
            c = np.array([moved.get(i, 0.0) for i in ids])
            sc = ax.scatter(xyz[:, 0], xyz[:, 1], xyz[:, 2], s=size, c=c, cmap="inferno",
                            depthshade=True, edgecolors="k", linewidths=0.2)
            fig.colorbar(sc, ax=ax, shrink=0.6, label="displacement [um]")
        box_edges(ax, *OUTER, color="0.3", linewidth=1.0)
        box_edges(ax, *INNER, color="0.6", linewidth=0.6, linestyle=":")
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        ax.set_zlabel("z [mm]")
        ax.set_box_aspect((40, 30, 30))
        ax.view_init(elev=18, azim=-60)
        ax.set_title(f"{title}: {len(atoms)} granules")
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    print(f"wrote {png}")


if __name__ == "__main__":
    main()
