#!/usr/bin/python3
"""The figures and headline numbers of a double-hull impact run (double_hull_impact.yaml,
coarse.yaml), filled with granules and, optionally, against the empty hull (empty.yaml,
coarse_empty.yaml).

Usage: plot_case.py FILLED_DIR [EMPTY_DIR] [--out DIR] [--driven DIR] [--rate OTHER_DIR ...]
  FILLED_DIR, EMPTY_DIR: the runs' output folders (bow.csv, parts.csv, granules.csv, energy.csv,
  vtk/); PNGs go to DIR (default FILLED_DIR). --driven DIR: for a collision run (a free bow,
  collision.yaml), the driven run of the same hull it is compared with (the collision_* keys). The case test calls it as `plot_case.py OUT` with the
  filled run alone (checks.yaml: {script: plot_case.py, key: ...}). --rate OTHER_DIR: the same
  case with the bow at another speed (the quasi-static check: the rate_* keys, rate_force.png);
  repeated, each further run at yet another speed (keys rate2_*, rate3_*, ..., one figure).

Writes force_penetration.png, energy.png, inner_deflection.png, section_<k>.png (k = 1, 2, 3: the
output frames nearest 1/3, 2/3 and all of the final penetration, cut at y = 0.181 m through the
bow's axis; section_empty_<k>.png for EMPTY_DIR) and prints key=value lines (SI units):
  weight_balance          -(sum of granules.cXX.force_z, or of section.yaml's granules.cavity_outer,
                          _inner, _webs.force_z) / (granules.mass g), averaged over the rows
                          before the bow touches (penetration 0) after the first 2 ms (1: the
                          granules' weight rests on the hull); weight_balance_last: the same over
                          the last 20 % of those rows (the settled state); weight_balance_impulse
                          (with the monitor granules.momentum_z): over the same rows, (the cells'
                          and the bow's impulse on the granules - the change of their momentum) /
                          the impulse of m g (1 also while the bed rings: Newton's second law);
                          hull_weight_balance (section.yaml): the same with the forces the
                          hull's three cavity interfaces received; bed_on_inner_plate_N: the mean of
                          granules.cavity_inner.force_z over those rows, the bed's load on the
                          inner plate before the strike
  max_abs_energy_error[_empty]   largest |energy balance error| of energy.csv over the rows whose
                          indenter work exceeds 1 % of its final value
  quasi_static_ke_ratio[_empty]  max of (hull + granules kinetic energy) / (hull strain energy +
                          plastic work + eroded elements' energy) over the rows after first contact whose internal energy
                          exceeds 5 % of its final value (before that the ratio is 0/0 noise)
  filled_over_empty_min   min of filled / empty force at equal penetration, from 60 % of the
                          smaller final penetration of the two runs on (needs EMPTY_DIR)
  granule_contact_penetration_m  the filled run's penetration at the granules' first force on the bow
  filled_minus_empty_work_min_J  min of the bow's work filled - empty at equal penetration, from
                          that first contact to the smaller final penetration (needs EMPTY_DIR)
  filled_force_where_empty_free_min_N, empty_free_from_m  min of the filled bow's force (smoothed
                          over 4 % of the travel) where the empty bow's smoothed force is zero after
                          its first contact (it has passed the outer plate's petals: the bed alone
                          resists), and where that begins
  final_penetration_{filled,empty}_m
  force_{25,50,100}_{filled,empty}_N   the indenter's resisting force (-(hull.bow.force_z +
                          granules.bow.force_z)) at 25/50/100 % of the final penetration, averaged
                          over a penetration window of 4 % of the final penetration (centred;
                          ending at the last row for 100 %): the raw contact force chatters
  rupture_time_{filled,empty}_s, rupture_penetration_{filled,empty}_m   hull.first_failure_time
  energy_to_rupture_{filled,empty}_J     indenter work (hull.bow.work + granules.bow.work) up to it
  inner_yield_penetration_{filled,empty}_m, energy_to_inner_yield_{filled,empty}_J   the same at the
                          first row with hull.inner_plate.plastic_work > 0
  inner_rupture_penetration_{filled,empty}_m, energy_to_inner_rupture_{filled,empty}_J   the same at
                          the inner plate's first failed element: the first row whose
                          hull.failed_elements rises while hull.inner_plate.plastic_work falls (an
                          eroded element's plastic work leaves its part's sum)
  powder_events, powder_mass_kg   granules.breakage.powder_* at the last row (below_limit: powder)
  energy_final_{filled,empty}_J   indenter work at the last row
  inner_deflection_final_{filled,empty}_m   hull.inner_centre.displacement_z at the last row
  broken_granules         granules.breakage.events at the last row
  footprint_area_90[_empty] [m^2] the smallest area of the inner plate's cavity faces (the cells' faces
                          facing -z above mid-depth) carrying 90 % of the upward force on them, at
                          the last output frame: the granules' (the DEM's mesh files vtk/granules_cXX
                          or the interface files vtk/granules_interface_cXX) and the bow's own
                          contact (the hull's point array contact_force, where the files have it);
                          footprint_fraction_90: that area over the cavity faces' total;
                          inner_plate_granule_force[_empty]_N, inner_plate_bow_force[_empty]_N: the
                          upward forces of each on the inner plate
  collision_initial_kinetic_energy_J, collision_max_penetration_m, collision_absorbed_J (the
                          bow's kinetic energy lost by its deepest row), collision_final_kinetic_energy_J
                          for a run whose bow is free (hull.bow.kinetic_energy > 0 at the start);
                          with --driven DIR also driven_penetration_at_absorbed_m (the penetration at
                          which the driven run's indenter work reached collision_absorbed_J) and
                          collision_over_driven_penetration (their ratio: 1 when the striker meets the
                          same force-penetration curve, the energy method of collision analysis)
  rate_force_ratio_<p>mm   with --rate: OTHER's force over FILLED's at penetration p (every 5 mm of
                          the common range, and at 25/50/100 % of FILLED's final penetration as
                          rate_force_ratio_{25,50,100}), each a +-1.5 mm mean; rate_work_ratio_<pct>:
                          the same for the indenter's work at 25/50/100 %; rate_max_force_dev
                          (rate_max_force_dev_at_m): the largest |ratio - 1| where FILLED's force
                          is above 10 % of its largest +-1.5 mm mean; a second (third, ...) --rate:
                          the same keys as rate2_* (rate3_*, ...)
A missing file or column skips its item with a note on stderr (plot_case: ...), never a traceback."""
import csv
import os
import re
import sys
import textwrap
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from python_modules import require  # noqa: E402  (cases/python_modules.py: the missing-module check)

