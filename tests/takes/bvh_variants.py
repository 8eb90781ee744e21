"""Rewrite one real BVH file the ways other exporters write the same motion (same figure, other conventions).

A `Figure` is the file's hierarchy with per-frame local rotation matrices; transforms return a new Figure and
`write` turns one back into BVH text (rotations as Z, Y, X Euler channels).
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from kinect_retarget.core import quat
from kinect_retarget.takes.bvh_fk import _local_transforms
from kinect_retarget.takes.bvh_parse import read_bvh_text


@dataclass
class Figure:
    names: list[str]
    parents: np.ndarray
    offsets: np.ndarray      # (N, 3)
    ends: np.ndarray         # (N,) bool
    local: np.ndarray        # (F, N, 3, 3) local rotations
    root_pos: np.ndarray     # (F, 3)
    frame_time: float


def load(path) -> Figure:
    sk, frame_time, values, _ = read_bvh_text(path)
    rot, trans = _local_transforms(sk, values)
    return Figure(list(sk.names), sk.parents.copy(), sk.offsets.copy(), sk.is_end_site.copy(),
                  quat.to_matrix(rot), trans[:, 0].copy(), frame_time)


def renamed(fig: Figure) -> Figure:
    return replace(fig, names=[f"node{i:02d}" for i in range(len(fig.names))])


def scaled(fig: Figure, s: float) -> Figure:
    return replace(fig, offsets=fig.offsets * s, root_pos=fig.root_pos * s)


def about_x(degrees: float) -> np.ndarray:
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    return np.array([[1.0, 0, 0], [0, c, -s], [0, s, c]])


def rotated(fig: Figure, a: np.ndarray) -> Figure:
    """The same take in rotated lab axes (rotation matrix `a`): every offset and rotation expressed in them."""
    return replace(fig, offsets=fig.offsets @ a.T, local=a @ fig.local @ a.T, root_pos=fig.root_pos @ a.T)


def z_up(fig: Figure) -> Figure:
    """The same take in a Z-up world (+90 degrees about X: Y -> Z)."""
    return rotated(fig, about_x(90.0))


def lying_down(fig: Figure, positions: np.ndarray, ankles: list[int], frames: slice) -> Figure:
    """The performer (Y up) lies down on their back over `frames` and holds still: the pose of the first of
    those frames turned -90 degrees about X around the hips, lowered until the lower ankle is as high above
    the floor as when standing (heel on the floor). `positions`: (F, N, 3) the source's joints (forward
    kinematics), for the heights."""
    w = about_x(-90.0)
    root = int(np.flatnonzero(fig.parents < 0)[0])
    first = frames.start
    floor = np.median(positions[:, ankles, 1].min(axis=1))  # the lower ankle's height while standing
    pivot = positions[first, root]
    drop = ((positions[first, ankles] - pivot) @ w.T + pivot)[:, 1].min() - floor
    local, root_pos = fig.local.copy(), fig.root_pos.copy()
    local[frames] = fig.local[first]
    local[frames, root] = w @ fig.local[first, root]
    root_pos[frames] = pivot - np.array([0.0, drop, 0.0])
    return replace(fig, local=local, root_pos=root_pos)


def _frame_with_x(d: np.ndarray) -> np.ndarray:
    """A rotation whose X axis points along d."""
    x = d / np.linalg.norm(d)
    helper = np.array([0.0, 0, 1]) if abs(x[2]) < 0.9 else np.array([0.0, 1, 0])
    z = np.cross(x, helper)
    z /= np.linalg.norm(z)
    return np.stack([x, np.cross(z, x), z], axis=1)


def x_along_bones(fig: Figure) -> Figure:
    """Rest frames turned so each joint's first child lies along its X axis (Rokoko, Bandai-Namco style):
    the rest pose (every channel zero) is no longer a standing figure, the motion is unchanged."""
    n = len(fig.names)
    c = np.tile(np.eye(3), (n, 1, 1))
    for j in range(n):
        kids = [k for k in range(n) if fig.parents[k] == j and np.linalg.norm(fig.offsets[k]) > 1e-6]
        if kids:
            c[j] = _frame_with_x(fig.offsets[kids[0]])
    parent_c = np.where((fig.parents >= 0)[:, None, None], c[np.maximum(fig.parents, 0)], np.eye(3))
    offsets = np.einsum("nji,nj->ni", parent_c, fig.offsets)  # C_parent^T @ offset
    local = np.swapaxes(parent_c, -1, -2) @ fig.local @ c
    return replace(fig, offsets=offsets, local=local)


def without_hands(fig: Figure) -> Figure:
    """Cut both hands off at the wrist: the hand joints' subtrees become one End Site each."""
    hands = [j for j, nm in enumerate(fig.names) if nm.endswith(("LeftHand", "RightHand"))]
    drop = set()
    for j in range(len(fig.names)):
        k = j
        while k >= 0:
            if k in hands and k != j:
                drop.add(j)
            k = int(fig.parents[k])
    keep = [j for j in range(len(fig.names)) if j not in drop]
    remap = {old: new for new, old in enumerate(keep)}
    ends = fig.ends.copy()
    ends[hands] = True
    return replace(fig, names=[fig.names[j] for j in keep],
                   parents=np.array([remap.get(int(fig.parents[j]), -1) for j in keep]),
                   offsets=fig.offsets[keep], ends=ends[keep], local=fig.local[:, keep])


