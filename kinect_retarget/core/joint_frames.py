"""Joint orientation frames from neighbouring joints (paper 000, §2.3, "improved D-H"), made robust.

A frame is a (..., 3, 3) rotation whose columns are X, Y, Z. Y runs along the segment (parent joint ->
joint, paper step 1); X comes from a second, sideways vector (paper step 2-3: X = Y × AB) and Z = X × Y
(step 4). Which sideways vector a segment uses depends on its role in the body:

* torso, neck, head, pelvis: AB is the left-right line of the hips or shoulders, so twist follows the body;
* clavicles and hips: AB is the spine's up direction;
* arms and legs: X is the hinge axis of the elbow or knee (upper × lower segment). The forearm/shin and the
  hand/foot carry it across by the minimal rotation between neighbouring segments, so the elbow and knee bend
  about one axis and nothing twists like a candy wrapper.
  A straight limb has no bend plane; the hinge then blends smoothly into an anatomical default (elbows bend
  toward the chest's front, knees about the hips' left-right axis).

The same rules build the target rig's rest frames from its rest joint positions, so rest-pose differences
(A-pose or T-pose) cancel out (see retarget.py).
"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .quat import normalize

# Canonical joint names are Kinect v1's; Kinect v2 names that differ resolve through these aliases.
ALIASES = {"HipCenter": ("HipCenter", "SpineBase"), "Spine": ("Spine", "SpineMid"),
           "ShoulderCenter": ("ShoulderCenter", "SpineShoulder")}

# role of the segment that ends at a joint (the joint at the bone's tail)
ROLES = {
    "HipCenter": "pelvis", "SpineBase": "pelvis", "Spine": "spine", "SpineMid": "spine",
    "ShoulderCenter": "chest", "SpineShoulder": "chest", "Neck": "neck", "Head": "head",
    "Shoulder": "clavicle", "Elbow": "upper_arm", "Wrist": "forearm", "Hand": "hand", "HandTip": "hand",
    "Thumb": "hand", "Hip": "hip", "Knee": "thigh", "Ankle": "shin", "Foot": "foot",
}
LIMB_LEVELS = {"upper_arm": ("arm", 0), "forearm": ("arm", 1), "hand": ("arm", 2),
               "thigh": ("leg", 0), "shin": ("leg", 1), "foot": ("leg", 2)}
HINGE_BLEND = 0.1  # weight of the default hinge: it takes over below a bend of about 6 degrees
HINGE_FADE = 0.3   # sine of the bend (about 17 degrees) above which the default has no say

GetJoint = Callable[[str], "np.ndarray | None"]


def role_and_side(joint: str) -> tuple[str, str]:
    for side in ("Left", "Right"):
        if joint.endswith(side):
            return ROLES[joint[: -len(side)]], side
    return ROLES[joint], ""


def resolver(names: tuple[str, ...], positions: np.ndarray, joint_axis: int = -2) -> GetJoint:
    """Lookup of (..., 3) joint positions by canonical name; None when the skeleton lacks the joint.
    positions has joints on `joint_axis` (-2 for (..., J, 3), 0 for joint-major (J, ..., 3))."""
    index = {n: i for i, n in enumerate(names)}

    def get(name: str):
        for alias in ALIASES.get(name, (name,)):
            if alias in index:
                return positions[index[alias]] if joint_axis == 0 else positions[..., index[alias], :]
        return None
    return get


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a × b over the last axis, written out (np.cross is several times slower on large stacks)."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def frame_axes(y: np.ndarray, hint: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit X, Y, Z axes of the frames with Y along `y` and X as close to `hint` as possible
    (X = Y × AB in the paper's terms)."""
    y = normalize(y)
    x = hint - np.einsum("...i,...i->...", hint, y)[..., None] * y
    # A hint parallel to Y leaves X undefined; pick any perpendicular so output stays finite.
    bad = np.einsum("...i,...i->...", x, x) < 1e-18
    if np.any(bad):
        alt = np.where(np.abs(y[..., :1]) < 0.9, np.array([1.0, 0, 0]), np.array([0, 0, 1.0]))
        x = np.where(bad[..., None], _cross(y, _cross(alt, y)), x)
    x = normalize(x)
    return x, y, _cross(x, y)


def frame_from_y_hint(y: np.ndarray, hint: np.ndarray) -> np.ndarray:
    """Frames (..., 3, 3) whose columns are X, Y, Z (see frame_axes)."""
    return np.stack(frame_axes(y, hint), axis=-1)


def _sub(a, b):
    return None if a is None or b is None else a - b


