"""Ensembles of double-hull runs (plot_case.py --ensemble FILLED... --empty EMPTY...): the same
hull filled with several packings against the empty hull (one or more runs), at equal penetration.

Spread: every figure shows the ensemble's mean and its min-max band (with three packings a
standard deviation says little more than the range); the key=value lines give mean, sample
standard deviation (ddof = 1, 0 for one run), min and max, and the CSV table the same.

Quantities (each on the bow's penetration, each run interpolated on a common grid from 0 to the
smallest final penetration of all runs):
  bow force           the indenter's resisting force, smoothed over 4 % of that penetration
  inner plate energy  hull.inner_plate.plastic_work + hull.inner_plate.strain_energy (the intact
                      elements: exact up to the inner plate's first failed element)
  inner plate force   d(inner plate energy)/d(penetration), smoothed as the bow force: the inner
                      plate's share of the bow's force (the parts' shares add up to it where the
                      motion is quasi-static), whatever carries the load to the inner plate (the
                      bed or the bow itself); negative where it springs back; with it, where the run has the column
                      granules.cavity_inner.force_z, the bed's own load on the inner plate
  energy shares       outer plate, inner plate, webs (plastic work + elastic energy of the intact
                      elements), eroded elements (hull.eroded_energy), granules' friction, damping
                      and crushing (granules.breakage_energy), and the rest of energy.csv's
                      `stored + dissipated` (kinetic energies, contact springs, stiffening, the
                      bow's friction), at the chosen penetrations
"""
import csv
import os

import numpy as np

SHARES = [
    ("outer plate", ["hull.outer_plate.plastic_work", "hull.outer_plate.strain_energy"]),
    ("inner plate", ["hull.inner_plate.plastic_work", "hull.inner_plate.strain_energy"]),
    ("webs", ["hull.webs.plastic_work", "hull.webs.strain_energy"]),
    ("eroded elements", ["hull.eroded_energy"]),
    ("granules friction", ["granules.friction_work"]),
    ("granules damping", ["granules.damping_work"]),
    ("granules crushing", ["granules.breakage_energy"]),
]
SHARE_COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#7f7f7f", "#ff7f0e", "#9467bd", "#8c564b", "#e5e5e5"]


def stats(values):
    """(mean, sample std, min, max, n) of the finite values; None when there is none."""
    v = np.array([x for x in values if x is not None and np.isfinite(x)], dtype=float)
    if not len(v):
        return None
    return float(v.mean()), float(v.std(ddof=1)) if len(v) > 1 else 0.0, float(v.min()), float(v.max()), len(v)


def on_grid(run, values, grid):
    """values (on run's rows) at the penetrations of grid, after first contact (the bow's
    penetration is monotone there; at a repeated penetration the first row counts)."""
    p = run.pen[run.contact:]
    v = values[run.contact:]
    pu, k = np.unique(p, return_index=True)
    return np.interp(grid, pu, v[k])


