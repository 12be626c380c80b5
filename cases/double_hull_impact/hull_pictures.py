"""The pictures of a double-hull run from its VTK output (plot_case.py's helper; matplotlib and
python3-vtk9, no ParaView):
  section_<k>.png          the section through the bow's axis (hull_geometry.Geometry.section_basis):
                           the deformed plates and webs coloured by equivalent plastic strain, the
                           eroded elements cut by the plane as red outlines, the bow's outline and
                           the granules cut by the plane coloured by their state (intact, fragment,
                           fragment below the comminution limit)
  inner_deflection_map.png the inner plate's out-of-plane displacement (along the bow's travel) in
                           plan, element by element, at the chosen frames; eroded elements black,
                           the webs' mid-planes and the bow's footprint drawn over it
  rupture_pattern.png      both plates in plan at the last frame, coloured by equivalent plastic
                           strain, the eroded elements black; and the crushed zone: every fragment
                           (a granule that the run created by breakage) projected on the plates'
                           plane, coloured by its depth in the cavity
A granule is a fragment when its id is not among the first frame's ids (a broken granule's
fragments take new ids; the parent leaves)."""
import numpy as np

from hull_geometry import INNER, OUTER, AXES, pvd_frames, read_vtk

HEX_EDGES = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)]
STATE_COLOURS = ["#9ecae1", "#fd8d3c", "#b2182b"]
STATE_NAMES = ["intact granule", "fragment", "fragment below the comminution limit"]


def hex_cells(cells):
    """The 8-node cells as an (n, 8) array and their indices."""
    idx = [i for i, c in enumerate(cells) if len(c) == 8]
    return np.array([cells[i] for i in idx], dtype=int).reshape(-1, 8), np.array(idx, dtype=int)


def cut_hull(path, origin, normal, h, v):
    """The hull's elements cut by the plane (origin, normal), in the picture's coordinates [mm]:
    (polygons of intact elements, their equivalent plastic strain or None, polygons of eroded
    elements). The cut is found on the reference points (a face lying in the plane belongs to the
    element on its positive side) and drawn on the deformed ones."""
    pts, cells, data = read_vtk(path)
    cur = pts + data["displacement"] if "displacement" in data else pts
    peeq = data["equivalent_plastic_strain"][:, 0] if "equivalent_plastic_strain" in data else None
    failed = data["failed"][:, 0] if "failed" in data and "failed" in data["_cell_arrays"] else None
    hexes, idx = hex_cells(cells)
    d = (pts - origin) @ normal
    dh = d[hexes]
    hit = np.nonzero((dh.min(axis=1) <= 0) & (dh.max(axis=1) > 0))[0]
    intact, values, eroded = [], [], []
    for k in hit:
        cl, dd = hexes[k], dh[k]
        cut = []
        for a, b in HEX_EDGES:
            da, db = dd[a], dd[b]
            if da > db:
                a, b, da, db = b, a, db, da
            if da <= 0 < db:
                s = -da / (db - da)
                cut.append(cur[cl[a]] + s * (cur[cl[b]] - cur[cl[a]]))
        if len(cut) < 3:
            continue
        q = np.array(cut) - origin
        xy = 1e3 * np.column_stack([q @ h, q @ v])
        c = xy.mean(axis=0)
        xy = xy[np.argsort(np.arctan2(xy[:, 1] - c[1], xy[:, 0] - c[0]))]
        i = idx[k]
        if failed is not None and failed[i] > 0:
            eroded.append(xy)
        else:
            intact.append(xy)
            values.append(peeq[i] if peeq is not None else 0.0)
    return intact, (np.array(values) if peeq is not None else None), eroded


def granule_state(ids, radius, first_ids, limit):
    """0 intact, 1 fragment, 2 fragment below the comminution limit (diameter < limit)."""
    frag = ~np.isin(ids, first_ids)
    state = frag.astype(int)
    if limit:
        state[frag & (2 * radius < limit)] = 2
    return state


def first_granule_ids(folder):
    frames = pvd_frames(folder, "granules_particles")
    if not frames:
        return None
    _, _, data = read_vtk(frames[0][1])
    return data["id"][:, 0] if "id" in data else None


def bow_outline(geom, centre, origin, h, v):
    """The bow's outline in the section (its axis parallel to the plane, at distance d from it:
    a capsule's cut is the capsule of radius sqrt(R^2 - d^2)) [mm], or None."""
    if centre is None or geom.bow_radius is None:
        return None
    a = geom.bow_axis
    u = np.array([a @ h, a @ v])
    if np.linalg.norm(u) < 0.5:
        return None
    u /= np.linalg.norm(u)
    p = np.array([-u[1], u[0]])
    c = np.array([(centre - origin) @ h, (centre - origin) @ v])
    d = float((centre - origin) @ np.cross(h, v))
    if abs(d) >= geom.bow_radius:
        return None
    half, r = geom.bow_length / 2, float(np.sqrt(geom.bow_radius ** 2 - d * d))
    ang = np.linspace(-np.pi / 2, np.pi / 2, 40)
    front = [c + half * u + r * (np.cos(t) * u + np.sin(t) * p) for t in ang]
    back = [c - half * u + r * (-np.cos(t) * u - np.sin(t) * p) for t in ang]
    xy = np.array(front + back + front[:1])
    return 1e3 * xy


