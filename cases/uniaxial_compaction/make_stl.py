#!/usr/bin/python3
"""Write plate_bottom.stl: the lower face of the 20 x 20 mm plate at z = 20 mm as a binary STL,
16 x 16 cells split into 512 triangles with normals facing down (towards the granules).
The FE side meshes the same face with 20 x 20 quadrilaterals: the two meshes do not match,
as in seed 000. Usage: python3 make_stl.py [N] [SIZE_M] [Z_M] [OUT]"""
import struct
import sys

n = int(sys.argv[1]) if len(sys.argv) > 1 else 16
size = float(sys.argv[2]) if len(sys.argv) > 2 else 0.02
z = float(sys.argv[3]) if len(sys.argv) > 3 else 0.02
out = sys.argv[4] if len(sys.argv) > 4 else "plate_bottom.stl"
h = size / n
tris = []
for j in range(n):
    for i in range(n):
        a, b = (i * h, j * h, z), ((i + 1) * h, j * h, z)
        c, d = (i * h, (j + 1) * h, z), ((i + 1) * h, (j + 1) * h, z)
        tris += [(a, d, b), (a, c, d)]  # clockwise seen from above: normal -z
with open(out, "wb") as f:
    f.write(b"partita uniaxial compaction: plate bottom".ljust(80, b" "))
    f.write(struct.pack("<I", len(tris)))
    for t in tris:
        f.write(struct.pack("<3f", 0.0, 0.0, -1.0))
        for v in t:
            f.write(struct.pack("<3f", *v))
        f.write(struct.pack("<H", 0))
