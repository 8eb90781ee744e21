"""Paper 004's lifting as published, selectable beside ours (`lift --method paper`).

* scaled orthographic camera (eq. 1), whatever focal length is known;
* the scale by temporal continuity, eq. 3 (scale.scale_paper), bounded below by eq. 2;
* each bone's plain depth dz = ±sqrt(L² − d²/s²), walked down the tree from the pelvis;
* no 2D smoothing, no gap filling, no noise-aware depth, no depth smoothing (ours, docs/lifting.md).
The paper leaves the ± open; by the continuity it uses for s, each bone takes the sign that keeps its child
joint's depth (relative to the pelvis) nearest to the previous frame's, and toward the camera on the first
frame (and after the body was lost).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ..core.skeletons import KINECT_V1
from .geometry import JointLines

METHODS = ("ours", "paper")


def paper_settings(settings):
    """LiftSettings for the paper's method: ours switched off where the paper has nothing."""
    return dataclasses.replace(settings, focal_px=None, scale="paper", signs="continuity", max_gap_s=0.0,
                               smooth_2d_s=0.0, smooth_depth_s=0.0, noise_aware=False, noise_px=0.0)


def continuity_signs(lines: JointLines, lengths: np.ndarray, root: np.ndarray, valid: np.ndarray,
                     order: np.ndarray) -> np.ndarray:
    """(F, J) signs (+1: the farther place along the joint's line) by depth continuity, frame after frame,
    each joint placed at dz = ±sqrt(L² − d²/s²) from its parent (order: parents first)."""
    parents = KINECT_V1.parent_array
    f, j_count = valid.shape[0], len(parents)
    signs = -np.ones((f, j_count))
    prev = None  # (J,) depth of each joint relative to the pelvis, last frame
    origin, direction = lines.origin, lines.direction
    for i in range(f):
        if not valid[i]:
            prev = None
            continue
        pos = np.zeros((j_count, 3))
        pos[order[0]] = root[i]
        for j in order[1:]:
            p = pos[parents[j]]
            o, u = origin[i, j], direction[i, j]
            foot = o + ((p - o) @ u) * u
            c = min(np.linalg.norm(p - foot) / lengths[j], 1.0)
            dz = lengths[j] * np.sqrt(1.0 - c * c)
            if prev is not None:
                near, far = foot - dz * u, foot + dz * u
                signs[i, j] = 1.0 if abs(far[2] - root[i, 2] - prev[j]) < abs(near[2] - root[i, 2] - prev[j]) \
                    else -1.0
            pos[j] = foot + signs[i, j] * dz * u
        prev = pos[:, 2] - root[i, 2]
    return signs
