#!/usr/bin/python3
"""The filling of a double-hull section given by cells (section.yaml), from the case itself.

  make_section.py CASE.yaml [--set KEY=VALUE ...] [-o DIR] [--diameters "20 mm,16 mm"]
                  [--fractions "1,1"] [--porosity 0.5] [--fill-height H] [--seed 1] [--end 0.15]
                  [--closed] [--gravity-scale F] [--relax T] [--stl-only]

Reads the hull's panel (mesh.panel: origin or centre, cells, web_spacing, web_thickness,
outer_thickness, depth) and the granules' materials, interactions and breakage from CASE, after the --set values
(key paths as `partita run --set` takes them, e.g. participants.hull.mesh.panel.cells=[5,5]), and
writes into DIR (default: out/<case>-fill):
  cells.stl   the cavities' floors and side walls (normals into the cells, walls 30 mm above the
              cavity's top): the fill's container, as the panel places them (webs flush with the
              edges, every cell closed)
  fill.yaml   a DEM case that generates the granules in every cell (one box a cell, its clear
              width, from the outer plate up to --fill-height, default the cavity's depth) at
              --porosity and lets them settle under the case's gravity for --end seconds; its
              end state (DIR/fill/granules.data after `partita run DIR/fill.yaml -o DIR/fill`)
              is the bed CASE reads with
              --set "participants.granules.particles={material: granule, file: <that path>}"
With --closed the container is the cavities themselves (floors, webs and the inner plate's
face: every cell closed), the boxes fill each cell whole, and the bed settles along the case's
gravity, whichever way it points (a standing section: gravity along the plates, the bed against
both plates from the start). --gravity-scale F settles under F times the case's gravity (a
compacted fill in less simulated time: the bed's weight as under F times the height of granules);
--relax T (with --closed) also writes relax.yaml: the settled bed (fill/granules.data beside it)
relaxed for T seconds under the case's own gravity, its end state (DIR/relax/granules.data after
`partita run DIR/relax.yaml -o DIR/relax`) being the bed the case reads.
The defaults are coarse_fill.yaml's (16 and 20 mm granules at porosity 0.5 settled for 150 ms).
"""
import argparse
import re
import sys
from pathlib import Path

import yaml

UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3}


def length(v, what):
    """A length in m from a number or 'N mm' / 'N m'."""
    if isinstance(v, (int, float)):
        return float(v)
    try:
        return float(v)
    except ValueError:
        pass
    m = re.fullmatch(r"\s*([-+0-9.eE]+)\s*(m|cm|mm)\s*", str(v))
    if not m:
        sys.exit(f"make_section: {what} = {v!r} is not a length (a number in m, or with m, cm, mm)")
    return float(m.group(1)) * UNITS[m.group(2)]