require("numpy", "matplotlib")
import numpy as np  # noqa: E402

G = 9.81
SECTION_Y = 0.181                 # the bow's axis (x = y = 0.181)
BOW_RADIUS, BOW_LENGTH = 0.030, 0.030   # the capsule's radius; its cylinder's length unless vtk/hull_bow says
CELLS = [f"c{i}{j}" for j in range(3) for i in range(3)]
PARTS = ["cavity_outer", "cavity_inner", "cavity_webs"]   # section.yaml's interfaces, by part


def note(msg):
    print(f"plot_case: {msg}", file=sys.stderr)


def key(name, value, fmt="{:.6g}"):
    if value is None or not np.isfinite(value):
        note(f"{name} not computed (no finite value)")
        return
    print(f"{name}={fmt.format(value)}")


# ---------------------------------------------------------------------------------------- data
class Run:
    """The monitors of one run: every column of every CSV, by its name without the unit, on the
    CSV's own time axis; `at(name)` gives it on bow.csv's time axis (`t`)."""

    def __init__(self, folder, label):
        if not os.path.isdir(folder):
            raise RuntimeError(f"{folder} is not a folder")
        self.folder, self.label = folder, label
        self.cols, self.kind = {}, {}
        for f in ("bow", "parts", "granules", "energy", "coupling"):
            self._read(os.path.join(folder, f + ".csv"))
        if "hull.bow.penetration" not in self.cols:
            raise RuntimeError(f"{folder}: no bow.csv with hull.bow.penetration")
        self.t, pen = self.cols["hull.bow.penetration"]
        self.pen = np.maximum.accumulate(pen)       # monotone for interpolation at equal penetration
        touching = np.nonzero(self.pen > 0)[0]
        self.contact = touching[0] if len(touching) else len(self.t)

    def _read(self, path):
        if not os.path.exists(path):
            note(f"{path} missing")
            return
        with open(path) as f:
            reader = csv.reader(f)
            header = next(reader, None)
            rows = []
            for r in reader:
                if len(r) != len(header):
                    continue  # a run still writing: a partial last line
                try:
                    rows.append([float(x) for x in r])
                except ValueError:
                    continue
        if not header or not rows:
            note(f"{path} has no rows")
            return
        a = np.array(rows)
        t = a[:, header.index("time [s]")] if "time [s]" in header else a[:, 0]
        for k, h in enumerate(header):
            name = h.split(" [")[0].strip()
            m = re.match(r"(input|stored|dissipated) (\S+\.\S+)$", name)
            if m and os.path.basename(path) == "energy.csv":
                name = m.group(2)
                self.kind[name] = m.group(1)
            if name not in self.cols or os.path.basename(path) != "energy.csv":
                self.cols.setdefault(name, (t, a[:, k]))

    def has(self, *names):
        return all(n in self.cols for n in names)

    def at(self, name, t=None):
        tt, v = self.cols[name]
        return np.interp(self.t if t is None else t, tt, v)

    def get(self, name, what):
        if name not in self.cols:
            note(f"{self.label}: no column {name} ({what} skipped)")
            return None
        return self.at(name)

    def force(self):
        """The indenter's resisting force [N] (positive when the hull pushes back)."""
        f = self.at("hull.bow.force_z")
        if self.has("granules.bow.force_z"):
            f = f + self.at("granules.bow.force_z")
        return -f

    def work(self):
        w = self.at("hull.bow.work") if self.has("hull.bow.work") else None
        if w is not None and self.has("granules.bow.work"):
            w = w + self.at("granules.bow.work")
        return w

    def smoothed_force(self, window):
        """Centred moving average of the force over a penetration window [m], on the rows after
        first contact (returns penetration, force)."""
        p, f = self.pen[self.contact:], self.force()[self.contact:]
        if len(p) == 0:
            return p, f
        c = np.concatenate([[0.0], np.cumsum(f)])
        lo = np.searchsorted(p, p - window / 2, side="left")
        hi = np.searchsorted(p, p + window / 2, side="right")
        return p, (c[hi] - c[lo]) / np.maximum(hi - lo, 1)

    def force_at(self, fraction, window):
        p, f = self.pen[self.contact:], self.force()[self.contact:]
        if len(p) == 0:
            return None
        target = fraction * p[-1]
        lo, hi = (target - window, target) if fraction >= 1 else (target - window / 2, target + window / 2)
        sel = (p >= lo) & (p <= hi)
        return float(np.mean(f[sel])) if sel.any() else float(np.interp(target, p, f))

    def first_rupture(self):
        """(time, penetration) of hull.first_failure_time (-1 until a failure), or None."""
        if not hasattr(self, "_rupture"):
            self._rupture = self._first_rupture()
        return self._rupture

    def _first_rupture(self):
        if not self.has("hull.first_failure_time"):
            note(f"{self.label}: no column hull.first_failure_time (rupture skipped)")
            return None
        ft = self.at("hull.first_failure_time")
        hit = ft[ft >= 0]
        if not len(hit):
            note(f"{self.label}: the hull did not rupture (hull.first_failure_time stays -1)")
            return None
        t = float(hit[-1])
        return t, float(np.interp(t, self.t, self.pen))


def pvd_frames(folder, name):
    """[(time, path)] of vtk/<name>.pvd, or [] with a note."""
    path = os.path.join(folder, "vtk", name + ".pvd")
    if not os.path.exists(path):
        return []
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError:
        note(f"{path} unreadable (a run still writing it?)")
        return []
    out = []
    for d in root.iter("DataSet"):
        f = os.path.join(os.path.dirname(path), d.get("file"))
        if os.path.exists(f):
            out.append((float(d.get("timestep")), f))
    return out


