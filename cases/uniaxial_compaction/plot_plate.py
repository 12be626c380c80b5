#!/usr/bin/python3
"""The deformed plate seen from both sides (the analogue of seed 000, Fig. 3): the lower face of
the FE plate and the STL plate of the DEM at the last output frame, deflection in colour, and a
section through the middle with both. Also prints how far the STL vertices lie from the FE
plate's deformed lower face, as a fraction of the largest deflection.

Usage: plot_plate.py OUTPUT_DIR [FE_PARTICIPANT] [DEM_PARTICIPANT] [MESH]
       (defaults: plate granules plate) -> OUTPUT_DIR/plate.png
Reads OUTPUT_DIR/vtk/<FE>_fem_NNNNNN.vtu and <DEM>_<MESH>_NNNNNN.vtp (VTK XML, any encoding,
read with VTK's own reader)."""
import glob
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from python_modules import require  # noqa: E402  (cases/python_modules.py: the missing-module check)
from vtk_file import arrays  # noqa: E402  (cases/vtk_file.py: VTK's reader, any encoding)


def rows(arr):
    n, flat = arr
    return [flat[i:i + n] for i in range(0, len(flat), n)]


def last(pattern):
    files = sorted(glob.glob(pattern))
    if not files:
        sys.exit(f"plot_plate: no file matches {pattern}")
    return files[-1]


def main(argv):
    require("vtk")
    out = argv[1]
    fe, dem, mesh = (argv[2:5] + ["plate", "granules", "plate"][len(argv[2:5]):])[:3]
    fa = arrays(last(os.path.join(out, "vtk", f"{fe}_fem_*.vtu")))
    sa = arrays(last(os.path.join(out, "vtk", f"{dem}_{mesh}_*.vtp")))
    X = rows(fa["Points"])
    U = rows(fa["displacement"])
    zmin = min(p[2] for p in X)
    bottom = [i for i, p in enumerate(X) if abs(p[2] - zmin) < 1e-9]
    # FE lower face: deformed position of each node; STL: deformed vertex positions.
    fx = [X[i][0] for i in bottom]
    fy = [X[i][1] for i in bottom]
    fz = [X[i][2] + U[i][2] for i in bottom]
    fw = [U[i][2] for i in bottom]
    S = rows(sa["Points"])
    sx, sy, sz = [p[0] for p in S], [p[1] for p in S], [p[2] for p in S]
    sw = [z - zmin for z in sz]

    # Distance of each STL vertex from the deformed FE face, measured in z at the vertex's (x, y)
    # through bilinear interpolation on the FE face grid (the FE face is a structured grid here).
    xs, ys = sorted(set(round(v, 12) for v in fx)), sorted(set(round(v, 12) for v in fy))
    grid = {(round(x, 12), round(y, 12)): z for x, y, z in zip(fx, fy, fz)}

    def fe_z(x, y):
        import bisect
        i = min(max(bisect.bisect_right(xs, x) - 1, 0), len(xs) - 2)
        j = min(max(bisect.bisect_right(ys, y) - 1, 0), len(ys) - 2)
        x0, x1, y0, y1 = xs[i], xs[i + 1], ys[j], ys[j + 1]
        s, t = (x - x0) / (x1 - x0), (y - y0) / (y1 - y0)
        return ((1 - s) * (1 - t) * grid[(x0, y0)] + s * (1 - t) * grid[(x1, y0)]
                + (1 - s) * t * grid[(x0, y1)] + s * t * grid[(x1, y1)])

    gap = max(abs(z - fe_z(x, y)) for x, y, z in zip(sx, sy, sz))
    deflection = max(abs(w) for w in fw)
    print(f"largest deflection of the FE lower face: {deflection:.4e} m; largest distance of an STL "
          f"vertex from it: {gap:.4e} m ({100 * gap / deflection:.3f} % of the deflection)")
    span = max(fw) - min(fw)
    print(f"stl_gap_fraction={gap / deflection:.6g}")
    print(f"stl_gap_fraction_of_bending={gap / span:.6g}  (bending: max - min of u_z = {span:.4e} m)")

    try:
        import matplotlib
    except ImportError:
        print(f"plot_plate: no python module matplotlib in {sys.executable} (Debian package "
              f"python3-matplotlib; {PARTITA_PYTHON} is the python partita's own plots use): no "
              "picture", file=sys.stderr)
        return 0
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 3, figsize=(14, 4.2), dpi=110)
    lo, hi = min(fw + sw) * 1e6, max(fw + sw) * 1e6
    for a, x, y, w, title in ((ax[0], fx, fy, fw, f"FE plate ({fe}), lower face"),
                              (ax[1], sx, sy, sw, f"STL plate ({dem}.{mesh})")):
        c = a.tricontourf([v * 1e3 for v in x], [v * 1e3 for v in y], [v * 1e6 for v in w], 24,
                          vmin=lo, vmax=hi, cmap="viridis")
        a.set_aspect("equal")
        a.set_title(title)
        a.set_xlabel("x [mm]")
        a.set_ylabel("y [mm]")
        fig.colorbar(c, ax=a, label="deflection u_z [um]")
    ymid = ys[len(ys) // 2]
    fsec = sorted((x, w) for x, y, w in zip(fx, fy, fw) if abs(y - ymid) < 1e-9)
    ax[2].plot([p[0] * 1e3 for p in fsec], [p[1] * 1e6 for p in fsec], "o-", ms=3, label="FE lower face")
    near = sorted((x, w) for x, y, w in zip(sx, sy, sw) if abs(y - ymid) <= 0.6 * (ys[1] - ys[0]))
    ax[2].plot([p[0] * 1e3 for p in near], [p[1] * 1e6 for p in near], "s", ms=4, mfc="none",
               label="STL vertices near the section")
    ax[2].set_xlabel("x [mm]")
    ax[2].set_ylabel("u_z [um]")
    ax[2].set_title(f"section y = {ymid * 1e3:.1f} mm")
    ax[2].grid(True, alpha=0.3)
    ax[2].legend(fontsize=8)
    fig.tight_layout()
    png = os.path.join(out, "plate.png")
    fig.savefig(png + ".part.png")
    os.replace(png + ".part.png", png)
    print(png)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
