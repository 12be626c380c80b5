#!/usr/bin/python3
"""Tests of plot_case.py's helpers on synthetic files (no run needed):
  /usr/bin/python3 cases/double_hull_impact/test_hull_plots.py
hull_geometry reads a panel of 2 x 1 cells written as the panel mesher writes it (regions 0 outer
plate, 1 inner plate, 2 webs) and a capsule's surface; hull_pictures cuts a hexahedron and tells
fragments from intact granules; hull_ensemble's energy shares add up to the audit's total."""
import os
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, ".."))
from python_modules import require  # noqa: E402

require("numpy", "vtk")
import numpy as np  # noqa: E402

import hull_ensemble  # noqa: E402
import hull_geometry  # noqa: E402
import hull_pictures  # noqa: E402

T, S, DEPTH = 0.002, 0.06, 0.03          # plate and web thickness, web spacing, cavity depth
R, L = 0.02, 0.05                         # the bow's radius and cylinder length


def write_pvd(folder, name, files):
    with open(os.path.join(folder, name + ".pvd"), "w") as f:
        f.write('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n<Collection>\n')
        for t, fn in files:
            f.write(f'<DataSet timestep="{t}" group="" part="0" file="{fn}"/>\n')
        f.write("</Collection>\n</VTKFile>\n")


def write_frame(folder, name, data, writer, ext):
    """data as the first (only) frame of vtk/<name>.pvd."""
    writer.SetFileName(os.path.join(folder, f"{name}_000000.{ext}"))
    writer.SetInputData(data)
    writer.Write()
    write_pvd(folder, name, [(0, f"{name}_000000.{ext}")])


def write_panel(folder, cells=(2, 1)):
    """A 2 x 1 cell panel (webs flush with the edges) as hexahedra with a region array."""
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk
    lines = []
    for n in cells:
        edges = sorted({k * S + d for k in range(n + 1) for d in (0.0, T)} |
                       {k * S + T + (S - T) / 2 for k in range(n)})
        lines.append(np.array(edges))
    z = np.array([0.0, T, T + DEPTH / 2, T + DEPTH, 2 * T + DEPTH])
    xs, ys = lines
    nx, ny, nz = len(xs), len(ys), len(z)
    pid = lambda i, j, k: i + nx * (j + ny * k)
    pts = np.array([[xs[i], ys[j], z[k]] for k in range(nz) for j in range(ny) for i in range(nx)])
    in_web = lambda a, b, n: any(abs(a - k * S) < 1e-12 and abs(b - (k * S + T)) < 1e-12 for k in range(n + 1))
    grid = vtk.vtkUnstructuredGrid()
    p = vtk.vtkPoints()
    p.SetData(numpy_to_vtk(pts))
    grid.SetPoints(p)
    region = []
    for k in range(nz - 1):
        for j in range(ny - 1):
            for i in range(nx - 1):
                if k == 0:
                    r = 0
                elif k == nz - 2:
                    r = 1
                elif in_web(xs[i], xs[i + 1], cells[0]) or in_web(ys[j], ys[j + 1], cells[1]):
                    r = 2
                else:
                    continue
                ids = [pid(i, j, k), pid(i + 1, j, k), pid(i + 1, j + 1, k), pid(i, j + 1, k),
                       pid(i, j, k + 1), pid(i + 1, j, k + 1), pid(i + 1, j + 1, k + 1), pid(i, j + 1, k + 1)]
                grid.InsertNextCell(vtk.VTK_HEXAHEDRON, 8, ids)
                region.append(r)
    a = numpy_to_vtk(np.array(region, dtype=float))
    a.SetName("region")
    grid.GetCellData().AddArray(a)
    d = numpy_to_vtk(np.zeros((len(pts), 3)))
    d.SetName("displacement")
    grid.GetPointData().AddArray(d)
    write_frame(folder, "hull_fem", grid, vtk.vtkXMLUnstructuredGridWriter(), "vtu")