def read_vtk(path):
    """(points, cells as lists of point ids, {array name: numpy array}) of a .vtu/.vtp file."""
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
    r = vtk.vtkXMLUnstructuredGridReader() if path.endswith(".vtu") else vtk.vtkXMLPolyDataReader()
    r.SetFileName(path)
    r.Update()
    g = r.GetOutput()
    pts = vtk_to_numpy(g.GetPoints().GetData()).astype(float) if g.GetPoints() else np.zeros((0, 3))
    cells = []
    if path.endswith(".vtu"):
        arr = g.GetCells()
        conn, off = vtk_to_numpy(arr.GetConnectivityArray()), vtk_to_numpy(arr.GetOffsetsArray())
        cells = [conn[off[i]:off[i + 1]] for i in range(len(off) - 1)]
    elif g.GetPolys() is not None and g.GetPolys().GetNumberOfCells():
        arr = g.GetPolys()
        conn, off = vtk_to_numpy(arr.GetConnectivityArray()), vtk_to_numpy(arr.GetOffsetsArray())
        cells = [conn[off[i]:off[i + 1]] for i in range(len(off) - 1)]
    data = {}
    for att in (g.GetPointData(), g.GetCellData()):
        for k in range(att.GetNumberOfArrays()):
            a = att.GetArray(k)
            data[a.GetName()] = vtk_to_numpy(a).astype(float).reshape(a.GetNumberOfTuples(), -1)
    data["_cell_arrays"] = [g.GetCellData().GetArrayName(k) for k in range(g.GetCellData().GetNumberOfArrays())]
    return pts, cells, data


# ------------------------------------------------------------------------------------- numbers
def weight_balance(run):
    cols = [f"granules.{c}.force_z" for c in CELLS]
    if not run.has(*cols):   # the cavity's faces by part (section.yaml)
        cols = [f"granules.{c}.force_z" for c in PARTS]
    if not run.has(*cols, "granules.mass"):
        note(f"{run.label}: granules.cXX.force_z (or granules.cavity_*.force_z) or granules.mass "
             "missing (weight_balance skipped)")
        return
    fz = sum(run.at(c) for c in cols)
    rows = np.nonzero((run.pen <= 0) & (run.t > 0.002))[0]
    if not len(rows):
        note(f"{run.label}: no rows between 2 ms and first contact (weight_balance skipped)")
        return
    weight = run.at("granules.mass")[rows] * G
    key("weight_balance", float(np.mean(-fz[rows]) / np.mean(weight)))
    hull_cols = [f"hull.{c}.force_z" for c in PARTS]
    if run.has(*hull_cols):
        # the same weight as the hull received it: the parts' interfaces share the nodes where a
        # web meets a plate, and their forces add there
        hz = sum(run.at(c) for c in hull_cols)
        key("hull_weight_balance", float(np.mean(-hz[rows]) / np.mean(weight)))
    if run.has("granules.cavity_inner.force_z"):
        # what the bed presses on the inner plate before the strike (the granules' force on the
        # mesh; +z: the plate pushed away from the cavity)
        key("bed_on_inner_plate_N", float(np.mean(run.at("granules.cavity_inner.force_z")[rows])))
    last = rows[len(rows) - max(1, len(rows) // 5):]
    key("weight_balance_last", float(np.mean(-fz[last]) / np.mean(run.at("granules.mass")[last] * G)))
    # the impulse balance over the same rows (a bed that rings is not at rest, so the cells' force
    # is its weight plus the rate of its momentum): (integral of the hull's and the bow's force on
    # the granules - the change of their momentum) / integral of m g
    if not run.has("granules.momentum_z"):
        note(f"{run.label}: no column granules.momentum_z (weight_balance_impulse skipped)")
        return
    if len(rows) < 2:
        return
    on_bed = fz[rows]
    if run.has("granules.bow.force_z"):
        on_bed = on_bed + run.at("granules.bow.force_z")[rows]
    t = run.t[rows]
    trap = lambda y: float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(t)))
    p = run.at("granules.momentum_z")[rows]
    key("weight_balance_impulse", (trap(-on_bed) - float(p[-1] - p[0])) / trap(weight))


def energy_error(run, suffix):
    w = run.work()
    if w is None or not run.has("energy balance error"):
        note(f"{run.label}: indenter work or energy balance error missing (max_abs_energy_error skipped)")
        return
    err = run.at("energy balance error")
    sel = w > 0.01 * w[-1]
    if w[-1] <= 0 or not sel.any():
        note(f"{run.label}: no indenter work yet (max_abs_energy_error skipped)")
        return
    key("max_abs_energy_error" + suffix, float(np.max(np.abs(err[sel]))))


def internal_energy(run):
    strain = run.at("hull.strain_energy") if run.has("hull.strain_energy") else None
    if strain is None and run.has(*[f"hull.{p}.strain_energy" for p in ("outer_plate", "inner_plate", "webs")]):
        strain = sum(run.at(f"hull.{p}.strain_energy") for p in ("outer_plate", "inner_plate", "webs"))
    plastic = run.at("hull.plastic_work") if run.has("hull.plastic_work") else None
    if plastic is None and run.has(*[f"hull.{p}.plastic_work" for p in ("outer_plate", "inner_plate", "webs")]):
        plastic = sum(run.at(f"hull.{p}.plastic_work") for p in ("outer_plate", "inner_plate", "webs"))
    if strain is None or plastic is None:
        return None
    # the failed elements' energy (elastic and plastic when they were eroded) stays absorbed:
    # without it the internal energy would fall at each erosion
    eroded = run.at("hull.eroded_energy") if run.has("hull.eroded_energy") else 0.0
    return strain + plastic + eroded


def ke_ratio(run, suffix):
    internal = internal_energy(run)
    if internal is None or not run.has("hull.kinetic_energy"):
        note(f"{run.label}: strain/plastic/kinetic energy missing (quasi_static_ke_ratio skipped)")
        return
    ke = run.at("hull.kinetic_energy")
    if run.has("granules.kinetic_energy"):
        ke = ke + run.at("granules.kinetic_energy")
    idx = np.arange(len(run.t))
    sel = (idx >= run.contact) & (internal > 0.05 * internal[-1])
    if internal[-1] <= 0 or not sel.any():
        note(f"{run.label}: no internal energy after contact (quasi_static_ke_ratio skipped)")
        return
    key("quasi_static_ke_ratio" + suffix, float(np.max(ke[sel] / internal[sel])))


