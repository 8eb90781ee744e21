"""Where the Kinect v1 SDK puts the torso's, arms' and legs' joints on a body, from where MakeHuman's skeleton puts them.

The tracker fits MakeHuman's skeleton (its body model, proposals and offsets are learned on MakeHuman bodies);
the SDK names the same joints but places several elsewhere. Its HipCenter sits well above the hip joints' line
(about a fifth of the torso; MakeHuman's is on it), its Spine a short way above that and behind it (MakeHuman's
is mid-back), its ShoulderCenter and head joint a little lower, its hip joints narrower (Kinect v2's, in the
redistributable recordings, are 0.099 of standing height apart; MakeHuman's 0.132) and a little farther
forward, its shoulders a little lower and narrower, its upper arm longer (Kinect v2's 0.152 of standing
height, MakeHuman's 0.137, and on real depth a little more: elbow, wrist and hand sit that much farther out
along it), its knees a little higher and farther back (its thighs lean about 6 degrees less forward than the
tracker's), its ankles higher up the shin and a little farther back (the tracker's lay 4 cm lower and 1-2 cm
farther forward, median, and its shins leaned about 3 degrees farther forward), its feet a little farther
forward, its arms a little farther forward (its upper arms lean about 3 degrees more forward than the
tracker's, in all four subject-trial groups), and its whole arm, shoulder to hand, a little nearer the midline
and lower. And it does not bend a knee backward or sideways: its knees stay within a narrow range across the
line from hip to ankle; nor does it put an ankle in front of its foot, nor sink its hips to its knees (the tracker's
upright torso, hung from the head top in a deep bend, does: its hips came down to the knees' height or below).
Output in the SDK's convention means a depth-tracked take is read, retargeted and compared like one the SDK
recorded.

The amounts are fractions of the torso (the hips' midpoint to ShoulderCenter), so the same function converts
the tracker's output and a rendered body's true joints alike (the synthetic benchmark scores against those).
The hips' width and the upper arm come from the Kinect v2 recordings; the other nineteen numbers and the knees',
ankles' and hips' limits (five of them and a bound on the move; no redistributable Kinect v1 skeleton shows
them) are settings chosen on the real-depth benchmark's subjects 1-2, as its other settings were, and they
hold on subjects 3-4 (docs/depth_tracking.md says which were chosen with subjects 3-4's medians in view).
"""
from __future__ import annotations

import numpy as np

from ..core.skeletons import KINECT_V1
from . import body_model_fit as bm

