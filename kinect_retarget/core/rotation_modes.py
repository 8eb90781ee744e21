"""Quaternions to the rotation channel a pose bone already uses, so baking never changes its rotation mode.

Blender's Euler order 'XYZ' applies X first: R = Rz · Ry · Rx (column vectors).
"""
from __future__ import annotations

import numpy as np

from .quat import to_matrix

EULER_ORDERS = ("XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX")


def quat_to_euler(q: np.ndarray, order: str) -> np.ndarray:
    """(..., 4) wxyz -> (..., 3) Euler angles (x, y, z components, radians) for Blender's `order`,
    unwrapped along axis 0 so keys never jump by 2π."""
    if order not in EULER_ORDERS:
        raise ValueError(f"unknown Euler order {order!r}")
    m = to_matrix(q)
    i, j, k = ("XYZ".index(c) for c in order)
    s = 1.0 if (i, j, k) in ((0, 1, 2), (1, 2, 0), (2, 0, 1)) else -1.0
    first = np.arctan2(s * m[..., k, j], m[..., k, k])
    middle = np.arcsin(np.clip(-s * m[..., k, i], -1.0, 1.0))
    last = np.arctan2(s * m[..., j, i], m[..., i, i])
    out = np.empty(m.shape[:-2] + (3,))
    out[..., i], out[..., j], out[..., k] = first, middle, last
    return np.unwrap(out, axis=0) if out.ndim > 1 and out.shape[0] > 1 else out


def quat_to_axis_angle(q: np.ndarray) -> np.ndarray:
    """(..., 4) wxyz -> (..., 4) Blender axis-angle (angle, x, y, z). The quaternion's sign is kept (angles
    run past 180° rather than flipping the axis), so sign-continuous quaternions give continuous keys."""
    q = np.asarray(q, dtype=np.float64)
    s = np.linalg.norm(q[..., 1:], axis=-1, keepdims=True)
    axis = np.where(s > 1e-12, q[..., 1:] / np.maximum(s, 1e-12), np.array([0.0, 1.0, 0.0]))
    angle = 2 * np.arctan2(s[..., 0], q[..., 0])
    return np.concatenate([angle[..., None], axis], axis=-1)


def channel_values(q: np.ndarray, rotation_mode: str) -> tuple[str, np.ndarray]:
    """(data path suffix, values (..., n)) for a pose bone's rotation mode."""
    if rotation_mode == "QUATERNION":
        return "rotation_quaternion", q
    if rotation_mode == "AXIS_ANGLE":
        return "rotation_axis_angle", quat_to_axis_angle(q)
    return "rotation_euler", quat_to_euler(q, rotation_mode)
