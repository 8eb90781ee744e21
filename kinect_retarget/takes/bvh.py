"""BVH motion capture from any exporter read as a Kinect v1 take, or as its raw skeleton.

`read_bvh_skeleton(path)` gives every BVH joint (end sites included, named `<parent>_end`) with its global
position and rotation per frame, in the file's own lab space and units, plus what the figure is
(bvh_figure.py). `read(path)` turns that into a Kinect-like take (docs/take_formats.md, "BVH"):

* layout: bvh_parse.py (root written JOINT, `JOINT Site` end sites, any rotation order, tabs, CRLF);
* position channels: full local translation or delta from the OFFSET, decided per file (bvh_fk.py);
* joints: the Kinect v1 set found by structure (core/structure_mapping.py); hands and feet a skeleton lacks
  are extrapolated and marked INFERRED;
* up axis and unit from the figure itself (bvh_figure.py); `scale` (metres per file unit) overrides the unit;
* a virtual Kinect stands on the floor `camera_distance` metres in front of where the performer starts,
  `camera_height` metres up, level, looking back at them; joints are expressed in its camera space.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field

import numpy as np

from ..core.skeletons import INFERRED, KINECT_V1, TRACKED
from ..core.structure_mapping import StructureMapping
from ..core.take import Take, TakeError
from . import bvh_names
from ._screening import screen_joints
from .bvh_figure import choose_unit, height_warning, kinect_joints, map_figure, standing_height
from .bvh_fk import DELTA, POSITION_MODES, _axis_rotations, axis_quaternions, forward_kinematics, position_channel_mode
from .bvh_parse import BvhSkeleton, looks_like, read_bvh_text

__all__ = [
    "BvhMotion",
    "BvhSkeleton",
    "VirtualKinect",
    "_axis_rotations",
    "axis_quaternions",
    "describe",
    "forward_kinematics",
    "kinect_joints_lab",
    "looks_like",
    "read",
    "read_bvh_skeleton",
    "virtual_kinect",
]

DEFAULT_CAMERA_DISTANCE = 3.0  # metres in front of the performer's start
DEFAULT_CAMERA_HEIGHT = 0.8    # metres above the floor: a Kinect on a low table or TV stand
MIN_RANGE = 1.0                # metres: a Kinect cannot see closer (v1 ~0.8 m), so keep the take beyond this


@dataclass
class BvhMotion:
    """A BVH file: skeleton, raw channel values and forward kinematics for every joint.

    positions (F, N, 3) and rotations (F, N, 4 quaternions w, x, y, z) are global, in the file's lab axes;
    positions are in file units (multiply by `units_to_metres` for metres).
    """

    path: str
    skeleton: BvhSkeleton
    frame_time: float
    values: np.ndarray           # (F, C) channel values as in the file (degrees, file units)
    positions: np.ndarray
    rotations: np.ndarray
    rest_positions: np.ndarray   # (N, 3) positions with every channel zero (the hierarchy's rest pose)
    family: str | None = None    # naming family from bvh_names (informational), None if not recognised
    units_to_metres: float = 1.0
    up_axis: int = 1             # 0, 1 or 2: the lab axis nearest to up
    up_sign: float = 1.0
    up_vector: np.ndarray | None = None  # up itself when the capture volume is tilted (floor_plane.py)
    notes: dict = field(default_factory=dict)
    # {kinect joint: BVH joint indices averaged} (empty tuple: extrapolated); None when not a humanoid
    mapping: dict | None = None
    structure: StructureMapping | None = None
    position_mode: str = DELTA
    height_units: float = 0.0    # standing height in file units
    warnings: list = field(default_factory=list)
    mapping_error: str | None = None
    lines: np.ndarray | None = None  # (F,) the file line of each frame's motion values

    @property
    def frame_count(self) -> int:
        return int(self.values.shape[0])

    @property
    def up(self) -> np.ndarray:
        return np.eye(3)[self.up_axis] * self.up_sign if self.up_vector is None else self.up_vector

    @property
    def positions_m(self) -> np.ndarray:
        return self.positions * self.units_to_metres


def read_bvh_skeleton(path: str | os.PathLike, scale: float | None = None) -> BvhMotion:
    """Parse a BVH file and run forward kinematics for all joints (end sites included).

    `scale` (metres per file unit) overrides the unit detection. A skeleton that is not a humanoid still
    reads (Y up, unit from its extent); kinect_joints_lab then raises with the reason.
    """
    path = os.fspath(path)
    sk, frame_time, values, lines = read_bvh_text(path)
    mode = position_channel_mode(sk, values)
    positions, g_rot = forward_kinematics(sk, values, mode)
    rest, _ = forward_kinematics(sk, np.zeros((1, sk.channel_count)))
    motion = BvhMotion(path, sk, frame_time, values, positions, g_rot, rest[0], position_mode=mode, lines=lines)
    motion.family = bvh_names.resolve(sk.names, KINECT_V1.joints)[0]
    try:
        motion.structure = map_figure(path, sk.names, sk.parents, rest[0], positions, sk.is_end_site)
    except TakeError as exc:
        motion.mapping_error = str(exc)
        motion.height_units = float(np.nanmax(np.ptp(positions[..., 1], axis=-1)))
    else:
        motion.mapping = motion.structure.indices()
        motion.up_axis, motion.up_sign = motion.structure.up_axis, motion.structure.up_sign
        motion.up_vector = motion.structure.up
        motion.height_units = standing_height(positions, motion.structure, sk.parents)
    motion.units_to_metres, motion.notes["units"] = choose_unit(motion.height_units, motion.family, scale, path)
    warning = height_warning(motion.height_units * motion.units_to_metres, motion.notes["units"])
    if warning and motion.structure is not None:
        motion.warnings.append(warning)
    return motion


def _require_structure(motion: BvhMotion) -> StructureMapping:
    if motion.structure is None:
        raise TakeError(motion.mapping_error or f"{motion.path}: BVH skeleton not recognised as a humanoid")
    return motion.structure


def kinect_joints_lab(motion: BvhMotion) -> np.ndarray:
    """(F, 20, 3) Kinect v1 joints in lab axes and metres (hands and feet the skeleton lacks extrapolated)."""
    joints, _ = kinect_joints(motion.positions, _require_structure(motion))
    return joints * motion.units_to_metres


def describe(motion: BvhMotion) -> dict:
    """What was read and guessed, for `info` and the bake report."""
    s = _require_structure(motion)
    return {"bvh_unit": motion.notes["units"], "bvh_units_to_metres": motion.units_to_metres,
            "bvh_standing_height_m": round(motion.height_units * motion.units_to_metres, 3),
            "bvh_up_axis": ("+" if motion.up_sign > 0 else "-") + "XYZ"[motion.up_axis],
            "bvh_up": [round(float(v), 4) for v in motion.up],
            "bvh_position_channels": POSITION_MODES[motion.position_mode],
            "bvh_mapping": s.describe(motion.skeleton.names), "bvh_mapping_notes": list(s.notes)}


@dataclass
class VirtualKinect:
    """A level sensor looking at the performer. `rotation` rows are the Kinect X, Y, Z axes in lab
    coordinates; `position` is in lab metres; `floor` is the lab height (metres, along up) of the floor."""

    position: np.ndarray
    rotation: np.ndarray
    floor: float
    distance: float
    height: float

    def to_kinect(self, points_lab_m: np.ndarray) -> np.ndarray:
        """(..., 3) lab points in metres -> Kinect camera space."""
        return (np.asarray(points_lab_m) - self.position) @ self.rotation.T

    def as_dict(self) -> dict:
        return {"distance_m": self.distance, "height_m": self.height, "floor_lab_m": round(self.floor, 5),
                "position_lab_m": self.position.round(4).tolist(),
                "rotation_lab_to_kinect": self.rotation.round(6).tolist()}


def virtual_kinect(motion: BvhMotion, distance: float = DEFAULT_CAMERA_DISTANCE,
                   height: float = DEFAULT_CAMERA_HEIGHT, min_range: float | None = MIN_RANGE,
                   joints: np.ndarray | None = None) -> VirtualKinect:
    """Where the virtual sensor stands for this motion (docs/take_formats.md, BVH step 5).

    `distance` metres in front of the hips at frame 0 (facing = (left hip - right hip) x up), `height` metres
    above the floor (the lowest any joint goes), level. If the performer ever comes closer than `min_range`
    metres, the sensor backs away along its viewing axis until they never do (None: stay put). `joints`:
    kinect_joints_lab(motion) if the caller already has it.
    """
    if joints is None:
        joints = kinect_joints_lab(motion)
    up = motion.up
    floor = float(np.nanmin(motion.positions_m @ up))  # NaN channels (dropped later) must not decide it
    k = KINECT_V1.index
    hips = joints[:, [k("HipLeft"), k("HipRight"), k("HipCenter")]]
    first = int(np.argmax(np.all(np.isfinite(hips), axis=(1, 2))))  # frame 0 unless its hips are broken
    left = joints[first, k("HipLeft")] - joints[first, k("HipRight")]
    left -= up * (left @ up)
    if np.linalg.norm(left) < 1e-9:
        raise TakeError(f"{motion.path}: hips coincide at frame 0; cannot tell which way the performer faces")
    forward = np.cross(left, up)
    forward /= np.linalg.norm(forward)
    start = joints[first, k("HipCenter")]
    start = start - up * (start @ up) + up * floor           # on the floor under the hips at frame 0
    z_axis = -forward                                        # the sensor looks back at the performer
    rotation = np.stack([np.cross(up, z_axis), up, z_axis])  # X is the sensor's left
    cam = VirtualKinect(start + forward * distance + up * height, rotation, floor, distance, height)
    if min_range is not None:
        nearest = float(np.nanmin(cam.to_kinect(joints)[..., 2]))
        if nearest < min_range:
            cam.distance += min_range - nearest
            cam.position = cam.position - z_axis * (min_range - nearest)
    return cam


def read(path: str | os.PathLike, scale: float | None = None,
         camera_distance: float = DEFAULT_CAMERA_DISTANCE, camera_height: float = DEFAULT_CAMERA_HEIGHT,
         min_range: float | None = MIN_RANGE) -> Take:
    """A BVH file as a Kinect v1 take seen by a virtual sensor in front of the performer (virtual_kinect)."""
    motion = read_bvh_skeleton(path, scale)
    joints, missing = kinect_joints(motion.positions, _require_structure(motion))
    joints = joints * motion.units_to_metres
    cam = virtual_kinect(motion, camera_distance, camera_height, min_range, joints)
    kinect = cam.to_kinect(joints)
    states = np.full(kinect.shape[:2], TRACKED, dtype=np.uint8)
    states[:, missing] = INFERRED
    times = np.arange(motion.frame_count) * motion.frame_time
    meta = {"source_file": os.path.basename(motion.path), "time_unit": "s (Frame Time)",
            "bvh_family": motion.family, **describe(motion), "virtual_camera": cam.as_dict(),
            "converted": "optical mocap (BVH) sampled at the Kinect v1 joints by kinect_retarget"}
    if motion.warnings:
        meta["warnings"] = list(motion.warnings)
    # a NaN channel reaches the joints below it through forward kinematics: those become untracked
    kinect, states = screen_joints(motion.path, kinect, states, motion.lines, meta)
    try:
        return Take(KINECT_V1, kinect, states, times, _round_rate(1.0 / motion.frame_time), "bvh", meta)
    except TakeError as exc:
        raise TakeError(f"{motion.path}: {exc}") from None


def _round_rate(rate: float) -> float:
    """BVH frame times are printed rounded (.0083333): snap 120.0005 to 120."""
    return float(round(rate)) if abs(rate - round(rate)) < 1e-3 * rate else rate
