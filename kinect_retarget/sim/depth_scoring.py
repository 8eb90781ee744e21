"""Scores for a tracked sequence against ground truth (used by the benchmark and the tests)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.skeletons import KINECT_V1, NOT_TRACKED, TRACKED
from ..depth.sdk_joints import to_sdk_joints

_PAIRS = [(KINECT_V1.index(f"{p}Left"), KINECT_V1.index(f"{p}Right")) for p in ("Hand", "Foot", "Elbow", "Knee")]


@dataclass
class Score:
    mean_error: float            # metres, over frames where the performer is present and a skeleton was output
    per_joint: np.ndarray        # (20,) metres
    within_or_flagged: float     # fraction of joint samples within 15 cm, or reported inferred/untracked
    tracked_error: float         # mean error of joints reported TRACKED
    longest_swap: int            # longest run of frames with a left/right pair swapped
    swaps_over_3: int            # number of swap runs longer than 3 frames
    coverage: float              # fraction of present frames with a skeleton
    nan_frames: int
    flagged: float = 0.0         # fraction of joint samples reported inferred/untracked (honesty has a price)
    wrong_tracked: int = 0       # joint samples reported TRACKED yet beyond 15 cm (the goal is none)


def facing_angle(gt: np.ndarray) -> np.ndarray:
    """(F,) degrees between the performer's facing (from the ground-truth hips and shoulders) and the
    direction toward the sensor: 0 = facing it, 90 = side on, 180 = back to it."""
    j = KINECT_V1.index
    lat = (gt[:, j("HipLeft")] - gt[:, j("HipRight")]) + (gt[:, j("ShoulderLeft")] - gt[:, j("ShoulderRight")])
    facing = np.cross(lat, [0.0, 1.0, 0.0])   # left x up = forward, in Kinect camera space
    toward = -gt[:, j("HipCenter")]
    facing[:, 1] = toward[:, 1] = 0
    c = np.sum(facing * toward, -1) / np.maximum(np.linalg.norm(facing, axis=-1) * np.linalg.norm(toward, axis=-1), 1e-9)
    return np.degrees(np.arccos(np.clip(c, -1, 1)))


def score(positions: np.ndarray, states: np.ndarray, gt: np.ndarray, present: np.ndarray) -> Score:
    """`gt`: the rendered body's joints on MakeHuman's skeleton; the tracker reports the SDK's, so they are
    compared where the SDK would put them on that body (depth/sdk_joints.py)."""
    gt = to_sdk_joints(gt)
    has = np.any(states != NOT_TRACKED, axis=1) & present
    nan_frames = int(np.sum(~np.all(np.isfinite(positions), axis=(1, 2))))
    err = np.linalg.norm(positions - gt, axis=-1)
    e = err[has]
    s = states[has]
    ok = (e <= 0.15) | (s != TRACKED)
    swapped = np.zeros(len(positions), bool)
    for l, r in _PAIRS:
        straight = err[:, l] + err[:, r]
        crossed = np.linalg.norm(positions[:, l] - gt[:, r], axis=-1) + np.linalg.norm(positions[:, r] - gt[:, l], axis=-1)
        sep = np.linalg.norm(gt[:, l] - gt[:, r], axis=-1)
        swapped |= (crossed + 0.1 < straight) & (sep > 0.15) & has
    runs, run = [], 0
    for f in swapped:
        run = run + 1 if f else 0
        if run == 1:
            runs.append(0)
        if run:
            runs[-1] = run
    return Score(float(e.mean()) if e.size else float("nan"), e.mean(axis=0) if e.size else np.full(20, np.nan),
                 float(ok.mean()) if ok.size else 0.0,
                 float(e[s == TRACKED].mean()) if np.any(s == TRACKED) else float("nan"),
                 max(runs, default=0), sum(r > 3 for r in runs), float(has.sum() / max(present.sum(), 1)),
                 nan_frames, float(np.mean(s != TRACKED)) if s.size else 0.0, int(np.sum(~ok)))
