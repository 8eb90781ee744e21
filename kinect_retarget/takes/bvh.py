"""BVH motion capture (CMU, MakeHuman, Mixamo-style) read as a Kinect v1 take, or as its raw skeleton.

`read_bvh_skeleton(path)` gives every BVH joint (end sites included, named `<parent>_end`) with its global
position and rotation per frame, in the file's own lab space and units. `read(path)` turns that into a
Kinect-like take (docs/take_formats.md, "BVH"):

* units: metres per file unit from `scale`, else from the skeleton family (CMU 0.0254/0.45, MakeHuman 0.1),
  else from the rest height (the unit among m, dm, CMU, inch, cm, mm that makes it closest to 1.7 m);
* up axis: the lab axis closest to ankles -> head in the rest pose (Y for CMU, Z for MakeHuman);
* a virtual Kinect stands on the floor `camera_distance` metres in front of where the performer starts,
  `camera_height` metres up, level, looking back at them; joints are expressed in its camera space;
* joints: the Kinect v1 set, picked by the name tables in bvh_names.py. All states are TRACKED.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field

import numpy as np

from ..core import quat
from ..core.skeletons import KINECT_V1, TRACKED
from ..core.take import Take, TakeError
from . import bvh_names
from ._numeric import parse_table, read_bytes
from ._screening import screen_joints

DEFAULT_CAMERA_DISTANCE = 3.0  # metres in front of the performer's start
DEFAULT_CAMERA_HEIGHT = 0.8    # metres above the floor: a Kinect on a low table or TV stand
MIN_RANGE = 1.0                # metres: a Kinect cannot see closer (v1 ~0.8 m), so keep the take beyond this
_AXES = {"Xposition": 0, "Yposition": 1, "Zposition": 2, "Xrotation": 0, "Yrotation": 1, "Zrotation": 2}
# Candidate units (metres per unit) for files of unknown family, with a nominal adult height to compare to.
_UNIT_CANDIDATES = (1.0, 0.1, 0.0254 / 0.45, 0.0254, 0.01, 0.001)
_NOMINAL_HEIGHT = 1.7


def looks_like(head: bytes) -> bool:
    return head.lstrip(b"\xef\xbb\xbf \t\r\n").upper().startswith(b"HIERARCHY")


@dataclass
class BvhSkeleton:
    """The hierarchy. Joints are in file order, so every parent comes before its children."""

    names: tuple[str, ...]
    parents: np.ndarray          # (N,) int, -1 for the root
    offsets: np.ndarray          # (N, 3) file units, lab axes
    channels: tuple[tuple[str, ...], ...]  # per joint, e.g. ("Zrotation", "Yrotation", "Xrotation")
    first_channel: np.ndarray    # (N,) column of the joint's first channel in a motion line
    is_end_site: np.ndarray      # (N,) bool

    @property
    def channel_count(self) -> int:
        return int(sum(len(c) for c in self.channels))

    def index(self, name: str) -> int:
        return self.names.index(name)


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
    family: str | None = None    # naming family from bvh_names, None if not recognised
    units_to_metres: float = 1.0
    up_axis: int = 1             # 0, 1 or 2: the lab axis pointing up
    up_sign: float = 1.0
    notes: dict = field(default_factory=dict)
    # bvh_names.resolve's mapping: {kinect joint: BVH joint indices}, or {family: [unresolved joints]} if
    # the family is None; None until resolved (read_bvh_skeleton resolves it)
    mapping: dict | None = None
    lines: np.ndarray | None = None  # (F,) the file line of each frame's motion values

    @property
    def frame_count(self) -> int:
        return int(self.values.shape[0])

    @property
    def positions_m(self) -> np.ndarray:
        return self.positions * self.units_to_metres


# ---------------------------------------------------------------------------------------------- parsing

def _parse_hierarchy(path: str, lines: list[str]) -> tuple[BvhSkeleton, int]:
    """Parse HIERARCHY ... up to MOTION; returns the skeleton and the index of the MOTION line."""
    names: list[str] = []
    parents: list[int] = []
    offsets: list[list[float]] = []
    channels: list[tuple[str, ...]] = []
    ends: list[bool] = []
    stack: list[int] = []
    pending: int | None = None   # joint declared, its '{' not yet seen
    motion_line = -1
    for i, raw in enumerate(lines):
        tok = raw.split()
        if not tok:
            continue
        key = tok[0].upper()
        where = f"{path}:{i + 1}"
        if i == 0 or (not names and key == "HIERARCHY"):
            if key != "HIERARCHY":
                raise TakeError(f"{where}: not a BVH file (first line should be HIERARCHY)")
            continue
        if key in ("ROOT", "JOINT") or (key == "END" and len(tok) > 1 and tok[1].upper() == "SITE"):
            if key == "ROOT" and stack:
                raise TakeError(f"{where}: ROOT inside another joint")
            if key != "ROOT" and not stack:
                raise TakeError(f"{where}: {tok[0]} outside any joint (missing ROOT or extra '}}')")
            if key == "END":
                name = f"{names[stack[-1]]}_end"
            elif len(tok) < 2:
                raise TakeError(f"{where}: {tok[0]} without a name")
            else:
                name = " ".join(tok[1:])
            if name in names:
                raise TakeError(f"{where}: joint name {name!r} used twice")
            names.append(name)
            parents.append(stack[-1] if stack else -1)
            offsets.append([0.0, 0.0, 0.0])
            channels.append(())
            ends.append(key == "END")
            pending = len(names) - 1
        elif key == "{":
            if pending is None:
                raise TakeError(f"{where}: '{{' without a joint")
            stack.append(pending)
            pending = None
        elif key == "}":
            if not stack:
                raise TakeError(f"{where}: unbalanced '}}'")
            stack.pop()
        elif key == "OFFSET":
            if not stack:
                raise TakeError(f"{where}: OFFSET outside a joint")
            try:
                off = [float(v) for v in tok[1:4]]
            except ValueError:
                raise TakeError(f"{where}: OFFSET has a non-numeric value") from None
            if len(off) != 3 or not np.all(np.isfinite(off)):
                raise TakeError(f"{where}: OFFSET needs 3 finite numbers")
            offsets[stack[-1]] = off
        elif key == "CHANNELS":
            if not stack or ends[stack[-1]]:
                raise TakeError(f"{where}: CHANNELS outside a joint")
            try:
                n = int(tok[1])
            except (IndexError, ValueError):
                raise TakeError(f"{where}: CHANNELS needs a count") from None
            chans = tuple(tok[2:])
            if len(chans) != n:
                raise TakeError(f"{where}: CHANNELS says {n} but lists {len(chans)}")
            unknown = [c for c in chans if c not in _AXES]
            if unknown:
                raise TakeError(f"{where}: unknown channel {unknown[0]!r}")
            channels[stack[-1]] = chans
        elif key == "MOTION":
            motion_line = i
            break
        else:
            raise TakeError(f"{where}: unexpected {tok[0]!r} in HIERARCHY")
    if not names:
        raise TakeError(f"{path}: BVH file has no ROOT joint")
    if motion_line < 0:
        raise TakeError(f"{path}: BVH file has no MOTION section (truncated?)")
    if stack or pending is not None:
        raise TakeError(f"{path}:{motion_line + 1}: HIERARCHY not closed before MOTION (missing '}}')")
    counts = np.array([len(c) for c in channels])
    first = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
    return BvhSkeleton(tuple(names), np.array(parents, dtype=np.int64), np.array(offsets, dtype=np.float64),
                       tuple(channels), first, np.array(ends, dtype=bool)), motion_line


def _parse_motion_header(path: str, lines: list[str], motion_line: int) -> tuple[int, float, int]:
    """'Frames: N' and 'Frame Time: t' after MOTION; returns (frames, frame_time, first data line index)."""
    frames = frame_time = None
    i = motion_line + 1
    while i < len(lines) and (frames is None or frame_time is None):
        text = lines[i].strip()
        low = text.lower()
        if low.startswith("frames:"):
            try:
                frames = int(text.split(":", 1)[1])
            except ValueError:
                raise TakeError(f"{path}:{i + 1}: 'Frames:' needs a whole number") from None
        elif low.startswith("frame time:"):
            try:
                frame_time = float(text.split(":", 1)[1])
            except ValueError:
                raise TakeError(f"{path}:{i + 1}: 'Frame Time:' needs a number") from None
        elif text:
            raise TakeError(f"{path}:{i + 1}: expected 'Frames:' and 'Frame Time:' after MOTION")
        i += 1
    if frames is None or frame_time is None:
        raise TakeError(f"{path}: MOTION section lacks 'Frames:' or 'Frame Time:' (truncated?)")
    if frames < 1:
        raise TakeError(f"{path}: BVH file has no frames")
    if not (np.isfinite(frame_time) and frame_time > 0):
        raise TakeError(f"{path}: frame time must be positive, got {frame_time}")
    return frames, frame_time, i


# ------------------------------------------------------------------------------------ forward kinematics

def axis_quaternions(angles_deg: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """(..., N, 4) quaternions (w, x, y, z) rotating by `angles_deg` (..., N) about coordinate axes
    `axes` (N,) or (..., N), values 0, 1, 2 = X, Y, Z."""
    half = np.radians(angles_deg) / 2
    q = np.zeros(half.shape + (4,))
    q[..., 0] = np.cos(half)
    axes = np.asarray(axes)
    if axes.ndim == 1 and half.ndim >= 1:  # one axis per joint: a single scatter, no per-axis masks
        q[..., np.arange(axes.size), axes + 1] = np.sin(half)
        return q
    axes = np.broadcast_to(axes, half.shape)
    sin = np.sin(half)
    for a in range(3):
        q[..., a + 1] = np.where(axes == a, sin, 0.0)
    return q


def _axis_rotations(angles_deg: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """(..., 3, 3) rotation matrices by `angles_deg` about coordinate axes `axes`."""
    return quat.to_matrix(axis_quaternions(angles_deg, axes))


def _rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Rotate (..., 3) vectors by (..., 4) unit quaternions: v + 2w (u x v) + 2 u x (u x v)."""
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    vx, vy, vz = v[..., 0], v[..., 1], v[..., 2]
    tx, ty, tz = 2 * (y * vz - z * vy), 2 * (z * vx - x * vz), 2 * (x * vy - y * vx)
    return np.stack([vx + w * tx + (y * tz - z * ty),
                     vy + w * ty + (z * tx - x * tz),
                     vz + w * tz + (x * ty - y * tx)], axis=-1)