def lateral(get: GetJoint, upper: bool, fallback: np.ndarray) -> np.ndarray:
    """Performer's right-to-left direction from shoulders (upper) or hips, whichever exists first."""
    pairs = [("ShoulderLeft", "ShoulderRight"), ("HipLeft", "HipRight")]
    for left, right in (pairs if upper else pairs[::-1]):
        v = _sub(get(left), get(right))
        if v is not None:
            return v
    return np.broadcast_to(fallback, np.shape(fallback))


def up_vector(get: GetJoint, fallback: np.ndarray) -> np.ndarray:
    v = _sub(get("ShoulderCenter"), get("HipCenter"))
    if v is None:
        v = _sub(get("Head"), get("HipCenter"))
    return fallback if v is None else v


def rotate_minimal(v: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Rotate v by the smallest rotation taking unit a to unit b (Rodrigues without normalising the axis;
    a and b are never opposite for neighbouring limb segments)."""
    k = _cross(a, b)
    c = np.sum(a * b, axis=-1, keepdims=True)
    return v * c + _cross(k, v) + k * np.sum(k * v, axis=-1, keepdims=True) / np.maximum(1.0 + c, 1e-9)


def hinge_axis(get: GetJoint, side: str, kind: str, y_upper: np.ndarray, world_lateral: np.ndarray,
               world_up: np.ndarray) -> np.ndarray:
    """Hinge axis of the elbow (kind 'arm') or knee ('leg') on one side, as seen by the upper segment;
    (..., 3), not normalised."""
    a, b, c = (("Shoulder", "Elbow", "Wrist") if kind == "arm" else ("Hip", "Knee", "Ankle"))
    upper = _sub(get(b + side), get(a + side))
    lower = _sub(get(c + side), get(b + side))
    y_upper = normalize(y_upper)
    bend = np.zeros_like(y_upper) if upper is None or lower is None else _cross(
        normalize(upper), normalize(lower))
    lat = normalize(lateral(get, upper=(kind == "arm"), fallback=world_lateral))
    if kind == "arm":
        forward = _cross(lat, normalize(up_vector(get, world_up)))
        # the small -lateral term settles the arm-straight-forward case, where y × forward vanishes
        default = _cross(y_upper, forward) - 0.05 * lat
    else:
        default = lat
    default = default - np.sum(default * y_upper, axis=-1, keepdims=True) * y_upper
    # the default fades out as the bend grows, so a clearly bent limb hinges about its true bend axis
    fade = np.clip(1.0 - np.linalg.norm(bend, axis=-1, keepdims=True) / HINGE_FADE, 0.0, 1.0) ** 2
    return bend + HINGE_BLEND * fade * normalize(default)


def limb_hint(get: GetJoint, side: str, kind: str, level: int, y: np.ndarray, world_lateral: np.ndarray,
              world_up: np.ndarray, cache: dict | None = None) -> np.ndarray:
    """X hint for the upper (level 0), lower (1) or end (2: hand, foot) segment of a limb. Lower segments
    carry the upper segment's hinge across by the minimal rotation between the segments, so nothing
    twists at the elbow, knee, wrist or ankle."""
    names = (("Shoulder", "Elbow", "Wrist", "Hand") if kind == "arm" else ("Hip", "Knee", "Ankle", "Foot"))
    dirs = [_sub(get(names[i + 1] + side), get(names[i] + side)) for i in range(3)]
    y_upper = y if level == 0 or dirs[0] is None else dirs[0]
    key = (side, kind)
    if cache is not None and key in cache:  # per-solve cache: the source's y_upper is always dirs[0]
        hint = cache[key]
    else:
        hint = hinge_axis(get, side, kind, y_upper, world_lateral, world_up)
        if cache is not None and dirs[0] is not None:
            cache[key] = hint
    for i in range(1, level + 1):
        prev = y_upper if i == 1 else dirs[i - 1]
        cur = y if i == level or dirs[i] is None else dirs[i]
        if prev is None or cur is None:
            break
        hint = rotate_minimal(hint, normalize(prev), normalize(cur))
    return hint


def segment_hint(get: GetJoint, tail: str, y: np.ndarray, world_lateral: np.ndarray,
                 world_up: np.ndarray, cache: dict | None = None) -> np.ndarray:
    """The X-direction hint for the segment ending at joint `tail` whose direction is `y`."""
    role, side = role_and_side(tail)
    if role in ("pelvis", "spine"):
        return _cross(y, lateral(get, upper=False, fallback=world_lateral))
    if role in ("chest", "neck", "head"):
        return _cross(y, lateral(get, upper=True, fallback=world_lateral))
    if role in ("clavicle", "hip"):
        return _cross(y, up_vector(get, world_up))
    kind, level = LIMB_LEVELS[role]
    return limb_hint(get, side, kind, level, y, world_lateral, world_up, cache)
