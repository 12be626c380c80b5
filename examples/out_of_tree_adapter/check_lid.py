#!/usr/bin/env python3
"""Static equilibrium of lid_on_granules.yaml from its output folder (python3, standard library).

Usage: check_lid.py OUTPUT_DIR [--mass KG] [--stiffness N_PER_M] [--gravity M_PER_S2]
       [--over-last FRACTION] [--rel-tol TOL]

Reads OUTPUT_DIR/lid.csv and compares, averaged over the last rows (default: the last 20 %):
  - the force the granules exert on the lid (granules.lid.force_z, the DEM's sum over the lid's
    contacts) with the lid's weight plus its spring force, m g + k z (z: the oscillator's
    displacement, the spring compressed by z > 0);
  - the force the granules exert on the box (-granules.box.force_z, walls and floor) with the
    granules' weight plus the force they carry from the lid, M g + granules.lid.force_z.
Defaults are the case's parameters (m = 50 g, k = 200 N/m, g = 9.81 m/s^2). Prints each pair and
their relative difference; exits 1 if one differs by more than --rel-tol (default 0.01).
"""
import argparse
import csv
import os
import sys


def column(header, name):
    for i, h in enumerate(header):
        if h.split(" [")[0] == name:
            return i
    sys.exit(f"check_lid.py: no column '{name}' in lid.csv (columns: {', '.join(header)})")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("output_dir")
    ap.add_argument("--mass", type=float, default=0.05)
    ap.add_argument("--stiffness", type=float, default=200.0)
    ap.add_argument("--gravity", type=float, default=9.81)
    ap.add_argument("--over-last", type=float, default=0.2)
    ap.add_argument("--rel-tol", type=float, default=0.01)
    a = ap.parse_args()
    path = os.path.join(a.output_dir, "lid.csv")
    try:
        with open(path, newline="") as f:
            rows = list(csv.reader(f))
    except OSError as e:
        sys.exit(f"check_lid.py: cannot read {path}: {e.strerror}")
    if len(rows) < 6:
        sys.exit(f"check_lid.py: {path} has {len(rows) - 1} rows; run the case to its end first")
    header, data = rows[0], [[float(x) for x in r] for r in rows[1:]]
    z, f_lid = column(header, "lid.z"), column(header, "granules.lid.force_z")
    f_box, mass = column(header, "granules.box.force_z"), column(header, "granules.mass")
    tail = data[-max(1, int(round(a.over_last * len(data)))):]

    def mean(f):
        return sum(f(r) for r in tail) / len(tail)

    g, m, k = a.gravity, a.mass, a.stiffness
    checks = [
        ("granules on the lid", mean(lambda r: r[f_lid]), "m g + k z", mean(lambda r: m * g + k * r[z])),
        ("granules on the box", mean(lambda r: -r[f_box]), "M g + lid force",
         mean(lambda r: r[mass] * g + r[f_lid])),
    ]
    ok = True
    print(f"over the last {len(tail)} of {len(data)} rows (t = {tail[0][0]:.4g} .. {tail[-1][0]:.4g} s):")
    print(f"  lid displacement z = {mean(lambda r: r[z]) * 1e3:.4f} mm, spring force k z = "
          f"{mean(lambda r: k * r[z]):.4f} N, weight m g = {m * g:.4f} N")
    for what, measured, name, expected in checks:
        rel = (measured - expected) / expected
        ok = ok and abs(rel) <= a.rel_tol
        print(f"  {what}: {measured:.5f} N, {name} = {expected:.5f} N, difference {rel * 100:+.3f} %")
    if not ok:
        print(f"check_lid.py: a balance is off by more than {a.rel_tol * 100:g} %", file=sys.stderr)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
