"""The generated Kinect rig: one bone per joint, in a fixed upright T-pose (paper 000, §2.2), bpy-free.

Bone j is named after joint j and runs from its parent joint (head) to joint j (tail); the root bone is named
after the root joint, starts at it and points up. Bone lengths are the take's median segment lengths. The
character faces -Y with its left along +X (Blender conventions, docs/conventions.md).
"""
from __future__ import annotations

import numpy as np

from .joint_frames import frame_from_y_hint, resolver, segment_hint
from .quat import normalize
from .skeletons import TRACKED, Skeleton, topological_order
from .take import Take
from .target_rig import TargetRig

UP, DOWN, FORWARD = np.array([0.0, 0, 1]), np.array([0.0, 0, -1]), np.array([0.0, -1, 0])
LEFT = np.array([1.0, 0, 0])

# rest direction of the segment ending at each joint, for the left side (right side mirrors X)
_DIRECTIONS = {
    "Spine": UP, "SpineMid": UP, "ShoulderCenter": UP, "SpineShoulder": UP, "Neck": UP, "Head": UP,
    "Shoulder": LEFT, "Elbow": LEFT, "Wrist": LEFT, "Hand": LEFT, "HandTip": LEFT,
    "Thumb": normalize(np.array([0.6, -0.8, 0.0])),
    "Hip": normalize(np.array([1.0, 0.0, -0.8])), "Knee": DOWN, "Ankle": DOWN, "Foot": FORWARD,
}
DEFAULT_LENGTH = 0.1
# Typical adult segment lengths (m), for a generated rig when no take gives real ones (OSC, USB sources).
TYPICAL_LENGTHS = {"SpineBase": 0.2, "HipCenter": 0.2, "SpineMid": 0.25, "Spine": 0.25, "SpineShoulder": 0.25,
                   "ShoulderCenter": 0.3, "Neck": 0.1, "Head": 0.15, "Shoulder": 0.18, "Elbow": 0.28,
                   "Wrist": 0.25, "Hand": 0.08, "HandTip": 0.07, "Thumb": 0.05, "Hip": 0.09, "Knee": 0.42,
                   "Ankle": 0.4, "Foot": 0.12}


def rest_direction(joint: str) -> np.ndarray:
    for side, sign in (("Left", 1.0), ("Right", -1.0)):
        if joint.endswith(side):
            d = _DIRECTIONS[joint[: -len(side)]].copy()
            d[0] *= sign
            return d
    return _DIRECTIONS[joint]


def typical_segment_lengths(skeleton: Skeleton) -> np.ndarray:
    """(J,) typical adult length of the segment ending at each joint (the root's: the hip width)."""
    out = []
    for name in skeleton.joints:
        key = name.removesuffix("Left").removesuffix("Right")
        out.append(TYPICAL_LENGTHS.get(key, DEFAULT_LENGTH))
    return np.array(out)


def median_segment_lengths(take: Take) -> np.ndarray:
    """(J,) median length of the segment parent -> joint over frames where both ends are tracked (all frames
    when never both tracked); the root's entry is the hip width, used as the root bone's length."""
    sk = take.skeleton
    lengths = np.full(len(sk), DEFAULT_LENGTH)
    both = take.states == TRACKED
    for j, p in enumerate(sk.parents):
        a, b = (j, p) if p >= 0 else _hip_pair(sk)
        if a is None:
            continue
        d = np.linalg.norm(take.positions[:, a] - take.positions[:, b], axis=-1)
        ok = both[:, a] & both[:, b] & np.isfinite(d)
        vals = d[ok] if ok.any() else d[np.isfinite(d)]
        if vals.size and np.median(vals) > 1e-4:
            lengths[j] = float(np.median(vals))
    return lengths


def _hip_pair(sk: Skeleton):
    if "HipLeft" in sk.joints and "HipRight" in sk.joints:
        return sk.index("HipLeft"), sk.index("HipRight")
    return None, None


def rest_joint_positions(skeleton: Skeleton, lengths: np.ndarray) -> np.ndarray:
    """(J, 3) Blender-space joint positions of the T-pose, the root above the origin at leg height."""
    pos = np.zeros((len(skeleton), 3))
    for j in topological_order(skeleton):
        p = skeleton.parents[j]
        if p >= 0:
            pos[j] = pos[p] + rest_direction(skeleton.joints[j]) * lengths[j]
    # stand on the floor: lowest foot/ankle joint at z = 0
    pos[:, 2] -= pos[:, 2].min()
    return pos


def generated_rig(skeleton: Skeleton, lengths: np.ndarray, name: str = "KinectRig") -> TargetRig:
    """TargetRig of the generated Kinect rig; bone axes are the rest pose's joint frames (X = hinge axis)."""
    pos = rest_joint_positions(skeleton, lengths)
    get = resolver(skeleton.joints, pos)
    rest = np.tile(np.eye(4), (len(skeleton), 1, 1))
    for j, name_j in enumerate(skeleton.joints):
        p = skeleton.parents[j]
        head, y = (pos[j], UP) if p < 0 else (pos[p], rest_direction(name_j))
        rest[j, :3, :3] = frame_from_y_hint(y, segment_hint(get, name_j, y, LEFT, UP))  # root: the pelvis
        rest[j, :3, 3] = head
    return TargetRig(name, skeleton.joints, skeleton.parent_array.copy(), rest, np.array(lengths, dtype=np.float64),
                     generated=True)


def generated_mapping(skeleton: Skeleton) -> dict[str, str]:
    """Every bone of the generated rig maps to the joint it is named after."""
    return {j: j for j in skeleton.joints}
