#!/usr/bin/python3
"""The double hull's coarse variant from Python: the granule-filled section and the empty one
struck by the same bow (cases/double_hull_impact/coarse.yaml and coarse_empty.yaml), run with
partita.run and plotted with matplotlib from the returned DataFrames: the force on the bow over
its penetration, filled against empty (left), and how the bow's work is shared between the outer
plate, the inner plate, the webs and the granules (friction, damping, crushing) over the
penetration (right, filled; from the monitors and the energy audit).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/double_hull_coarse.py [--threads 2] [--end T]

About 3 minutes on 2 quiet cores (the filled run 82-96 s, the empty one 65 s); --end T shortens
both (the bow starts to move at 5 ms and reaches the outer plate at about 15 ms: --end 0.03 shows
the outer plate's first 20 mm in about a minute). Writes out/double-hull-python/{filled,empty}/ and
double_hull_python.png there (--read: plots earlier runs' folders again), and prints the work to the outer plate's first failure and the
largest bow force of each run.
"""
import argparse
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import partita  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
CASES = ROOT / "cases" / "double_hull_impact"


def bow_curve(result):
    """Penetration [mm], the resistance of the hull and the granules to the bow [kN] (the bow
    moves along +z, the force on it along -z), the bow's work [J]."""
    bow = result["bow"]
    pen = bow["hull.bow.penetration"] * 1e3
    force = -bow["hull.bow.force_z"]
    work = bow["hull.bow.work"].copy()
    if "granules.bow.force_z" in bow:  # after the outer plate tears, the granules push back too
        force -= bow["granules.bow.force_z"]
        work += bow["granules.bow.work"]
    return pen, force * 1e-3, work


def first_failure_work(result):
    """The bow's work when the first element fails (None if none failed)."""
    bow = result["bow"]
    failed = bow[bow["hull.failed_elements"] > 0]
    if failed.empty:
        return None
    _, _, work = bow_curve(result)
    return float(work[failed.index[0]])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int, default=2, help="threads of each run (default 2)")
    ap.add_argument("--end", type=float, default=None, help="time.end of both runs [s] (default: the cases')")
    ap.add_argument("--output", default="out/double-hull-python", help="output folder")
    ap.add_argument("--quiet", action="store_true", help="no progress bar")
    ap.add_argument("--read", action="store_true",
                    help="no runs: read the folders of earlier runs (partita.read) and plot")
    args = ap.parse_args()
    out = Path(args.output)
    shorter = {"time.end": args.end} if args.end else {}

    runs = {}
    for label, case in (("filled", "coarse.yaml"), ("empty", "coarse_empty.yaml")):
        if args.read:
            runs[label] = partita.read(out / label)
            continue
        try:
            runs[label] = partita.run(CASES / case, output=out / label, threads=args.threads,
                                      set=shorter, plots=False, progress=not args.quiet)
        except partita.CaseError as e:  # file, line and key of what is wrong, as the CLI says
            print(f"{case}: {e}", file=sys.stderr)
            return 1
        s = runs[label].summary
        print(f"{label}: {s.windows} windows in {s.wall_seconds:.1f} s "
              f"({', '.join(f'{k} {v:.1f} s' for k, v in (s.participant_seconds or {}).items())})")

    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.8))
    for label, style, colour in (("filled", "-", "tab:blue"), ("empty", "--", "k")):
        pen, force, _ = bow_curve(runs[label])
        # the contact force rings from window to window: a running mean over 1 mm of penetration
        step = pen.diff().clip(lower=0).median()
        rows = max(1, int(round(1.0 / step))) if step > 0 else 1
        left.plot(pen, force, style, color=colour, lw=0.3, alpha=0.35)
        left.plot(pen, force.rolling(rows, center=True, min_periods=1).mean(), style, color=colour,
                  label=f"{label} (mean over 1 mm)")
        w = first_failure_work(runs[label])
        peak = float(force.max())
        print(f"{label}: largest bow force {peak:.2f} kN; work to the first failure "
              + (f"{w:.1f} J" if w is not None else "(no element failed)"))
    left.set_xlabel("bow penetration [mm]")
    left.set_ylabel("resistance to the bow [kN]")
    left.set_title("force over penetration")
    left.legend()

    filled = runs["filled"]
    pen = filled["bow"]["hull.bow.penetration"] * 1e3
    parts = filled["parts"]
    audit = filled.energy  # energy.csv: every term of the case's energy audit
    shares = {
        "outer plate (plastic)": parts["hull.outer_plate.plastic_work"],
        "inner plate (plastic)": parts["hull.inner_plate.plastic_work"],
        "webs (plastic)": parts["hull.webs.plastic_work"],
        "eroded elements": audit["dissipated hull.eroded_energy"],
        "hull (elastic + kinetic)": audit["stored hull.strain_energy"] + audit["stored hull.kinetic_energy"],
        "granules: friction + damping": audit["dissipated granules.friction_work"]
        + audit["dissipated granules.damping_work"],
        "granules: crushing": audit["dissipated granules.breakage_energy"],
        "granules (elastic + kinetic)": audit["stored granules.elastic_energy"]
        + audit["stored granules.kinetic_energy"],
    }
    n = min(len(pen), *(len(v) for v in shares.values()))  # the monitors and the audit share rows
    right.stackplot(pen[:n], *(v[:n] for v in shares.values()), labels=list(shares))
    _, _, work = bow_curve(filled)
    right.plot(pen[:n], work[:n], "k", lw=1, label="bow work")
    right.set_xlabel("bow penetration [mm]")
    right.set_ylabel("energy [J]")
    right.set_title("where the bow's work goes (filled)")
    right.legend(fontsize=8, loc="upper left")
    for ax in (left, right):
        ax.grid(True, alpha=0.3)
    fig.suptitle("Granule-filled double-hull section, coarse variant (cases/double_hull_impact)")
    fig.tight_layout()
    png = out / "double_hull_python.png"
    fig.savefig(png, dpi=120)
    print(f"figure: {png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
