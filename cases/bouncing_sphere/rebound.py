#!/usr/bin/python3
"""The rebound of cases/bouncing_sphere: reads DIR/sphere.csv (the sphere's centre height z and
vertical velocity every window) and prints key=value lines:
  drop_height_m     bottom of the sphere above the plane at the start (z0 - R)
  rebound_height_m  highest bottom after the first impact (z_max - R)
  rebound_ratio     rebound / drop height: e^2 = 0.25 for e = 0.5
Usage: rebound.py OUTPUT_DIR"""
import csv
import sys

R = 0.005  # the sphere's radius (sphere.data)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "out/bouncing-sphere"
    with open(f"{out}/sphere.csv") as f:
        rows = list(csv.reader(f))
    head = rows[0]
    iz = next(i for i, h in enumerate(head) if h.startswith("ball.particle.1.z "))
    ivz = next(i for i, h in enumerate(head) if h.startswith("ball.particle.1.vz "))
    z = [float(r[iz]) for r in rows[1:]]
    vz = [float(r[ivz]) for r in rows[1:]]
    # the first impact: the first row moving up after moving down
    hit = next(k for k in range(1, len(vz)) if vz[k - 1] < 0.0 <= vz[k])
    # the apex: the highest row before the sphere falls back onto the plane
    fall = next((k for k in range(hit + 1, len(vz)) if vz[k] < 0.0), None)
    if fall is None:
        sys.exit("rebound.py: the run ends before the apex of the first rebound")
    apex = max(z[hit:fall + 1])
    drop = z[0] - R
    print(f"drop_height_m={drop:.9g}")
    print(f"rebound_height_m={apex - R:.9g}")
    print(f"rebound_ratio={(apex - R) / drop:.9g}")


if __name__ == "__main__":
    main()