def milestones(run, suffix):
    if len(run.t) <= run.contact:
        note(f"{run.label}: the bow has not touched the hull yet (forces skipped)")
        return
    final = run.pen[-1]
    key("final_penetration" + suffix + "_m", float(final))
    window = 0.04 * final
    for pct in (25, 50, 100):
        key(f"force_{pct}{suffix}_N", run.force_at(pct / 100, window))
    w = run.work()
    rup = run.first_rupture()
    if rup:
        key("rupture_time" + suffix + "_s", rup[0])
        key("rupture_penetration" + suffix + "_m", rup[1])
        if w is not None:
            key("energy_to_rupture" + suffix + "_J", float(np.interp(rup[0], run.t, w)))
    pw = run.get("hull.inner_plate.plastic_work", "inner plate's first yield")
    if pw is not None:
        hit = np.nonzero(pw > 0)[0]
        if not len(hit):
            note(f"{run.label}: the inner plate has not yielded (hull.inner_plate.plastic_work = 0)")
        else:
            key("inner_yield_time" + suffix + "_s", float(run.t[hit[0]]))
            key("inner_yield_penetration" + suffix + "_m", float(run.pen[hit[0]]))
            if w is not None:
                key("energy_to_inner_yield" + suffix + "_J", float(w[hit[0]]))
    if pw is not None and run.has("hull.failed_elements"):
        # an eroded element's plastic work leaves its part's sum, which otherwise never falls:
        # the first row whose failed count rises while the inner plate's plastic work falls
        failed = run.at("hull.failed_elements")
        hit = np.nonzero((np.diff(failed) > 0) & (np.diff(pw) < 0))[0]
        if not len(hit):
            note(f"{run.label}: no element of the inner plate has failed")
        else:
            k = hit[0] + 1
            key("inner_rupture_time" + suffix + "_s", float(run.t[k]))
            key("inner_rupture_penetration" + suffix + "_m", float(run.pen[k]))
            if w is not None:
                key("energy_to_inner_rupture" + suffix + "_J", float(w[k]))
    if run.has("granules.breakage.powder_events"):
        key("powder_events", float(run.at("granules.breakage.powder_events")[-1]))
    if run.has("granules.breakage.powder_mass"):
        key("powder_mass_kg", float(run.at("granules.breakage.powder_mass")[-1]))
    if w is not None:
        key("energy_final" + suffix + "_J", float(w[-1]))
    if run.has("hull.inner_centre.displacement_z"):
        key("inner_deflection_final" + suffix + "_m", float(run.at("hull.inner_centre.displacement_z")[-1]))


def collision(run, driven):
    """A free bow: how deep it went and how much of its kinetic energy the section absorbed; with
    a driven run of the same hull, the penetration at which the driven bow had done that work."""
    if not run.has("hull.bow.kinetic_energy"):
        note(f"{run.label}: no column hull.bow.kinetic_energy (collision keys skipped)")
        return
    ke = run.at("hull.bow.kinetic_energy")
    if ke[0] <= 0.0:
        return  # a driven bow: no collision keys
    pen = run.at("hull.bow.penetration")
    deepest = int(np.argmax(pen))
    absorbed = float(ke[0] - ke[deepest])
    key("collision_initial_kinetic_energy_J", float(ke[0]))
    key("collision_max_penetration_m", float(pen[deepest]))
    key("collision_absorbed_J", absorbed)
    key("collision_final_kinetic_energy_J", float(ke[-1]))
    if driven is None:
        return
    w = driven.work()
    if w is None:
        note("driven run: no hull.bow.work (driven_penetration_at_absorbed_m skipped)")
        return
    w = np.maximum.accumulate(w)
    if absorbed > w[-1]:
        note(f"the driven run did {w[-1]:.4g} J, less than the collision's {absorbed:.4g} J: "
             "too short for the comparison")
        return
    reached = float(np.interp(absorbed, w, driven.pen))
    key("driven_penetration_at_absorbed_m", reached)
    key("collision_over_driven_penetration", float(pen[deepest]) / reached)


def rate_compare(run, others, outdir, plt):
    """The same case at other bow speeds: force and work ratios at equal penetration (keys
    rate_* for the first OTHER, rate<k>_* for the k-th, k >= 2), one figure with them all."""
    for r in [run] + others:
        if len(r.t) <= r.contact + 10:
            note(f"{r.label}: no contact yet (rate keys skipped)")
            return
    half = 0.0015
    p1, f1 = run.smoothed_force(2 * half)
    curves = []
    for k, other in enumerate(others):
        prefix = "rate" if k == 0 else f"rate{k + 1}"
        p2, f2 = other.smoothed_force(2 * half)
        top = min(p1[-1], p2[-1]) - half
        p2u, k2 = np.unique(p2, return_index=True)
        curves.append((other, p2, f2, p2u, k2, top))

        def ratio(p):
            a = float(np.interp(p, p1, f1))
            b = float(np.interp(p, p2u, f2[k2]))
            return b / a if a != 0 else float("nan")
        for mm in range(5, int(1e3 * top) + 1, 5):
            key(f"{prefix}_force_ratio_{mm}mm", ratio(1e-3 * mm), "{:.4f}")
        final = run.pen[-1]
        w1, w2 = run.work(), other.work()
        for pct in (25, 50, 100):
            p = pct / 100 * final
            if p <= top:
                key(f"{prefix}_force_ratio_{pct}", ratio(p), "{:.4f}")
            if w1 is not None and w2 is not None and p <= min(run.pen[-1], other.pen[-1]):
                a = float(np.interp(p, run.pen, np.maximum.accumulate(w1)))
                b = float(np.interp(p, other.pen, np.maximum.accumulate(w2)))
                key(f"{prefix}_work_ratio_{pct}", b / a if a else float("nan"), "{:.5f}")
        sel = (p1 >= run.pen[run.contact] + half) & (p1 <= top) & (f1 > 0.1 * np.max(f1))
        if sel.any():
            r = np.interp(p1[sel], p2u, f2[k2]) / f1[sel]
            i = int(np.argmax(np.abs(r - 1)))
            key(f"{prefix}_max_force_dev", float(abs(r[i] - 1)), "{:.4f}")
            key(f"{prefix}_max_force_dev_at_m", float(p1[sel][i]))
    fig, (ax, bx) = plt.subplots(2, 1, figsize=(7, 6), sharex=True, gridspec_kw={"height_ratios": [2, 1]})
    label = lambda r: f"{os.path.basename(os.path.normpath(r.folder))} (+-1.5 mm mean)"
    ax.plot(1e3 * p1, 1e-3 * f1, color="C0", lw=1.4, label=label(run))
    for k, (other, p2, f2, p2u, k2, top) in enumerate(curves):
        c = f"C{k + 1}"
        ax.plot(1e3 * p2, 1e-3 * f2, color=c, lw=1.4, label=label(other))
        pp = p1[(p1 <= top)]
        a = np.interp(pp, p1, f1)
        rr = np.interp(pp, p2u, f2[k2]) / np.where(a != 0, a, np.nan)
        bx.plot(1e3 * pp, rr, color=c, lw=1,
                label=f"{os.path.basename(os.path.normpath(other.folder))} / {os.path.basename(os.path.normpath(run.folder))}")
    bx.axhspan(0.97, 1.03, color="C2", alpha=0.2, label="+-3 %")
    ax.set_ylabel("indenter force [kN]")
    ax.set_yscale("symlog", linthresh=0.1)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("the same case at several bow speeds" if len(others) > 1 else "the same case at two bow speeds")
    bx.set_ylim(0.6 if len(others) > 1 else 0.8, 1.4 if len(others) > 1 else 1.2)
    bx.set_xlabel("penetration [mm]")
    bx.set_ylabel("force ratio")
    bx.grid(alpha=0.3)
    bx.legend(fontsize=7, loc="upper left")  # (the curves part past 45 mm, on the right)
    save(fig, outdir, "rate_force.png")


