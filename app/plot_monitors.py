#!/usr/bin/python3
"""Plot partita monitor CSV files: PNGs of the columns over time, and over another column.

Usage: plot_monitors.py FILE.csv [FILE.csv ...]
       plot_monitors.py --list-panels FILE.csv     print the panels, one line each, and plot nothing

Each CSV has a header like "time [s],granules.plate.force_z [N],plate.applied_force_z [N]".
The columns are drawn over the first (coupling.csv: over its time column) in panels stacked on
one time axis, so that a reader tells every line apart:
- one unit per panel: a count, a mass in kg, a force in N and an energy in J never share an
  axis (columns without a unit are grouped as one unit);
- in a unit, columns of unrelated size get panels of their own: a count (integer values) never
  shares an axis with a ratio, nor a column with one more than SPAN times smaller
  (iterations beside an imbalance of 4e-8);
- at most MAX_SERIES lines per panel, each with its own colour and line style, the legend
  beside the panel; more lines are split by their participant (energy.csv: by role);
- more than MAX_PANELS panels: further figures NAME_2.png, NAME_3.png, ...
A time column (unit s) holds -1 while its event has not happened (a first failure): those rows
are not drawn. Columns whose name contains "applied", "reference" or "static" (expected values)
are drawn thicker. coupling.csv with nothing but iterations of 1 (one participant: nothing
coupled) gets no plot. A grading table (time_s, diameter_m, passing) is drawn as the grading
curves of at most MAX_SERIES of its times.

NAME.plots beside NAME.csv (written by the run for the monitor's `plots` key), one line
"x,y1,y2,..." of column names without units each, adds NAME_vs_<x>.png: the y columns over x.

The PNGs are written beside the CSV, under a temporary name and then renamed.
"""
import csv
import math
import os
import sys

MAX_SERIES = 6
MAX_PANELS = 6
SPAN = 100.0
STYLES = ["-", "--", "-.", ":", (0, (5, 1, 1, 1, 1, 1)), (0, (8, 2))]
PLACEHOLDER = -1.0
GRADING = ["time_s", "diameter_m", "passing"]  # a DEM grading table (granules_grading.csv)


def unit_of(name):
    """'granules.plate.force_z [N]' -> 'N'; no brackets -> ''."""
    if name.endswith("]") and " [" in name:
        return name[name.rindex(" [") + 2:-1]
    return ""


def bare(name):
    """The name without its unit."""
    return name[:name.rindex(" [")] if unit_of(name) else name


def dimensionless(unit):
    return unit in ("", "-", "1")


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        return None, None
    header, data = rows[0], rows[1:]
    cols = [list(c) for c in zip(*[[float(v) for v in r] for r in data if len(r) == len(header)])]
    if not cols:
        cols = [[] for _ in header]
    return header, cols


def mask_placeholders(header, cols, x):
    """A time (unit s) of -1 is "not yet": NaN, so that it is not drawn. The names masked."""
    masked = set()
    for i, name in enumerate(header):
        if i != x and unit_of(name) == "s" and PLACEHOLDER in cols[i]:
            cols[i] = [math.nan if v == PLACEHOLDER else v for v in cols[i]]
            masked.add(i)
    return masked


def x_of(header):
    """The column the others are drawn over: the first, or coupling.csv's time after its window."""
    if header and header[0] == "window" and "time [s]" in header:
        return header.index("time [s]")
    return 0


def nothing_coupled(header, cols):
    """coupling.csv of a case of one participant: iterations of 1, nothing else to show."""
    if not header or header[0] != "window":
        return False
    x = x_of(header)
    rest = [i for i in range(1, len(header)) if i != x]
    return all(header[i] == "iterations" for i in rest) and \
        all(v == 1.0 for i in rest for v in cols[i])


def magnitude(values):
    finite = [abs(v) for v in values if math.isfinite(v)]
    return max(finite) if finite else 0.0


def is_count(values):
    finite = [v for v in values if math.isfinite(v)]
    return bool(finite) and any(v != 0 for v in finite) and all(v == int(v) for v in finite)


