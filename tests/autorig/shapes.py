"""Small synthetic meshes for the auto-rig tests (seeded, deterministic)."""
from __future__ import annotations

import numpy as np


def grid_mesh(n: int, rng: np.random.Generator, jitter: float = 0.3):
    """An n x n vertex sheet of triangles with jittered vertices (uneven edge lengths)."""
    u, v = np.meshgrid(np.arange(n, dtype=float), np.arange(n, dtype=float))
    verts = np.stack([u.ravel(), v.ravel(), np.zeros(n * n)], axis=1)
    verts[:, :2] += rng.uniform(-jitter, jitter, (n * n, 2))
    verts[:, 2] = rng.uniform(-0.5, 0.5, n * n)
    i = np.arange(n - 1)
    a = (i[:, None] * n + i[None, :]).ravel()
    faces = np.concatenate([np.stack([a, a + 1, a + n], 1), np.stack([a + 1, a + n + 1, a + n], 1)])
    return verts, faces


def spiky_sphere(directions: np.ndarray, subdivisions: int = 40, spike=3.0):
    """A UV sphere pulled out into one spike per direction (a star: not a human); `spike`: length, one for
    all or one per direction."""
    th, ph = np.meshgrid(np.linspace(0, np.pi, subdivisions), np.linspace(0, 2 * np.pi, 2 * subdivisions,
                                                                            endpoint=False), indexing="ij")
    unit = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1).reshape(-1, 3)
    d = directions / np.linalg.norm(directions, axis=1, keepdims=True)
    lengths = np.broadcast_to(np.asarray(spike, dtype=float), (len(d),))
    r = 1 + (lengths * np.exp(-(np.arccos(np.clip(unit @ d.T, -1, 1)) ** 2) / 0.04)).sum(axis=1)
    verts = unit * r[:, None]
    rows, cols = subdivisions, 2 * subdivisions
    i, j = np.meshgrid(np.arange(rows - 1), np.arange(cols), indexing="ij")
    a = (i * cols + j).ravel()
    b = (i * cols + (j + 1) % cols).ravel()
    faces = np.concatenate([np.stack([a, b, a + cols], 1), np.stack([b, b + cols, a + cols], 1)])
    # merge the duplicated pole vertices so the surface is one closed piece
    key = np.round(verts, 9)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    faces = inverse.reshape(-1)[faces]
    faces = faces[(faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])]
    return verts[first], faces
