"""Bone lengths of the Kinect v1 skeleton: anthropometric ratios of body height, or measured from a take.

Lengths are indexed by the bone's child joint (the root's entry is 0), as everywhere in the lifter.
"""
from __future__ import annotations

import numpy as np

from ..core.skeletons import KINECT_V1, NOT_TRACKED, Skeleton
from ..core.take import Take
from .tracks2d import LiftError

# Bone lengths as fractions of standing height, for the Kinect v1 joint positions. Legs follow Winter
# ("Biomechanics and Motor Control of Human Movement": thigh 0.245 H, shank 0.246 H); the rest are measured
# on the CMU optical takes sampled at Kinect v1 joints (takes/bvh.py), with each subject's height taken
# from their legs, so lifted takes match what the retargeting engine sees from a Kinect.
HEIGHT_RATIOS = {
    "Spine": 0.102, "ShoulderCenter": 0.080, "Head": 0.096,
    "ShoulderLeft": 0.105, "ElbowLeft": 0.160, "WristLeft": 0.116, "HandLeft": 0.030,
    "ShoulderRight": 0.105, "ElbowRight": 0.160, "WristRight": 0.116, "HandRight": 0.030,
    "HipLeft": 0.077, "KneeLeft": 0.245, "AnkleLeft": 0.246, "FootLeft": 0.077,
    "HipRight": 0.077, "KneeRight": 0.245, "AnkleRight": 0.246, "FootRight": 0.077,
}
_LEG_RATIO = 0.491  # thigh + shank
DEFAULT_HEIGHT_M = 1.70


def lengths_from_height(height_m: float = DEFAULT_HEIGHT_M, skeleton: Skeleton = KINECT_V1) -> np.ndarray:
    if not (np.isfinite(height_m) and 0.5 <= height_m <= 2.6):
        raise LiftError(f"body height {height_m} m is not plausible (expected 0.5 to 2.6 m)")
    out = np.zeros(len(skeleton))
    for name, ratio in HEIGHT_RATIOS.items():
        out[skeleton.index(name)] = ratio * height_m
    return out


def lengths_from_take(take: Take) -> np.ndarray:
    """Median length of every bone over the frames where both its ends are tracked (calibration)."""
    sk = take.skeleton
    child = np.arange(len(sk))[sk.parent_array >= 0]
    parent = sk.parent_array[child]
    out = np.zeros(len(sk))
    ok = (take.states[:, child] != NOT_TRACKED) & (take.states[:, parent] != NOT_TRACKED)
    d = np.linalg.norm(take.positions[:, child] - take.positions[:, parent], axis=-1)
    for k, j in enumerate(child):
        if not ok[:, k].any():
            raise LiftError(f"cannot calibrate bone {sk.joints[j]}: never tracked in the take")
        out[j] = float(np.median(d[ok[:, k], k]))
    return out


def lengths_scaled_to_height(lengths: np.ndarray, height_m: float,
                             skeleton: Skeleton = KINECT_V1) -> np.ndarray:
    """Scale a set of lengths so the skeleton's standing height (ankle to head top) becomes height_m."""
    return np.asarray(lengths) * (height_m / standing_height(lengths, skeleton))


def standing_height(lengths: np.ndarray, skeleton: Skeleton = KINECT_V1) -> float:
    """Standing height implied by a skeleton's legs (the most stable anthropometric relation)."""
    L = dict(zip(skeleton.joints, np.asarray(lengths)))
    legs = 0.5 * (L["KneeLeft"] + L["AnkleLeft"] + L["KneeRight"] + L["AnkleRight"])
    return float(legs / _LEG_RATIO)
