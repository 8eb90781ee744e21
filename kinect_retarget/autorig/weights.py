"""Skin weights by bone projection (paper 003, §5): each vertex is weighted by its distance to the bone
segments it may belong to; at most four influences, normalized to sum to one."""
from __future__ import annotations

import numpy as np

from ..core.skeletons import KINECT_V1

MAX_INFLUENCES = 4
FALLOFF = 4.0  # weight ~ 1 / distance**FALLOFF: joints blend over a short span, bones stay rigid between

# Which bones (named after their tail joint, as the generated Kinect rig names them) each body segment may
# use: an arm never pulls the thigh it hangs beside. Segments in features.LABELS order.
_TRUNK = ("HipCenter", "Spine", "ShoulderCenter", "Head")
_ARM = ("ShoulderSIDE", "ElbowSIDE", "WristSIDE", "HandSIDE")
_LEG = ("HipSIDE", "KneeSIDE", "AnkleSIDE", "FootSIDE")


def _side(names, side):
    return tuple(n.replace("SIDE", side) for n in names)


SEGMENT_BONES = (
    _TRUNK + _side(_ARM[:2], "Left") + _side(_ARM[:2], "Right") + _side(_LEG[:2], "Left") + _side(_LEG[:2], "Right"),
    ("ShoulderCenter", "Spine") + _side(_ARM, "Left"),
    ("ShoulderCenter", "Spine") + _side(_ARM, "Right"),
    ("HipCenter", "Spine") + _side(_LEG, "Left"),
    ("HipCenter", "Spine") + _side(_LEG, "Right"),
)


def bone_segments(joints: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(B, 3) heads and tails of the 20 bones, bone j ending at joint j; the root bone is a short stub
    from the hip centre toward the spine (its weight region is the pelvis)."""
    parents = KINECT_V1.parent_array
    heads = joints[np.maximum(parents, 0)].copy()
    tails = joints.copy()
    r = KINECT_V1.root
    spine = KINECT_V1.children[r][0]
    heads[r] = joints[r]
    tails[r] = joints[r] + 0.25 * (joints[spine] - joints[r])
    return heads, tails


def point_segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(V, B) distance from each point to each segment a-b."""
    ab = b - a
    t = np.einsum("vbk,bk->vb", p[:, None, :] - a[None], ab) / np.maximum((ab * ab).sum(axis=1), 1e-24)
    closest = a[None] + np.clip(t, 0.0, 1.0)[..., None] * ab[None]
    return np.linalg.norm(p[:, None, :] - closest, axis=2)


def bone_projection_weights(vertices: np.ndarray, segment: np.ndarray, joints: np.ndarray,
                            height: float) -> tuple[np.ndarray, np.ndarray]:
    """(V, 4) bone indices (KINECT_V1 order) and (V, 4) weights summing to 1 (unused slots weigh 0)."""
    heads, tails = bone_segments(joints)
    d = point_segment_distance(vertices, heads, tails) + 1e-3 * height  # no division by zero on a bone
    allowed = np.zeros((len(SEGMENT_BONES), len(KINECT_V1)), dtype=bool)
    for s, names in enumerate(SEGMENT_BONES):
        allowed[s, [KINECT_V1.index(n) for n in names]] = True
    w = np.where(allowed[segment], (d / height) ** -FALLOFF, 0.0)
    top = np.argsort(-w, axis=1)[:, :MAX_INFLUENCES]
    tw = np.take_along_axis(w, top, axis=1)
    tw /= tw.sum(axis=1, keepdims=True)
    return top, tw


def dense_weights(index: np.ndarray, weight: np.ndarray, bones: int) -> np.ndarray:
    """(V, 4) sparse influences -> (V, bones) dense matrix."""
    out = np.zeros((len(index), bones))
    np.add.at(out, (np.repeat(np.arange(len(index)), index.shape[1]), index.ravel()), weight.ravel())
    return out