def section_limits(geom, origin, h, v):
    """(xlim, ylim) [mm]: the hull's extent in the picture, with the bow's approach side."""
    corners = np.array([[x, y, z] for x in (geom.lo[0], geom.hi[0]) for y in (geom.lo[1], geom.hi[1])
                        for z in (geom.lo[2], geom.hi[2])]) - origin
    xs, ys = 1e3 * corners @ h, 1e3 * corners @ v
    lim = [[xs.min() - 5, xs.max() + 5], [ys.min() - 5, ys.max() + 5]]
    a = geom.bow_axis if geom.bow_axis is not None else np.eye(3)[geom.normal_axis]
    depth = 1e3 * (max(geom.outer[1], geom.inner[1]) - min(geom.outer[0], geom.inner[0]))
    for k, e in enumerate((h, v)):
        c = a @ e
        if abs(c) > 0.5:   # this picture axis runs along the bow: room for it on the struck side
            if c > 0:
                lim[k] = [lim[k][0] - 1.1 * depth, lim[k][1] + 0.3 * depth]
            else:
                lim[k] = [lim[k][0] - 0.3 * depth, lim[k][1] + 1.1 * depth]
    return lim


def plot_section(run, geom, frame, out_path, plt, title_extra=""):
    """One section picture at hull frame (t, path)."""
    from matplotlib.collections import PatchCollection, PolyCollection
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Circle, Patch
    t, path = frame
    origin, normal, h, v = geom.section_basis()
    (x0, x1), (y0, y1) = section_limits(geom, origin, h, v)
    # the figure shaped to the section (an upright one is tall and narrow), room for the colour
    # bar and the legend
    aspect = (x1 - x0) / max(y1 - y0, 1e-9)
    fig, ax = plt.subplots(figsize=(min(12.0, max(6.5, 6.0 * aspect + 3.0)), 6.6 if aspect >= 1 else 8.0))
    intact, peeq, eroded = cut_hull(path, origin, normal, h, v)
    pc = PolyCollection(intact, edgecolors="k", linewidths=0.3)
    if peeq is not None and len(peeq):
        pc.set_array(peeq)
        pc.set_cmap("plasma")
        pc.set_clim(0, max(0.02, float(peeq.max())))
    else:
        pc.set_facecolor("0.6")
    ax.add_collection(pc)
    if peeq is not None and len(peeq):
        fig.colorbar(pc, ax=ax, fraction=0.04, pad=0.02, label="equivalent plastic strain (hull)")
    handles = []
    if eroded:
        ax.add_collection(PolyCollection(eroded, facecolors="none", edgecolors="r", linewidths=0.8, linestyles="--"))
        handles.append(Patch(facecolor="none", edgecolor="r", ls="--", label=f"eroded elements ({len(eroded)} cut)"))
    outline = bow_outline(geom, geom.bow_centre(t), origin, h, v)
    if outline is not None:
        ax.fill(outline[:, 0], outline[:, 1], facecolor="0.85", edgecolor="k", lw=1.2, zorder=0)
    granules = dict(pvd_frames(run.folder, "granules_particles"))
    count = None
    gpath = granules.get(t)
    if gpath:
        pts, _, data = read_vtk(gpath)
        if "radius" in data:
            r = data["radius"][:, 0]
            d = (pts - origin) @ normal
            cut = np.abs(d) < r
            rc = np.sqrt(r[cut] ** 2 - d[cut] ** 2)
            q = pts[cut] - origin
            xy = 1e3 * np.column_stack([q @ h, q @ v])
            first = first_granule_ids(run.folder)
            if first is not None and "id" in data:
                state = granule_state(data["id"][cut, 0], r[cut], first, geom.comminution_limit)
            else:
                state = np.zeros(int(cut.sum()), dtype=int)
            circles = [Circle(tuple(c), 1e3 * rr) for c, rr in zip(xy, rc)]
            gc = PatchCollection(circles, cmap=ListedColormap(STATE_COLOURS), edgecolors="k", linewidths=0.2, alpha=0.9)
            gc.set_array(state.astype(float))
            gc.set_clim(-0.5, 2.5)
            ax.add_collection(gc)
            count = int(cut.sum())
            shown = [0, 1] + ([2] if geom.comminution_limit else [])
            for s in shown:
                handles.append(Patch(facecolor=STATE_COLOURS[s], edgecolor="k",
                                     label=f"{STATE_NAMES[s]} ({int(np.sum(state == s))})"))
    if handles:
        ax.legend(handles=handles, fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2)
    p = float(np.interp(t, run.t, run.pen))
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    name = lambda e: "-".join(AXES[i] if e[i] > 0 else "-" + AXES[i] for i in range(3) if abs(e[i]) > 0.5) or "oblique"
    ax.set_xlabel(f"along {name(h)} from the bow's axis at the struck face [mm]"
                  + (f"\n(plane {1e3 * np.linalg.norm(geom.section_offset):.0f} mm off the bow's axis: "
                     "the middle of the next cell,\nnot the web struck)"
                     if np.any(geom.section_offset) else ""), fontsize=9)
    ax.set_ylabel(f"along {name(v)} [mm]" + (" (up)" if geom.gravity is not None else ""))
    plane = " = ".join([AXES[int(np.argmax(np.abs(normal)))], f"{1e3 * float(origin[int(np.argmax(np.abs(normal)))]):.0f} mm"])
    ax.set_title(f"{run.label}: section {plane} at t = {1e3 * t:.1f} ms,\npenetration {1e3 * p:.1f} mm"
                 + (f" ({count} granules cut)" if count is not None else "") + title_extra, fontsize=10)
    save(fig, out_path, plt)