def filled_over_empty(filled, empty):
    if len(filled.t) <= filled.contact or len(empty.t) <= empty.contact:
        note("a run has no contact yet (filled_over_empty_min skipped)")
        return
    start = 0.6 * min(filled.pen[-1], empty.pen[-1])
    window = 0.04 * min(filled.pen[-1], empty.pen[-1])
    pf, ff = filled.smoothed_force(window)
    pe, fe = empty.smoothed_force(window)
    sel = (pf >= start) & (pf <= pe[-1])
    if not sel.any():
        note("no common penetration range (filled_over_empty_min skipped)")
        return
    pe_u, k = np.unique(pe, return_index=True)
    ref = np.interp(pf[sel], pe_u, fe[k])
    if np.min(ref) <= 0:
        note("the empty hull's force is not positive over the range (filled_over_empty_min skipped)")
        return
    key("filled_over_empty_min", float(np.min(ff[sel] / ref)))
    key("filled_over_empty_from_m", float(start))


def filled_against_empty(filled, empty):
    """Filled > empty beyond the bow's first contact with the granules: the work at equal
    penetration (the force itself crosses where the two hulls tear a fraction of a millimetre
    apart), and the force where the empty bow touches nothing (the bed alone resists)."""
    if not filled.has("granules.bow.force_z"):
        note("filled: no column granules.bow.force_z (filled_minus_empty keys skipped)")
        return
    touched = np.nonzero(filled.at("granules.bow.force_z") != 0)[0]
    if not len(touched):
        note("filled: the granules never touch the bow (filled_minus_empty keys skipped)")
        return
    p_c = float(filled.pen[touched[0]])
    key("granule_contact_penetration_m", p_c)
    wf, we = filled.work(), empty.work()
    if wf is None or we is None:
        note("a run has no bow work column (filled_minus_empty_work_min_J skipped)")
        return
    end = min(filled.pen[-1], empty.pen[-1])
    sel = (filled.pen >= p_c) & (filled.pen <= end)
    if not sel.any():
        note("no common penetration beyond the granules' first contact (filled_minus_empty skipped)")
        return
    pe_u, k = np.unique(empty.pen, return_index=True)
    key("filled_minus_empty_work_min_J", float(np.min(wf[sel] - np.interp(filled.pen[sel], pe_u, we[k]))))
    # where the empty bow touches nothing after its first contact (the outer plate's petals have let
    # it go): its force is zero, the filled bow's is the bed's (smoothed over 4 % of the travel)
    window = 0.04 * end
    pf, ff = filled.smoothed_force(window)
    pe_s, fe = empty.smoothed_force(window)
    free = fe == 0
    if not free.any():
        note("the empty bow touches the hull all the way (filled_force_where_empty_free_min_N skipped)")
        return
    p_free = pe_s[free]
    lo, hi = float(p_free.min()), float(p_free.max())
    inside = (pf >= lo) & (pf <= hi)
    inside &= np.interp(pf, pe_s, free.astype(float)) == 1.0
    if not inside.any():
        note("no filled row where the empty bow is free (filled_force_where_empty_free_min_N skipped)")
        return
    key("filled_force_where_empty_free_min_N", float(np.min(ff[inside])))
    key("empty_free_from_m", lo)


def granule_items(run):
    """(area, upward force) of the inner plate's cavity faces from the granules' mesh or interface
    files at the last output frame, and the files' name; ([], None) without them."""
    faces = []
    for c in CELLS + ["cavity_inner"]:
        for name in (f"granules_{c}", f"granules_interface_{c}"):
            frames = pvd_frames(run.folder, name)
            if not frames:
                continue
            pts, cells, data = read_vtk(frames[-1][1])
            if "force" not in data or not cells:
                continue
            force = data["force"]
            tri = [np.asarray(cl) for cl in cells if len(cl) >= 3]
            per_cell = len(force) == len(cells) and "force" in data["_cell_arrays"]
            if not per_cell and len(force) != len(pts):
                continue
            top = []
            for i, cl in enumerate(tri):
                p = pts[cl]
                n = np.cross(p[1] - p[0], p[2] - p[0])
                a = 0.5 * np.linalg.norm(n)
                if a <= 0 or abs(n[2]) < 0.7 * 2 * a or p[:, 2].mean() < 0.042:
                    continue
                top.append((i, cl, a))
            if per_cell:
                for i, cl, a in top:
                    faces.append((a, force[i, 2]))
            else:   # nodal forces: each node stands for a third of its top triangles' area
                area_n = np.zeros(len(pts))
                for _, cl, a in top:
                    area_n[cl] += a / len(cl)
                for v in np.nonzero(area_n > 0)[0]:
                    faces.append((area_n[v], force[v, 2]))
            source = name if c in PARTS else name.rsplit("_", 1)[0] + "_cXX"
            break
    return faces, (source if faces else None)


