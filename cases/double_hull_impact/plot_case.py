#!/usr/bin/python3
"""The figures and headline numbers of a double-hull impact run (double_hull_impact.yaml,
coarse.yaml, section.yaml with any cells, web_spacing, thicknesses or bow), filled with granules
and, optionally, against the empty hull (empty.yaml, coarse_empty.yaml); or of an ensemble of
packings against the empty hull.

Usage: plot_case.py FILLED_DIR [EMPTY_DIR] [--out DIR] [--driven DIR] [--rate OTHER_DIR ...]
                    [--case CASE.yaml [--set KEY=VALUE ...]] [--at MM,MM,...]
       plot_case.py --ensemble FILLED_DIR FILLED_DIR ... [--empty EMPTY_DIR ...] [--out DIR]
                    [--at MM,MM,...]
  FILLED_DIR, EMPTY_DIR: the runs' output folders (bow.csv, parts.csv, granules.csv, energy.csv,
  vtk/); PNGs go to DIR (default FILLED_DIR). --driven DIR: for a collision run (a free bow,
  collision.yaml), the driven run of the same hull it is compared with (the collision_* keys). The case test calls it as `plot_case.py OUT` with the
  filled run alone (checks.yaml: {script: plot_case.py, key: ...}). --rate OTHER_DIR: the same
  case with the bow at another speed (the quasi-static check: the rate_* keys, rate_force.png);
  repeated, each further run at yet another speed (keys rate2_*, rate3_*, ..., one figure).
  --case CASE.yaml (with the run's --set values): the case the run was made from, for what its
  output does not hold: the granules' gravity (the section's orientation in the pictures, the
  weight's axis) and comminution limit (the fragments below it); without it gravity is -z.
  --at: the penetrations [mm] of the pictures (sections, deflection maps) or of the ensemble's
  energy shares, instead of 1/3, 2/3, 1 (25, 50, 75, 100 % for the ensemble) of the final one.

The geometry is read from the run's VTK output (hull_geometry.py): the plates, webs and footprint
from vtk/hull_fem's first frame (its region array), the bow's axis, radius, length and position
from vtk/hull_bow; nothing is tied to one section.

Writes force_penetration.png, energy.png, inner_deflection.png (the inner plate's centre over
penetration), and from the VTK output (hull_pictures.py): section_<k>.png (k = 1, 2, 3: the output
frames nearest 1/3, 2/3 and all of the final penetration, or --at: the section through the bow's
axis, upright with gravity along the plates, with the deformed plates coloured by plastic strain,
the eroded elements cut by it, the bow, the granules coloured intact / fragment / fragment below
the comminution limit), inner_deflection_map.png (the inner plate's displacement along the bow's
travel in plan at the same frames), rupture_pattern.png (both plates' plastic strain and eroded
elements in plan at the last frame, and the crushed zone: the fragments in plan); the same with
_empty for EMPTY_DIR (section_empty_<k>.png, ...). It prints key=value lines (SI units):
  weight_balance          -(sum of granules.cXX.force_z, or of section.yaml's granules.cavity_outer,
                          _inner, _webs.force_z) / (granules.mass g) (with --case: the force
                          along the case's gravity, e.g. force_y for an upright section with
                          gravity along -y, over |g|), averaged over the rows
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
                          the inner plate's first failed element: the first row where
                          hull.inner_plate.first_failure_time is set, or (runs without that
                          column) whose hull.failed_elements rises while
                          hull.inner_plate.plastic_work falls (an eroded element's plastic work
                          leaves its part's sum); outer_rupture_*, webs_rupture_*,
                          energy_to_{outer,webs}_rupture_*: the same for the outer plate and the
                          webs (the hull's first failure, rupture_*, is any part's)
  powder_events, powder_mass_kg   granules.breakage.powder_* at the last row (below_limit: powder)
  energy_final_{filled,empty}_J   indenter work at the last row
  inner_deflection_final_{filled,empty}_m   hull.inner_centre.displacement_z at the last row
  broken_granules         granules.breakage.events at the last row
  footprint_area_90[_empty] [m^2] the smallest area of the inner plate's cavity faces (the cells' faces
                          on the inner plate's side of mid-depth, facing the outer plate) carrying
                          90 % of the force on them pushing the inner plate outwards, at
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
With --ensemble (hull_ensemble.py; the runs interpolated on a common penetration grid up to the
smallest final penetration of them all; spread: figures show the mean and the min-max band, keys
give mean, sample standard deviation (ddof 1), min and max) it writes ensemble_curves.png (the
bow's force, the inner plate's force d(energy)/d(penetration) with the bed's load on it where
granules.cavity_inner.force_z exists, the inner plate's absorbed energy (plastic + elastic), each
filled against empty, the outer plate's rupture marked; with empty runs the bow's work filled less
the empty mean), energy_shares.png and energy_shares.csv
(outer plate, inner plate, webs, eroded elements, granules' friction, damping, crushing and the
rest of the audit's stored + dissipated energy, at the --at penetrations; the CSV: penetration
[mm], variant, term, mean/std/min/max [J], share of the total [%], runs) and prints:
  ensemble_runs_{filled,empty}, ensemble_common_penetration_m
  ensemble_energy_to_rupture_<variant>_{mean,std,min,max}_J (the hull's first failure, any
                          part), ensemble_rupture_penetration_<variant>_{mean,std,min,max}_m,
                          ensemble_energy_to_{outer,webs,inner}_rupture_<variant>_{...}_J (each
                          part's first failure, part_rupture_row),
                          ensemble_{outer,webs}_rupture_penetration_<variant>_{...}_m,
                          ensemble_inner_rupture_penetration_<variant>_{...}_m, each with
                          _<variant>_runs (how many runs reached it);
                          ensemble_inner_plate_energy_at_rupture_<variant>_{...}_J: the inner
                          plate's energy when the outer plate ruptures (before it / after it: the
                          ensemble_inner_plate_energy_* keys below less this)
  ensemble_<q>_<at>_<variant>_{mean,std}_<unit>   q: inner_plate_energy [J], inner_plate_force [N]
                          (d(inner plate energy)/d(penetration): its share of the bow's force),
                          work [J] (the bow's), bed_on_inner_plate [N]; at: 25pct, 50pct, 75pct,
                          100pct of the common penetration, or <mm>mm for --at (a dot as p)
  ensemble_energy_to_rupture_filled_minus_empty_J, _filled_over_empty (and the same for
                          energy_to_inner_rupture): the filled mean less (over) the empty mean
  ensemble_work_filled_minus_empty_final_J, ensemble_work_filled_spread_final_J   the mean
                          filled work less the mean empty one at the common penetration, and the
                          filled runs' range there
A missing file or column skips its item with a note on stderr (plot_case: ...), never a traceback."""
import csv
import os
import re
import sys
import textwrap

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from python_modules import require  # noqa: E402  (cases/python_modules.py: the missing-module check)