def frames_at(run, frames, penetrations):
    """The indices of the output frames nearest each penetration [m] (no repeats)."""
    frame_pen = [float(np.interp(t, run.t, run.pen)) for t, _ in frames]
    chosen = []
    for p in penetrations:
        k = int(np.argmin([abs(fp - p) for fp in frame_pen]))
        if k not in chosen:
            chosen.append(k)
    return chosen, frame_pen


def plan_rects(pts, hexes, axes):
    """Each element's rectangle in plan (its reference extent along the two in-plane axes) [mm]."""
    a1, a2 = axes
    lo1, hi1 = pts[hexes, a1].min(axis=1), pts[hexes, a1].max(axis=1)
    lo2, hi2 = pts[hexes, a2].min(axis=1), pts[hexes, a2].max(axis=1)
    return 1e3 * np.stack([np.column_stack([lo1, lo2]), np.column_stack([hi1, lo2]),
                           np.column_stack([hi1, hi2]), np.column_stack([lo1, hi2])], axis=1)


def decorate_plan(ax, geom, centre=None):
    a1, a2 = geom.in_plane_axes
    for x in geom.frames:
        ax.axvline(1e3 * x, color="0.5", lw=0.6, ls=":")
    for y in geom.stringers:
        ax.axhline(1e3 * y, color="0.5", lw=0.6, ls=":")
    if centre is not None and geom.bow_radius:
        from matplotlib.patches import Circle
        ax.add_patch(Circle((1e3 * centre[a1], 1e3 * centre[a2]), 1e3 * geom.bow_radius, fill=False,
                            ec="c", lw=1.0, ls="--"))
    ax.set_xlim(1e3 * geom.lo[a1], 1e3 * geom.hi[a1])
    ax.set_ylim(1e3 * geom.lo[a2], 1e3 * geom.hi[a2])
    ax.set_aspect("equal")
    ax.set_xlabel(f"{AXES[a1]} [mm]")
    ax.set_ylabel(f"{AXES[a2]} [mm]")


def plot_deflection_maps(run, geom, chosen, frames, frame_pen, out_path, plt):
    """The inner plate's displacement along the bow's travel, in plan, at the chosen frames."""
    from matplotlib.collections import PolyCollection
    axis = geom.bow_axis if geom.bow_axis is not None else np.eye(3)[geom.normal_axis]
    maps = []
    for k in chosen:
        t, path = frames[k]
        pts, cells, data = read_vtk(path)
        hexes, idx = hex_cells(cells)
        region = data["region"][idx, 0].astype(int)
        failed = data["failed"][idx, 0] > 0 if "failed" in data else np.zeros(len(idx), bool)
        sel = region == INNER
        disp = data["displacement"] @ axis if "displacement" in data else np.zeros(len(pts))
        w = disp[hexes[sel]].mean(axis=1)
        maps.append((t, frame_pen[k], plan_rects(pts, hexes[sel], geom.in_plane_axes), 1e3 * w, failed[sel]))
    top = max([float(np.max(np.abs(m[3][~m[4]]))) if (~m[4]).any() else 0.0 for m in maps] + [1e-3])
    fig, axes = plt.subplots(1, len(maps), figsize=(5.2 * len(maps) + 1.2, 5.0), squeeze=False, layout="constrained")
    for ax, (t, p, rects, w, failed) in zip(axes[0], maps):
        pc = PolyCollection(rects[~failed], edgecolors="none")
        pc.set_array(w[~failed])
        pc.set_cmap("RdBu_r")        # red: pushed along the bow's travel, blue: back
        pc.set_clim(-top, top)
        ax.add_collection(pc)
        if failed.any():
            ax.add_collection(PolyCollection(rects[failed], facecolors="k", edgecolors="k"))
        decorate_plan(ax, geom, geom.bow_centre(t))
        ax.set_title(f"penetration {1e3 * p:.1f} mm (t = {1e3 * t:.1f} ms)\nlargest {float(w.max()):.2f} mm"
                     + (f", {int(failed.sum())} eroded (black)" if failed.any() else ""), fontsize=9)
    fig.colorbar(pc, ax=list(axes[0]), fraction=0.03, pad=0.02,
                 label="inner plate's displacement along the bow's travel [mm]")
    fig.suptitle(f"{run.label}: the inner plate's deflection (webs dotted, the bow's radius dashed)", fontsize=10)
    save(fig, out_path, plt, tight=False)


