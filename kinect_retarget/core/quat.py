"""Batched quaternion and rotation-matrix helpers. Quaternions are (..., 4) arrays (w, x, y, z), Hamilton.

All functions broadcast over leading axes and never loop over frames in Python.
"""
from __future__ import annotations

import numpy as np


def normalize(v: np.ndarray, eps: float = 1e-12) -> np.ndarray:
    n = np.sqrt(np.einsum("...i,...i->...", v, v))[..., None]  # einsum: one pass, no temporary
    return v / np.maximum(n, eps)


def mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product a * b (apply b first, then a)."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    aw, ax, ay, az = a[..., 0], a[..., 1], a[..., 2], a[..., 3]
    bw, bx, by, bz = b[..., 0], b[..., 1], b[..., 2], b[..., 3]
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = aw * bw - ax * bx - ay * by - az * bz
    out[..., 1] = aw * bx + ax * bw + ay * bz - az * by
    out[..., 2] = aw * by - ax * bz + ay * bw + az * bx
    out[..., 3] = aw * bz + ax * by - ay * bx + az * bw
    return out


def conjugate(q: np.ndarray) -> np.ndarray:
    return np.asarray(q, dtype=np.float64) * np.array([1.0, -1.0, -1.0, -1.0])


def to_matrix(q: np.ndarray) -> np.ndarray:
    """(..., 4) unit quaternions -> (..., 3, 3) rotation matrices."""
    w, x, y, z = np.moveaxis(np.asarray(q, dtype=np.float64), -1, 0)
    m = np.empty(w.shape + (3, 3))
    m[..., 0, 0] = 1 - 2 * (y * y + z * z)
    m[..., 0, 1] = 2 * (x * y - w * z)
    m[..., 0, 2] = 2 * (x * z + w * y)
    m[..., 1, 0] = 2 * (x * y + w * z)
    m[..., 1, 1] = 1 - 2 * (x * x + z * z)
    m[..., 1, 2] = 2 * (y * z - w * x)
    m[..., 2, 0] = 2 * (x * z - w * y)
    m[..., 2, 1] = 2 * (y * z + w * x)
    m[..., 2, 2] = 1 - 2 * (x * x + y * y)
    return m


def from_axes(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Quaternions (..., 4), w >= 0, of the rotations whose matrix columns are the unit axes x, y, z (..., 3).

    Where w is large the trace formula is exact and cheap; elsewhere (rotations beyond ~140°) the largest of
    the four components is the pivot, so the result stays exact near 180° too."""
    t = 1 + x[..., 0] + y[..., 1] + z[..., 2]  # 4w²
    big = t > 0.5
    s = 2 * np.sqrt(np.where(big, t, 1.0))  # 4w
    q = np.empty(t.shape + (4,))
    q[..., 0] = s / 4
    q[..., 1] = (y[..., 2] - z[..., 1]) / s
    q[..., 2] = (z[..., 0] - x[..., 2]) / s
    q[..., 3] = (x[..., 1] - y[..., 0]) / s
    if not np.all(big):
        small = ~big
        q[small] = _from_matrix_pivot(np.stack([x[small], y[small], z[small]], axis=-1))
    return q


def from_axis_angle(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """(..., 3) unit axes and (...,) angles (radians) -> (..., 4) quaternions."""
    half = np.asarray(angle)[..., None] / 2
    return np.concatenate([np.cos(half), np.sin(half) * axis], axis=-1)

def from_matrix(m: np.ndarray) -> np.ndarray:
    """(..., 3, 3) rotation matrices -> (..., 4) unit quaternions with w >= 0 (see from_axes)."""
    m = np.asarray(m, dtype=np.float64)
    return from_axes(m[..., :, 0], m[..., :, 1], m[..., :, 2])


def _from_matrix_pivot(m: np.ndarray) -> np.ndarray:
    """(N, 3, 3) -> (N, 4): divide by the largest of 4w², 4x², 4y², 4z² (robust at any angle)."""
    m00, m11, m22 = m[:, 0, 0], m[:, 1, 1], m[:, 2, 2]
    cand = np.stack([1 + m00 + m11 + m22, 1 + m00 - m11 - m22, 1 - m00 + m11 - m22, 1 - m00 - m11 + m22], -1)
    pick = np.argmax(cand, axis=-1)
    s = 2 * np.sqrt(np.maximum(cand[np.arange(len(m)), pick], 1e-300))  # 4 × the pivot component
    a, b, c = m[:, 2, 1] - m[:, 1, 2], m[:, 0, 2] - m[:, 2, 0], m[:, 1, 0] - m[:, 0, 1]
    d, e, f = m[:, 0, 1] + m[:, 1, 0], m[:, 0, 2] + m[:, 2, 0], m[:, 1, 2] + m[:, 2, 1]
    rows = np.stack([
        np.stack([s / 4, a / s, b / s, c / s], -1), np.stack([a / s, s / 4, d / s, e / s], -1),
        np.stack([b / s, d / s, s / 4, f / s], -1), np.stack([c / s, e / s, f / s, s / 4], -1)], 1)
    q = rows[np.arange(len(m)), pick]
    return q * np.where(q[:, :1] < 0, -1.0, 1.0)


def make_continuous(q: np.ndarray, axis: int = 0) -> np.ndarray:
    """Flip signs along `axis` (time) so consecutive quaternions lie in the same hemisphere.

    q and -q are the same rotation, but keys that jump between them interpolate the long way round.
    """
    q = np.asarray(q, dtype=np.float64)
    qt = np.moveaxis(q, axis, 0)
    if qt.shape[0] < 2:
        return q.copy()
    dots = np.sum(qt[1:] * qt[:-1], axis=-1)
    flips = np.concatenate([np.zeros((1,) + dots.shape[1:], dtype=bool), dots < 0], axis=0)
    sign = np.where(np.cumsum(flips, axis=0) % 2 == 1, -1.0, 1.0)
    return np.moveaxis(qt * sign[..., None], 0, axis)


def angle_between(q1: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """Rotation angle (radians) between two rotations; q and -q compare as equal."""
    r = mul(conjugate(normalize(q1)), normalize(q2))
    return 2 * np.arctan2(np.linalg.norm(r[..., 1:], axis=-1), np.abs(r[..., 0]))


def rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate (..., 3) vectors by (..., 4) quaternions."""
    return np.einsum("...ij,...j->...i", to_matrix(q), v)
