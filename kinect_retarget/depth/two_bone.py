"""Two-bone inverse kinematics: where the middle joint (elbow, knee) can be, given the root, the end and the
two bone lengths."""
from __future__ import annotations

import numpy as np

from ..core.quat import normalize


def unit(v):
    """v / |v| (core.quat.normalize with this module's threshold)."""
    return normalize(v, 1e-9)


def two_bone_candidates(a: np.ndarray, c: np.ndarray, l1: float, l2: float, n: int = 16):
    """Middle-joint candidates (n, 3) for root a, end c and bone lengths l1, l2, plus the end clamped to
    reach."""
    v = c - a
    d = np.linalg.norm(v)
    if d < 1e-6:
        v, d = np.array([0.0, -1.0, 0.0]), 1e-6
    u = v / d
    if d >= l1 + l2 - 1e-6:  # out of reach: straight limb
        return (a + u * l1)[None], a + u * (l1 + l2)
    if d <= abs(l1 - l2):
        d = abs(l1 - l2) + 1e-6
    x = (d * d + l1 * l1 - l2 * l2) / (2 * d)
    r = np.sqrt(max(l1 * l1 - x * x, 0.0))
    ref = np.array([0.0, 0.0, 1.0]) if abs(u[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    e1 = unit(np.cross(u, ref))
    e2 = np.cross(u, e1)
    ang = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return a + u * x + r * (np.cos(ang)[:, None] * e1 + np.sin(ang)[:, None] * e2), a + u * d
