"""Other bodies from MakeHuman's redistributable mesh (CC0), for checking the auto-rig beyond the one body
its proportions were measured on: changed proportions, decimated, re-triangulated, re-posed.

Each is mirror-symmetric in its surface (MakeHuman's base mesh is, about x = 0) but not necessarily in its
triangulation, like the bodies of other parametric families. The reference joints move with the surface
(`reshape_points` applies the same map to them).
"""
from __future__ import annotations

import numpy as np

from ..autorig.mesh import Mesh


def _quads(faces: np.ndarray) -> tuple[np.ndarray, ...]:
    """MakeHuman's quads back from their fan triangles (a, b, c), (a, c, d)."""
    t0, t1 = faces[0::2], faces[1::2]
    if len(t0) != len(t1) or not np.all((t0[:, 0] == t1[:, 0]) & (t0[:, 2] == t1[:, 1])):
        raise ValueError("faces are not fan-triangulated quads")
    return t0[:, 0], t0[:, 1], t0[:, 2], t1[:, 2]


def _split(a, b, c, d, along_ac: np.ndarray) -> np.ndarray:
    return np.concatenate([np.stack([a, b, c], 1)[along_ac], np.stack([a, c, d], 1)[along_ac],
                           np.stack([a, b, d], 1)[~along_ac], np.stack([b, c, d], 1)[~along_ac]])


def one_sided_diagonals(mesh: Mesh) -> Mesh:
    """Every quad of the character's left half split along one diagonal, of the right half along the other:
    the surface stays mirror-symmetric, its triangulation is nowhere mirrored."""
    a, b, c, d = _quads(mesh.faces)
    left = mesh.vertices[a, 0] + mesh.vertices[c, 0] > 0
    return Mesh(mesh.vertices, _split(a, b, c, d, left), mesh.name + "-one-sided-diagonals")


def random_diagonals(mesh: Mesh, rng: np.random.Generator) -> Mesh:
    """Each quad split along a diagonal drawn at random."""
    a, b, c, d = _quads(mesh.faces)
    return Mesh(mesh.vertices, _split(a, b, c, d, rng.random(len(a)) < 0.5), mesh.name + "-random-diagonals")


def reshape_points(points: np.ndarray, bounds: tuple[float, float], width: float = 1.15, depth: float = 1.1,
                   legs: float = 1.12, upper: float = 0.95) -> np.ndarray:
    """Other proportions (OBJ axes: x left, y up, z front): broader and deeper, the lower half of the body
    (`bounds` = its lowest and highest y) longer and the upper half shorter, mirror symmetry kept."""
    lo, hi = bounds
    mid = lo + 0.5 * (hi - lo)
    out = np.array(points, dtype=np.float64)
    out[..., 0] *= width
    out[..., 2] *= depth
    y = out[..., 1]
    out[..., 1] = np.where(y < mid, mid - (mid - y) * legs, mid + (y - mid) * upper)
    return out


def reshaped(mesh: Mesh) -> Mesh:
    y = mesh.vertices[:, 1]
    return Mesh(reshape_points(mesh.vertices, (y.min(), y.max())), mesh.faces, mesh.name + "-reshaped")


def decimated(mesh: Mesh, cell: float) -> Mesh:
    """Vertex clustering on a grid of `cell`-wide cubes centred on the mirror plane x = 0: the vertices in a
    cube merge into their mean, collapsed and repeated triangles go."""
    v = mesh.vertices
    key = np.floor((v - [-cell / 2, v[:, 1].min(), v[:, 2].min()]) / cell).astype(np.int64)
    _, cluster = np.unique(key, axis=0, return_inverse=True)
    cluster = cluster.ravel()
    n = int(cluster.max()) + 1
    merged = np.stack([np.bincount(cluster, v[:, k], n) for k in range(3)], axis=1) / np.bincount(cluster)[:, None]
    f = cluster[mesh.faces]
    f = f[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])]
    _, first = np.unique(np.sort(f, axis=1), axis=0, return_index=True)
    f = f[np.sort(first)]
    used = np.unique(f)
    remap = np.full(n, -1)
    remap[used] = np.arange(len(used))
    return Mesh(merged[used], remap[f], mesh.name + "-decimated")