def bow_items(run):
    """(area, upward force) of the inner plate's cavity-facing nodes from the bow's own contact
    forces (the hull's point array contact_force, at the last output frame): each node stands for
    a quarter of the reference areas of the inner plate's element faces it is a corner of. None
    when the files have no contact_force (runs written without that array)."""
    frames = pvd_frames(run.folder, "hull_fem")
    if not frames:
        return None
    pts, cells, data = read_vtk(frames[-1][1])
    if "contact_force" not in data or "region" not in data or "displacement" not in data:
        return None
    ref = pts - data["displacement"]
    region = data["region"].reshape(-1)
    area = np.zeros(len(pts))
    for cl, r in zip(cells, region):
        if int(r) != 1 or len(cl) != 8:   # the inner plate's hexahedra
            continue
        cl = np.asarray(cl)
        z = ref[cl, 2]
        low = cl[np.argsort(z)[:4]]        # the cavity-facing (lower) face
        p = ref[low]
        c = p.mean(axis=0)
        ang = np.arctan2(p[:, 1] - c[1], p[:, 0] - c[0])
        q = p[np.argsort(ang)]
        a = 0.5 * np.linalg.norm(np.cross(q[2] - q[0], q[3] - q[1]))
        area[low] += a / 4
    fz = data["contact_force"][:, 2]
    return [(area[v], fz[v]) for v in np.nonzero(area > 0)[0]]


def footprint(run, suffix=""):
    """The smallest area of the inner plate's cavity faces carrying 90 % of the upward force on
    them (the granules' and the bow's own contact), at the last output frame."""
    faces, source = granule_items(run)
    cavity_area = sum(x for x, _ in faces)
    bow = bow_items(run)
    bow_up = float(np.clip([f for _, f in bow], 0, None).sum()) if bow else 0.0
    if bow is not None:
        key("inner_plate_bow_force" + suffix + "_N", bow_up)
    if bow_up > 0:
        faces = faces + bow
    if not faces:
        note(f"{run.label}: no granules' mesh or interface files (vtk/granules_cXX.pvd or "
             "vtk/granules_interface_cXX.pvd) with forces and no bow contact on the inner plate "
             "(footprint_area_90 skipped)")
        return
    a, f = np.array(faces).T
    up = np.clip(f, 0, None)
    if up.sum() <= 0:
        note(f"{run.label}: no upward force on the inner plate (footprint_area_90 skipped)")
        return
    order = np.argsort(-up / a)
    carried = np.cumsum(up[order])
    n = int(np.searchsorted(carried, 0.9 * carried[-1])) + 1
    key("footprint_area_90" + suffix, float(a[order][:n].sum()))
    if source:
        key("footprint_fraction_90" + suffix, float(a[order][:n].sum() / cavity_area))
        key("inner_plate_granule_force" + suffix + "_N", float(up.sum() - bow_up))
    note(f"{run.label}: footprint from " + " and ".join(x for x in (source, bow_up > 0 and "the bow's contact_force") if x) + " (last frame)")