def write_bow(folder, centre):
    """A capsule's surface points (axis z), as the bow's first frame."""
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk
    pts = []
    for a in np.linspace(0, 2 * np.pi, 24, endpoint=False):
        for h in np.linspace(-L / 2, L / 2, 5):
            pts.append([R * np.cos(a), R * np.sin(a), h])
        for b in np.linspace(0, np.pi / 2, 7)[1:]:
            for sgn in (1, -1):
                pts.append([R * np.cos(b) * np.cos(a), R * np.cos(b) * np.sin(a), sgn * (L / 2 + R * np.sin(b))])
    pts = np.unique(np.round(np.array(pts), 12), axis=0) + centre
    poly = vtk.vtkPolyData()
    p = vtk.vtkPoints()
    p.SetData(numpy_to_vtk(pts))
    poly.SetPoints(p)
    write_frame(folder, "hull_bow", poly, vtk.vtkXMLPolyDataWriter(), "vtp")


def write_case(folder, gravity):
    path = os.path.join(folder, "case.yaml")
    with open(path, "w") as f:
        f.write("participants:\n  granules:\n    solver: dem\n"
                f"    gravity: {list(gravity)}\n    breakage: {{comminution_limit: 4 mm}}\n")
    return path


class GeometryTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.folder = cls.tmp.name
        os.makedirs(os.path.join(cls.folder, "vtk"))
        write_panel(os.path.join(cls.folder, "vtk"))
        cls.centre = np.array([S + T / 2, S / 2 + T / 2, -(L / 2 + R) - 0.001])
        write_bow(os.path.join(cls.folder, "vtk"), cls.centre)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_panel_is_read_from_the_mesh(self):
        g = hull_geometry.Geometry.of_run(self.folder)
        self.assertEqual(g.normal_axis, 2)
        np.testing.assert_allclose(g.outer, (0.0, T), atol=1e-12)
        np.testing.assert_allclose(g.inner, (T + DEPTH, 2 * T + DEPTH), atol=1e-12)
        self.assertAlmostEqual(g.web_thickness, T, delta=1e-12)
        # the webs' mid-planes: flush with the edges, web_spacing apart
        np.testing.assert_allclose(g.frames, [T / 2 + k * S for k in range(3)], atol=1e-12)
        np.testing.assert_allclose(g.stringers, [T / 2 + k * S for k in range(2)], atol=1e-12)
        self.assertEqual(g.cells(), (2, 1))
        self.assertAlmostEqual(g.web_spacing(), S, delta=1e-12)
        np.testing.assert_allclose(g.cavity, (T, T + DEPTH), atol=1e-12)
        self.assertEqual(g.inner_faces_up, 1.0)

    def test_bow_is_read_from_its_surface(self):
        g = hull_geometry.Geometry.of_run(self.folder)
        self.assertAlmostEqual(g.bow_radius, R, delta=1e-9)
        self.assertAlmostEqual(g.bow_length, L, delta=1e-9)
        np.testing.assert_allclose(g.bow_axis, [0, 0, 1], atol=1e-9)   # towards the hull
        np.testing.assert_allclose(g.bow_centre(0.0), self.centre, atol=1e-9)

    def test_section_lies_flat_or_upright_by_gravity(self):
        flat = hull_geometry.Geometry.of_run(self.folder, write_case(self.folder, [0, 0, -9.81]))
        self.assertAlmostEqual(flat.comminution_limit, 0.004)
        origin, normal, h, v = flat.section_basis()
        np.testing.assert_allclose(v, [0, 0, 1], atol=1e-9)      # up: against gravity
        np.testing.assert_allclose(abs(normal @ [0, 1, 0]), 1, atol=1e-9)
        np.testing.assert_allclose(origin, [self.centre[0], self.centre[1], 0.0], atol=1e-9)  # at the struck face
        upright = hull_geometry.Geometry.of_run(self.folder, write_case(self.folder, [0, -9.81, 0]))
        origin, normal, h, v = upright.section_basis()
        np.testing.assert_allclose(v, [0, 1, 0], atol=1e-9)      # up: against gravity
        np.testing.assert_allclose(h, [0, 0, 1], atol=1e-9)      # the bow travels across
        # a --set value overrides the case file's
        g = hull_geometry.Geometry.of_run(self.folder, write_case(self.folder, [0, 0, -9.81]),
                                          ["participants.granules.gravity=[-9.81, 0, 0]"])
        np.testing.assert_allclose(g.section_basis()[3], [1, 0, 0], atol=1e-9)

    def test_section_through_a_web_moves_to_the_next_cells_middle(self):
        # upright, the plane through the bow's axis is x = S + T/2: the middle frame's own plane
        upright = hull_geometry.Geometry.of_run(self.folder, write_case(self.folder, [0, -9.81, 0]))
        origin, normal, h, v = upright.section_basis()
        np.testing.assert_allclose(upright.section_offset, [S / 2, 0, 0], atol=1e-12)
        self.assertAlmostEqual(origin[0], S + T / 2 + S / 2, delta=1e-12)
        # flat, the plane y = centre is mid-cell already: not moved
        flat = hull_geometry.Geometry.of_run(self.folder, write_case(self.folder, [0, 0, -9.81]))
        flat.section_basis()
        np.testing.assert_allclose(flat.section_offset, 0.0, atol=0)

    def test_bow_outline_in_a_plane_off_its_axis(self):
        g = hull_geometry.Geometry.of_run(self.folder, write_case(self.folder, [0, 0, -9.81]))
        origin, normal, h, v = g.section_basis()
        centre = g.bow_centre(0.0)
        width = lambda xy: xy[:, 0].max() - xy[:, 0].min()
        full = hull_pictures.bow_outline(g, centre, origin, h, v)
        self.assertAlmostEqual(width(full), 2e3 * R, delta=1e-6)
        d = 0.6 * R      # the capsule cut off its axis: radius sqrt(R^2 - d^2)
        off = hull_pictures.bow_outline(g, centre, origin + d * normal, h, v)
        self.assertAlmostEqual(width(off), 2e3 * np.sqrt(R * R - d * d), delta=1e-6)
        self.assertIsNone(hull_pictures.bow_outline(g, centre, origin + 1.1 * R * normal, h, v))

    def test_section_cuts_every_element_the_plane_crosses(self):
        g = hull_geometry.Geometry.of_run(self.folder)
        origin, normal, h, v = g.section_basis()
        path = hull_geometry.pvd_frames(self.folder, "hull_fem")[0][1]
        intact, peeq, eroded = hull_pictures.cut_hull(path, origin, normal, h, v)
        area = sum(0.5 * abs(np.dot(q[:, 0], np.roll(q[:, 1], 1)) - np.dot(q[:, 1], np.roll(q[:, 0], 1))) for q in intact)
        # the plane y = centre (mid-cell): both plates over the width and the three frames over the depth
        width = 2 * S + T
        expected = 1e6 * (2 * T * width + 3 * T * DEPTH)
        self.assertAlmostEqual(area / expected, 1.0, delta=1e-9)
        self.assertEqual(eroded, [])


