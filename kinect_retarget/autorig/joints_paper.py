"""The paper's joint rule (003 §4.1-§4.2): the 20 Kinect joints taken from the paper's skeleton points.

Each segment's skeleton points (eq. 7-9: the plain coordinate mean of each connected vertex group of one
level) are chained from its feature point by level, taking the largest group of each level (the limb, not a
finger); the chain is the paper's skeleton of that segment. A joint is the point of the chain at its
anatomical geodesic distance from the feature point (the same distances as the fractions rule, joints.py),
interpolated between the two skeleton points around it, so the joints move with K and with the eq. 6
normalization: few levels give a coarse chain that cuts the corners of a bent limb. Then §4.2: the shoulder
and the ankle are moved along one body axis in steps of 0.01 of the height to a "suitable position", which
the paper chooses by eye and this module takes as the middle of the body's thickness along that axis (the
shoulder up and down, the ankle front to back).

The paper names no joints; which level distance is which joint is ours (measured on MakeHuman at rest).
"""
from __future__ import annotations

import numpy as np

from ..core.skeletons import KINECT_V1
from .features import FeaturePoints
from .joints import body_length
from .levels import SkeletonPoints

# Geodesic distance of each joint from its segment's feature point, as fractions of the body's geodesic
# length (head top to feet): segment 0 is the head (with the trunk), 1/2 the hands, 3/4 the feet.
CHAIN_AT = {
    0: {"Head": 0.062, "ShoulderCenter": 0.183, "Spine": 0.364, "HipCenter": 0.47},
    1: {"HandLeft": 0.088, "WristLeft": 0.113, "ElbowLeft": 0.217, "ShoulderLeft": 0.30},
    3: {"FootLeft": 0.078, "AnkleLeft": 0.122, "KneeLeft": 0.302, "HipLeft": 0.51},
}
STEP = 0.01          # §4.2: the adjustment's step, in units of the body's height
ADJUST_RADIUS = 0.02  # vertices this close to the adjustment line (× height) measure the body's thickness
ADJUST_REACH = 0.08   # ... up to this far along it (× height) on either side
ADJUST_SHOULDER = ("left", "up", "front")  # the axes each joint is centred along, in turn
ADJUST_ANKLE = ("front",)


def segment_chain(sk: SkeletonPoints, segment: int, tip: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(g, points) of the segment's chain: the feature point (g = 0) then, level by level, the skeleton
    point of the level's largest group."""
    g, pts = [0.0], [np.asarray(tip, dtype=np.float64)]
    mine = np.flatnonzero(sk.segment == segment)
    for level in np.unique(sk.level[mine]):
        at = mine[sk.level[mine] == level]
        best = at[np.argmax(sk.size[at])]
        g.append(float(sk.value[best]))
        pts.append(sk.points[best])
    order = np.argsort(g, kind="stable")
    return np.asarray(g)[order], np.asarray(pts)[order]


def chain_point(g: np.ndarray, pts: np.ndarray, at: float) -> np.ndarray:
    """The chain's point at geodesic distance `at`: linear between the skeleton points around it, and
    along the last link past the chain's end."""
    if len(g) < 2:
        return pts[0].copy()
    i = int(np.clip(np.searchsorted(g, at) - 1, 0, len(g) - 2))
    t = (at - g[i]) / max(g[i + 1] - g[i], 1e-12)
    return pts[i] + t * (pts[i + 1] - pts[i])


def centre_along(vertices: np.ndarray, point: np.ndarray, axis: np.ndarray, height: float) -> np.ndarray:
    """§4.2: `point` moved along `axis` in steps of STEP × height to the middle of the surface it crosses
    there (the vertices within ADJUST_RADIUS of the line, ADJUST_REACH either side)."""
    axis = axis / max(np.linalg.norm(axis), 1e-12)
    d = vertices - point
    t = d @ axis
    near = (np.linalg.norm(d - np.outer(t, axis), axis=1) < ADJUST_RADIUS * height) & \
           (np.abs(t) < ADJUST_REACH * height)
    if near.sum() < 2:
        return point  # no surface along the line near the point: leave it
    step = STEP * height
    return point + axis * step * np.round(0.5 * (t[near].min() + t[near].max()) / step)


def paper_joints(vertices: np.ndarray, fp: FeaturePoints, sk: SkeletonPoints, height: float) -> np.ndarray:
    """(20, 3) joint positions in KINECT_V1 order from the paper's skeleton points `sk`."""
    out = np.zeros((len(KINECT_V1), 3))
    size = body_length(fp)
    for segment, tip in enumerate(fp.vertices):
        base = segment if segment in CHAIN_AT else segment - 1
        side = "Right" if segment in (2, 4) else "Left"
        g, pts = segment_chain(sk, segment, vertices[tip])
        for name, at in CHAIN_AT[base].items():
            out[KINECT_V1.index(name.replace("Left", side))] = chain_point(g, pts, at * size)
    for side in ("Left", "Right"):  # §4.2, one body axis after the other
        for joint, axes in (("Shoulder", ADJUST_SHOULDER), ("Ankle", ADJUST_ANKLE)):
            j = KINECT_V1.index(joint + side)
            for axis in axes:
                out[j] = centre_along(vertices, out[j], getattr(fp, axis), height)
    return out
