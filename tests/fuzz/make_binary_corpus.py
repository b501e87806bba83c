#!/usr/bin/env python3
"""Writes the binary inputs of tests/fuzz/corpus (run from anywhere; output is fixed).

convex_detect: two shapes, then two poses, in the decoding of convex_detect.cpp:
  per shape: u8 scale (2^(b % 25 - 12) m), u8 count (4 + b % 13 points), 3 x i8 per point
  (coordinate = b / 8 * scale); per pose: 3 x i8 position (b / 64 * reach, reach = the two
  bounding-box diagonals added), 4 x i8 quaternion w, x, y, z (normalised; all zero = identity).
obj_loader (array half): u8 vertex count (b % 33), 3 x i8 per vertex (b / 8 m; -128 escapes to a
  raw double), u8 triangle count (b % 65), 3 x i8 indices per triangle.
"""
import math
import os
import random
import struct

HERE = os.path.dirname(os.path.abspath(__file__))


def i8(v):
    return struct.pack("b", int(v))


def shape(points, scale_exp=0):
    assert 4 <= len(points) <= 16
    out = bytes([scale_exp + 12, len(points) - 4])
    for p in points:
        for c in p:
            out += i8(round(c * 8))
    return out


def diagonal(points, scale_exp=0):
    lo = [min(p[i] for p in points) for i in range(3)]
    hi = [max(p[i] for p in points) for i in range(3)]
    return math.dist(lo, hi) * 2**scale_exp


def pose(position, q, reach):
    out = b""
    for c in position:
        out += i8(max(-128, min(127, round(c / reach * 64))))
    for c in q:
        out += i8(c)
    return out


def box(hx, hy, hz):
    return [(sx * hx, sy * hy, sz * hz) for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]


def write(folder, name, data):
    os.makedirs(os.path.join(HERE, "corpus", folder), exist_ok=True)
    with open(os.path.join(HERE, "corpus", folder, name), "wb") as f:
        f.write(data)


def pair(name, pts_a, pts_b, pos_a, q_a, pos_b, q_b, exp_a=0, exp_b=0):
    reach = diagonal(pts_a, exp_a) + diagonal(pts_b, exp_b)
    data = shape(pts_a, exp_a) + shape(pts_b, exp_b)
    data += pose(pos_a, q_a, reach) + pose(pos_b, q_b, reach)
    write("convex_detect", name, data)


IDENTITY = (1, 0, 0, 0)
CUBE = box(0.5, 0.5, 0.5)
TETRA = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
OCTA = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]

pair("face_face", CUBE, box(0.5, 0.4, 0.4), (0, 0, 0), IDENTITY, (0.9, 0, 0), IDENTITY)
pair("vertex_into_face", CUBE, TETRA, (0, 0, 0), IDENTITY, (0.45, 0.1, 0.1), IDENTITY)
pair("edge_edge_crossed", box(1, 0.125, 0.125), box(1, 0.125, 0.125), (0, 0, 0), IDENTITY,
     (0, 0, 0.22), (1, 0, 0, 1))
pair("separated", CUBE, CUBE, (0, 0, 0), IDENTITY, (2, 0, 0), IDENTITY)
pair("touching", CUBE, CUBE, (0, 0, 0), IDENTITY, (1, 0, 0), IDENTITY)
pair("octahedron_rotated", OCTA, CUBE, (0, 0, 0), (1, 1, 0, 0), (0, 0, 1.2), (1, 0, 0, 1))
pair("plate_and_small_cube", box(4, 4, 0.125), CUBE, (0, 0, 0), IDENTITY, (0, 0, 0.14),
     IDENTITY, 0, -4)
pair("corner_down", CUBE, box(2, 2, 0.5), (0, 0, 0.3), (3, 1, -1, 0), (0, 0, -0.7), IDENTITY)
rng = random.Random(7)  # fixed seed
for k in range(4):
    def cloud():
        return [tuple(rng.randint(-8, 8) / 8 for _ in range(3)) for _ in range(rng.randint(6, 14))]
    pair("random_%d" % k, cloud(), cloud(), (0, 0, 0),
         tuple(rng.randint(-5, 5) for _ in range(4)),
         tuple(rng.uniform(-1, 1) for _ in range(3)), tuple(rng.randint(-5, 5) for _ in range(4)))


def mesh(name, vertices, triangles):
    data = bytes([len(vertices)])
    for v in vertices:
        for c in v:
            data += i8(round(c * 8))
    data += bytes([len(triangles)])
    for t in triangles:
        for k in t:
            data += i8(k)
    write("obj_loader", name, data)


# The engine's box triangulation (engine/polyhedron.cpp make_box), vertex i at (+-, +-, +-)
# by bits x = 1, y = 2, z = 4.
mesh("array_cube", [((i & 1) - 0.5, ((i >> 1) & 1) - 0.5, ((i >> 2) & 1) - 0.5) for i in range(8)],
     [(0, 4, 6), (0, 6, 2), (1, 3, 7), (1, 7, 5), (0, 1, 5), (0, 5, 4), (2, 6, 7), (2, 7, 3),
      (0, 2, 3), (0, 3, 1), (4, 5, 7), (4, 7, 6)])
mesh("array_tetra", TETRA, [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)])
mesh("array_tetra_inward", TETRA, [(0, 1, 2), (0, 3, 1), (0, 2, 3), (1, 3, 2)])
mesh("array_open", TETRA, [(0, 2, 1), (0, 1, 3), (0, 3, 2)])
