#!/usr/bin/python3
"""Force balance of the granules in the loaded hollow box (hollow_box.yaml), from OUT/wall.csv:
the forces the FE box received on its six inner faces, averaged over the last 20 % of the rows.
At (quasi-static) rest the granules are in equilibrium: the box's inner faces carry their weight
(sum of the six z-forces = -m g) and no net horizontal force (the push on the loaded wall comes
back on the far wall and through friction on the others).

Usage: balance.py OUT  ->  key=value lines:
  weight_balance      = -(sum of the z-forces) / (m g)            (expected 1)
  horizontal_balance  = |sum of the x-forces| / |force on the loaded wall|   (expected 0)
  applied_load_N      = -box.static_reaction_x: the pressure times the end face (500 kPa x 9 cm^2)"""
import csv
import os
import sys

FACES = ["near", "far", "side_ymin", "side_ymax", "floor", "lid"]


def main():
    with open(os.path.join(sys.argv[1], "wall.csv")) as f:
        rows = list(csv.DictReader(f))
    rows = rows[len(rows) - max(1, len(rows) // 5):]
    mean = {k.split(" [")[0]: sum(float(r[k]) for r in rows) / len(rows) for k in rows[0]}
    weight = mean["granules.mass"] * 9.81
    fz = sum(mean[f"box.{f}.force_z"] for f in FACES)
    fx = sum(mean[f"box.{f}.force_x"] for f in FACES)
    print(f"weight_balance={-fz / weight:.6f}")
    print(f"horizontal_balance={abs(fx) / abs(mean['box.near.force_x']):.6f}")
    print(f"applied_load_N={-mean['box.static_reaction_x']:.6f}")
    print(f"near_wall_force_N={mean['box.near.force_x']:.6f}")
    print(f"far_wall_force_N={mean['box.far.force_x']:.6f}")


if __name__ == "__main__":
    main()