require("numpy", "matplotlib")
import numpy as np  # noqa: E402
import hull_pictures as pictures  # noqa: E402  (the pictures from the VTK output)
from hull_geometry import Geometry, pvd_frames, read_vtk  # noqa: E402  (the geometry read from the run)

G = 9.81
CELL_FORCE = re.compile(r"granules\.(c\d+)\.force_z$")   # double_hull_impact.yaml's cell interfaces cXY
PARTS = ["cavity_outer", "cavity_inner", "cavity_webs"]   # section.yaml's interfaces, by part
CASE = {"file": None, "sets": []}   # --case FILE and its --set values


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
        self._geometry = False   # not read yet
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

    def geometry(self):
        """The hull's and the bow's geometry from the run's VTK output (hull_geometry.Geometry,
        with the case file of --case for gravity and the comminution limit), None with a note
        when the files are missing."""
        if self._geometry is False:
            try:
                self._geometry = Geometry.of_run(self.folder, CASE["file"], CASE["sets"])
                note(f"{self.label}: {self._geometry.describe()}")
            except (RuntimeError, OSError, KeyError, ValueError) as e:
                note(f"{self.label}: the geometry not read ({e})")
                self._geometry = None
        return self._geometry

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


# ------------------------------------------------------------------------------------- numbers
def weight_balance(run):
    # along gravity (the case's, with --case; else -z): sign * force / (m g) is the share of the
    # weight that a force carries
    geom = run.geometry()
    g_vec = geom.gravity if geom is not None and geom.gravity is not None else np.array([0.0, 0.0, -G])
    g_axis = int(np.argmax(np.abs(g_vec)))
    ga, sign, g_abs = "xyz"[g_axis], -float(np.sign(g_vec[g_axis])), float(np.linalg.norm(g_vec))
    cols = sorted(c for c in run.cols if CELL_FORCE.match(c))
    if ga != "z" or not cols:   # the cavity's faces by part (section.yaml)
        cols = [f"granules.{c}.force_{ga}" for c in PARTS]
    if not run.has(*cols, "granules.mass"):
        note(f"{run.label}: granules.cXX.force_z (or granules.cavity_*.force_{ga}) or granules.mass "
             "missing (weight_balance skipped)")
        return
    fz = sign * sum(run.at(c) for c in cols)
    rows = np.nonzero((run.pen <= 0) & (run.t > 0.002))[0]
    if not len(rows):
        note(f"{run.label}: no rows between 2 ms and first contact (weight_balance skipped)")
        return
    weight = run.at("granules.mass")[rows] * g_abs
    key("weight_balance", float(np.mean(-fz[rows]) / np.mean(weight)))
    hull_cols = [f"hull.{c}.force_{ga}" for c in PARTS]
    if run.has(*hull_cols):
        # the same weight as the hull received it: the parts' interfaces share the nodes where a
        # web meets a plate, and their forces add there
        hz = sign * sum(run.at(c) for c in hull_cols)
        key("hull_weight_balance", float(np.mean(-hz[rows]) / np.mean(weight)))
    if run.has("granules.cavity_inner.force_z"):
        # what the bed presses on the inner plate before the strike (the granules' force on the
        # mesh; +z: the plate pushed away from the cavity)
        key("bed_on_inner_plate_N", float(np.mean(run.at("granules.cavity_inner.force_z")[rows])))
    last = rows[len(rows) - max(1, len(rows) // 5):]
    key("weight_balance_last", float(np.mean(-fz[last]) / np.mean(run.at("granules.mass")[last] * g_abs)))
    # the impulse balance over the same rows (a bed that rings is not at rest, so the cells' force
    # is its weight plus the rate of its momentum): (integral of the hull's and the bow's force on
    # the granules - the change of their momentum) / integral of m g
    if not run.has(f"granules.momentum_{ga}"):
        note(f"{run.label}: no column granules.momentum_{ga} (weight_balance_impulse skipped)")
        return
    if len(rows) < 2:
        return
    on_bed = fz[rows]
    if run.has(f"granules.bow.force_{ga}"):
        on_bed = on_bed + sign * run.at(f"granules.bow.force_{ga}")[rows]
    t = run.t[rows]
    trap = lambda y: float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(t)))
    p = sign * run.at(f"granules.momentum_{ga}")[rows]
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
        k = inner_rupture_row(run)
        if k is None:
            note(f"{run.label}: no element of the inner plate has failed")
        else:
            key("inner_rupture_time" + suffix + "_s", float(run.t[k]))
            key("inner_rupture_penetration" + suffix + "_m", float(run.pen[k]))
            if w is not None:
                key("energy_to_inner_rupture" + suffix + "_J", float(w[k]))
    for part, tag in (("outer_plate", "outer"), ("webs", "webs")):
        k = part_rupture_row(run, part)
        if k is not None:
            key(f"{tag}_rupture_penetration{suffix}_m", float(run.pen[k]))
            if w is not None:
                key(f"energy_to_{tag}_rupture{suffix}_J", float(w[k]))
    if run.has("granules.breakage.powder_events"):
        key("powder_events", float(run.at("granules.breakage.powder_events")[-1]))
    if run.has("granules.breakage.powder_mass"):
        key("powder_mass_kg", float(run.at("granules.breakage.powder_mass")[-1]))
    if w is not None:
        key("energy_final" + suffix + "_J", float(w[-1]))
    if run.has("hull.inner_centre.displacement_z"):
        key("inner_deflection_final" + suffix + "_m", float(run.at("hull.inner_centre.displacement_z")[-1]))