# ---------------------------------------------------------------------------------------- plots
def plot_force(runs, outdir, plt):
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for run, color in zip(runs, ("C0", "C3")):
        if len(run.t) <= run.contact or not run.has("hull.bow.force_z"):
            continue
        p, f = run.pen[run.contact:], run.force()[run.contact:]
        ax.plot(1e3 * p, 1e-3 * f, color=color, alpha=0.25, lw=0.5)
        ps, fs = run.smoothed_force(0.04 * run.pen[-1])
        ax.plot(1e3 * ps, 1e-3 * fs, color=color, lw=1.8, label=f"{run.label} (4 % window mean)")
        rup = run.first_rupture()
        if rup:
            fr = np.interp(rup[1], ps, fs)
            ax.plot(1e3 * rup[1], 1e-3 * fr, "v", color=color, ms=10, mec="k",
                    label=f"{run.label}: first rupture, {1e3 * rup[0]:.2f} ms")
    ax.set_xlabel("penetration [mm]")
    ax.set_ylabel("indenter force [kN]")
    ax.set_title("bow force over penetration (thin: raw output rows, clipped)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    top = max((np.max(r.smoothed_force(0.04 * r.pen[-1])[1]) for r in runs if len(r.t) > r.contact + 10), default=None)
    if top and top > 0:
        ax.set_ylim(0, 2.0e-3 * top)   # the raw chatter goes off scale
    save(fig, outdir, "force_penetration.png")


NICE = {"hull.strain_energy": "hull elastic (strain, bow contact springs)", "hull.kinetic_energy": "hull kinetic",
        "hull.enhanced_strain_work": "hull enhanced strain (reduced Hex8)", "hull.bow.kinetic_energy": "bow kinetic", "granules.kinetic_energy": "granules kinetic",
        "granules.elastic_energy": "granules contact (elastic)", "hull.eroded_energy": "eroded elements",
        "granules.friction_work": "granules friction",
        "granules.damping_work": "granules damping", "granules.stiffening_work": "granules stiffening",
        "granules.breakage_energy": "granules breakage"}


def energy_terms(run):
    """[(label, values)] of every stored and dissipated term, the hull's plastic work split by part."""
    terms = []
    parts = [f"hull.{p}.plastic_work" for p in ("outer_plate", "inner_plate", "webs")]
    for name, kind in run.kind.items():
        if kind == "input":
            continue
        if name == "hull.plastic_work" and run.has(*parts):
            split = [run.at(p) for p in parts]
            for p, v in zip(("outer plate", "inner plate", "webs"), split):
                terms.append((f"plastic work {p}", v))
            rest = run.at(name) - sum(split)
            if np.max(np.abs(rest)) > 0.01 * max(np.max(np.abs(run.at(name))), 1e-12):
                terms.append(("plastic work (other)", rest))
            continue
        terms.append((NICE.get(name, name), run.at(name)))
    if run.has("coupling created"):
        terms.append(("coupling created", run.at("coupling created")))
    order = ["plastic work", "hull elastic", "granules friction", "granules damping", "granules breakage",
             "granules contact", "granules kinetic", "hull kinetic", "bow contact"]
    rank = lambda label: next((k for k, o in enumerate(order) if label.startswith(o)), len(order))
    return sorted(terms, key=lambda lv: rank(lv[0]))   # stable: the plates keep their order


COLOURS = {}
BANDS = 6   # stacked bands a reader tells apart: the largest terms, the rest summed in one


def bands(terms):
    """The largest BANDS - 1 terms (by their final value) in their order, and the others summed
    as one band named after them."""
    big = sorted(range(len(terms)), key=lambda k: -abs(float(terms[k][1][-1])))
    keep = sorted(big[:BANDS - 1]) if len(terms) > BANDS else list(range(len(terms)))
    out = [terms[k] for k in keep]
    rest = [terms[k] for k in range(len(terms)) if k not in keep]
    if rest:
        names = ", ".join(l for l, _ in rest)
        out.append((f"{len(rest)} smaller terms:\n" + "\n".join(textwrap.wrap(names, 50)),
                    sum(v for _, v in rest)))
    return out


def color_of(label, cmap):
    """The same colour for a term in every panel."""
    return COLOURS.setdefault(label, cmap(len(COLOURS) % 20))


def plot_energy(runs, outdir, plt):
    runs = [r for r in runs if r.kind and len(r.t) > r.contact]
    if not runs:
        note("no energy.csv with rows after contact (energy.png skipped)")
        return
    fig, axes = plt.subplots(1, len(runs), figsize=(7.5 * len(runs), 7.4), squeeze=False)
    cmap = plt.get_cmap("tab20")
    for ax, run in zip(axes[0], runs):
        s = slice(run.contact, None)
        p = 1e3 * run.pen[s]
        terms = [(l, v[s]) for l, v in energy_terms(run)]
        shown = bands(terms)
        ax.stackplot(p, *[v for _, v in shown], labels=[l for l, _ in shown],
                     colors=[color_of(l, cmap) for l, _ in shown], alpha=0.85)
        ax.plot(p, sum(v for _, v in terms), "k-", lw=1.5, label="sum of the terms")
        w = run.work()
        if w is not None:
            ax.plot(p, w[s], "k--", lw=1.5, label="indenter work (hull + granules)")
        if run.has("inputs", "initial"):
            ax.plot(p, run.at("inputs")[s] + run.at("initial")[s], ":", color="0.3", lw=1.2,
                    label="all inputs + initial energy")
        ax.set_xlabel("penetration [mm]")
        ax.set_ylabel("energy [J]")
        ax.set_title(f"{run.label}: energy absorbed (cumulative from t = 0)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2)  # below
        if run.has("energy balance error"):
            ax2 = ax.twinx()
            err = 100 * run.at("energy balance error")[s]
            ax2.plot(p, err, color="m", lw=0.8)
            lim = min(20.0, max(3.0, 1.3 * float(np.percentile(np.abs(err), 99))))
            ax2.set_ylim(-lim, lim)
            off = np.abs(err) > lim
            if off.any():
                k = int(np.argmax(np.abs(err)))
                ax2.annotate(f"off scale: {err[k]:+.1f} % at {p[k]:.2f} mm ({int(off.sum())} rows)",
                             xy=(0.99, 0.02), xycoords="axes fraction", ha="right", color="m", fontsize=8)
            ax2.set_ylabel("energy balance error [%]", color="m")
            ax2.axhline(2, color="m", ls=":", lw=0.6)
            ax2.axhline(-2, color="m", ls=":", lw=0.6)
            ax2.tick_params(axis="y", colors="m")
    save(fig, outdir, "energy.png")


def plot_deflection(runs, outdir, plt):
    fig, ax = plt.subplots(figsize=(7, 4.5))
    drawn = False
    for run, color in zip(runs, ("C0", "C3")):
        d = run.get("hull.inner_centre.displacement_z", "inner_deflection.png")
        if d is None:
            continue
        ax.plot(1e3 * run.pen, 1e3 * d, color=color, label=run.label)
        drawn = True
    if not drawn:
        plt.close(fig)
        return
    ax.set_xlabel("penetration [mm]")
    ax.set_ylabel("inner plate centre displacement z [mm]")
    ax.set_title("inner hull deflection over penetration")
    ax.grid(alpha=0.3)
    ax.legend()
    save(fig, outdir, "inner_deflection.png")


def hull_section(path):
    """Quads (deformed x-z corner lists) of the hull's elements cut by y = SECTION_Y and their
    equivalent plastic strain (None if absent); eroded (failed) elements are left out."""
    pts, cells, data = read_vtk(path)
    cur = pts + data["displacement"] if "displacement" in data else pts   # Points are the reference
    peeq = data["equivalent_plastic_strain"][:, 0] if "equivalent_plastic_strain" in data else None
    failed = data["failed"][:, 0] if "failed" in data and "failed" in data["_cell_arrays"] else None
    edges = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)]
    quads, values = [], []
    for i, cl in enumerate(cells):
        if len(cl) != 8 or (failed is not None and failed[i] > 0):
            continue
        y = pts[cl, 1]
        if y.min() > SECTION_Y or y.max() <= SECTION_Y:
            continue
        cut = []
        for a, b in edges:
            ya, yb = y[a] - SECTION_Y, y[b] - SECTION_Y
            if ya > yb:
                a, b, ya, yb = b, a, yb, ya
            if ya <= 0 < yb:   # half-open: a face lying in the plane belongs to the element above
                s = -ya / (yb - ya)
                cut.append(cur[cl[a]] + s * (cur[cl[b]] - cur[cl[a]]))
        if len(cut) < 3:
            continue
        xz = np.array(cut)[:, [0, 2]]
        c = xz.mean(axis=0)
        xz = xz[np.argsort(np.arctan2(xz[:, 1] - c[1], xz[:, 0] - c[0]))]
        quads.append(1e3 * xz)
        values.append(peeq[i] if peeq is not None else 0.0)
    return quads, (np.array(values) if peeq is not None else None)


