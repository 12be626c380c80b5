"""The geometry of a double-hull run, read from its own output (plot_case.py's helper).

`Geometry.of_run(folder, case=None, sets=())` reads
  - the hull (vtk/hull_fem's first frame: reference points, the cells' `region` array, 0 outer
    plate, 1 inner plate, 2 webs, as the panel mesher names them): the plates' normal (the axis
    along which the outer plate is thinnest), the plates' faces along it, the webs' mid-planes
    (frames across the first in-plane axis, stringers across the second), the footprint, and so
    the panel's centre, cells, web spacing and thicknesses, whatever the case's `cells`,
    `web_spacing` or thicknesses;
  - the bow (vtk/hull_bow's frames: the indenter's current surface): its axis (the principal
    direction of its points), radius (their largest distance from the axis), cylinder length
    (their extent along the axis less two radii) and centre at any output time;
  - from the case file, when one is given (CASE with `--set KEY=VALUE` as `partita run` takes
    them): the granules' gravity and comminution limit, which the output does not hold.
The section through the bow's axis that plot_case.py draws lies in the plane spanned by the
bow's axis and the direction against gravity (an upright section: gravity along the plates, the
bow travelling across the picture), or by the bow's axis and the panel's first in-plane axis when
gravity is along the axis (the section lying flat) or unknown; the picture's vertical is then
against gravity (`vertical`), its horizontal `horizontal`.
"""
import os
import re
import xml.etree.ElementTree as ET

import numpy as np

OUTER, INNER, WEBS = 0, 1, 2   # the panel mesher's regions, in the order it writes them
AXES = "xyz"


def pvd_frames(folder, name):
    """[(time, path)] of vtk/<name>.pvd ([] when missing or unreadable)."""
    path = os.path.join(folder, "vtk", name + ".pvd")
    if not os.path.exists(path):
        return []
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError:
        return []
    out = []
    for d in root.iter("DataSet"):
        f = os.path.join(os.path.dirname(path), d.get("file"))
        if os.path.exists(f):
            out.append((float(d.get("timestep")), f))
    return out


def read_vtk(path):
    """(points, cells as lists of point ids, {array name: numpy array}) of a .vtu/.vtp file; the
    key `_cell_arrays` lists the arrays given per cell."""
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
    r = vtk.vtkXMLUnstructuredGridReader() if path.endswith(".vtu") else vtk.vtkXMLPolyDataReader()
    r.SetFileName(path)
    r.Update()
    g = r.GetOutput()
    pts = vtk_to_numpy(g.GetPoints().GetData()).astype(float) if g.GetPoints() else np.zeros((0, 3))
    cells = []
    arr = g.GetCells() if path.endswith(".vtu") else g.GetPolys()
    if arr is not None and arr.GetNumberOfCells():
        conn, off = vtk_to_numpy(arr.GetConnectivityArray()), vtk_to_numpy(arr.GetOffsetsArray())
        cells = [conn[off[i]:off[i + 1]] for i in range(len(off) - 1)]
    data = {}
    for att in (g.GetPointData(), g.GetCellData()):
        for k in range(att.GetNumberOfArrays()):
            a = att.GetArray(k)
            data[a.GetName()] = vtk_to_numpy(a).astype(float).reshape(a.GetNumberOfTuples(), -1)
    data["_cell_arrays"] = [g.GetCellData().GetArrayName(k) for k in range(g.GetCellData().GetNumberOfArrays())]
    return pts, cells, data


def _levels(values, tol):
    """Distinct values (sorted), those closer than tol merged to their mean."""
    out = []
    for v in np.sort(np.asarray(values, dtype=float)):
        if out and v - out[-1][-1] <= tol:
            out[-1].append(v)
        else:
            out.append([v])
    return [float(np.mean(g)) for g in out]


def load_case(path, sets=()):
    """The case file as a dict, with `KEY.PATH=VALUE` overrides (as `partita run --set`)."""
    import yaml
    with open(path) as f:
        doc = yaml.safe_load(f)
    for s in sets:
        k, sep, v = s.partition("=")
        if not sep:
            raise ValueError(f"--set {s!r}: expected KEY.PATH=VALUE")
        parts = re.findall(r"([^.\[\]]+)|\[(\d+)\]", k)
        node = doc
        for n, (name, index) in enumerate(parts):
            sel = int(index) if index else name
            if n == len(parts) - 1:
                node[sel] = yaml.safe_load(v)
            else:
                node = node[sel] if isinstance(node, list) else node.setdefault(sel, {})
    return doc


UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6}


