#!/usr/bin/env python3
"""Writes the corpus's meshes as the tools that publish robots write them.

Run from this folder (python3 make_meshes.py); the files are committed, the
script says how they were made. Standard library only.

- SolidWorks' STL export: binary, with an 80-byte header that starts with
  "solid" (the trap that makes naive readers take it for ASCII STL), upper-case
  .STL, one file per link named after it, coordinates in metres.
- A foot about its ankle as CAD gives it (a convex boot shape), and the boxes
  of a torso and a head, as binary STL with an ordinary header.
"""
import math
import os
import struct


def write_stl(path, triangles, header):
    header = header.encode()[:80].ljust(80, b" ")
    with open(path, "wb") as f:
        f.write(header)
        f.write(struct.pack("<I", len(triangles)))
        for a, b, c in triangles:
            u = [b[i] - a[i] for i in range(3)]
            v = [c[i] - a[i] for i in range(3)]
            n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
            length = math.sqrt(sum(x * x for x in n)) or 1.0
            f.write(struct.pack("<3f", *[x / length for x in n]))
            for p in (a, b, c):
                f.write(struct.pack("<3f", *p))
            f.write(struct.pack("<H", 0))


def hexahedron(bottom, top):
    """Triangles of the convex solid with quads `bottom` and `top` (counter-clockwise seen from above)."""
    tris = [(bottom[0], bottom[2], bottom[1]), (bottom[0], bottom[3], bottom[2]),
            (top[0], top[1], top[2]), (top[0], top[2], top[3])]
    for i in range(4):
        j = (i + 1) % 4
        tris += [(bottom[i], bottom[j], top[j]), (bottom[i], top[j], top[i])]
    return tris


def box(lx, ly, lz, centre=(0, 0, 0)):
    cx, cy, cz = centre
    quad = lambda z: [(cx - lx / 2, cy - ly / 2, z), (cx + lx / 2, cy - ly / 2, z),
                      (cx + lx / 2, cy + ly / 2, z), (cx - lx / 2, cy + ly / 2, z)]
    return hexahedron(quad(cz - lz / 2), quad(cz + lz / 2))


def wheel(radius, width, sides):
    """A flat-treaded wheel about its z axis, tessellated as CAD exports it."""
    ring = lambda z: [(radius * math.cos(2 * math.pi * k / sides), radius * math.sin(2 * math.pi * k / sides), z)
                      for k in range(sides)]
    lo, hi = ring(-width / 2), ring(width / 2)
    tris = []
    for k in range(sides):
        m = (k + 1) % sides
        tris += [(lo[k], lo[m], hi[m]), (lo[k], hi[m], hi[k])]
        tris += [((0, 0, -width / 2), lo[m], lo[k]), ((0, 0, width / 2), hi[k], hi[m])]
    return tris


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    sw = os.path.join(here, "ament/install/cart_description/share/cart_description/meshes")
    os.makedirs(sw, exist_ok=True)
    solid = lambda name: "solid " + name  # SolidWorks' binary header
    write_stl(os.path.join(sw, "base_link.STL"), box(0.4, 0.3, 0.1, (0, 0, 0.05)), solid("base_link"))
    for side in ("left", "right"):
        write_stl(os.path.join(sw, side + "_wheel_link.STL"), wheel(0.08, 0.03, 48), solid(side + "_wheel_link"))
    ros = os.path.join(here, "ros1/src/humanoids/biped/biped_description/meshes")
    os.makedirs(ros, exist_ok=True)
    write_stl(os.path.join(ros, "torso.stl"), box(0.25, 0.3, 0.4, (0, 0, 0.2)), "torso")
    write_stl(os.path.join(ros, "head.stl"), box(0.18, 0.16, 0.2), "head")
    # The foot about the ankle axis (y): a sole 0.22 × 0.1 m, 0.1 m below the
    # ankle, narrowing to the 0.08 × 0.08 m ankle block 0.03 m above it.
    boot = hexahedron([(-0.08, -0.05, -0.1), (0.14, -0.05, -0.1), (0.14, 0.05, -0.1), (-0.08, 0.05, -0.1)],
                      [(-0.04, -0.04, 0.03), (0.04, -0.04, 0.03), (0.04, 0.04, 0.03), (-0.04, 0.04, 0.03)])
    write_stl(os.path.join(ros, "foot.stl"), boot, "foot")


if __name__ == "__main__":
    main()