def part_rupture_row(run, part):
    """The row of a part's (outer_plate, webs, inner_plate) first failed element, None before it
    (or without the columns): the first row where hull.<part>.first_failure_time is set when the
    run records it; else, for an eroding hull, the first row whose hull.failed_elements rises while
    hull.<part>.plastic_work falls (an eroded element's plastic work leaves its part's sum, which
    otherwise never falls)."""
    if run.has(f"hull.{part}.first_failure_time"):
        hit = np.nonzero(run.at(f"hull.{part}.first_failure_time") >= 0)[0]
        return int(hit[0]) if len(hit) else None
    if not run.has(f"hull.{part}.plastic_work", "hull.failed_elements"):
        return None
    pw, failed = run.at(f"hull.{part}.plastic_work"), run.at("hull.failed_elements")
    hit = np.nonzero((np.diff(failed) > 0) & (np.diff(pw) < 0))[0]
    return int(hit[0] + 1) if len(hit) else None


def inner_rupture_row(run):
    """The row of the inner plate's first failed element (part_rupture_row)."""
    return part_rupture_row(run, "inner_plate")


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
    faces, source = [], None
    geom = run.geometry()
    if geom is None:
        return faces, source
    ax, up = geom.normal_axis, geom.inner_faces_up
    mid = 0.5 * sum(geom.cavity)
    vtk_dir = os.path.join(run.folder, "vtk")
    cell_names = sorted(m.group(1) for m in map(re.compile(r"granules_(c\d+)\.pvd$").match,
                                                 os.listdir(vtk_dir) if os.path.isdir(vtk_dir) else []) if m)
    for c in cell_names + ["cavity_inner"]:
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
                if a <= 0 or abs(n[ax]) < 0.7 * 2 * a or up * (p[:, ax].mean() - mid) < 0:
                    continue
                top.append((i, cl, a))
            if per_cell:
                for i, cl, a in top:
                    faces.append((a, up * force[i, ax]))
            else:   # nodal forces: each node stands for a third of its top triangles' area
                area_n = np.zeros(len(pts))
                for _, cl, a in top:
                    area_n[cl] += a / len(cl)
                for v in np.nonzero(area_n > 0)[0]:
                    faces.append((area_n[v], up * force[v, ax]))
            source = name if c in PARTS else name.rsplit("_", 1)[0] + "_cXX"
            break
    return faces, (source if faces else None)


