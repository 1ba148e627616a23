#!/usr/bin/env python3
"""Writes a large mesh scene for timing the HTML viewer (docs/viewer.md): two tori side by side of
N x N quads each (2 N^2 triangles), split into 8 x 8 OBJ groups (surfaces), whose tubes overlap by
5 mm at one spot. Usage: make_large_scene.py OUT_DIR [N]  (N = 500 gives ~1 M triangles in all)."""
import math
import os
import sys


def torus(path, name, n, centre, big_r=100.0, small_r=25.0, patches=8):
    with open(path, "w") as f:
        f.write(f"# {name}: torus R={big_r} r={small_r}, {n}x{n} quads, {patches}x{patches} groups\n")
        for i in range(n):
            u = 2 * math.pi * i / n
            for j in range(n):
                v = 2 * math.pi * j / n
                rr = big_r + small_r * math.cos(v)
                x, y, z = rr * math.cos(u), rr * math.sin(u), small_r * math.sin(v)
                f.write(f"v {x + centre[0]:.6f} {y + centre[1]:.6f} {z + centre[2]:.6f}\n")
        step = n // patches
        for pi in range(patches):
            for pj in range(patches):
                f.write(f"g patch_{pi}_{pj}\n")
                for i in range(pi * step, n if pi == patches - 1 else (pi + 1) * step):
                    for j in range(pj * step, n if pj == patches - 1 else (pj + 1) * step):
                        a = i * n + j + 1
                        b = ((i + 1) % n) * n + j + 1
                        c = ((i + 1) % n) * n + (j + 1) % n + 1
                        d = i * n + (j + 1) % n + 1
                        f.write(f"f {a} {b} {c} {d}\n")


def main():
    out = sys.argv[1]
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 500
    os.makedirs(out, exist_ok=True)
    torus(os.path.join(out, "torus_a.obj"), "torus_a", n, (0.0, 0.0, 0.0))
    # 2 (R + r) - 5 apart: the tubes cross by 5 mm around x = 122.5, a few penetrating patch pairs.
    torus(os.path.join(out, "torus_b.obj"), "torus_b", n, (245.0, 0.0, 0.0))


if __name__ == "__main__":
    main()
