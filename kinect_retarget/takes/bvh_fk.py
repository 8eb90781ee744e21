"""BVH forward kinematics: channel values -> global joint positions and rotations.

Rotation channels compose in the order they are listed (R = R_first @ R_second @ R_third, column vectors),
whatever that order is, per joint. Position channels on the root give its position. Position channels on
other joints mean one of two things, decided per file by `position_channel_mode`: MotionBuilder-style solves,
Perception Neuron, Bandai-Namco and Blender write the joint's full local translation there (equal to its
OFFSET at rest), MakeHuman writes a small delta added to the OFFSET.
"""
from __future__ import annotations

import numpy as np

from ..core import quat
from .bvh_parse import BvhSkeleton, channel_axis

ABSOLUTE, DELTA, NONE = "absolute", "delta", "none"
POSITION_MODES = {ABSOLUTE: "position channels hold each joint's full local translation (OFFSET ignored)",
                  DELTA: "position channels are added to each joint's OFFSET",
                  NONE: "position channels on the root only"}


def position_channel_mode(sk: BvhSkeleton, values: np.ndarray) -> str:
    """ABSOLUTE when the non-root position channels stay closer to their joint's OFFSET than to zero over the
    take (a full translation), DELTA when closer to zero, NONE when only the root has them."""
    to_offset, to_zero = [], []
    for j, chans in enumerate(sk.channels):
        if sk.parents[j] < 0:
            continue
        cols = [(sk.first_channel[j] + i, channel_axis(c)) for i, c in enumerate(chans) if c.endswith("position")]
        if not cols:
            continue
        v = values[:, [c for c, _ in cols]]
        off = sk.offsets[j, [a for _, a in cols]]
        to_offset.append(np.abs(v - off).sum(axis=1))
        to_zero.append(np.abs(v).sum(axis=1))
    if not to_offset:
        return NONE
    return ABSOLUTE if np.median(np.concatenate(to_offset)) < np.median(np.concatenate(to_zero)) else DELTA


def axis_quaternions(angles_deg: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """(..., N, 4) quaternions (w, x, y, z) rotating by `angles_deg` (..., N) about coordinate axes
    `axes` (N,) or (..., N), values 0, 1, 2 = X, Y, Z."""
    half = np.radians(angles_deg) / 2
    q = np.zeros(half.shape + (4,))
    q[..., 0] = np.cos(half)
    axes = np.asarray(axes)
    if axes.ndim == 1 and half.ndim >= 1:  # one axis per joint: a single scatter, no per-axis masks
        q[..., np.arange(axes.size), axes + 1] = np.sin(half)
        return q
    axes = np.broadcast_to(axes, half.shape)
    sin = np.sin(half)
    for a in range(3):
        q[..., a + 1] = np.where(axes == a, sin, 0.0)
    return q


def _axis_rotations(angles_deg: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """(..., 3, 3) rotation matrices by `angles_deg` about coordinate axes `axes`."""
    return quat.to_matrix(axis_quaternions(angles_deg, axes))


def _rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate (..., 3) vectors by (..., 4) unit quaternions: v + 2w (u x v) + 2 u x (u x v)."""
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    vx, vy, vz = v[..., 0], v[..., 1], v[..., 2]
    tx, ty, tz = 2 * (y * vz - z * vy), 2 * (z * vx - x * vz), 2 * (x * vy - y * vx)
    return np.stack([vx + w * tx + (y * tz - z * ty),
                     vy + w * ty + (z * tx - x * tz),
                     vz + w * tz + (x * ty - y * tx)], axis=-1)


def _local_transforms(sk: BvhSkeleton, values: np.ndarray, mode: str = DELTA) -> tuple[np.ndarray, np.ndarray]:
    """Per-frame local rotations (F, N, 4 quaternions) and translations (F, N, 3) from channel values."""
    f, n = values.shape[0], len(sk.names)
    trans = np.broadcast_to(sk.offsets, (f, n, 3)).copy()
    # Rotation channels: slot k (0..2) of each joint, padded with zero angles about X.
    slots = np.zeros((n, 3), dtype=np.int64)
    cols = np.full((n, 3), -1, dtype=np.int64)
    for j, chans in enumerate(sk.channels):
        k = 0
        for c_i, c in enumerate(chans):
            col = sk.first_channel[j] + c_i
            if c.endswith("rotation"):
                if k == 3:
                    continue  # a fourth rotation channel: ignored (no exporter writes one)
                slots[j, k], cols[j, k] = channel_axis(c), col
                k += 1
            elif sk.parents[j] < 0 or mode == ABSOLUTE:
                trans[:, j, channel_axis(c)] = values[:, col]
            else:
                trans[:, j, channel_axis(c)] += values[:, col]
    padded = np.concatenate([values, np.zeros((f, 1))], axis=1)  # column -1 reads 0
    rot = axis_quaternions(padded[:, cols[:, 0]], slots[:, 0])
    for k in (1, 2):
        rot = quat.mul(rot, axis_quaternions(padded[:, cols[:, k]], slots[:, k]))
    return rot, trans


def _depth_levels(parents: np.ndarray) -> list[np.ndarray]:
    """Joint indices grouped by depth below the root (parents come before children in file order)."""
    depth = np.zeros(len(parents), dtype=np.int64)
    for j, p in enumerate(parents):
        depth[j] = depth[p] + 1 if p >= 0 else 0
    return [np.flatnonzero(depth == d) for d in range(int(depth.max()) + 1)]


def forward_kinematics(sk: BvhSkeleton, values: np.ndarray, mode: str = DELTA) -> tuple[np.ndarray, np.ndarray]:
    """Global positions (F, N, 3) and rotations (F, N, 4 quaternions) for every joint and frame.

    Joints at the same depth are done together, so the Python loop runs once per level, not per joint.
    """
    rot, trans = _local_transforms(sk, values, mode)
    g_rot = np.empty_like(rot)
    g_pos = np.empty_like(trans)
    levels = _depth_levels(sk.parents)
    g_rot[:, levels[0]] = rot[:, levels[0]]
    g_pos[:, levels[0]] = trans[:, levels[0]]
    for joints in levels[1:]:
        parents = sk.parents[joints]
        g_rot[:, joints] = quat.mul(g_rot[:, parents], rot[:, joints])
        g_pos[:, joints] = g_pos[:, parents] + _rotate(g_rot[:, parents], trans[:, joints])
    return g_pos, g_rot


