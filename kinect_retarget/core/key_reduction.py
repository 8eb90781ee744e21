"""Key reduction within a stated tolerance: drop keys that linear interpolation between the kept ones
reproduces to within `deg` degrees (rotations) or `mm` millimetres (root location).

The error is measured the way Blender plays the keys back: each F-Curve component is interpolated linearly
(Euler angles, axis-angle, or quaternion components that Blender normalises), and the result is compared as
a rotation with the original one. Douglas-Peucker: the key with the largest error splits a span until every
span is within tolerance, so the first and last keys always stay."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .quat import to_matrix
from .rotation_modes import EULER_ORDERS


def _axis_matrix(axis: int, angle: np.ndarray) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    m = np.zeros(angle.shape + (3, 3))
    j, k = (axis + 1) % 3, (axis + 2) % 3  # cyclic, so every axis turns counter-clockwise
    m[..., axis, axis] = 1.0
    m[..., j, j], m[..., j, k], m[..., k, j], m[..., k, k] = c, -s, s, c
    return m


def channel_matrices(values: np.ndarray, rotation_mode: str) -> np.ndarray:
    """(..., n) F-Curve values of a pose bone's rotation channel -> (..., 3, 3) as Blender evaluates them."""
    if rotation_mode == "QUATERNION":
        q = values / np.maximum(np.linalg.norm(values, axis=-1, keepdims=True), 1e-12)
        return to_matrix(q)
    if rotation_mode == "AXIS_ANGLE":
        angle, axis = values[..., 0], values[..., 1:]
        axis = axis / np.maximum(np.linalg.norm(axis, axis=-1, keepdims=True), 1e-12)
        half = angle / 2
        q = np.concatenate([np.cos(half)[..., None], np.sin(half)[..., None] * axis], axis=-1)
        return to_matrix(q)
    if rotation_mode not in EULER_ORDERS:
        raise ValueError(f"unknown rotation mode {rotation_mode!r}")
    m = np.broadcast_to(np.eye(3), values.shape[:-1] + (3, 3))
    for c in rotation_mode:  # 'XYZ' applies X first: R = Rz · Ry · Rx
        a = "XYZ".index(c)
        m = _axis_matrix(a, values[..., a]) @ m
    return m


def rotation_error(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angle (radians) between rotation matrices (..., 3, 3)."""
    r = np.swapaxes(a, -1, -2) @ b
    skew = np.stack([r[..., 2, 1] - r[..., 1, 2], r[..., 0, 2] - r[..., 2, 0], r[..., 1, 0] - r[..., 0, 1]], -1)
    trace = r[..., 0, 0] + r[..., 1, 1] + r[..., 2, 2]
    return np.arctan2(np.linalg.norm(skew, axis=-1), trace - 1)


def reduce_track(frames: np.ndarray, values: np.ndarray, error, tolerance: float) -> tuple[np.ndarray, float]:
    """Keys (indices, ascending) of `values` (N, C) at `frames` (N,) to keep so that linear interpolation
    stays within `tolerance` of every original key by `error(original (K, C), approx (K, C)) -> (K,)`, and the
    largest error left."""
    n = len(frames)
    if n <= 2:
        return np.arange(n), 0.0
    keep = np.zeros(n, dtype=bool)
    keep[[0, n - 1]] = True
    worst = 0.0
    spans = [(0, n - 1)]
    while spans:
        i, j = spans.pop()
        if j - i < 2:
            continue
        u = ((frames[i + 1:j] - frames[i]) / (frames[j] - frames[i]))[:, None]
        approx = values[i] * (1 - u) + values[j] * u
        err = error(values[i + 1:j], approx)
        k = int(np.argmax(err))
        if err[k] > tolerance:
            m = i + 1 + k
            keep[m] = True
            spans += [(i, m), (m, j)]
        else:
            worst = max(worst, float(err[k]))
    return np.flatnonzero(keep), worst


@dataclass
class Reduction:
    """Kept key indices per rotation track, for the root location and for each other keyed location (root
    motion's root bone), keys removed, and the largest error left (degrees, millimetres)."""
    rotation_keys: list[np.ndarray]
    location_keys: np.ndarray | None
    removed: int
    max_deg: float
    max_mm: float
    other_location_keys: dict[str, np.ndarray] = field(default_factory=dict)


def reduce_keys(frames: np.ndarray, rotations: list[tuple[np.ndarray, str]], location: np.ndarray | None,
                deg: float, mm: float, other_locations: dict[str, np.ndarray] | None = None) -> Reduction:
    """rotations: per bone (channel values (N, n), rotation mode); location (N, 3) metres or None (the root
    bone's); other_locations: {bone: (N, 3)} other keyed locations (root motion's root bone), thinned within
    the same `mm`."""
    frames = np.asarray(frames, dtype=np.float64)
    tol = np.radians(deg)
    kept, removed, max_deg = [], 0, 0.0
    for values, mode in rotations:
        def err(orig, approx, mode=mode):
            return rotation_error(channel_matrices(orig, mode), channel_matrices(approx, mode))
        idx, worst = reduce_track(frames, np.asarray(values, dtype=np.float64), err, tol)
        kept.append(idx)
        removed += (len(frames) - len(idx)) * values.shape[-1]
        max_deg = max(max_deg, np.degrees(worst))
    loc_idx, max_mm, others = None, 0.0, {}
    tracks = ([(None, location)] if location is not None else []) + list((other_locations or {}).items())
    for bone, values in tracks:
        idx, worst = reduce_track(frames, np.asarray(values, dtype=np.float64),
                                  lambda o, a: np.linalg.norm(o - a, axis=-1), mm / 1000.0)
        removed += (len(frames) - len(idx)) * 3
        max_mm = max(max_mm, worst * 1000.0)
        if bone is None:
            loc_idx = idx
        else:
            others[bone] = idx
    return Reduction(kept, loc_idx, removed, max_deg, max_mm, others)
