"""Skin weights by bone projection (paper 003, §5): each vertex is weighted by its distance to the bone
segments it may belong to; at most four influences, normalized to sum to one."""
from __future__ import annotations

import numpy as np

from ..core.skeletons import KINECT_V1

MAX_INFLUENCES = 4
FALLOFF = 4.0  # weight ~ 1 / distance**FALLOFF: joints blend over a short span, bones stay rigid between
OUTER_HALF = 0.5  # shoulder and hip bones pull skin only along their outer half

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


# Bones each segment owns; the other allowed bones are weighed down by FOREIGN so they only take skin that
# is right at them (the armpit, the groin) and the chest does not ride on a raised arm.
_OWN = (_TRUNK + _side(("ShoulderSIDE", "HipSIDE"), "Left") + _side(("ShoulderSIDE", "HipSIDE"), "Right"),
        _side(_ARM, "Left"), _side(_ARM, "Right"), _side(_LEG, "Left"), _side(_LEG, "Right"))
FOREIGN = 0.1


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


def projection_matrix(vertices: np.ndarray, segment: np.ndarray, joints: np.ndarray,
                      height: float) -> np.ndarray:
    """(V, 20) raw bone-projection weights, each row summing to 1."""
    heads, tails = bone_segments(joints)
    # The shoulder and hip bones run across the chest and pelvis; only their outer halves pull skin, so
    # the chest and the pelvis follow the trunk and do not crease at the midline when one arm rises.
    for name in ("ShoulderLeft", "ShoulderRight", "HipLeft", "HipRight"):
        j = KINECT_V1.index(name)
        heads[j] = heads[j] + OUTER_HALF * (tails[j] - heads[j])
    d = point_segment_distance(vertices, heads, tails) + 1e-3 * height  # no division by zero on a bone
    allowed = np.zeros((len(SEGMENT_BONES), len(KINECT_V1)))
    for s, names in enumerate(SEGMENT_BONES):
        allowed[s, [KINECT_V1.index(n) for n in names]] = FOREIGN
        allowed[s, [KINECT_V1.index(n) for n in _OWN[s]]] = 1.0
    w = allowed[segment] * (d / height) ** -FALLOFF
    return w / w.sum(axis=1, keepdims=True)


def smooth_over_surface(w: np.ndarray, indptr: np.ndarray, indices: np.ndarray, iterations: int) -> np.ndarray:
    """Jacobi steps of w <- w / 4 + 3/4 mean of neighbours over the CSR adjacency: blends the hard switch
    where two bones' projections meet over a few edge lengths (shoulder, ankle, groin)."""
    w = w.astype(np.float32)  # half the memory traffic; weights need no more precision
    deg = np.diff(indptr).astype(np.float32)
    has = deg > 0
    starts = indptr[:-1][has]
    for _ in range(iterations):
        acc = np.add.reduceat(w[indices], starts, axis=0) if len(indices) else np.zeros((0, w.shape[1]))
        mean = w.copy()
        mean[has] = acc / deg[has, None]
        w = 0.25 * w + 0.75 * mean
    return w.astype(np.float64)


def smoothing_iterations(edge_lengths: np.ndarray, height: float, blend: float = 0.03) -> int:
    """Steps that diffuse over about `blend` x height (diffusion spreads as the square root of steps; a
    3/4 step spreads 1.5 times as far as a half step)."""
    e = float(np.median(edge_lengths)) if len(edge_lengths) else height
    return int(np.clip((blend * height / max(e, 1e-12)) ** 2 / 1.5, 2, 20))


def top_influences(w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(V, 4) strongest bones and their weights, renormalized to sum to 1."""
    top = np.argsort(-w, axis=1)[:, :MAX_INFLUENCES]
    tw = np.take_along_axis(w, top, axis=1)
    tw /= tw.sum(axis=1, keepdims=True)
    return top, tw


def bone_projection_weights(vertices: np.ndarray, segment: np.ndarray, joints: np.ndarray, height: float,
                            graph=None) -> tuple[np.ndarray, np.ndarray]:
    """(V, 4) bone indices (KINECT_V1 order) and (V, 4) weights summing to 1 (unused slots weigh 0).
    With the mesh graph, the weights are smoothed along the surface before the top four are kept."""
    w = projection_matrix(vertices, segment, joints, height)
    if graph is not None and len(graph.edges):
        w = smooth_over_surface(w, graph.indptr, graph.indices, smoothing_iterations(graph.lengths, height))
    return top_influences(w)
