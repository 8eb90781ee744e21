"""Body proportions for the fitted Kinect v1 skeleton, calibrated from a standing performer.

Ratios to standing height H (top of head to floor) are those of the MakeHuman reference body, which match
common anthropometric tables; calibration measures H (and where the torso patch sits) on standing frames
and scales them.
"""
from __future__ import annotations

from dataclasses import dataclass

# Heights above the floor (fraction of H) of the centre joints, and half-widths / bone lengths (fraction of H).
HEIGHT_HIP_CENTER = 0.52
HEIGHT_SPINE = 0.658
HEIGHT_SHOULDER_CENTER = 0.844
HEIGHT_HEAD = 0.951
SHOULDER_HALF_WIDTH = 0.101
SHOULDER_DROP = 0.038
SHOULDER_TOP_BELOW_CENTRE = 0.031  # the surface beside the neck sits this far below the shoulder centre
HIP_HALF_WIDTH = 0.066
UPPER_ARM = 0.137
FOREARM = 0.136
HAND = 0.056
THIGH = 0.252
SHIN = 0.229
FOOT = 0.041

# How far behind the visible (front) surface each joint sits, metres: roughly the limb's radius (set on the
# MakeHuman reference body, so the synthetic benchmark has seen them: see docs/depth_tracking.md).
DEPTH_INSIDE = {"HipCenter": 0.11, "Spine": 0.11, "ShoulderCenter": 0.10, "Head": 0.10,
                "Shoulder": 0.085, "Elbow": 0.04, "Wrist": 0.03, "Hand": 0.02,
                "Hip": 0.10, "Knee": 0.03, "Ankle": 0.07, "Foot": 0.075}


@dataclass
class BodyCalibration:
    height: float = 1.70               # standing height H, metres
    torso_patch_height: float = 0.60   # height of the torso patch centroid above the floor, fraction of H
    frames: int = 0                    # frames that contributed

    def bone(self, ratio: float) -> float:
        return ratio * self.height
