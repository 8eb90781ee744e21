"""UI-PRMD Kinect data (University of Idaho Physical Rehabilitation Movement Data), as Kinect v2 takes.

A movement is two files side by side: `<name>_positions.txt` and `<name>_angles.txt`, each 66 comma-separated
numbers per frame = 22 joints x 3, 30 Hz, no header. Joint 0 (Waist) is absolute in cm; every other triple is
an offset in its parent's local frame, turned by the Euler angles of the angles file (degrees, R = Rz Ry Rx
of the listed (x, y, z)). Forward kinematics follows the data set's own visualisation code (arms hang from the
chest's own rotation, legs from the waist's).

Their space: centimetres, Y up from the FLOOR, the sensor at x = z = 0 looking down -z, the subject facing +z
with their left at +x. Kinect camera space is (-x, y - h, -z) / 100 with h the sensor height, which the data
does not record: we assume 80 cm (as for the BVH virtual sensor), kept in metadata.

The 22 joints are named after segments; each sits at the segment's start, so they map onto Kinect v2 joints as
below. HandLeft/Right, HandTips and Thumbs are not in the data: NOT_TRACKED (NaN).
"""
from __future__ import annotations

import os
import re

import numpy as np

from ..core.skeletons import KINECT_V2, TRACKED
from ..core.take import Take, TakeError
from ._numeric import numeric_first_row, parse_table, read_bytes
from ._screening import screen_joints
from ._timebase import FRAME_ORDER
from .bvh import _axis_rotations

RATE = 30.0
SENSOR_HEIGHT_CM = 80.0
NAMES = ("Waist", "Spine", "Chest", "Neck", "Head", "HeadTip", "LeftCollar", "LeftUpperArm", "LeftForearm",
         "LeftHand", "RightCollar", "RightUpperArm", "RightForearm", "RightHand", "LeftUpperLeg",
         "LeftLowerLeg", "LeftFoot", "LeftLegToes", "RightUpperLeg", "RightLowerLeg", "RightFoot",
         "RightLegToes")
PARENTS = (-1, 0, 1, 2, 3, 4, 2, 6, 7, 8, 2, 10, 11, 12, 0, 14, 15, 16, 0, 18, 19, 20)
# Whose rotation a joint's offset is turned by, as in the data set's code: the parent's accumulated one,
# except the collars (the chest's own angles) and the upper legs (the waist's).
_FRAME_OF = {6: "own2", 10: "own2", 14: "own0", 18: "own0"}
TO_KINECT_V2 = {
    "SpineBase": "Waist", "SpineMid": "Spine", "SpineShoulder": "Chest", "Neck": "Head", "Head": "HeadTip",
    "ShoulderLeft": "LeftUpperArm", "ElbowLeft": "LeftForearm", "WristLeft": "LeftHand",
    "ShoulderRight": "RightUpperArm", "ElbowRight": "RightForearm", "WristRight": "RightHand",
    "HipLeft": "LeftUpperLeg", "KneeLeft": "LeftLowerLeg", "AnkleLeft": "LeftFoot", "FootLeft": "LeftLegToes",
    "HipRight": "RightUpperLeg", "KneeRight": "RightLowerLeg", "AnkleRight": "RightFoot",
    "FootRight": "RightLegToes",
}
NCOL = 3 * len(NAMES)


def looks_like(head: bytes) -> bool:
    return numeric_first_row(head, NCOL, b",") is not None


def partner_paths(path: str) -> tuple[str, str]:
    """(positions, angles) paths for either file of a movement."""
    base = os.path.basename(path)
    m = re.search(r"_(positions|angles)(\.\w+)?$", base)
    if m is None:
        raise TakeError(f"{path}: UI-PRMD files are named <movement>_positions.txt and <movement>_angles.txt; "
                        f"cannot find this file's partner")
    stem = os.path.join(os.path.dirname(path), base[:m.start()])
    ext = m.group(2) or ""
    return f"{stem}_positions{ext}", f"{stem}_angles{ext}"


def read(path: str | os.PathLike, sensor_height_cm: float = SENSOR_HEIGHT_CM) -> Take:
    path = os.fspath(path)
    pos_path, ang_path = partner_paths(path)
    for p in (pos_path, ang_path):
        if not os.path.exists(p):
            raise TakeError(f"{path}: UI-PRMD needs both {os.path.basename(pos_path)} and "
                            f"{os.path.basename(ang_path)}; {p} not found")
    pos, pos_lines = parse_table(pos_path, read_bytes(pos_path), NCOL, delimiters=b",", what="frame line")
    ang, _ = parse_table(ang_path, read_bytes(ang_path), NCOL, delimiters=b",", what="frame line")
    if pos.shape[0] != ang.shape[0]:
        raise TakeError(f"{pos_path}: {pos.shape[0]} frames but {os.path.basename(ang_path)} has "
                        f"{ang.shape[0]} (one file truncated?)")
    lab = forward_kinematics(pos.reshape(-1, 22, 3), ang.reshape(-1, 22, 3))
    kinect = np.stack([-lab[..., 0], lab[..., 1] - sensor_height_cm, -lab[..., 2]], axis=-1) / 100.0
    f = kinect.shape[0]
    positions = np.full((f, len(KINECT_V2), 3), np.nan)
    states = np.zeros((f, len(KINECT_V2)), dtype=np.uint8)
    for v2, name in TO_KINECT_V2.items():
        positions[:, KINECT_V2.index(v2)] = kinect[:, NAMES.index(name)]
        states[:, KINECT_V2.index(v2)] = TRACKED
    meta = {"source_file": os.path.basename(pos_path), "angles_file": os.path.basename(ang_path),
            "time_unit": FRAME_ORDER, "assumed_sensor_height_m": sensor_height_cm / 100.0,
            "untracked_joints": [j for j in KINECT_V2.joints if j not in TO_KINECT_V2]}
    # a NaN offset or angle reaches the joints below it through the kinematic chain: those become untracked
    positions, states = screen_joints(pos_path, positions, states, pos_lines, meta)
    return Take(KINECT_V2, positions, states, np.arange(f) / RATE, RATE, "uiprmd", meta)


def forward_kinematics(offsets: np.ndarray, angles_deg: np.ndarray) -> np.ndarray:
    """(F, 22, 3) offsets (joint 0 absolute) and Euler angles -> (F, 22, 3) absolute positions, cm."""
    f = offsets.shape[0]
    own = (_axis_rotations(angles_deg[..., 2], np.full((f, 22), 2))
           @ _axis_rotations(angles_deg[..., 1], np.full((f, 22), 1))
           @ _axis_rotations(angles_deg[..., 0], np.full((f, 22), 0)))
    acc = np.empty_like(own)
    out = np.empty_like(offsets)
    acc[:, 0], out[:, 0] = own[:, 0], offsets[:, 0]
    for j in range(1, 22):
        p = PARENTS[j]
        frame = own[:, int(_FRAME_OF[j][-1])] if j in _FRAME_OF else acc[:, p]
        out[:, j] = out[:, p] + np.einsum("fab,fb->fa", frame, offsets[:, j])
        acc[:, j] = frame @ own[:, j]
    return out