class GranuleStateTest(unittest.TestCase):
    def test_fragments_are_new_ids(self):
        first = np.array([1, 2, 3])
        ids = np.array([1, 3, 7, 8])
        radius = np.array([0.005, 0.005, 0.003, 0.0015])
        np.testing.assert_array_equal(hull_pictures.granule_state(ids, radius, first, 0.004), [0, 0, 1, 2])
        np.testing.assert_array_equal(hull_pictures.granule_state(ids, radius, first, None), [0, 0, 1, 1])


class FakeRun:
    """The columns hull_ensemble reads, on a linear penetration."""

    def __init__(self, scale):
        self.t = np.linspace(0, 1, 101)
        self.pen = 0.05 * self.t
        self.contact = 0
        p = self.pen
        self.cols = {"hull.outer_plate.plastic_work": 100 * p * scale, "hull.outer_plate.strain_energy": 5 * p,
                     "hull.inner_plate.plastic_work": 40 * p ** 2, "hull.inner_plate.strain_energy": p,
                     "hull.webs.plastic_work": 10 * p, "hull.webs.strain_energy": p,
                     "hull.eroded_energy": 20 * p ** 3, "granules.friction_work": 3 * p,
                     "granules.damping_work": p, "granules.breakage_energy": 0.1 * p}
        self.cols["stored + dissipated"] = sum(self.cols.values()) + 0.5 * p   # 0.5 p: the rest

    def has(self, *names):
        return all(n in self.cols for n in names)

    def at(self, name):
        return self.cols[name]