def _local_transforms(sk: BvhSkeleton, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per-frame local rotations (F, N, 4 quaternions) and translations (F, N, 3) from channel values.

    Rotation channels compose in the order listed (R = R_first @ R_second @ R_third, column vectors).
    The root's position channels give its position; other joints' position channels add to their OFFSET
    (MakeHuman writes small deltas there).
    """
    f, n = values.shape[0], len(sk.names)
    trans = np.broadcast_to(sk.offsets, (f, n, 3)).copy()
    # Rotation channels: slot k (0..2) of each joint, padded with zero angles about X.
    slots = np.zeros((n, 3), dtype=np.int64)
    cols = np.full((n, 3), -1, dtype=np.int64)
    for j, chans in enumerate(sk.channels):
        k = 0
        for c_i, c in enumerate(chans):
            col = sk.first_channel[j] + c_i
            if c.endswith("rotation"):
                slots[j, k], cols[j, k] = _AXES[c], col
                k += 1
            elif sk.parents[j] < 0:
                trans[:, j, _AXES[c]] = values[:, col]
            else:
                trans[:, j, _AXES[c]] += values[:, col]
    padded = np.concatenate([values, np.zeros((f, 1))], axis=1)  # column -1 reads 0
    rot = axis_quaternions(padded[:, cols[:, 0]], slots[:, 0])
    for k in (1, 2):
        rot = quat.mul(rot, axis_quaternions(padded[:, cols[:, k]], slots[:, k]))
    return rot, trans


def _depth_levels(parents: np.ndarray) -> list[np.ndarray]:
    """Joint indices grouped by depth below the root (parents come before children in file order)."""
    depth = np.zeros(len(parents), dtype=np.int64)
    for j, p in enumerate(parents):
        depth[j] = depth[p] + 1 if p >= 0 else 0
    return [np.flatnonzero(depth == d) for d in range(int(depth.max()) + 1)]


def forward_kinematics(sk: BvhSkeleton, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Global positions (F, N, 3) and rotations (F, N, 4 quaternions) for every joint and frame.

    Joints at the same depth are done together, so the Python loop runs once per level, not per joint.
    """
    rot, trans = _local_transforms(sk, values)
    g_rot = np.empty_like(rot)
    g_pos = np.empty_like(trans)
    levels = _depth_levels(sk.parents)
    g_rot[:, levels[0]] = rot[:, levels[0]]
    g_pos[:, levels[0]] = trans[:, levels[0]]
    for joints in levels[1:]:
        parents = sk.parents[joints]
        g_rot[:, joints] = quat.mul(g_rot[:, parents], rot[:, joints])
        g_pos[:, joints] = g_pos[:, parents] + _rotate(g_rot[:, parents], trans[:, joints])
    return g_pos, g_rot


# ------------------------------------------------------------------------------------------ public API

def read_bvh_skeleton(path: str | os.PathLike, scale: float | None = None) -> BvhMotion:
    """Parse a BVH file and run forward kinematics for all joints (end sites included).

    `scale` (metres per file unit) overrides the unit detection.
    """
    path = os.fspath(path)
    data = read_bytes(path)
    if not looks_like(data[:4096]):
        raise TakeError(f"{path}:1: not a BVH file (first line should be HIERARCHY)")
    text = data.decode("utf-8", errors="replace")
    lines = text.splitlines()
    sk, motion_line = _parse_hierarchy(path, lines)
    frames, frame_time, first = _parse_motion_header(path, lines, motion_line)
    body = "\n".join(lines[first:]).encode("latin-1", errors="replace")
    values, line_numbers = parse_table(path, body, sk.channel_count, first_line=first + 1, what="motion line")
    if values.shape[0] < frames:
        raise TakeError(f"{path}: 'Frames: {frames}' but only {values.shape[0]} motion lines "
                        f"(file truncated after line {int(line_numbers[-1])})")
    if values.shape[0] > frames:
        raise TakeError(f"{path}:{int(line_numbers[frames])}: more motion lines than 'Frames: {frames}'")
    positions, g_rot = forward_kinematics(sk, values)
    rest, _ = forward_kinematics(sk, np.zeros((1, sk.channel_count)))
    motion = BvhMotion(path, sk, frame_time, values, positions, g_rot, rest[0], lines=line_numbers)
    motion.family, motion.mapping = _family(sk)
    if motion.family is not None:  # unknown skeletons keep the BVH convention, Y up
        motion.up_axis, motion.up_sign = _up_axis(rest[0], motion.mapping)
    motion.units_to_metres = _units(motion, scale)
    return motion


def kinect_joints_lab(motion: BvhMotion) -> np.ndarray:
    """(F, 20, 3) Kinect v1 joints in lab axes and metres, from the name tables (bvh_names.py)."""
    family, mapping = (motion.family, motion.mapping) if motion.mapping is not None else _family(motion.skeleton)
    if family is None:
        detail = "; ".join(f"{fam}: no {', '.join(miss[:4])}{'...' if len(miss) > 4 else ''}"
                           for fam, miss in mapping.items())
        raise TakeError(f"{motion.path}: BVH skeleton not recognised as a humanoid (tried {detail}). "
                        f"Its joints: {', '.join(motion.skeleton.names[:12])}...")
    pos = np.stack([motion.positions[:, list(idx)].mean(axis=1) for idx in mapping.values()], axis=1)
    return pos * motion.units_to_metres


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
    up = np.zeros(3)
    up[motion.up_axis] = motion.up_sign
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
    joints = kinect_joints_lab(motion)
    cam = virtual_kinect(motion, camera_distance, camera_height, min_range, joints)
    kinect = cam.to_kinect(joints)
    states = np.full(kinect.shape[:2], TRACKED, dtype=np.uint8)
    times = np.arange(motion.frame_count) * motion.frame_time
    meta = {"source_file": os.path.basename(motion.path), "time_unit": "s (Frame Time)",
            "bvh_family": motion.family, "bvh_units_to_metres": motion.units_to_metres,
            "virtual_camera": cam.as_dict(),
            "converted": "optical mocap (BVH) sampled at the Kinect v1 joints by kinect_retarget"}
    # a NaN channel reaches the joints below it through forward kinematics: those become untracked
    kinect, states = screen_joints(motion.path, kinect, states, motion.lines, meta)
    try:
        return Take(KINECT_V1, kinect, states, times, _round_rate(1.0 / motion.frame_time), "bvh", meta)
    except TakeError as exc:
        raise TakeError(f"{motion.path}: {exc}") from None


def _round_rate(rate: float) -> float:
    """BVH frame times are printed rounded (.0083333): snap 120.0005 to 120."""
    return float(round(rate)) if abs(rate - round(rate)) < 1e-3 * rate else rate


def _family(sk: BvhSkeleton):
    return bvh_names.resolve(sk.names, KINECT_V1.joints)


def _up_axis(rest: np.ndarray, mapping: dict[str, tuple[int, ...]]) -> tuple[int, float]:
    head = rest[list(mapping["Head"])].mean(axis=0)
    ankles = rest[list(mapping["AnkleLeft"] + mapping["AnkleRight"])].mean(axis=0)
    d = head - ankles
    axis = int(np.argmax(np.abs(d)))
    return axis, float(np.sign(d[axis]) or 1.0)


def _units(motion: BvhMotion, scale: float | None) -> float:
    if scale is not None:
        if not (np.isfinite(scale) and scale > 0):
            raise TakeError(f"{motion.path}: scale must be a positive number of metres per unit, got {scale}")
        motion.notes["units"] = "explicit"
        return float(scale)
    if motion.family in bvh_names.FAMILY_UNITS:
        motion.notes["units"] = f"family {motion.family}"
        return bvh_names.FAMILY_UNITS[motion.family]
    rest = motion.rest_positions
    height = float(np.ptp(rest[:, motion.up_axis])) if rest.shape[0] > 1 else 0.0
    if height <= 0:
        motion.notes["units"] = "assumed metres"
        return 1.0
    best = min(_UNIT_CANDIDATES, key=lambda s: abs(np.log(height * s / _NOMINAL_HEIGHT)))
    motion.notes["units"] = f"rest height {height:.4g} units"
    return best
