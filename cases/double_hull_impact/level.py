#!/usr/bin/python3
"""Strike a settled bed off level: remove every granule whose top (z + r) is above a height
(LAMMPS data as partita writes it). The step between fill.yaml (the bed settled under gravity,
standing above the cavities' top) and the relaxation under the inner plate (fill.yaml again,
reading the levelled file, with a lid at z = 82 mm: README.md "Variants, commands and times").

Usage: level.py IN.data OUT.data Z      (the shipped settled.data: Z = 0.082, the cavities' top)"""
import sys


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    src, dst, height = sys.argv[1:]
    try:
        top = float(height)
    except ValueError:
        sys.exit(f"level.py: the height Z must be a number in metres (e.g. 0.082), got '{height}'")
    try:
        lines = open(src).read().split("\n")
    except OSError as e:
        sys.exit(f"level.py: cannot read {src}: {e.strerror}")
    out, section, removed, kept, highest = [], None, set(), 0, -1e300
    for number, line in enumerate(lines, 1):
        s = line.strip()
        if s and s[0].isalpha():
            section = s.split()[0]
        elif section in ("Atoms", "Velocities") and s:
            cols = s.split()
            try:
                pid = int(cols[0])
                if section == "Atoms":
                    # atom style sphere: id type diameter density x y z
                    reach = float(cols[6]) + 0.5 * float(cols[2])
            except (ValueError, IndexError):
                sys.exit(f"{src}:{number}: level.py: a line of the {section} section must start with "
                         f"'id type diameter density x y z' (atom style sphere), got: {s[:80]}")
            if section == "Atoms":
                if reach > top:
                    removed.add(pid)
                    continue
                kept += 1
                highest = max(highest, reach)
            elif pid in removed:
                continue
        out.append(line)
    if kept == 0:
        sys.exit(f"level.py: no granule of {src} lies below z = {top} m (or it has no Atoms section)")
    out = [f"{kept} atoms" if l.strip().endswith(" atoms") else l for l in out]
    open(dst, "w").write("\n".join(out))
    print(f"{kept + len(removed)} granules, {len(removed)} reaching above z = {top} m removed, "
          f"{kept} left (highest top now {highest:.6f} m)")


if __name__ == "__main__":
    main()