def plot_sections(run, outdir, plt, prefix):
    hull = pvd_frames(run.folder, "hull_fem")
    if not hull:
        note(f"{run.label}: no vtk/hull_fem.pvd ({prefix}_<k>.png skipped)")
        return
    if len(run.t) <= run.contact:
        note(f"{run.label}: no contact yet ({prefix}_<k>.png skipped)")
        return
    final = run.pen[-1]
    frame_pen = [float(np.interp(t, run.t, run.pen)) for t, _ in hull]
    chosen = []
    for frac in (1 / 3, 2 / 3, 1.0):
        k = int(np.argmin([abs(p - frac * final) for p in frame_pen]))
        if k not in chosen:
            chosen.append(k)
    granule_frames = dict(pvd_frames(run.folder, "granules_particles"))
    from matplotlib.collections import PatchCollection, PolyCollection
    from matplotlib.patches import Circle
    for n, k in enumerate(chosen, 1):
        t, path = hull[k]
        fig, ax = plt.subplots(figsize=(10, 6.2))
        quads, peeq = hull_section(path)
        pc = PolyCollection(quads, edgecolors="k", linewidths=0.3)
        if peeq is not None:
            pc.set_array(peeq)
            pc.set_cmap("plasma")
            pc.set_clim(0, max(0.02, float(peeq.max()) if len(peeq) else 0.02))
        else:
            pc.set_facecolor("0.6")
        ax.add_collection(pc)
        if peeq is not None:
            fig.colorbar(pc, ax=ax, fraction=0.04, pad=0.02, label="equivalent plastic strain (hull)")
        gpath = granule_frames.get(t)
        count = None
        if gpath:
            pts, _, data = read_vtk(gpath)
            if "radius" in data:
                r = data["radius"][:, 0]
                dy = np.abs(pts[:, 1] - SECTION_Y)
                cut = dy < r
                rc = np.sqrt(r[cut] ** 2 - dy[cut] ** 2)
                speed = np.linalg.norm(data["velocity"][cut], axis=1) if "velocity" in data else np.zeros(cut.sum())
                circles = [Circle((1e3 * x, 1e3 * z), 1e3 * rr) for (x, _, z), rr in zip(pts[cut], rc)]
                gc = PatchCollection(circles, cmap="viridis", edgecolors="k", linewidths=0.2, alpha=0.9)
                gc.set_array(speed)
                ax.add_collection(gc)
                fig.colorbar(gc, ax=ax, orientation="horizontal", fraction=0.05, pad=0.13, aspect=50,
                             label="granule speed [m/s] (circles: the spheres cut by the plane)")
                count = int(cut.sum())
        if run.has("hull.bow.z"):
            zc = float(run.at("hull.bow.z", t))
            ang = np.linspace(0, np.pi, 60)
            half = bow_length(run.folder) / 2
            xs = np.concatenate([SECTION_Y + BOW_RADIUS * np.cos(ang), SECTION_Y - BOW_RADIUS * np.cos(ang)])
            zs = np.concatenate([zc + half + BOW_RADIUS * np.sin(ang), zc - half - BOW_RADIUS * np.sin(ang)])
            xs, zs = np.append(xs, xs[0]), np.append(zs, zs[0])
            ax.fill(1e3 * xs, 1e3 * zs, facecolor="0.85", edgecolor="k", lw=1.2, zorder=0)
        p = float(np.interp(t, run.t, run.pen))
        ax.set_title(f"{run.label}: section y = {1e3 * SECTION_Y:.0f} mm at t = {1e3 * t:.1f} ms, "
                     f"penetration {1e3 * p:.1f} mm" + (f" ({count} granules cut)" if count is not None else ""),
                     fontsize=10)
        ax.set_xlim(-5, 367)
        ax.set_ylim(-95, 110)
        ax.set_aspect("equal")
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("z [mm]")
        save(fig, outdir, f"{prefix}_{n}.png")


def bow_length(folder):
    """The capsule's cylinder length from the bow's surface mesh (vtk/hull_bow_000000.vtp: its
    extent along z less the two hemispheres), BOW_LENGTH when the file is missing."""
    path = os.path.join(folder, "vtk", "hull_bow_000000.vtp")
    if not os.path.exists(path):
        return BOW_LENGTH
    pts, _, _ = read_vtk(path)
    return max(0.0, float(pts[:, 2].max() - pts[:, 2].min()) - 2 * BOW_RADIUS)


def save(fig, outdir, name):
    fig.tight_layout()
    path = os.path.join(outdir, name)
    fig.savefig(path, dpi=120)
    import matplotlib.pyplot as plt
    plt.close(fig)
    note(f"wrote {path}")


def guarded(what, f, *args):
    try:
        f(*args)
    except Exception as e:   # one broken item must not stop the others
        note(f"{what} skipped: {type(e).__name__}: {e}")


def main():
    args, outdir, driven_dir, rate_dirs = [], None, None, []
    argv = sys.argv[1:]
    while argv:
        a = argv.pop(0)
        if a == "--out" and argv:
            outdir = argv.pop(0)
        elif a == "--driven" and argv:
            driven_dir = argv.pop(0)
        elif a == "--rate" and argv:
            rate_dirs.append(argv.pop(0))
        elif a in ("-h", "--help") or a.startswith("--"):
            sys.exit(__doc__)
        else:
            args.append(a)
    if not 1 <= len(args) <= 2:
        sys.exit(__doc__)
    runs = []
    for folder, label in zip(args, ("filled", "empty")):
        try:
            runs.append(Run(folder, label))
        except (RuntimeError, OSError) as e:
            sys.exit(f"plot_case: {e}")
    filled = runs[0]
    empty = runs[1] if len(runs) > 1 else None
    driven = None
    if driven_dir:
        try:
            driven = Run(driven_dir, "driven")
        except (RuntimeError, OSError) as e:
            sys.exit(f"plot_case: --driven: {e}")
    outdir = outdir or args[0]
    os.makedirs(outdir, exist_ok=True)

    guarded("weight_balance", weight_balance, filled)
    for run, suffix in ((filled, ""), (empty, "_empty")):
        if run is None:
            continue
        guarded("max_abs_energy_error" + suffix, energy_error, run, suffix)
        guarded("quasi_static_ke_ratio" + suffix, ke_ratio, run, suffix)
    for run in runs:
        guarded(f"forces and milestones ({run.label})", milestones, run, "_" + run.label)
    if empty:
        guarded("filled_over_empty_min", filled_over_empty, filled, empty)
        guarded("filled_minus_empty keys", filled_against_empty, filled, empty)
    guarded("collision keys", collision, filled, driven)
    if filled.has("granules.breakage.events"):
        key("broken_granules", float(filled.at("granules.breakage.events")[-1]), "{:.0f}")
    else:
        note("filled: no column granules.breakage.events (broken_granules skipped)")
    guarded("footprint_area_90", footprint, filled)
    if empty:
        guarded("footprint_area_90_empty", footprint, empty, "_empty")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    if rate_dirs:
        others = []
        for d in rate_dirs:
            try:
                others.append(Run(d, f"other speed ({d})"))
            except (RuntimeError, OSError) as e:
                sys.exit(f"plot_case: --rate: {e}")
        guarded("rate keys", rate_compare, filled, others, outdir, plt)
    guarded("force_penetration.png", plot_force, runs, outdir, plt)
    guarded("energy.png", plot_energy, runs, outdir, plt)
    guarded("inner_deflection.png", plot_deflection, runs, outdir, plt)
    guarded("section_<k>.png", plot_sections, filled, outdir, plt, "section")
    if empty:
        guarded("section_empty_<k>.png", plot_sections, empty, outdir, plt, "section_empty")


if __name__ == "__main__":
    main()
