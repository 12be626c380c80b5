#!/usr/bin/env python3
"""Plot partita monitor CSV files: one PNG per CSV, every column against the first (time).

Usage: plot_monitors.py FILE.csv [FILE.csv ...]
Each CSV has a header like "time [s],granules.plate.force_z [N],plate.applied_force_z [N]".
The PNG is written beside the CSV (same name, .png), under a temporary name and then renamed.
Columns whose name contains "applied", "reference" or "static" are drawn dashed (expected values).
"""
import csv
import os
import sys


def plot(path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if len(rows) < 3:
        return None  # nothing worth a plot
    header, data = rows[0], rows[1:]
    cols = list(zip(*[[float(v) for v in r] for r in data if len(r) == len(header)]))
    if not cols:
        return None
    x = cols[0]
    fig, ax = plt.subplots(figsize=(7, 4.2), dpi=120)
    units = set()
    for name, y in zip(header[1:], cols[1:]):
        dashed = any(k in name for k in ("applied", "reference", "static"))
        ax.plot(x, y, "--" if dashed else "-", lw=1.6 if dashed else 1.2, label=name)
        if "[" in name:
            units.add(name[name.index("[") + 1:name.rindex("]")])
    ax.set_xlabel(header[0])
    ax.set_ylabel(", ".join(sorted(units)) if units else "value")
    ax.set_title(os.path.splitext(os.path.basename(path))[0])
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    out = os.path.splitext(path)[0] + ".png"
    tmp = out + ".part.png"
    fig.savefig(tmp)
    plt.close(fig)
    os.replace(tmp, out)
    return out


def main(argv):
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        print("plot_monitors: python3-matplotlib is not installed; no plots", file=sys.stderr)
        return 0
    for p in argv[1:]:
        out = plot(p)
        if out:
            print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