J = KINECT_V1.index
HIP_CENTER_UP = 0.20     # HipCenter above the hip joints' midpoint, along the torso
SPINE_UP = 0.12          # Spine above HipCenter ...
SPINE_BACK = 0.05        # ... and behind it (the tracker's Spine lay 2.3-3.4 cm in front of the SDK's)
SHOULDER_CENTER_DOWN = 0.05   # ShoulderCenter lower (the tracker's lay 2.3-2.7 cm above the SDK's) ...
SHOULDER_CENTER_BACK = 0.03   # ... and farther back (1.3-1.5 cm in front)
HEAD_DOWN = 0.05         # the head joint lower (2.5-2.6 cm above)
HIPS_INWARD = 0.25       # hip joints moved this share of the way toward the midline (1 - 0.099 / 0.132)
HIPS_UP = 0.06
HIPS_FORWARD = 0.03      # hip joints moved this much forward (the tracker's lay 1.4-1.8 cm behind the SDK's) ...
FEET_FORWARD = 0.04      # ... and the feet (2.1-3.6 cm behind)
SHOULDERS_INWARD = 0.05  # shoulders moved this share of the way toward ShoulderCenter
SHOULDERS_UP = -0.06
KNEES_BACK = 0.05        # knees moved this much back (the SDK's thighs lean 6 degrees less forward) ...
KNEES_UP = 0.05          # ... and up
# the knee's place across its hip-ankle line, held within the SDK's 5th-95th percentiles (subjects 1-2):
KNEE_BEHIND_MAX = 0.095  # no farther behind it than this
KNEE_OUTWARD = (-0.026, 0.071)   # nor farther inward or outward (toward the performer's own side) than these,
KNEE_SIDEWAYS_MOVE = 0.1         # moved sideways no more than this
# the hips' midpoint no nearer the knees' midpoint along the torso than this, lifted up the torso if it is (the SDK's
# 2nd and 5th percentiles on subjects 1-2 are 0.43 and 0.60, the tracker's 0.21 and 0.41; lifting farther bettered
# the limbs' directions a little more and worsened the joints' places)
HIPS_ABOVE_KNEES = 0.45
ANKLE_BEFORE_FOOT = 0.004   # no ankle farther forward of its foot than this (the SDK's 95th percentile; median -0.063)
ANKLES_BACK = 0.03       # ankles moved this much back (1.5 cm on a 0.5 m torso) ...
ANKLES_UP_SHIN = 0.07    # ... and up along the shin (3.5 cm: the shin's direction is kept)
ARMS_FORWARD = 0.03      # elbow, wrist and hand moved this much forward (the SDK's upper arms lean 3 degrees more so)
SDK_UPPER_ARM = 0.152    # of standing height, Kinect v2 (MakeHuman's bm.UPPER_ARM 0.137)
TORSO = bm.HEIGHT_SHOULDER_CENTER - bm.HEIGHT_HIP_CENTER   # the torso as a share of standing height
UPPER_ARM_LONGER = 0.03  # and more: the tracker's tracked upper arms were still 2.5-2.9 cm short of the SDK's
ARM_OUT = (SDK_UPPER_ARM - bm.UPPER_ARM) / TORSO + UPPER_ARM_LONGER   # elbow, wrist and hand moved out along it
# the whole arm, shoulder to hand, moved together (its bones keep their directions): the SDK's arm joints lay
# 1.1-2.3 cm nearer the midline and its shoulders and elbows 1.4-2.5 cm lower than the tracker's (median, on
# both subject pairs)
ARM_INWARD = 0.03
ARM_DOWN = 0.02


