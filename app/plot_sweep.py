#!/usr/bin/python3
"""Overlay one monitor column of every variant of a partita sweep in one PNG.

Usage: plot_sweep.py [--x XCOLUMN] [--x-scale F] [--y-scale F] [--list-panels] OUT.png COLUMN LABEL FILE.csv [...]
--list-panels prints the variants of each panel, one line a panel, and draws nothing.
COLUMN is the column's name without its unit ("granules.plate.force_z"); each FILE.csv is the
variant's monitor CSV (first column: time). Variants whose file or column is missing are left
out. Each variant has its own colour and line style, the legend beside its panel. Variants are
grouped into panels by size (their largest |value|): a variant more than SPREAD times the smallest
of its panel starts a new panel, each with its own y range, so a 0.1 N curve is not flattened
under a 45 N one; a panel holds at most MAX_SERIES variants.
The PNG is written under a temporary name and renamed.
"""
import csv
import os
import sys

MAX_SERIES = 6
SPREAD = 100.0
STYLES = ["-", "--", "-.", ":", (0, (5, 1, 1, 1, 1, 1)), (0, (8, 2))]


def main(argv):
    list_panels = "--list-panels" in argv
    argv = [a for a in argv if a != "--list-panels"]
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
    xlabel, ylabel, curves = "time [s]", column, []
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
        curves.append((label, [x_scale * float(r[xc]) for r in data],
                       [y_scale * float(r[c]) for r in data]))
    if not curves:
        return 1
    def size(curve):
        return max((abs(y) for y in curve[2]), default=0.0)

    # panels by size (the variants' own order kept inside a panel), at most MAX_SERIES each
    chunks = []
    for curve in sorted(curves, key=size):
        last = chunks[-1] if chunks else None
        if (last is None or len(last) >= MAX_SERIES
                or size(curve) > SPREAD * max(size(last[0]), 1e-300)):
            chunks.append([curve])
        else:
            last.append(curve)
    order = {id(c): k for k, c in enumerate(curves)}
    chunks = [sorted(chunk, key=lambda c: order[id(c)]) for chunk in chunks]
    chunks.sort(key=lambda chunk: min(order[id(c)] for c in chunk))
    if list_panels:
        for chunk in chunks:
            print(", ".join(c[0] for c in chunk))
        return 0
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(len(chunks), 1, sharex=True, sharey=False, squeeze=False,
                             figsize=(9, 1.2 + 3.2 * len(chunks)), dpi=120,
                             constrained_layout=True)
    for ax, chunk in zip(axes[:, 0], chunks):
        for k, (label, xs, ys) in enumerate(chunk):
            ax.plot(xs, ys, color="C%d" % k, ls=STYLES[k % len(STYLES)], lw=1.3, label=label)
        ax.set_ylabel(ylabel)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    axes[-1, 0].set_xlabel(xlabel)
    axes[0, 0].set_title("sweep: " + column)
    tmp = out + ".part.png"
    fig.savefig(tmp)
    os.replace(tmp, out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
