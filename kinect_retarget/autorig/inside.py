"""Inside/outside test for points against a triangle mesh: the generalized winding number (robust to the
small holes body meshes have at the eyes, mouth or neck)."""
from __future__ import annotations

import numpy as np


def winding_number(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(P,) winding number of the surface around each point: about 1 inside a closed surface, 0 outside."""
    out = np.zeros(len(points))
    tri = vertices[faces]                                  # (T, 3, 3)
    for i, p in enumerate(np.asarray(points, dtype=np.float64)):  # P is small (joints); T is vectorised
        a, b, c = (tri[:, k] - p for k in range(3))
        la, lb, lc = (np.linalg.norm(x, axis=1) for x in (a, b, c))
        det = np.einsum("ij,ij->i", a, np.cross(b, c))
        den = la * lb * lc + (a * b).sum(1) * lc + (b * c).sum(1) * la + (c * a).sum(1) * lb
        out[i] = np.arctan2(det, den).sum() * 2 / (4 * np.pi)  # Van Oosterom-Strackee solid angle
    return np.abs(out)


def inside_mesh(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    return winding_number(points, vertices, faces) > 0.5