def to_sdk_joints(positions: np.ndarray) -> np.ndarray:
    """(..., 20, 3) Kinect v1 joints on MakeHuman's convention -> the same body's joints where the SDK puts
    them (a copy)."""
    p = np.array(positions, dtype=np.float64, copy=True)
    hips = (p[..., J("HipLeft"), :] + p[..., J("HipRight"), :]) / 2
    axis = p[..., J("ShoulderCenter"), :] - hips
    torso = np.linalg.norm(axis, axis=-1, keepdims=True)
    up = axis / np.maximum(torso, 1e-9)
    step = torso * up   # the torso's length along its own axis
    # hips sunk toward the knees go up the torso (HipCenter and Spine follow them below); the torso's length and
    # axis stay as measured, so the amounts below are the same fractions of the same torso
    knees = (p[..., J("KneeLeft"), :] + p[..., J("KneeRight"), :]) / 2
    lift = np.maximum(HIPS_ABOVE_KNEES * torso - np.sum((hips - knees) * up, axis=-1, keepdims=True), 0.0) * up
    for n in ("HipLeft", "HipRight"):
        p[..., J(n), :] += lift
    hips = hips + lift

    def toward(joint: int, centre: np.ndarray, share: float, rise: float) -> None:
        side = p[..., joint, :] - centre
        side -= np.sum(side * up, axis=-1, keepdims=True) * up   # across the torso only
        p[..., joint, :] += -share * side + rise * step

    left = p[..., J("HipLeft"), :] - p[..., J("HipRight"), :]
    forward = np.cross(left, up)   # the performer's front
    forward /= np.maximum(np.linalg.norm(forward, axis=-1, keepdims=True), 1e-9)
    for s in ("Left", "Right"):   # the arm first, along the upper arm as fitted, then forward
        upper = p[..., J(f"Elbow{s}"), :] - p[..., J(f"Shoulder{s}"), :]
        out = ARM_OUT * torso * upper / np.maximum(np.linalg.norm(upper, axis=-1, keepdims=True), 1e-9)
        out += ARMS_FORWARD * torso * forward
        for n in ("Elbow", "Wrist", "Hand"):
            p[..., J(f"{n}{s}"), :] += out
    across = left - np.sum(left * up, axis=-1, keepdims=True) * up
    across /= np.maximum(np.linalg.norm(across, axis=-1, keepdims=True), 1e-9)   # toward the performer's left
    for s, outward in (("Left", 1.0), ("Right", -1.0)):
        for n in ("Shoulder", "Elbow", "Wrist", "Hand"):
            p[..., J(f"{n}{s}"), :] -= (ARM_INWARD * outward * across + ARM_DOWN * up) * torso
    for s, outward in (("Left", 1.0), ("Right", -1.0)):
        shin = p[..., J(f"Knee{s}"), :] - p[..., J(f"Ankle{s}"), :]
        shin /= np.maximum(np.linalg.norm(shin, axis=-1, keepdims=True), 1e-9)
        p[..., J(f"Ankle{s}"), :] += (ANKLES_UP_SHIN * shin - ANKLES_BACK * forward) * torso
        p[..., J(f"Knee{s}"), :] += (KNEES_UP * up - KNEES_BACK * forward) * torso
        toward(J(f"Hip{s}"), hips, HIPS_INWARD, HIPS_UP)
        p[..., J(f"Hip{s}"), :] += HIPS_FORWARD * torso * forward
        p[..., J(f"Foot{s}"), :] += FEET_FORWARD * torso * forward
        before = np.sum((p[..., J(f"Ankle{s}"), :] - p[..., J(f"Foot{s}"), :]) * forward, axis=-1, keepdims=True)
        p[..., J(f"Ankle{s}"), :] -= np.maximum(before - ANKLE_BEFORE_FOOT * torso, 0.0) * forward
        _knee_within_sdk_range(p, s, forward, outward * across, torso)
        toward(J(f"Shoulder{s}"), p[..., J("ShoulderCenter"), :], SHOULDERS_INWARD, SHOULDERS_UP)
    p[..., J("HipCenter"), :] = hips + HIP_CENTER_UP * step
    p[..., J("Spine"), :] = p[..., J("HipCenter"), :] + SPINE_UP * step - SPINE_BACK * torso * forward
    p[..., J("ShoulderCenter"), :] -= SHOULDER_CENTER_DOWN * step + SHOULDER_CENTER_BACK * torso * forward
    p[..., J("Head"), :] -= HEAD_DOWN * step
    return p


def _knee_within_sdk_range(p: np.ndarray, side: str, forward: np.ndarray, outward: np.ndarray,
                           torso: np.ndarray) -> None:
    """Move the knee, in place, across the line from its hip to its ankle until it lies no more than
    KNEE_BEHIND_MAX behind that line and within KNEE_OUTWARD of it sideways (fractions of the torso). The SDK
    does not bend a knee backward or sideways: on the real benchmark's subjects 1-2 its knees lay 2.5 cm behind
    the line, median (4.6 cm at the 95th percentile), and 0.034 of the torso outward (-0.026 to 0.071 from the
    5th to the 95th percentile), while the tracker's, from a body part or the leg's fit, lay beyond those in
    27 % and 33 % of samples (the SDK's 5 % and 10 %; 22 cm behind at the 99th percentile)."""
    hip, knee, ankle = (J(f"{n}{side}") for n in ("Hip", "Knee", "Ankle"))
    line = p[..., ankle, :] - p[..., hip, :]
    line /= np.maximum(np.linalg.norm(line, axis=-1, keepdims=True), 1e-9)
    for direction, (low, high), most in ((-forward, (-np.inf, KNEE_BEHIND_MAX), np.inf),
                                         (outward, KNEE_OUTWARD, KNEE_SIDEWAYS_MOVE)):
        off_line = direction - np.sum(direction * line, axis=-1, keepdims=True) * line
        off_line /= np.maximum(np.linalg.norm(off_line, axis=-1, keepdims=True), 1e-9)
        now = np.sum((p[..., knee, :] - p[..., hip, :]) * off_line, axis=-1, keepdims=True)
        move = np.clip(np.clip(now, low * torso, high * torso) - now, -most * torso, most * torso)
        p[..., knee, :] += move * off_line
