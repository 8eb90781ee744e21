"""Hands from Kinect v2's hand joints and hand states: the hand's roll from the thumb, the fingers' overall
direction from the hand tip, and a curl per finger from the hand state (open, closed = fist, lasso = index
and middle out), blended smoothly over time. Pure numpy; the Blender side (blender/io/finger_rig.py) finds
the rig's finger bones and keys them."""
from __future__ import annotations

import numpy as np

from .quat import from_axis_angle, mul, normalize

UNKNOWN, NOT_TRACKED, OPEN, CLOSED, LASSO = 0, 1, 2, 3, 4  # Kinect v2 HandState
FINGERS = ("thumb", "index", "middle", "ring", "pinky")
STATE_CURL = {OPEN: (0.0, 0.0, 0.0, 0.0, 0.0), CLOSED: (0.6, 1.0, 1.0, 1.0, 1.0),
              LASSO: (0.6, 0.0, 0.0, 1.0, 1.0)}
CURL_DEG = 70.0      # bend of each finger joint at full curl (three joints: a fist)
SMOOTH_S = 0.1       # time constant of the blend between hand states, seconds
MAX_ROLL_DEG = 120.0  # a thumb reading further off than this is noise, not a turned hand
BEND_RANGE_DEG = (-30.0, 60.0)  # fingers' overall bend from the hand tip: a little back, well forward

# finger bones (base to tip) per rig family; {s}: side tag, {S}: Left/Right, {i}: 1..3
FINGER_NAMES = {
    "rigify": ("thumb.0{i}{s}", "f_index.0{i}{s}", "f_middle.0{i}{s}", "f_ring.0{i}{s}", "f_pinky.0{i}{s}"),
    "mixamo": ("mixamorig:{S}HandThumb{i}", "mixamorig:{S}HandIndex{i}", "mixamorig:{S}HandMiddle{i}",
               "mixamorig:{S}HandRing{i}", "mixamorig:{S}HandPinky{i}"),
    "ue": ("thumb_0{i}_{s}", "index_0{i}_{s}", "middle_0{i}_{s}", "ring_0{i}_{s}", "pinky_0{i}_{s}"),
}
SIDE_TAGS = {"rigify": (".L", ".R"), "mixamo": ("", ""), "ue": ("l", "r")}


def finger_chains(bone_names, side: str) -> dict[str, list[str]] | None:
    """{finger: [bones base to tip]} for `side` ('Left'/'Right') in the first rig family whose four fingers
    all exist, else None."""
    names = set(bone_names)
    for family, patterns in FINGER_NAMES.items():
        tag = SIDE_TAGS[family][0 if side == "Left" else 1]
        chains = {}
        for finger, pattern in zip(FINGERS, patterns):
            chain = [pattern.format(i=i, s=tag, S=side) for i in (1, 2, 3)]
            chain = [b for b in chain if b in names]
            if chain:
                chains[finger] = chain
        if all(f in chains for f in FINGERS[1:]):
            return chains
    return None


def finger_curls(states: np.ndarray, times: np.ndarray, smooth_s: float = SMOOTH_S) -> np.ndarray:
    """(F,) hand states at (F,) times -> (F, 5) curl of each finger in [0, 1]: each state's target curl,
    unknown or untracked states holding the last known one, reached by a first-order blend (time constant
    smooth_s) so a fist closes over a few frames instead of snapping."""
    out = np.zeros((len(states), len(FINGERS)))
    curl = np.zeros(len(FINGERS))
    target = curl
    for f, state in enumerate(np.asarray(states)):
        target = np.asarray(STATE_CURL.get(int(state), target))
        dt = times[f] - times[f - 1] if f else 0.0
        curl = curl + (target - curl) * (1.0 - np.exp(-max(dt, 0.0) / smooth_s)) if f else target.copy()
        out[f] = curl
    return out


def signed_angle(a: np.ndarray, b: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """Angle (radians) turning a to b about `axis`, all (..., 3); a and b projected off the axis."""
    a = a - np.sum(a * axis, -1, keepdims=True) * axis
    b = b - np.sum(b * axis, -1, keepdims=True) * axis
    return np.arctan2(np.sum(np.cross(a, b) * axis, -1), np.sum(a * b, -1))


def hand_roll(desired: np.ndarray, thumb_local: np.ndarray, thumb_dir: np.ndarray) -> np.ndarray:
    """Twist (F,) radians about the hand bone's own Y that turns its thumb side toward the performer's thumb.
    desired (F, 3, 3) the hand's armature-space rotation, thumb_local (3,) the rig's thumb side in the hand
    bone's rest frame, thumb_dir (F, 3) hand -> thumb joint in armature space."""
    y = desired[:, :, 1]
    current = np.einsum("fij,j->fi", desired, thumb_local)
    angle = signed_angle(current, thumb_dir, y)
    return np.clip(angle, -np.radians(MAX_ROLL_DEG), np.radians(MAX_ROLL_DEG))


def twist_quats(quats: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Pose quaternions (F, 4) turned by (F,) radians about the bone's own Y axis (applied last, in bone
    space, so the bone's direction is unchanged)."""
    return mul(quats, from_axis_angle(np.array([0.0, 1.0, 0.0]), angle))


def fingers_bend(desired: np.ndarray, curl_axis_local: np.ndarray, tip_dir: np.ndarray) -> np.ndarray:
    """(F,) bend of the fingers as a whole (radians, + toward the palm) that points them along hand -> hand
    tip, measured about the hand's curl axis (its rest value curl_axis_local in the hand's frame)."""
    axis = normalize(np.einsum("fij,j->fi", desired, curl_axis_local))
    angle = signed_angle(desired[:, :, 1], tip_dir, axis)
    lo, hi = np.radians(BEND_RANGE_DEG)
    return np.clip(angle, lo, hi)


def finger_quats(axis_local: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """(F, 4) pose rotations of one finger bone: `angle` (F,) radians about its curl axis (3,) in its own
    frame (positive curls toward the palm)."""
    return from_axis_angle(np.broadcast_to(normalize(axis_local), (len(angle), 3)), angle)
