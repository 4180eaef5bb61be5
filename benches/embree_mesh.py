#!/usr/bin/env python3
"""Embree's nearest hits on the blob `cargo bench --bench engine -- mesh_262k`
times in GI Studio: the same mesh (a sphere of 256 x 512 quads, radius
rippled) and rays drawn the same way (from a sphere of radius 3 into a ball
of radius 0.9), one thread, Embree through embreex (a tool to check
against, never a dependency of the binary).

    python3 -m venv ../venv-embree && ../venv-embree/bin/pip install embreex numpy
    ../venv-embree/bin/python benches/embree_mesh.py
    cargo bench --bench engine -- mesh_262k
"""
import math
import time

import numpy as np
from embreex import rtcore_scene, mesh_construction


def blob(rings):
    i, j = np.meshgrid(np.arange(rings + 1), np.arange(2 * rings + 1), indexing="ij")
    theta, phi = math.pi * i / rings, math.pi * j / rings
    r = 1.0 + 0.1 * np.sin(7.0 * theta) * np.cos(5.0 * phi)
    points = np.stack([np.sin(theta) * np.cos(phi), np.cos(theta), np.sin(theta) * np.sin(phi)], -1) * r[..., None]
    a, b = points[:-1, :-1], points[1:, :-1]
    c, d = points[1:, 1:], points[:-1, 1:]
    first = np.stack([a, c, b], -2).reshape(-1, 3, 3)
    second = np.stack([a, d, c], -2).reshape(-1, 3, 3)
    return np.concatenate([first, second]).astype(np.float32)


def uniform_sphere(rng, n):
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


triangles = blob(256)
scene = rtcore_scene.EmbreeScene()
mesh_construction.TriangleMesh(scene, triangles)
rng = np.random.default_rng(3)
n = 100_000
origins = (uniform_sphere(rng, n) * 3.0).astype(np.float32)
targets = uniform_sphere(rng, n) * 0.9 * np.cbrt(rng.random((n, 1)))
directions = (targets - origins)
directions = (directions / np.linalg.norm(directions, axis=1, keepdims=True)).astype(np.float32)
scene.run(origins, directions)  # builds the BVH and warms up
times = []
for _ in range(9):
    start = time.perf_counter()
    hits = scene.run(origins, directions)
    times.append(time.perf_counter() - start)
median = sorted(times)[len(times) // 2]
print(f"{len(triangles)} triangles, {n} rays, {int((hits >= 0).sum())} hit: "
      f"median {median * 1e3:.1f} ms, {n / median / 1e6:.2f} M rays/s (Embree, one thread)")
