"""Name the skeleton: the 20 Kinect v1 joints placed on the geodesic centre lines of the segments.

Each limb joint is the centroid of an iso-geodesic ring around the limb, at a fixed fraction of the limb's
branch length (tip to where it meets the body); the fractions are human proportions (they hold for
MakeHuman's base mesh and its posed versions, see benchmarks/bench_autorig.py). Joints inside the torso
(hips, shoulder line) come from lines fitted to the limb centre lines, which is the automatic form of the
paper's shoulder/ankle adjustment (§4.2): instead of stepping a point by hand, it is moved onto the axis of
the limb it belongs to.
"""
from __future__ import annotations

import numpy as np

from ..core.skeletons import KINECT_V1
from .features import FeaturePoints, branch_lengths

# Ring positions, as fractions of the branch length from the tip.
ARM = {"WristLeft": 0.334, "ElbowLeft": 0.70, "ShoulderLeft": 1.06}
HAND_AT = (0.15, 0.5)    # the palm: half-way from the wrist to the finger ring at 15 %
LEG = {"FootLeft": 0.183, "AnkleLeft": 0.262, "KneeLeft": 0.655}
THIGH = (0.72, 1.0)      # the leg's centre line: the thigh (its top is level with the crotch)
NECK_AT = 1.09           # head field: the ring at the base of the neck
HEAD_DOWN = 0.30         # Head joint: this far from the top toward the neck base
HIP_CENTRE_AT = 0.97     # head-segment field, fraction of its 99th percentile (the crotch)
SPINE_AT = 0.58          # Spine: fraction of the way from the neck base to the hip centre


def ring_centroid(vertices: np.ndarray, field: np.ndarray, g: float, width: float,
                  mask: np.ndarray | None = None) -> np.ndarray:
    """Centroid of the vertices whose geodesic value is within `width` of g (widened until non-empty)."""
    for w in (width, 2 * width, 4 * width, 8 * width):
        band = np.abs(field - g) < w
        if mask is not None:
            band &= mask
        if band.any():
            return vertices[band].mean(axis=0)
    near = np.argmin(np.abs(field - g) + (0 if mask is None else np.where(mask, 0, np.inf)))
    return vertices[near].copy()


def kinect_joints(vertices: np.ndarray, fp: FeaturePoints, segment: np.ndarray, height: float) -> np.ndarray:
    """(20, 3) joint positions in KINECT_V1 order, in mesh coordinates."""
    out = np.zeros((len(KINECT_V1), 3))
    idx = KINECT_V1.index
    branch = branch_lengths(fp.distances[:, fp.vertices])
    width = 0.006 * height
    head_f = fp.distances[0]
    in_torso = segment == 0  # the head's domain holds the neck and the whole trunk

    for side, s_hand, s_foot in (("Left", 1, 3), ("Right", 2, 4)):
        f, b = fp.distances[s_hand], branch[s_hand]
        for name, t in ARM.items():
            out[idx(name.replace("Left", side))] = ring_centroid(vertices, f, t * b, width)
        wrist = out[idx("Wrist" + side)]
        out[idx("Hand" + side)] = wrist + HAND_AT[1] * (ring_centroid(vertices, f, HAND_AT[0] * b, width) - wrist)
        f, b = fp.distances[s_foot], branch[s_foot]
        for name, t in LEG.items():
            out[idx(name.replace("Left", side))] = ring_centroid(vertices, f, t * b, width)

    top = vertices[fp.vertices[0]]
    neck = ring_centroid(vertices, head_f, NECK_AT * branch[0], width, in_torso)
    out[idx("ShoulderCenter")] = neck
    head = top + HEAD_DOWN * (neck - top)
    # Centre it front-to-back on the skull: the middle of a thin slice of the head at that height.
    in_head = head_f < NECK_AT * branch[0]
    level = (vertices - head) @ fp.up
    slab = in_head & (np.abs(level) < 0.02 * height)
    if slab.any():
        depth = vertices[slab] @ fp.front
        head += fp.front * ((depth.min() + depth.max()) / 2 - head @ fp.front)
    out[idx("Head")] = head
    g_end = np.percentile(head_f[in_torso], 99)
    hip_centre = ring_centroid(vertices, head_f, HIP_CENTRE_AT * g_end, width, in_torso)
    out[idx("HipCenter")] = hip_centre
    g_neck = NECK_AT * branch[0]
    out[idx("Spine")] = ring_centroid(vertices, head_f, g_neck + SPINE_AT * (HIP_CENTRE_AT * g_end - g_neck),
                                      width, in_torso)
    # Hips: the top of the thigh's centre line, carried along the trunk axis to the hip centre's level
    # (the femur head sits level with the pelvis centre, whatever the leg does).
    trunk = neck - hip_centre
    trunk /= max(np.linalg.norm(trunk), 1e-12)
    for side, s_foot in (("Left", 3), ("Right", 4)):
        top_of_thigh = ring_centroid(vertices, fp.distances[s_foot], THIGH[1] * branch[s_foot], width)
        out[idx("Hip" + side)] = top_of_thigh + trunk * ((hip_centre - top_of_thigh) @ trunk)
    return out
