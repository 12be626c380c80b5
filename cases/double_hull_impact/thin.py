#!/usr/bin/env python3
"""Remove every N-th granule of a particle file (LAMMPS data as partita writes it): the step
between fill.yaml (the bed pressed to the cavities' top by the lid, 8 kN on the lid: too dense)
and the relaxation (fill.yaml again, reading the thinned file, the lid held at the cavities'
top: README.md).

Usage: thin.py IN.data OUT.data N      (the shipped settled.data: N = 33, 3 % of the granules)"""
import sys


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    src, dst, every = sys.argv[1], sys.argv[2], int(sys.argv[3])
    out, section, removed, k = [], None, set(), 0
    for line in open(src).read().split("\n"):
        s = line.strip()
        if s and s[0].isalpha():
            section = s.split()[0]
        elif section in ("Atoms", "Velocities") and s:
            pid = int(s.split()[0])
            if section == "Atoms":
                k += 1
                if k % every == 0:
                    removed.add(pid)
                    continue
            elif pid in removed:
                continue
        out.append(line)
    n = k - len(removed)
    out = [f"{n} atoms" if l.strip().endswith(" atoms") else l for l in out]
    open(dst, "w").write("\n".join(out))
    print(f"{k} granules, {len(removed)} removed, {n} left")


if __name__ == "__main__":
    main()
