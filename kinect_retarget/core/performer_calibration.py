"""Calibration from about a second of a standing performer (T-pose or A-pose).

It fixes, for the current rig: the performer's bone lengths and leg length, hence the root scale
n = target leg / performer leg (paper 000, eq. 13) and the bone-length ratios; and the standing root
position, which becomes the rig's rest position for root motion. Stored as JSON on the rig object.
"""
from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field

import numpy as np

from .joint_frames import resolver
from .retarget import leg_length
from .skeletons import NOT_TRACKED, SKELETONS, Skeleton

MIN_FRAMES = 10
MAX_ROOT_SWAY_M = 0.05     # standing still: the root stays within 5 cm
PROPERTY = "kinect_retarget_calibration"  # custom property name on the rig object


class CalibrationError(ValueError):
    pass


@dataclass
class Calibration:
    skeleton: str
    frames: int
    pose: str                      # "T-pose", "A-pose" or "arms down"
    source_leg: float              # metres, hip -> knee -> ankle, mean of both sides
    root_reference: list           # Kinect camera space, metres
    bone_lengths: dict = field(default_factory=dict)   # joint at the bone's tail -> metres
    target_leg: float | None = None
    root_scale: float = 1.0
    version: int = 1

    def to_json(self) -> str:
        return json.dumps(asdict(self))

    @classmethod
    def from_json(cls, text: str) -> Calibration:
        try:
            data = json.loads(text)
            if data.get("version") != 1 or data.get("skeleton") not in SKELETONS:
                raise CalibrationError("unsupported calibration data")
            cal = cls(**data)
        except (TypeError, ValueError) as exc:
            raise CalibrationError(f"stored calibration is unreadable ({exc})") from None
        if not (np.isfinite(cal.root_scale) and cal.root_scale > 0 and len(cal.root_reference) == 3):
            raise CalibrationError("stored calibration has an invalid root scale or reference")
        return cal


def calibrate(skeleton: Skeleton, positions: np.ndarray, states: np.ndarray,
              target_leg: float | None = None, generated_rig: bool = False) -> Calibration:
    """positions (F, J, 3), states (F, J) of the capture window."""
    positions = np.asarray(positions, dtype=np.float64)
    states = np.asarray(states)
    root = skeleton.root
    legs = [skeleton.index(f"{p}{s}") for s in ("Left", "Right") for p in ("Hip", "Knee", "Ankle")
            if f"{p}{s}" in skeleton.joints]
    usable = (states[:, root] != NOT_TRACKED) & np.all(states[:, legs] != NOT_TRACKED, axis=1)
    if usable.sum() < MIN_FRAMES:
        raise CalibrationError(f"only {int(usable.sum())} of {len(states)} frames show the hips and both legs "
                               f"(need {MIN_FRAMES}); stand fully in view")
    p = np.where((states != NOT_TRACKED)[..., None], positions, np.nan)[usable]
    sway = np.nanmax(np.linalg.norm(p[:, root] - np.nanmedian(p[:, root], axis=0), axis=1))
    if sway > MAX_ROOT_SWAY_M:
        raise CalibrationError(f"the performer moved {sway * 100:.0f} cm during calibration; stand still")
    med = np.nanmedian(p, axis=0)  # (J, 3) the standing pose, robust to single bad frames
    bone = {skeleton.joints[j]: float(np.linalg.norm(med[j] - med[par]))
            for j, par in enumerate(skeleton.parents) if par >= 0 and np.all(np.isfinite(med[[j, par]]))}
    source_leg = leg_length(resolver(skeleton.joints, p))  # the engine's own measure, so n matches a bake
    if source_leg is None or not source_leg > 0.2:
        raise CalibrationError("leg length could not be measured (are the knees and ankles tracked?)")
    if generated_rig or not target_leg:
        scale = 1.0
    else:
        scale = float(target_leg) / source_leg
    return Calibration(skeleton.name, int(usable.sum()), _arm_pose(skeleton, med), source_leg,
                       [float(v) for v in med[root]], bone, target_leg, scale)


def _arm_pose(skeleton: Skeleton, med: np.ndarray) -> str:
    angles = []
    for s in ("Left", "Right"):
        names = (f"Shoulder{s}", f"Wrist{s}")
        if all(n in skeleton.joints for n in names):
            arm = med[skeleton.index(names[1])] - med[skeleton.index(names[0])]
            if np.all(np.isfinite(arm)) and np.linalg.norm(arm) > 0:
                # angle from straight down (Kinect Y is up)
                angles.append(np.degrees(np.arccos(np.clip(-arm[1] / np.linalg.norm(arm), -1, 1))))
    if not angles:
        return "unknown"
    a = float(np.mean(angles))
    return "T-pose" if a > 65 else "A-pose" if a > 25 else "arms down"


class CalibrationCapture:
    """Collects frames on the main thread for `duration` seconds of session time."""

    def __init__(self, duration: float = 1.0):
        self.duration = duration
        self.positions: list[np.ndarray] = []
        self.states: list[np.ndarray] = []
        self.t0: float | None = None

    def add(self, t: float, positions: np.ndarray, states: np.ndarray) -> bool:
        """True once the window is full."""
        if self.t0 is None:
            self.t0 = t
        self.positions.append(np.asarray(positions, dtype=np.float64))
        self.states.append(np.asarray(states))
        return t - self.t0 >= self.duration

    def result(self, skeleton: Skeleton, target_leg: float | None, generated_rig: bool) -> Calibration:
        if not self.positions:
            raise CalibrationError("no frames arrived during calibration")
        return calibrate(skeleton, np.stack(self.positions), np.stack(self.states), target_leg, generated_rig)
