#!/usr/bin/env python3
"""Plot partita monitor CSV files: one PNG per CSV, the columns against the first (time).

Usage: plot_monitors.py FILE.csv [FILE.csv ...]
       plot_monitors.py --list-panels FILE.csv     print the panels, one line each, and plot nothing

Each CSV has a header like "time [s],granules.plate.force_z [N],plate.applied_force_z [N]".
Columns are grouped by unit: one panel per unit, stacked and sharing the time axis, so that a
count, a mass in kg, a force in N and an energy in J never share one y axis (columns without a
unit form a panel of their own). The PNG is written beside the CSV (same name, .png), under a
temporary name and then renamed. Columns whose name contains "applied", "reference" or "static"
are drawn dashed (expected values).
"""
import csv
import os
import sys


def unit_of(name):
    """'granules.plate.force_z [N]' -> 'N'; no brackets -> ''."""
    if name.endswith("]") and " [" in name:
        return name[name.rindex(" [") + 2:-1]
    return ""


def panels(header):
    """[(unit, [column index, ...]), ...] in the order the units first appear."""
    order, groups = [], {}
    for i, name in enumerate(header[1:], start=1):
        u = unit_of(name)
        if u not in groups:
            groups[u] = []
            order.append(u)
        groups[u].append(i)
    return [(u, groups[u]) for u in order]


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        return None, None
    header, data = rows[0], rows[1:]
    cols = list(zip(*[[float(v) for v in r] for r in data if len(r) == len(header)]))
    return header, cols


def plot(path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    header, cols = read(path)
    if not header or len(cols) == 0 or len(cols[0]) < 2:
        return None  # nothing worth a plot
    x = cols[0]
    groups = panels(header)
    fig, axes = plt.subplots(len(groups), 1, sharex=True, squeeze=False,
                             figsize=(7, 1.2 + 2.6 * len(groups)), dpi=120)
    for ax, (unit, indices) in zip(axes[:, 0], groups):
        for i in indices:
            name = header[i]
            dashed = any(k in name for k in ("applied", "reference", "static"))
            label = name[:name.rindex(" [")] if unit else name
            ax.plot(x, cols[i], "--" if dashed else "-", lw=1.6 if dashed else 1.2, label=label)
        ax.set_ylabel(unit if unit else "value")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    axes[-1, 0].set_xlabel(header[0])
    axes[0, 0].set_title(os.path.splitext(os.path.basename(path))[0])
    fig.tight_layout()
    out = os.path.splitext(path)[0] + ".png"
    tmp = out + ".part.png"
    fig.savefig(tmp)
    plt.close(fig)
    os.replace(tmp, out)
    return out


def main(argv):
    if len(argv) > 1 and argv[1] == "--list-panels":
        for p in argv[2:]:
            header, _ = read(p)
            for unit, indices in panels(header or []):
                print("[%s]: %s" % (unit, ", ".join(header[i] for i in indices)))
        return 0
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
