"""Procedural meshes for the render and bake tests (no shared data needed)."""
from __future__ import annotations

from typing import Tuple

import numpy as np


def torus(major: int = 40, minor: int = 20, radius: float = 1.0,
          tube: float = 0.4) -> Tuple[np.ndarray, np.ndarray]:
    """A closed, outward-oriented torus around the z axis: ``major`` x ``minor`` quads split
    into triangles. Returns (vertices float64 (major*minor, 3), faces int64 (2*major*minor, 3))."""
    i, j = np.meshgrid(np.arange(major), np.arange(minor), indexing="ij")
    u = 2 * np.pi * i.ravel() / major
    v = 2 * np.pi * j.ravel() / minor
    ring = radius + tube * np.cos(v)
    verts = np.stack([ring * np.cos(u), ring * np.sin(u), tube * np.sin(v)], axis=1)
    a = (i * minor + j).ravel()
    b = (((i + 1) % major) * minor + j).ravel()
    c = (((i + 1) % major) * minor + (j + 1) % minor).ravel()
    d = (i * minor + (j + 1) % minor).ravel()
    faces = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    return verts, faces


def obj_bytes(vertices: np.ndarray, faces: np.ndarray) -> bytes:
    """An OBJ file of the mesh (positions written with 17 significant digits)."""
    lines = [f"v {x:.17g} {y:.17g} {z:.17g}" for x, y, z in np.asarray(vertices, float)]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in np.asarray(faces, int)]
    return ("\n".join(lines) + "\n").encode()
