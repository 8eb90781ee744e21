"""Bone lengths of the Kinect v1 skeleton: anthropometric ratios of body height, or measured from a take.

Lengths are indexed by the bone's child joint (the root's entry is 0), as everywhere in the lifter.
"""
from __future__ import annotations

import numpy as np

from ..core.skeletons import KINECT_V1, NOT_TRACKED, Skeleton
from ..core.take import Take
from .tracks2d import LiftError

# Segment lengths as fractions of standing height (Winter, "Biomechanics and Motor Control of Human
# Movement", segment-length figure), split onto Kinect v1 joints.
HEIGHT_RATIOS = {
    "Spine": 0.100, "ShoulderCenter": 0.186, "Head": 0.110,
    "ShoulderLeft": 0.110, "ElbowLeft": 0.172, "WristLeft": 0.146, "HandLeft": 0.050,
    "ShoulderRight": 0.110, "ElbowRight": 0.172, "WristRight": 0.146, "HandRight": 0.050,
    "HipLeft": 0.055, "KneeLeft": 0.245, "AnkleLeft": 0.246, "FootLeft": 0.090,
    "HipRight": 0.055, "KneeRight": 0.245, "AnkleRight": 0.246, "FootRight": 0.090,
}
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
    """Head-top height of a straight standing skeleton: legs + spine + neck/head + a head radius."""
    L = dict(zip(skeleton.joints, np.asarray(lengths)))
    legs = 0.5 * (L["KneeLeft"] + L["AnkleLeft"] + L["KneeRight"] + L["AnkleRight"])
    return float(legs + L["Spine"] + L["ShoulderCenter"] + 1.6 * L["Head"] + 0.045 * (legs / 0.49))