def under_reference(fig: Figure) -> Figure:
    """A 'Reference' root above the hips carrying the root motion (MotionBuilder, Unreal-style exports)."""
    local = np.concatenate([np.broadcast_to(np.eye(3), (fig.local.shape[0], 1, 3, 3)), fig.local], axis=1)
    parents = np.concatenate([[-1], np.where(fig.parents < 0, 0, fig.parents + 1)])
    return replace(fig, names=["Reference", *fig.names], parents=parents,
                   offsets=np.concatenate([np.zeros((1, 3)), np.where((fig.parents < 0)[:, None], 0.0, fig.offsets)]),
                   ends=np.concatenate([[False], fig.ends]), local=local)


def _zyx_degrees(m: np.ndarray) -> np.ndarray:
    """(..., 3) angles (Z, Y, X) in degrees with m = Rz @ Ry @ Rx."""
    y = np.arcsin(np.clip(-m[..., 2, 0], -1, 1))
    x = np.arctan2(m[..., 2, 1], m[..., 2, 2])
    z = np.arctan2(m[..., 1, 0], m[..., 0, 0])
    return np.degrees(np.stack([z, y, x], axis=-1))


def write(fig: Figure, path, *, absolute: bool = False, joint_site: bool = False, root_joint: bool = False,
          newline: str = "\n") -> None:
    """BVH text; `absolute`: every joint carries its full local translation in position channels;
    `joint_site`: end sites written `JOINT Site` with `CHANNELS 0`; `root_joint`: the root written `JOINT`."""
    lines = ["HIERARCHY"]
    kids = {j: [k for k in range(len(fig.names)) if fig.parents[k] == j] for j in range(len(fig.names))}
    columns = []

    def emit(j: int, depth: int) -> None:
        pad = "\t" * depth
        if fig.ends[j]:
            lines.append(pad + ("JOINT Site" if joint_site else "End Site"))
        else:
            key = "JOINT" if fig.parents[j] >= 0 or root_joint else "ROOT"
            lines.append(f"{pad}{key} {fig.names[j]}")
        lines.append(pad + "{")
        lines.append(pad + "\tOFFSET " + " ".join(f"{v:.6f}" for v in fig.offsets[j]))
        if fig.ends[j]:
            if joint_site:
                lines.append(pad + "\tCHANNELS 0")
        else:
            pos = fig.parents[j] < 0 or absolute
            lines.append(pad + ("\tCHANNELS 6 Xposition Yposition Zposition " if pos else "\tCHANNELS 3 ")
                         + "Zrotation Yrotation Xrotation")
            if pos:
                columns.append(fig.root_pos if fig.parents[j] < 0 else np.broadcast_to(fig.offsets[j], fig.root_pos.shape))
            columns.append(_zyx_degrees(fig.local[:, j]))
        for k in kids[j]:
            emit(k, depth + 1)
        lines.append(pad + "}")

    for root in (j for j in range(len(fig.names)) if fig.parents[j] < 0):
        emit(root, 0)
    values = np.concatenate(columns, axis=1)
    lines += ["MOTION", f"Frames: {values.shape[0]}", f"Frame Time: {fig.frame_time:.6f}"]
    lines += [" ".join(f"{v:.6f}" for v in row) for row in values]
    with open(path, "w", newline="") as fh:
        fh.write(newline.join(lines) + newline)
