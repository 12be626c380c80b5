#!/usr/bin/env python3
"""Overlay one monitor column of every variant of a partita sweep in one PNG.

Usage: plot_sweep.py [--x XCOLUMN] [--x-scale F] [--y-scale F] OUT.png COLUMN LABEL FILE.csv [...]
COLUMN is the column's name without its unit ("granules.plate.force_z"); each FILE.csv is the
variant's monitor CSV (first column: time). Variants whose file or column is missing are left
out. The PNG is written under a temporary name and renamed.
"""
import csv
import os
import sys


def main(argv):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    x_column, x_scale, y_scale = "", 1.0, 1.0
    while len(argv) > 1 and argv[1].startswith("--"):
        key, value = argv[1], argv[2]
        if key == "--x":
            x_column = value
        elif key == "--x-scale":
            x_scale = float(value)
        elif key == "--y-scale":
            y_scale = float(value)
        argv = argv[:1] + argv[3:]
    out, column = argv[1], argv[2]
    fig, ax = plt.subplots(figsize=(7, 4.2), dpi=120)
    xlabel, ylabel, drawn = "time [s]", column, 0
    pairs = argv[3:]
    for label, path in zip(pairs[0::2], pairs[1::2]):
        if not os.path.exists(path):
            continue
        with open(path, newline="") as f:
            rows = list(csv.reader(f))
        if len(rows) < 2:
            continue
        header = rows[0]
        names = [h.split(" [")[0] for h in header]
        if column not in names:
            continue
        c = names.index(column)
        xc = names.index(x_column) if x_column in names else 0
        xlabel, ylabel = header[xc], header[c]
        if x_scale != 1.0:
            xlabel += " x %g" % x_scale
        if y_scale != 1.0:
            ylabel += " x %g" % y_scale
        data = [r for r in rows[1:] if len(r) == len(header)]
        ax.plot([x_scale * float(r[xc]) for r in data], [y_scale * float(r[c]) for r in data],
                lw=1.3, label=label)
        drawn += 1
    if drawn == 0:
        return 1
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title("sweep: " + column)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    tmp = out + ".part.png"
    fig.savefig(tmp)
    os.replace(tmp, out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
