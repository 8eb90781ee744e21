"""Minimal BVH forward kinematics: joint global positions per frame, for posing the synthetic body.

The project's general BVH reader lives in kinect_retarget/takes/bvh.py; this one only needs joint
positions (no Take, no Kinect mapping) so the depth renderer has no dependency on it.
"""
from __future__ import annotations

import os

import numpy as np

CMU_UNIT_M = 0.0564  # 1 CMU unit = 1/0.45 inch (data/README.md §3)


class BvhError(ValueError):
    pass


def _axis_rot(axis: str, ang: np.ndarray) -> np.ndarray:
    c, s = np.cos(ang), np.sin(ang)
    m = np.zeros(ang.shape + (3, 3))
    i = "XYZ".index(axis)
    j, k = (i + 1) % 3, (i + 2) % 3
    m[..., i, i] = 1
    m[..., j, j] = c
    m[..., k, k] = c
    m[..., j, k] = -s
    m[..., k, j] = s
    return m


def read_bvh_positions(path: str | os.PathLike, unit: float = CMU_UNIT_M):
    """Return (names, parents, positions (F, J, 3) metres in BVH world axes, frame_time)."""
    path = os.fspath(path)
    with open(path, "r", encoding="utf-8", errors="replace") as fh:
        tokens = fh.read().split()
    names, parents, offsets, channels = [], [], [], []
    stack: list[int] = []
    i = 0
    try:
        while tokens[i] != "MOTION":
            t = tokens[i]
            if t in ("ROOT", "JOINT"):
                names.append(tokens[i + 1])
                parents.append(stack[-1] if stack else -1)
                offsets.append([0.0, 0.0, 0.0])
                channels.append([])
                i += 2
            elif t == "End":  # end sites carry no channels: skip the block
                depth = 0
                while True:
                    i += 1
                    if tokens[i] == "{":
                        depth += 1
                    elif tokens[i] == "}":
                        depth -= 1
                        if depth == 0:
                            break
                i += 1
            elif t == "{":
                stack.append(len(names) - 1)
                i += 1
            elif t == "}":
                stack.pop()
                i += 1
            elif t == "OFFSET":
                offsets[-1] = [float(x) for x in tokens[i + 1:i + 4]]
                i += 4
            elif t == "CHANNELS":
                n = int(tokens[i + 1])
                channels[-1] = tokens[i + 2:i + 2 + n]
                i += 2 + n
            else:
                i += 1
        nframes = int(tokens[i + 2])
        frame_time = float(tokens[i + 5])
        data = np.array(tokens[i + 6:], dtype=np.float64)
    except (IndexError, ValueError) as exc:
        raise BvhError(f"{path}: malformed BVH ({exc})") from None
    nch = sum(len(c) for c in channels)
    if data.size < nframes * nch:
        raise BvhError(f"{path}: {nframes} frames declared but only {data.size // max(nch, 1)} present")
    data = data[:nframes * nch].reshape(nframes, nch)
    off = np.asarray(offsets) * unit
    glob_r = np.zeros((nframes, len(names), 3, 3))
    glob_p = np.zeros((nframes, len(names), 3))
    col = 0
    for j, chans in enumerate(channels):
        rot = np.broadcast_to(np.eye(3), (nframes, 3, 3)).copy()
        trans = np.zeros((nframes, 3))
        for c in chans:
            v = data[:, col]
            col += 1
            if c.endswith("position"):
                trans[:, "XYZ".index(c[0])] = v * unit
            else:
                rot = rot @ _axis_rot(c[0], np.radians(v))
        p = parents[j]
        if p < 0:
            glob_r[:, j] = rot
            glob_p[:, j] = off[j] + trans
        else:
            glob_p[:, j] = glob_p[:, p] + np.einsum("fij,j->fi", glob_r[:, p], off[j])
            glob_r[:, j] = glob_r[:, p] @ rot
    return names, parents, glob_p, frame_time