def prefix(name):
    """'hull.bow.work' -> 'hull'; 'input hull.bow.work' -> 'input' (energy.csv's role); a name
    without a participant ('inputs', 'stored + dissipated': energy.csv's sums) -> ''."""
    name = bare(name)
    space, dot = name.find(" "), name.find(".")
    if dot < 0:
        return ""
    return name[:space] if 0 < space < dot else name[:dot]


def split_long(indices, header):
    """Groups of at most MAX_SERIES: by prefix (participant, role), neighbours merged."""
    if len(indices) <= MAX_SERIES:
        return [indices]
    by = {}
    for i in indices:
        by.setdefault(prefix(header[i]), []).append(i)
    groups = []
    for g in by.values():
        n = -(-len(g) // MAX_SERIES)  # chunks of near-equal size
        size = -(-len(g) // n)
        groups += [g[k:k + size] for k in range(0, len(g), size)]
    merged = []
    for g in groups:
        if merged and len(merged[-1]) + len(g) <= MAX_SERIES:
            merged[-1] = merged[-1] + g
        else:
            merged.append(g)
    return merged


def panels(header, cols=None, x=0):
    """[(unit, [column index, ...]), ...]: by unit in the order the units first appear; with the
    data, each unit split by kind (count or not) and size, and into panels of MAX_SERIES."""
    order, groups = [], {}
    for i, name in enumerate(header):
        if i == x or (i == 0 and x != 0):
            continue
        u = unit_of(name)
        if u not in groups:
            groups[u] = []
            order.append(u)
        groups[u].append(i)
    if cols is None:
        return [(u, groups[u]) for u in order]
    out = []
    for u in order:
        idx = groups[u]
        mags = {i: magnitude(cols[i]) for i in idx}
        kinds = {}
        for i in idx:
            kinds.setdefault(dimensionless(u) and is_count(cols[i]), []).append(i)
        clusters, values = [], []  # values: the clusters that are not counts
        for count, members in kinds.items():
            left = sorted((i for i in members if mags[i] > 0), key=lambda i: -mags[i])
            while left:
                head = mags[left[0]]
                c = [i for i in left if mags[i] >= head / SPAN]
                clusters.append(c)
                if not count:
                    values.append(c)
                left = [i for i in left if i not in c]
        zeros = [i for i in idx if mags[i] == 0]
        if zeros:  # all zero (or not yet drawn): beside the largest values, never a count
            if values:
                values[0] += zeros
            else:
                clusters.append(zeros)
        for c in sorted((sorted(c) for c in clusters), key=lambda c: c[0]):
            out += [(u, g) for g in split_long(c, header)]
    return out


def draw(plt, panel_list, header, cols, x, masked, title):
    """One figure of stacked panels sharing x."""
    n = len(panel_list)
    fig, axes = plt.subplots(n, 1, sharex=True, squeeze=False, figsize=(10, 1.0 + 2.3 * n),
                             dpi=120, constrained_layout=True)
    for ax, (unit, indices) in zip(axes[:, 0], panel_list):
        for k, i in enumerate(indices):
            name = header[i]
            expected = any(w in name for w in ("applied", "reference", "static"))
            label = bare(name) + (" (-1 = not yet: not drawn)" if i in masked else "")
            ax.plot(cols[x], cols[i], color="C%d" % (k % 10), ls=STYLES[k % len(STYLES)],
                    lw=2.0 if expected else 1.3, label=label)
        counts = dimensionless(unit) and all(is_count(cols[i]) for i in indices)
        ax.set_ylabel(unit if unit else ("count" if counts else "value"))
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    axes[-1, 0].set_xlabel(header[x])
    axes[0, 0].set_title(title)
    return fig


def grading(plt, cols, name):
    """A DEM grading table (time, diameter, mass passing; rows by time): the curves of at most
    MAX_SERIES output times, the first and the last among them, over the diameter."""
    times = sorted(set(cols[0]))
    if len(times) > MAX_SERIES:
        times = [times[round(k * (len(times) - 1) / (MAX_SERIES - 1))] for k in range(MAX_SERIES)]
    fig, ax = plt.subplots(figsize=(9, 4.2), dpi=120, constrained_layout=True)
    for k, t in enumerate(times):
        rows = sorted((d, p) for tt, d, p in zip(*cols) if tt == t)
        ax.step([1e3 * d for d, _ in rows], [p for _, p in rows], where="post",
                color="C%d" % k, ls=STYLES[k % len(STYLES)], lw=1.3, label="t = %.4g s" % t)
    ax.set_xscale("log")
    from matplotlib.ticker import FormatStrFormatter
    ax.xaxis.set_major_formatter(FormatStrFormatter("%g"))
    ax.xaxis.set_minor_formatter(FormatStrFormatter("%g"))
    ax.tick_params(axis="x", which="minor", labelsize=7)
    ax.set_xlabel("diameter [mm]")
    ax.set_ylabel("mass passing [-]")
    ax.set_title(name)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    return fig


def save(plt, fig, out):
    tmp = out + ".part.png"
    fig.savefig(tmp)
    plt.close(fig)
    os.replace(tmp, out)
    return out


def plot(path):
    """The PNGs of one CSV (and of its .plots), as a list of paths."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    header, cols = read(path)
    if not header or len(cols) < 2 or len(cols[0]) < 2 or nothing_coupled(header, cols):
        return []  # nothing worth a plot
    base = os.path.splitext(path)[0]
    name = os.path.basename(base)
    if header == GRADING:
        return [save(plt, grading(plt, cols, name), base + ".png")]
    x = x_of(header)
    masked = mask_placeholders(header, cols, x)
    found = panels(header, cols, x)
    written = []
    figures = [found[k:k + MAX_PANELS] for k in range(0, len(found), MAX_PANELS)]
    for k, chunk in enumerate(figures):
        title = name if len(figures) == 1 else "%s (%d of %d)" % (name, k + 1, len(figures))
        fig = draw(plt, chunk, header, cols, x, masked, title)
        written.append(save(plt, fig, base + (".png" if k == 0 else "_%d.png" % (k + 1))))
    for xy in plot_requests(base + ".plots", header):
        xi, ys = xy[0], xy[1:]
        sub = [header[i] for i in [xi] + ys]
        subcols = [cols[i] for i in [xi] + ys]
        found = panels(sub, subcols, 0)
        fig = draw(plt, found[:MAX_PANELS], sub, subcols, 0,
                   {k for k, i in enumerate([xi] + ys) if i in masked},
                   "%s: over %s" % (name, bare(header[xi])))
        written.append(save(plt, fig, "%s_vs_%s.png" % (base, bare(header[xi]))))
    return written


def plot_requests(path, header):
    """The column indices [x, y1, ...] of each line of NAME.plots; a name the CSV lacks: an error
    line on stderr, and that plot is left out."""
    if not os.path.exists(path):
        return []
    names = [bare(h) for h in header]
    out = []
    with open(path) as f:
        for n, line in enumerate(f, start=1):
            wanted = [w.strip() for w in line.strip().split(",") if w.strip()]
            if len(wanted) < 2:
                continue
            missing = [w for w in wanted if w not in names]
            if missing:
                print("plot_monitors: %s:%d: no column %s in the CSV (its columns: %s); plot left "
                      "out" % (path, n, ", ".join(missing), ", ".join(names[1:])), file=sys.stderr)
                continue
            out.append([names.index(w) for w in wanted])
    return out


def main(argv):
    if len(argv) > 1 and argv[1] == "--list-panels":
        for p in argv[2:]:
            header, cols = read(p)
            if not header:
                continue
            if cols and nothing_coupled(header, cols):
                print("(no plot: nothing coupled)")
                continue
            if header == GRADING:
                print("(grading curves of %d of %d times)" % (
                    min(MAX_SERIES, len(set(cols[0]))), len(set(cols[0]))))
                continue
            x = x_of(header)
            masked = mask_placeholders(header, cols, x) if cols and cols[0] else set()
            for unit, indices in panels(header, cols if cols and cols[0] else None, x):
                print("[%s]: %s" % (unit, ", ".join(
                    header[i] + (" (-1 not drawn)" if i in masked else "") for i in indices)))
        return 0
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        print("plot_monitors: the python module matplotlib is missing in %s (Debian package "
              "python3-matplotlib): no plots" % sys.executable, file=sys.stderr)
        return 1
    for p in argv[1:]:
        for out in plot(p):
            print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