def bow_items(run):
    """(area, upward force) of the inner plate's cavity-facing nodes from the bow's own contact
    forces (the hull's point array contact_force, at the last output frame): each node stands for
    a quarter of the reference areas of the inner plate's element faces it is a corner of. None
    when the files have no contact_force (runs written without that array)."""
    frames = pvd_frames(run.folder, "hull_fem")
    geom = run.geometry()
    if not frames or geom is None:
        return None
    ax, up = geom.normal_axis, geom.inner_faces_up
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
        z = up * ref[cl, ax]
        low = cl[np.argsort(z)[:4]]        # the cavity-facing face
        p = ref[low]
        c = p.mean(axis=0)
        a1, a2 = geom.in_plane_axes
        ang = np.arctan2(p[:, a2] - c[a2], p[:, a1] - c[a1])
        q = p[np.argsort(ang)]
        a = 0.5 * np.linalg.norm(np.cross(q[2] - q[0], q[3] - q[1]))
        area[low] += a / 4
    fz = up * data["contact_force"][:, ax]
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


def plot_sections(run, outdir, plt, prefix, at_mm=None):
    """section_<k>.png (the section through the bow's axis, hull_pictures.plot_section) at the
    output frames nearest 1/3, 2/3 and all of the final penetration, or nearest each of at_mm;
    with them, for the filled run, inner_deflection_map.png at the same frames and
    rupture_pattern.png at the last."""
    geom = run.geometry()
    hull = pvd_frames(run.folder, "hull_fem")
    if geom is None or not hull:
        note(f"{run.label}: no vtk/hull_fem.pvd ({prefix}_<k>.png skipped)")
        return
    if len(run.t) <= run.contact:
        note(f"{run.label}: no contact yet ({prefix}_<k>.png skipped)")
        return
    targets = [1e-3 * p for p in at_mm] if at_mm else [f * run.pen[-1] for f in (1 / 3, 2 / 3, 1.0)]
    chosen, frame_pen = pictures.frames_at(run, hull, targets)
    for n, k in enumerate(chosen, 1):
        path = os.path.join(outdir, f"{prefix}_{n}.png")
        pictures.plot_section(run, geom, hull[k], path, plt)
        note(f"wrote {path}")
    suffix = prefix[len("section"):]
    path = os.path.join(outdir, f"inner_deflection_map{suffix}.png")
    guarded(path, pictures.plot_deflection_maps, run, geom, chosen, hull, frame_pen, path, plt)
    note(f"wrote {path}")
    path = os.path.join(outdir, f"rupture_pattern{suffix}.png")
    guarded(path, pictures.plot_rupture_pattern, run, geom, hull[-1], path, plt)
    note(f"wrote {path}")


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
    args, outdir, driven_dir, rate_dirs, at_mm = [], None, None, [], None
    ensemble, empties, into = None, [], args
    argv = sys.argv[1:]
    while argv:
        a = argv.pop(0)
        if a == "--ensemble":
            ensemble = into = []
        elif a == "--empty":
            into = empties
        elif a == "--out" and argv:
            outdir = argv.pop(0)
        elif a == "--case" and argv:
            CASE["file"] = argv.pop(0)
            if not os.path.isfile(CASE["file"]):
                sys.exit(f"plot_case: --case {CASE['file']}: no such file")
        elif a == "--set" and argv:
            CASE["sets"].append(argv.pop(0))
        elif a == "--at" and argv:
            try:
                at_mm = [float(x) for x in argv.pop(0).split(",")]
            except ValueError:
                sys.exit("plot_case: --at takes penetrations in mm separated by commas, e.g. --at 20,40,55")
        elif a == "--driven" and argv:
            driven_dir = argv.pop(0)
        elif a == "--rate" and argv:
            rate_dirs.append(argv.pop(0))
        elif a in ("-h", "--help") or a.startswith("--"):
            sys.exit(__doc__)
        else:
            into.append(a)
    if CASE["sets"] and not CASE["file"]:
        sys.exit("plot_case: --set needs --case (the values change the case file's)")
    if ensemble is not None or empties:
        if args or not ensemble:
            sys.exit("plot_case: --ensemble FILLED1 FILLED2 ... [--empty EMPTY1 ...] (no other run folders)")
        return main_ensemble(ensemble, empties, outdir, at_mm)
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
    guarded("section_<k>.png", plot_sections, filled, outdir, plt, "section", at_mm)
    if empty:
        guarded("section_empty_<k>.png", plot_sections, empty, outdir, plt, "section_empty", at_mm)


def main_ensemble(filled_dirs, empty_dirs, outdir, at_mm):
    import hull_ensemble
    filled, empty = [], []
    for dirs, runs, label in ((filled_dirs, filled, "filled"), (empty_dirs, empty, "empty")):
        for k, d in enumerate(dirs, 1):
            try:
                runs.append(Run(d, f"{label} {k}"))
            except (RuntimeError, OSError) as e:
                sys.exit(f"plot_case: {e}")
    outdir = outdir or filled_dirs[0]
    os.makedirs(outdir, exist_ok=True)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    try:
        hull_ensemble.run_ensemble(filled, empty, outdir, at_mm, part_rupture_row, key, note, plt)
    except RuntimeError as e:
        sys.exit(f"plot_case: --ensemble: {e}")


if __name__ == "__main__":
    main()
