#!/usr/bin/python3
"""The cavities of the double-hull section as one ASCII STL (floor and four side walls of each
cell, normals into the cell, walls 30 mm taller than the cavity): the fill's container."""
import sys
webs = [0.001, 0.121, 0.241, 0.361]
t = 0.002
z0, z1 = 0.002, 0.112
cav = [(webs[i] + t / 2, webs[i + 1] - t / 2) for i in range(3)]
tris = []
def quad(a, b, c, d, n):
    tris.append((n, a, b, c)); tris.append((n, a, c, d))
for (y0, y1) in cav:
    for (x0, x1) in cav:
        quad((x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0), (0, 0, 1))
        quad((x0, y0, z0), (x0, y1, z0), (x0, y1, z1), (x0, y0, z1), (1, 0, 0))
        quad((x1, y0, z0), (x1, y0, z1), (x1, y1, z1), (x1, y1, z0), (-1, 0, 0))
        quad((x0, y0, z0), (x0, y0, z1), (x1, y0, z1), (x1, y0, z0), (0, 1, 0))
        quad((x0, y1, z0), (x1, y1, z0), (x1, y1, z1), (x0, y1, z1), (0, -1, 0))
with open(sys.argv[1] if len(sys.argv) > 1 else "cells.stl", "w") as f:
    f.write("solid cells\n")
    for n, *v in tris:
        f.write(f"facet normal {n[0]} {n[1]} {n[2]}\n outer loop\n")
        for p in v:
            f.write(f"  vertex {p[0]:.6f} {p[1]:.6f} {p[2]:.6f}\n")
        f.write(" endloop\nendfacet\n")
    f.write("endsolid cells\n")