class EnsembleTest(unittest.TestCase):
    def test_shares_add_up_to_the_audit_total(self):
        runs = [FakeRun(1.0), FakeRun(1.1), FakeRun(0.9)]
        at = np.array([0.01, 0.03, 0.05])
        for r in runs:
            v = hull_ensemble.share_values(r, at)
            total = sum(v.values())
            np.testing.assert_allclose(total, np.interp(at, r.pen, r.cols["stored + dissipated"]), rtol=1e-12)
            np.testing.assert_allclose(v["other"], 0.5 * at, rtol=1e-9)

    def test_stats_give_mean_sample_std_and_range(self):
        mean, std, lo, hi, n = hull_ensemble.stats([1.0, 2.0, 3.0, None, float("nan")])
        self.assertEqual((mean, lo, hi, n), (2.0, 1.0, 3.0, 3))
        self.assertAlmostEqual(std, 1.0)              # ddof = 1
        self.assertEqual(hull_ensemble.stats([5.0])[1], 0.0)
        self.assertIsNone(hull_ensemble.stats([None]))


class PartRuptureTest(unittest.TestCase):
    """Each part's first failed element: from hull.<part>.first_failure_time where the run records
    it, else from the part's plastic work falling as the failed count rises (an eroded element's
    plastic work leaves its part's sum)."""

    def run_with(self, per_part_times):
        import plot_case
        r = FakeRun(1.0)
        n = len(r.t)
        failed = np.zeros(n)
        failed[30:] += 1          # a web element fails at row 30,
        failed[60:] += 1          # an inner plate element at row 60
        r.cols["hull.failed_elements"] = failed
        r.cols["hull.webs.plastic_work"] = r.cols["hull.webs.plastic_work"].copy()
        r.cols["hull.webs.plastic_work"][30:] -= 0.2
        r.cols["hull.inner_plate.plastic_work"] = r.cols["hull.inner_plate.plastic_work"].copy()
        r.cols["hull.inner_plate.plastic_work"][60:] -= 0.2
        if per_part_times:
            for part, row in (("webs", 30), ("inner_plate", 60), ("outer_plate", None)):
                ft = -np.ones(n)
                if row is not None:
                    ft[row:] = r.t[row]
                r.cols[f"hull.{part}.first_failure_time"] = ft
        return plot_case, r

    def test_from_the_plastic_work_of_each_part(self):
        plot_case, r = self.run_with(per_part_times=False)
        self.assertEqual(plot_case.part_rupture_row(r, "webs"), 30)
        self.assertEqual(plot_case.part_rupture_row(r, "inner_plate"), 60)
        self.assertIsNone(plot_case.part_rupture_row(r, "outer_plate"))
        self.assertEqual(plot_case.inner_rupture_row(r), 60)

    def test_from_the_parts_failure_times(self):
        plot_case, r = self.run_with(per_part_times=True)
        r.cols["hull.webs.plastic_work"] = 10 * r.pen     # the columns, not the heuristic, decide
        self.assertEqual(plot_case.part_rupture_row(r, "webs"), 30)
        self.assertEqual(plot_case.part_rupture_row(r, "inner_plate"), 60)
        self.assertIsNone(plot_case.part_rupture_row(r, "outer_plate"))


if __name__ == "__main__":
    unittest.main()