def smooth(grid, values, window):
    """Centred moving average over a penetration window on a uniform grid."""
    n = max(1, int(round(window / (grid[1] - grid[0])))) if len(grid) > 1 else 1
    if n <= 1:
        return values
    kernel = np.ones(n) / n
    pad = np.pad(values, (n // 2, n - 1 - n // 2), mode="edge")
    return np.convolve(pad, kernel, mode="valid")


def inner_energy(run):
    cols = ["hull.inner_plate.plastic_work", "hull.inner_plate.strain_energy"]
    if not run.has(*cols):
        return None
    return sum(run.at(c) for c in cols)


def share_values(run, grid_pts):
    """{term: values at grid_pts} of SHARES and `other` (J)."""
    out = {}
    named = np.zeros(len(grid_pts))
    for name, cols in SHARES:
        have = [c for c in cols if run.has(c)]
        if not have:
            continue
        v = on_grid(run, sum(run.at(c) for c in have), grid_pts)
        out[name] = v
        named = named + v
    if run.has("stored + dissipated"):
        out["other"] = on_grid(run, run.at("stored + dissipated"), grid_pts) - named
    return out


class Ensemble:
    def __init__(self, filled, empty, key, note):
        self.groups = [("filled", filled)] + ([("empty", empty)] if empty else [])
        self.key, self.note = key, note
        runs = filled + (empty or [])
        for r in runs:
            if len(r.t) <= r.contact + 10:
                raise RuntimeError(f"{r.folder}: the bow has not touched the hull yet")
        self.end = min(float(r.pen[-1]) for r in runs)
        self.grid = np.linspace(0.0, self.end, max(50, int(self.end / 1e-4) + 1))
        self.window = 0.04 * self.end

    # ------------------------------------------------------------------ numbers
    def milestones(self, part_rupture_row):
        """Energy to the hull's and to each part's first failure, per group, as mean/std/min/max;
        filled less empty (the difference of the means, and relative to the empty mean)."""
        means = {}
        for label, runs in self.groups:
            outer, outer_p, inner, inner_p, inner_e = [], [], [], [], []
            by_part = {"outer": ([], []), "webs": ([], [])}
            for r in runs:
                w = r.work()
                for tag, part in (("outer", "outer_plate"), ("webs", "webs")):
                    k = part_rupture_row(r, part)
                    if k is not None and w is not None:
                        by_part[tag][0].append(float(w[k]))
                        by_part[tag][1].append(float(r.pen[k]))
            for tag, (energies, pens) in by_part.items():
                for name, values in ((f"energy_to_{tag}_rupture", energies),
                                     (f"{tag}_rupture_penetration", pens)):
                    unit = "_m" if name.endswith("penetration") else "_J"
                    self._stats_keys(f"ensemble_{name}_{label}{unit}", values, len(runs))
                    s = stats(values)
                    if s is not None:
                        means[(name, label)] = s[0]
            for r in runs:
                w = r.work()
                rup = r.first_rupture()
                if rup and w is not None:
                    outer.append(float(np.interp(rup[0], r.t, w)))
                    outer_p.append(rup[1])
                e = inner_energy(r)
                if rup and e is not None:
                    inner_e.append(float(np.interp(rup[0], r.t, e)))
                k = part_rupture_row(r, "inner_plate")
                if k is not None and w is not None:
                    inner.append(float(w[k]))
                    inner_p.append(float(r.pen[k]))
            for name, values in (("energy_to_rupture", outer), ("rupture_penetration", outer_p),
                                 ("energy_to_inner_rupture", inner), ("inner_rupture_penetration", inner_p),
                                 ("inner_plate_energy_at_rupture", inner_e)):
                unit = "_m" if name.endswith("penetration") else "_J"
                self._stats_keys(f"ensemble_{name}_{label}{unit}", values, len(runs))
                s = stats(values)
                if s is not None:
                    means[(name, label)] = s[0]
        for name in ("energy_to_rupture", "energy_to_inner_rupture", "energy_to_outer_rupture",
                     "energy_to_webs_rupture"):
            f, e = means.get((name, "filled")), means.get((name, "empty"))
            if f is not None and e is not None:
                self.key(f"ensemble_{name}_filled_minus_empty_J", f - e)
                if e:
                    self.key(f"ensemble_{name}_filled_over_empty", f / e)
        return self

    def _stats_keys(self, stem, values, n_runs):
        s = stats(values)
        if s is None:
            self.note(f"{stem}: no run reached it")
            return
        head = stem.rsplit("_", 1)
        for what, v in zip(("mean", "std", "min", "max"), s[:4]):
            self.key(f"{head[0]}_{what}_{head[1]}", v)
        self.key(f"{head[0]}_runs", float(s[4]), "{:.0f}")
        if s[4] < n_runs:
            self.note(f"{stem}: {n_runs - s[4]} of {n_runs} runs did not reach it")

    def curves(self):
        """{group: {quantity: (n_runs, len(grid)) array}}."""
        out = {}
        for label, runs in self.groups:
            c = {"force": [], "inner_energy": [], "inner_force": [], "bed_on_inner": [], "work": []}
            for r in runs:
                p, f = r.smoothed_force(self.window)
                pu, k = np.unique(p, return_index=True)
                c["force"].append(np.interp(self.grid, pu, f[k]))
                w = r.work()
                if w is not None:
                    c["work"].append(on_grid(r, w, self.grid))
                e = inner_energy(r)
                if e is not None:
                    eg = on_grid(r, e, self.grid)
                    c["inner_energy"].append(eg)
                    c["inner_force"].append(smooth(self.grid, np.gradient(eg, self.grid), self.window))
                if r.has("granules.cavity_inner.force_z"):
                    b = on_grid(r, r.at("granules.cavity_inner.force_z"), self.grid)
                    c["bed_on_inner"].append(smooth(self.grid, b, self.window))
            out[label] = {q: np.array(v) for q, v in c.items() if v}
        return out

    def curve_keys(self, curves, at_m, tags):
        """The inner plate's energy and force, the bow's work and the bed's load on the inner plate
        at the chosen penetrations (tags: their names in the keys), mean and std."""
        for p, tag in zip(at_m, tags):
            for label, c in curves.items():
                for q, name, unit in (("inner_energy", "inner_plate_energy", "J"), ("inner_force", "inner_plate_force", "N"),
                                      ("work", "work", "J"), ("bed_on_inner", "bed_on_inner_plate", "N")):
                    if q not in c:
                        continue
                    s = stats([float(np.interp(p, self.grid, row)) for row in c[q]])
                    self.key(f"ensemble_{name}_{tag}_{label}_mean_{unit}", s[0])
                    self.key(f"ensemble_{name}_{tag}_{label}_std_{unit}", s[1])
        if "empty" in curves and "work" in curves["filled"] and "work" in curves["empty"]:
            # filled above empty as work over penetration, against the packings' spread
            diff = curves["filled"]["work"].mean(axis=0) - curves["empty"]["work"].mean(axis=0)
            spread = curves["filled"]["work"].max(axis=0) - curves["filled"]["work"].min(axis=0)
            self.key("ensemble_work_filled_minus_empty_final_J", float(diff[-1]))
            self.key("ensemble_work_filled_spread_final_J", float(spread[-1]))

    def shares(self, at_m, csv_path):
        """The energy shares at the penetrations at_m: a CSV table (long form, units in the
        header) and {group: {term: (n_runs, len(at_m))}}."""
        table = {}
        for label, runs in self.groups:
            per_run = [share_values(r, np.asarray(at_m)) for r in runs]
            terms = [n for n, _ in SHARES] + ["other"]
            table[label] = {t: np.array([pr[t] for pr in per_run]) for t in terms if all(t in pr for pr in per_run)}
        with open(csv_path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["penetration [mm]", "variant", "term", "mean [J]", "std [J]", "min [J]", "max [J]",
                        "share of the total [%]", "runs"])
            for i, p in enumerate(at_m):
                for label, terms in table.items():
                    total = sum(terms.values())
                    mean_total = float(np.mean(total[:, i]))
                    for t, v in list(terms.items()) + [("total", total)]:
                        s = stats(v[:, i])
                        share = 100 * s[0] / mean_total if mean_total else float("nan")
                        w.writerow([f"{1e3 * p:.4g}", label, t] + [f"{x:.6g}" for x in s[:4]] + [f"{share:.4g}", s[4]])
        return table

    # ------------------------------------------------------------------ figures
    def plot_curves(self, curves, rupture_bands, path, plt):
        """The bow's force, the inner plate's share of it and its energy, filled against empty;
        and the bow's work filled less the empty mean (each packing: the band)."""
        both = "empty" in curves and "work" in curves["filled"] and "work" in curves["empty"]
        fig, axes = plt.subplots(4 if both else 3, 1, figsize=(8, 13.5 if both else 10.5), sharex=True)
        colours = {"filled": "C0", "empty": "C3"}
        mm = 1e3 * self.grid
        panels = (("force", 1e-3, "bow force [kN]"), ("inner_force", 1e-3, "inner plate's share of it:\n"
                                                                              "d(its energy)/d(penetration) [kN]"),
                  ("inner_energy", 1.0, "inner plate's absorbed energy [J]"))
        for ax, (q, scale, ylabel) in zip(axes, panels):
            for label, c in curves.items():
                if q not in c:
                    continue
                a = scale * c[q]
                n = len(a)
                ax.fill_between(mm, a.min(axis=0), a.max(axis=0), color=colours[label], alpha=0.25, lw=0)
                ax.plot(mm, a.mean(axis=0), color=colours[label], lw=1.6,
                        label=f"{label}: mean of {n} run{'s' if n > 1 else ''} (band: min-max)")
                if q == "inner_force" and "bed_on_inner" in c:
                    b = scale * c["bed_on_inner"]
                    ax.fill_between(mm, b.min(axis=0), b.max(axis=0), color="C2", alpha=0.25, lw=0)
                    ax.plot(mm, b.mean(axis=0), color="C2", lw=1.2, label=f"{label}: the bed's load on it "
                            "(granules.cavity_inner.force_z)")
            for label, (lo, hi) in rupture_bands.items():
                ax.axvspan(1e3 * lo, 1e3 * hi + 0.05, color=colours[label], alpha=0.12, hatch="//")
            ax.set_ylabel(ylabel)
            ax.grid(alpha=0.3)
        if both:
            ax = axes[3]
            d = curves["filled"]["work"] - curves["empty"]["work"].mean(axis=0)
            ax.fill_between(mm, d.min(axis=0), d.max(axis=0), color="C0", alpha=0.25, lw=0)
            ax.plot(mm, d.mean(axis=0), color="C0", lw=1.6,
                    label=f"filled less the empty mean: mean of {len(d)} (band: min-max)")
            ax.axhline(0, color="k", lw=0.6)
            ax.set_ylabel("bow's work, filled - empty [J]")
            ax.grid(alpha=0.3)
            for label, (lo, hi) in rupture_bands.items():
                ax.axvspan(1e3 * lo, 1e3 * hi + 0.05, color=colours[label], alpha=0.12, hatch="//")
        if rupture_bands:
            axes[0].plot([], [], color="0.6", lw=6, alpha=0.4, label="the outer plate ruptures (hatched: the runs' range)")
        for ax in axes:
            ax.legend(fontsize=7, loc="upper left")
        axes[-1].set_xlabel("penetration [mm]")
        axes[0].set_title(f"filled against empty, smoothed over {1e3 * self.window:.2g} mm", fontsize=10)
        fig.tight_layout()
        fig.savefig(path, dpi=120)
        plt.close(fig)

    def plot_shares(self, table, at_m, path, plt):
        """Stacked bars of the mean shares, a bar a variant at each penetration (whisker: the
        total's min-max over the runs); on the right the granules' terms alone, to scale."""
        groups = list(table)
        terms = [n for n, _ in SHARES] + ["other"]
        granular = [t for t in terms if t.startswith("granules")]
        fig, (ax, gx) = plt.subplots(1, 2, figsize=(max(10.0, 1.1 * len(at_m) * len(groups) + 4), 5.8),
                                     gridspec_kw={"width_ratios": [3, 2]})
        width = 0.8 / len(groups)
        for g, label in enumerate(groups):
            x = np.arange(len(at_m)) + (g - (len(groups) - 1) / 2) * width
            for axis, shown in ((ax, terms), (gx, granular)):
                bottom = np.zeros(len(at_m))
                for t in shown:
                    if t not in table[label]:
                        continue
                    colour = SHARE_COLOURS[terms.index(t)]
                    v = table[label][t].mean(axis=0)
                    axis.bar(x, v, width * 0.95, bottom=bottom, color=colour, edgecolor="k", lw=0.3,
                             label=t if g == 0 else None)
                    bottom = bottom + v
                parts = [table[label][t] for t in shown if t in table[label]]
                if parts:
                    total = sum(parts)
                    axis.errorbar(x, bottom, yerr=[bottom - total.min(axis=0), total.max(axis=0) - bottom], fmt="none",
                                  ecolor="k", capsize=3, lw=0.8)
                for xi, b in zip(x, bottom if parts else []):
                    axis.text(xi, b, f"{label}\n", ha="center", va="bottom", fontsize=7)
        for axis in (ax, gx):
            axis.set_xticks(np.arange(len(at_m)))
            axis.set_xticklabels([f"{1e3 * p:.3g} mm" for p in at_m])
            axis.set_xlabel("penetration")
            axis.grid(alpha=0.3, axis="y")
            handles, labels = axis.get_legend_handles_labels()
            axis.legend(handles[::-1], labels[::-1], fontsize=8, loc="upper left")
        ax.set_ylabel("energy [J] (mean over the runs; whisker: the total's min-max)")
        ax.set_title("where the bow's work goes, at equal penetration", fontsize=10)
        gx.set_title("of it the granules' (friction, damping, crushing)", fontsize=10)
        fig.tight_layout()
        fig.savefig(path, dpi=120)
        plt.close(fig)


def run_ensemble(filled, empty, outdir, at_mm, part_rupture_row, key, note, plt):
    """Everything of --ensemble: keys on stdout, ensemble_curves.png, energy_shares.png and
    energy_shares.csv in outdir."""
    ens = Ensemble(filled, empty, key, note)
    key("ensemble_runs_filled", float(len(filled)), "{:.0f}")
    key("ensemble_runs_empty", float(len(empty)), "{:.0f}")
    key("ensemble_common_penetration_m", ens.end)
    ens.milestones(part_rupture_row)
    if at_mm:
        kept = [p for p in at_mm if 1e-3 * p <= ens.end]
        if len(kept) < len(at_mm):
            note(f"--at values beyond the common penetration {1e3 * ens.end:.4g} mm left out")
        at_m = [1e-3 * p for p in kept]
        tags = [f"{p:g}mm".replace(".", "p") for p in kept]
    else:
        at_m = [f / 100 * ens.end for f in (25, 50, 75, 100)]
        tags = [f"{f}pct" for f in (25, 50, 75, 100)]
    curves = ens.curves()
    ens.curve_keys(curves, at_m, tags)
    bands = {}
    for label, runs in ens.groups:
        p = [r.first_rupture()[1] for r in runs if r.first_rupture()]
        if p:
            bands[label] = (min(p), max(p))
    path = os.path.join(outdir, "ensemble_curves.png")
    ens.plot_curves(curves, bands, path, plt)
    note(f"wrote {path}")
    csv_path = os.path.join(outdir, "energy_shares.csv")
    table = ens.shares(at_m, csv_path)
    note(f"wrote {csv_path}")
    path = os.path.join(outdir, "energy_shares.png")
    ens.plot_shares(table, at_m, path, plt)
    note(f"wrote {path}")