def to_metres(v):
    """A length from a number (m) or a string with m, cm, mm, um; None when it is neither."""
    if isinstance(v, (int, float)):
        return float(v)
    m = re.fullmatch(r"\s*([-+0-9.eE]+)\s*(m|cm|mm|um)?\s*", str(v))
    return float(m.group(1)) * UNITS[m.group(2) or "m"] if m else None


class Geometry:
    def __init__(self):
        self.normal_axis = 2        # the plates' normal (the panel's z)
        self.outer = self.inner = None   # (low, high) faces of each plate along the normal
        self.frames, self.stringers = [], []   # webs' mid-planes across in-plane axes 1 and 2
        self.web_thickness = None
        self.lo = self.hi = None    # the hull's bounding box (reference)
        self.bow_frames = []        # [(time, path)] of the bow's surface
        self.bow_radius = self.bow_length = None
        self.bow_axis = None        # unit vector from the bow's centre towards the hull
        self.gravity = None         # from the case file
        self.comminution_limit = None

    # ------------------------------------------------------------------ reading
    @classmethod
    def of_run(cls, folder, case=None, sets=()):
        g = cls()
        hull = pvd_frames(folder, "hull_fem")
        if not hull:
            raise RuntimeError(f"{folder}: no vtk/hull_fem.pvd (the hull's geometry is read from it)")
        pts, cells, data = read_vtk(hull[0][1])
        if "region" not in data:
            raise RuntimeError(f"{hull[0][1]}: no cell array `region` (outer plate, inner plate, webs)")
        g._hull(pts, cells, data["region"][:, 0].astype(int))
        g.bow_frames = pvd_frames(folder, "hull_bow")
        if g.bow_frames:
            g._bow(read_vtk(g.bow_frames[0][1])[0])
        if case:
            g._case(load_case(case, sets))
        return g

    def _hull(self, pts, cells, region):
        self.lo, self.hi = pts.min(axis=0), pts.max(axis=0)
        boxes = {r: [] for r in (OUTER, INNER, WEBS)}
        for cl, r in zip(cells, region):
            if r in boxes:
                p = pts[cl]
                boxes[r].append((p.min(axis=0), p.max(axis=0)))
        if not boxes[OUTER] or not boxes[INNER]:
            raise RuntimeError("the hull's mesh has no outer or inner plate region (0 and 1)")
        ext = lambda r: (np.min([b[0] for b in boxes[r]], axis=0), np.max([b[1] for b in boxes[r]], axis=0))
        olo, ohi = ext(OUTER)
        self.normal_axis = int(np.argmin(ohi - olo))
        n = self.normal_axis
        ilo, ihi = ext(INNER)
        self.outer, self.inner = (float(olo[n]), float(ohi[n])), (float(ilo[n]), float(ihi[n]))
        a1, a2 = self.in_plane_axes
        if boxes[WEBS]:
            size = np.array([b[1] - b[0] for b in boxes[WEBS]])
            centre = np.array([0.5 * (b[0] + b[1]) for b in boxes[WEBS]])
            t = float(np.min(size[:, [a1, a2]]))   # one element through a web's thickness
            self.web_thickness = t
            self.frames = _levels(centre[size[:, a1] <= 1.01 * t, a1], 0.25 * t)
            self.stringers = _levels(centre[size[:, a2] <= 1.01 * t, a2], 0.25 * t)

    def _bow(self, pts):
        c = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
        q = pts - c
        w, v = np.linalg.eigh(q.T @ q)
        axis = v[:, int(np.argmax(w))]
        if np.ptp(w) <= 1e-9 * max(w.max(), 1e-30):   # a sphere: the hull's normal
            axis = np.eye(3)[self.normal_axis]
        along = q @ axis
        self.bow_radius = float(np.max(np.linalg.norm(q - np.outer(along, axis), axis=1)))
        self.bow_length = max(0.0, float(np.ptp(along)) - 2 * self.bow_radius)
        # towards the hull: the bow starts on the outer plate's side
        to_hull = self.centre_point() - c
        self.bow_axis = axis if to_hull @ axis >= 0 else -axis

    def _case(self, doc):
        for p in (doc.get("participants") or {}).values():
            if not isinstance(p, dict):
                continue
            if p.get("solver") == "dem":
                if p.get("gravity") is not None:
                    self.gravity = np.asarray(p["gravity"], dtype=float)
                b = p.get("breakage") or {}
                if "comminution_limit" in b:
                    self.comminution_limit = to_metres(b["comminution_limit"])

    # ------------------------------------------------------------------ derived
    @property
    def in_plane_axes(self):
        return [a for a in range(3) if a != self.normal_axis]

    def centre_point(self):
        return 0.5 * (self.lo + self.hi)

    @property
    def cavity(self):
        """(low, high) of the cavity along the normal: the outer plate's inner face to the inner
        plate's cavity face (the outer plate is the one the bow meets first)."""
        a, b = sorted([self.outer, self.inner])
        return a[1], b[0]

    @property
    def inner_faces_up(self):
        """+1 when the inner plate lies at larger normal coordinate than the outer."""
        return 1.0 if self.inner[0] > self.outer[0] else -1.0

    def web_spacing(self):
        gaps = np.diff(self.frames) if len(self.frames) > 1 else np.diff(self.stringers)
        return float(np.median(gaps)) if len(gaps) else None

    def cells(self):
        return max(len(self.frames) - 1, 0), max(len(self.stringers) - 1, 0)

    def bow_centre(self, t):
        """The bow's centre at time t (the output frame nearest t), None without its files."""
        if not self.bow_frames:
            return None
        k = int(np.argmin([abs(tt - t) for tt, _ in self.bow_frames]))
        pts = read_vtk(self.bow_frames[k][1])[0]
        return 0.5 * (pts.min(axis=0) + pts.max(axis=0))

    def bow_centre_start(self):
        return self.bow_centre(self.bow_frames[0][0]) if self.bow_frames else self.centre_point()

    def section_basis(self):
        """(origin, normal, horizontal, vertical) of the section through the bow's axis (unit
        vectors; the picture's coordinates are (p - origin) . horizontal and . vertical, origin on
        the bow's axis at the outer plate's struck face)."""
        n_ax = self.normal_axis
        axis = self.bow_axis if self.bow_axis is not None else np.eye(3)[n_ax]
        up = None
        if self.gravity is not None and np.linalg.norm(self.gravity) > 0:
            g = -self.gravity / np.linalg.norm(self.gravity)
            side = g - (g @ axis) * axis
            if np.linalg.norm(side) > 0.5:     # gravity along the plates: an upright section
                up = side / np.linalg.norm(side)
                horizontal, vertical = axis, up
        if up is None:
            horizontal = np.eye(3)[self.in_plane_axes[0]]
            horizontal = horizontal - (horizontal @ axis) * axis
            horizontal /= np.linalg.norm(horizontal)
            vertical = axis if (self.gravity is None or axis @ self.gravity <= 0) else -axis
        normal = np.cross(horizontal, vertical)
        c = self.bow_centre_start()
        struck = self.outer[0] if self.inner_faces_up > 0 else self.outer[1]
        origin = c + (struck - c[n_ax]) / axis[n_ax] * axis if abs(axis[n_ax]) > 1e-9 else c
        self.section_offset = self.off_web(origin, normal)
        return origin + self.section_offset, normal, horizontal, vertical

    def off_web(self, origin, normal):
        """The shift that moves a section plane lying in a web (a bow struck at a web, or at a
        crossing) to the middle of the next cell, so that it cuts the bed rather than the web's
        own plane; zero otherwise."""
        k = int(np.argmax(np.abs(normal)))
        if abs(normal[k]) < 0.999 or self.web_thickness is None or len(self.in_plane_axes) < 2:
            return np.zeros(3)
        a1, a2 = self.in_plane_axes
        webs = self.frames if k == a1 else self.stringers if k == a2 else []
        s = self.web_spacing()
        if not len(webs) or not s:
            return np.zeros(3)
        if np.min(np.abs(np.asarray(webs) - origin[k])) > self.web_thickness:
            return np.zeros(3)
        shift = np.zeros(3)
        shift[k] = 0.5 * s if origin[k] + 0.5 * s <= max(webs) else -0.5 * s
        return shift

    def describe(self):
        nx, ny = self.cells()
        s = self.web_spacing()
        parts = [f"plates normal to {AXES[self.normal_axis]}",
                 f"outer plate {1e3 * self.outer[0]:.4g}..{1e3 * self.outer[1]:.4g} mm",
                 f"inner plate {1e3 * self.inner[0]:.4g}..{1e3 * self.inner[1]:.4g} mm",
                 f"{nx} x {ny} cells" + (f" at {1e3 * s:.4g} mm" if s else "")]
        if self.bow_radius is not None:
            parts.append(f"bow radius {1e3 * self.bow_radius:.4g} mm, cylinder {1e3 * self.bow_length:.4g} mm")
        if self.gravity is not None:
            parts.append(f"gravity {self.gravity.tolist()}")
        return ", ".join(parts)