def set_path(doc, path, value):
    """Set a --set key path (map keys with dots, list items as [i]) in the loaded case."""
    parts = re.findall(r"([^.\[\]]+)|\[(\d+)\]", path)
    node = doc
    for k, (key, index) in enumerate(parts):
        last = k == len(parts) - 1
        sel = int(index) if index else key
        if last:
            try:
                node[sel]
            except (KeyError, IndexError, TypeError):
                sys.exit(f"make_section: --set {path}: the case has no {sel!r} there (only keys "
                         "the case file holds can be set)")
            node[sel] = value
        else:
            try:
                node = node[sel]
            except (KeyError, IndexError, TypeError):
                sys.exit(f"make_section: --set {path}: the case has no {sel!r} there")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("case")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("-o", "--out")
    ap.add_argument("--diameters", default="20 mm,16 mm")
    ap.add_argument("--porosity", type=float, default=0.5)
    ap.add_argument("--fill-height", help="height of the generated boxes above the outer plate [m] (default: the depth)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--end", type=float, default=0.15, help="settling time [s]")
    ap.add_argument("--fractions", help="share of each diameter by number (default: equal)")
    ap.add_argument("--closed", action="store_true",
                    help="the container is the closed cavities (inner plate's face included)")
    ap.add_argument("--gravity-scale", type=float, default=1.0,
                    help="settle under this multiple of the case's gravity")
    ap.add_argument("--relax", type=float, help="with --closed: also write relax.yaml (T seconds at 1 g)")
    ap.add_argument("--window", type=float, default=1.0e-4, help="coupling window of the fill runs [s]")
    ap.add_argument("--stl-only", action="store_true", help="write DIR/cells.stl alone")
    a = ap.parse_args()

    case = yaml.safe_load(Path(a.case).read_text())
    for s in a.set:
        key, _, value = s.partition("=")
        set_path(case, key, yaml.safe_load(value))
    hull = next((p for p in case["participants"].values()
                 if isinstance(p.get("mesh"), dict) and "panel" in p["mesh"]), None)
    if hull is None:
        sys.exit("make_section: the case has no participant with mesh.panel")
    panel = hull["mesh"]["panel"]
    if "cells" not in panel:
        sys.exit("make_section: the panel is not given by cells (cells: [nx, ny], web_spacing): "
                 "its cells cannot be placed from the case")
    cells = panel["cells"]
    if not (isinstance(cells, list) and len(cells) == 2 and all(isinstance(n, int) for n in cells)):
        sys.exit(f"make_section: cells must be two integers [nx, ny], got {cells!r}")
    nx, ny = cells
    if nx < 1 or ny < 1:
        sys.exit(f"make_section: cells must be >= 1, got {panel['cells']}")
    s = length(panel["web_spacing"], "web_spacing")
    t = length(panel["web_thickness"], "web_thickness")
    t_o = length(panel["outer_thickness"], "outer_thickness")
    h = length(panel["depth"], "depth")
    if not s >= 2 * t:
        sys.exit(f"make_section: web_spacing {s} m must be at least 2 web_thickness ({2 * t} m)")
    if "origin" in panel:
        ox, oy, oz = (length(v, "origin") for v in panel["origin"])
    else:   # centre: the footprint (cells x web_spacing + web_thickness) about it
        cx, cy, oz = (length(v, "centre") for v in panel["centre"])
        ox, oy = cx - 0.5 * (nx * s + t), cy - 0.5 * (ny * s + t)
    fill_h = length(a.fill_height, "--fill-height") if a.fill_height else h
    if a.closed and fill_h > h:
        sys.exit(f"make_section: --fill-height {fill_h} m exceeds the closed cavity's depth {h} m")
    if not a.gravity_scale > 0:
        sys.exit(f"make_section: --gravity-scale must be > 0, got {a.gravity_scale}")
    if a.relax is not None and not (a.closed and a.relax > 0):
        sys.exit("make_section: --relax T needs --closed and T > 0 (seconds)")
    if not 0 < fill_h:
        sys.exit(f"make_section: --fill-height must be > 0, got {fill_h}")
    granules = next((p for p in case["participants"].values() if p.get("solver") == "dem"), None)
    if granules is None:
        sys.exit("make_section: the case has no DEM participant (its materials fill the cells)")

    out = Path(a.out) if a.out else Path("out") / (str(case.get("case", "section")) + "-fill")
    out.mkdir(parents=True, exist_ok=True)
    # the cells' clear extents, as the panel mesher places the webs: mid-planes at t/2 + k s
    z0 = oz + t_o
    z1 = z0 + h if a.closed else z0 + h + 0.030
    xs = [(ox + 0.5 * t + i * s + 0.5 * t, ox + 0.5 * t + (i + 1) * s - 0.5 * t) for i in range(nx)]
    ys = [(oy + 0.5 * t + j * s + 0.5 * t, oy + 0.5 * t + (j + 1) * s - 0.5 * t) for j in range(ny)]
    tris = []

    def quad(p, q, r, u, n):
        tris.append((n, p, q, r))
        tris.append((n, p, r, u))

    for (y0, y1) in ys:
        for (x0, x1) in xs:
            quad((x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0), (0, 0, 1))
            quad((x0, y0, z0), (x0, y1, z0), (x0, y1, z1), (x0, y0, z1), (1, 0, 0))
            quad((x1, y0, z0), (x1, y0, z1), (x1, y1, z1), (x1, y1, z0), (-1, 0, 0))
            quad((x0, y0, z0), (x0, y0, z1), (x1, y0, z1), (x1, y0, z0), (0, 1, 0))
            quad((x0, y1, z0), (x1, y1, z0), (x1, y1, z1), (x0, y1, z1), (0, -1, 0))
            if a.closed:   # the inner plate's face
                quad((x0, y0, z1), (x0, y1, z1), (x1, y1, z1), (x1, y0, z1), (0, 0, -1))
    with open(out / "cells.stl", "w") as f:
        f.write("solid cells\n")
        for n, *v in tris:
            f.write(f"facet normal {n[0]} {n[1]} {n[2]}\n outer loop\n")
            for p in v:
                f.write(f"  vertex {p[0]:.6f} {p[1]:.6f} {p[2]:.6f}\n")
            f.write(" endloop\nendfacet\n")
        f.write("endsolid cells\n")
    if a.stl_only:
        print(f"make_section: {out / 'cells.stl'} ({len(tris)} triangles)")
        return

    boxes = [{"origin": [round(x0, 12), round(y0, 12), round(z0, 12)],
              "size": [round(x1 - x0, 12), round(y1 - y0, 12), round(fill_h, 12)]}
             for (y0, y1) in ys for (x0, x1) in xs]
    material = (granules.get("particles") or {}).get("material", "granule")
    steel = next((m for m in granules.get("materials", {}) if m != material), None)
    dem = {"solver": "dem", "materials": granules["materials"]}
    if "interactions" in granules:
        dem["interactions"] = granules["interactions"]
    generate = {"boxes": boxes, "diameters": [d.strip() for d in a.diameters.split(",")],
                "porosity": a.porosity, "seed": a.seed}
    if a.fractions:
        try:
            generate["fractions"] = [float(f) for f in a.fractions.split(",")]
        except ValueError:
            sys.exit(f"make_section: --fractions must be numbers separated by commas, got {a.fractions!r}")
        if len(generate["fractions"]) != len(generate["diameters"]):
            sys.exit(f"make_section: --fractions has {len(generate['fractions'])} values for "
                     f"{len(generate['diameters'])} diameters")
    dem["particles"] = {"material": material, "generate": generate}
    dem["meshes"] = [{"name": "cells", "stl": "cells.stl", "material": steel or material}]
    if "breakage" in granules:
        dem["breakage"] = granules["breakage"]
    gravity = granules.get("gravity", [0, 0, -9.81])
    if a.gravity_scale != 1.0 or "gravity" in granules:
        dem["gravity"] = [round(a.gravity_scale * float(g), 12) for g in gravity]
    for k in ("rolling_friction", "time_step_fraction", "damping"):
        if k in granules:
            dem[k] = granules[k]
    dem["output"] = {"particles_file": "end"}
    fill = {"case": f"{case.get('case', 'section')}-fill",
            "time": {"window": a.window, "end": a.end},
            "participants": {"granules": dem},
            "monitors": [{"name": "settling", "quantities": [
                "granules.kinetic_energy", "granules.cells.force_x", "granules.cells.force_y",
                "granules.cells.force_z", "granules.mass", "granules.particles"]}],
            "output": {"every": min(0.05, a.end)}}
    head = (f"# Written by make_section.py from {a.case} ({' '.join(a.set) or 'as written'}): "
            f"{nx} x {ny} cells at {s} m, the granules generated in each cell and settled "
            f"under gravity in cells.stl. Not to be edited: run make_section.py again.\n")
    (out / "fill.yaml").write_text(head + yaml.safe_dump(fill, sort_keys=False, default_flow_style=None))
    if a.relax is not None:
        relax = yaml.safe_load(yaml.safe_dump(fill))
        relax["case"] = f"{case.get('case', 'section')}-relax"
        relax["time"]["end"] = a.relax
        relax["output"]["every"] = min(0.05, a.relax)
        gr = relax["participants"]["granules"]
        gr["particles"] = {"material": material, "file": "fill/granules.data"}
        if "gravity" in granules:
            gr["gravity"] = granules["gravity"]
        else:
            gr.pop("gravity", None)
        (out / "relax.yaml").write_text(
            head + f"# The bed of fill.yaml (run with -o {out}/fill) relaxed under the case's gravity.\n"
            + yaml.safe_dump(relax, sort_keys=False, default_flow_style=None))
    print(f"make_section: {out / 'cells.stl'} ({len(tris)} triangles), {out / 'fill.yaml'} "
          f"({nx * ny} boxes of {xs[0][1] - xs[0][0]:.4g} x {ys[0][1] - ys[0][0]:.4g} x {fill_h:.4g} m)")


if __name__ == "__main__":
    main()
