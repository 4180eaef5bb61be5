#!/usr/bin/env python3
"""Writes the meshes the built-in scenes use (standard library only, the
same bytes on every run):

- cornell-white.obj, cornell-red.obj, cornell-green.obj: the Cornell box's
  room as finite walls (floor, ceiling and back wall; the left wall; the
  right wall), one file a material as in Mitsuba's own Cornell box. The
  room is x in [-1, 1], y in [0, 2], z in [-1, 1.6]: deep enough that the
  camera of assets/scenes/cornell.ron sees only the room, open at the front.
- torus-knot.ply: a (2, 3) torus knot, a tube swept along the knot, closed
  (every edge shared by two triangles), wound so that the normals point
  out of the tube; binary little-endian.

    python3 assets/meshes/make_meshes.py
"""

import math
import struct
from pathlib import Path

HERE = Path(__file__).resolve().parent


def quad(lo_hi_corners):
    """Two triangles of a rectangle given as four corners in winding order."""
    a, b, c, d = lo_hi_corners
    return [(a, b, c), (a, c, d)]


def write_obj(name, comment, faces):
    vertices, lines = [], [f"# {comment}", "# written by make_meshes.py"]
    for face in faces:
        for v in face:
            if v not in vertices:
                vertices.append(v)
    lines += ["v {} {} {}".format(*v) for v in vertices]
    lines += ["f {} {} {}".format(*(vertices.index(v) + 1 for v in face)) for face in faces]
    (HERE / name).write_text("\n".join(lines) + "\n")


def cornell_room():
    x0, x1, y0, y1, z0, z1 = -1, 1, 0, 2, -1, 1.6
    # Each wall wound so that its normal points into the room
    floor = quad([(x0, y0, z0), (x0, y0, z1), (x1, y0, z1), (x1, y0, z0)])
    ceiling = quad([(x0, y1, z0), (x1, y1, z0), (x1, y1, z1), (x0, y1, z1)])
    back = quad([(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0)])
    left = quad([(x0, y0, z0), (x0, y1, z0), (x0, y1, z1), (x0, y0, z1)])
    right = quad([(x1, y0, z0), (x1, y0, z1), (x1, y1, z1), (x1, y1, z0)])
    write_obj("cornell-white.obj", "the Cornell box's floor, ceiling and back wall", floor + ceiling + back)
    write_obj("cornell-red.obj", "the Cornell box's left wall", left)
    write_obj("cornell-green.obj", "the Cornell box's right wall", right)


def torus_knot(p=2, q=3, along=384, around=48, tube=0.35):
    def curve(t):
        r = 2.0 + math.cos(q * t)
        return (r * math.cos(p * t), r * math.sin(p * t), -math.sin(q * t))

    def sub(a, b):
        return tuple(x - y for x, y in zip(a, b))

    def cross(a, b):
        return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])

    def unit(a):
        n = math.sqrt(sum(x * x for x in a))
        return tuple(x / n for x in a)

    vertices = []
    step = 2.0 * math.pi / along
    for i in range(along):
        t = i * step
        c = curve(t)
        # A frame from the curve's tangent and its second difference
        tangent = unit(sub(curve(t + 1e-4), curve(t - 1e-4)))
        bend = sub(sub(curve(t + 1e-3), c), sub(c, curve(t - 1e-3)))
        binormal = unit(cross(tangent, bend))
        normal = cross(binormal, tangent)
        for j in range(around):
            v = 2.0 * math.pi * j / around
            offset = [tube * (math.cos(v) * n + math.sin(v) * b) for n, b in zip(normal, binormal)]
            vertices.append(tuple(x + o for x, o in zip(c, offset)))
    faces = []
    for i in range(along):
        for j in range(around):
            a = i * around + j
            b = ((i + 1) % along) * around + j
            c = ((i + 1) % along) * around + (j + 1) % around
            d = i * around + (j + 1) % around
            faces += [(a, b, c), (a, c, d)]
    # Wind outward: the first face's normal against the way out of the tube
    a, b, c = (vertices[k] for k in faces[0])
    outward = sub(a, curve(0.0))
    if sum(x * y for x, y in zip(cross(sub(b, a), sub(c, a)), outward)) < 0:
        faces = [(a, c, b) for a, b, c in faces]
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        "comment a (2, 3) torus knot written by make_meshes.py\n"
        f"element vertex {len(vertices)}\nproperty float x\nproperty float y\nproperty float z\n"
        f"element face {len(faces)}\nproperty list uchar uint vertex_indices\nend_header\n"
    )
    body = b"".join(struct.pack("<3f", *v) for v in vertices)
    body += b"".join(struct.pack("<B3I", 3, *f) for f in faces)
    (HERE / "torus-knot.ply").write_bytes(header.encode() + body)


if __name__ == "__main__":
    cornell_room()
    torus_knot()