def plot_rupture_pattern(run, geom, frame, out_path, plt):
    """Both plates in plan at one frame (plastic strain, eroded elements black) and the crushed
    zone (the fragments in plan)."""
    from matplotlib.collections import PolyCollection
    t, path = frame
    pts, cells, data = read_vtk(path)
    hexes, idx = hex_cells(cells)
    region = data["region"][idx, 0].astype(int)
    failed = data["failed"][idx, 0] > 0 if "failed" in data else np.zeros(len(idx), bool)
    peeq = data["equivalent_plastic_strain"][idx, 0] if "equivalent_plastic_strain" in data else np.zeros(len(idx))
    granules = dict(pvd_frames(run.folder, "granules_particles"))
    fragments = None
    if t in granules:
        gp, _, gd = read_vtk(granules[t])
        first = first_granule_ids(run.folder)
        if first is not None and "id" in gd:
            state = granule_state(gd["id"][:, 0], gd["radius"][:, 0], first, geom.comminution_limit)
            fragments = (gp[state > 0], gd["radius"][state > 0, 0], state[state > 0])
    n = 3 if fragments is not None else 2
    fig, axes = plt.subplots(1, n, figsize=(5.2 * n + 1.2, 5.2), squeeze=False, layout="constrained")
    top = max(0.02, float(peeq[~failed].max()) if (~failed).any() else 0.02)
    p = float(np.interp(t, run.t, run.pen))
    centre = geom.bow_centre(t)
    for ax, (part, name) in zip(axes[0], ((OUTER, "outer plate"), (INNER, "inner plate"))):
        sel = region == part
        rects = plan_rects(pts, hexes[sel], geom.in_plane_axes)
        ok = ~failed[sel]
        pc = PolyCollection(rects[ok], edgecolors="none")
        pc.set_array(peeq[sel][ok])
        pc.set_cmap("YlOrRd")
        pc.set_clim(0, top)
        ax.add_collection(pc)
        if (~ok).any():
            ax.add_collection(PolyCollection(rects[~ok], facecolors="k", edgecolors="k"))
        decorate_plan(ax, geom, centre)
        ax.set_title(f"{name}: {int((~ok).sum())} eroded elements (black)", fontsize=9)
    fig.colorbar(pc, ax=list(axes[0][:2]), fraction=0.03, pad=0.02, label="equivalent plastic strain")
    if fragments is not None:
        ax = axes[0][2]
        fp, fr, fs = fragments
        a1, a2 = geom.in_plane_axes
        lo, hi = geom.cavity
        depth = np.clip((fp[:, geom.normal_axis] - lo) / max(hi - lo, 1e-12), 0, 1)
        if geom.inner_faces_up < 0:
            depth = 1 - depth
        sc = ax.scatter(1e3 * fp[:, a1], 1e3 * fp[:, a2], s=np.clip((1e3 * fr) ** 2 * 0.8, 2, 200), c=depth,
                        cmap="coolwarm", vmin=0, vmax=1, edgecolors="k", linewidths=0.2)
        decorate_plan(ax, geom, centre)
        below = int(np.sum(fs == 2))
        ax.set_title(f"crushed zone: {len(fr)} fragments" + (f" ({below} below the comminution limit)" if geom.comminution_limit else ""),
                     fontsize=9)
        fig.colorbar(sc, ax=ax, fraction=0.046, pad=0.02, label="depth in the cavity (0 outer, 1 inner plate)")
    fig.suptitle(f"{run.label}: rupture pattern and crushed zone at penetration {1e3 * p:.1f} mm "
                 f"(t = {1e3 * t:.1f} ms; webs dotted, the bow's radius dashed)", fontsize=10)
    save(fig, out_path, plt, tight=False)


def save(fig, path, plt, tight=True):
    if tight:
        fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
