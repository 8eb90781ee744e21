"""Zero-phase cleanup of a recorded capture's joints (offline: every frame of the take is known).

The live tracker smooths with the frames it has seen only (output_smoothing.py), so it trades jitter against
lag and lets a limb that is wrong for a frame or two through. A recorded capture tracked into a take
(`track_depth_frames`, the `track` command) has its future frames too: each joint coordinate then goes
through a centred running median (5 frames for a tracked joint, 9 for an inferred one: a limb taken wrongly
for a frame or two, or four, is dropped) and a centred Gaussian (1 and 1.5 frames: the jitter left), with no
lag: each window stays centred on its frame (it shrinks at the ends of a run, and a tracked joint uses the
frames where it is tracked). Frames without a skeleton and gaps in time split the take into runs that are
cleaned apart; states are kept.

On the real-depth benchmark (all 216 UTD-MHAD sequences, docs/depth_tracking.md) this took the limbs'
directions against the Kinect SDK from 10.5 to 9.7 degrees and the joints from 5.6 to 5.2 cm; the windows
were chosen on subjects 1-2 (docs/depth_tracking.md, step 15, has what else was measured).
"""
from __future__ import annotations

import numpy as np

from ..core.skeletons import NOT_TRACKED, TRACKED

# (frames each side of the running median, the Gaussian's standard deviation in frames) for tracked joints,
# and wider for inferred ones (the guesses for a limb not seen jitter and stray more)
TRACKED_WINDOW = (2, 1.0)
INFERRED_WINDOW = (4, 1.5)
MAX_GAP_S = 0.2       # frames farther apart than this are not smoothed together


def smooth_recorded_joints(positions: np.ndarray, states: np.ndarray, times: np.ndarray) -> np.ndarray:
    """(F, J, 3) joints, (F, J) states, (F,) seconds -> the joints cleaned with past and future frames (a
    copy). Frames whose joints are all NOT_TRACKED (no skeleton) are left as they are."""
    out = np.array(positions, dtype=np.float64, copy=True)
    st = np.asarray(states)
    have = np.any(st != NOT_TRACKED, axis=1)
    t = np.asarray(times, dtype=np.float64)
    gap = ~(np.abs(np.diff(t)) <= MAX_GAP_S)   # a non-finite time is a gap too
    i = 0
    while i < len(out):
        if not have[i]:
            i += 1
            continue
        end = i + 1
        while end < len(out) and have[end] and not gap[end - 1]:
            end += 1
        run, run_st = out[i:end], st[i:end]
        out[i:end] = np.where((run_st == TRACKED)[..., None], _clean_run(run, run_st, *TRACKED_WINDOW),
                              _clean_run(run, run_st, *INFERRED_WINDOW))
        i = end
    return out


def _clean_run(run: np.ndarray, states: np.ndarray, median_half: int, sigma: float) -> np.ndarray:
    """One run of consecutive frames: centred median, then centred Gaussian, over windows that shrink at the
    run's ends. A tracked joint is cleaned with the frames where it is tracked only: a limb found again after
    frames of guessing must not be pulled back toward the guesses."""
    n = len(run)
    if n < 3:
        return run
    frames = np.arange(n)[:, None]

    def window(joints, offsets):
        """The frames about each frame, and which of them to use: a frame and its mirror image about the
        centre both or neither (both inside the run; for a tracked joint, both tracked), so the window stays
        centred and a steady move is neither lagged nor led."""
        near, mirror = frames + offsets, frames - offsets   # (frames, window)
        inside = (near >= 0) & (near < n) & (mirror >= 0) & (mirror < n)
        near, mirror = np.clip(near, 0, n - 1), np.clip(mirror, 0, n - 1)
        both = (states[near] == TRACKED) & (states[mirror] == TRACKED)
        use = inside[..., None] & (both | (states[:, None, :] != TRACKED))   # (frames, window, joints)
        return joints[near], use

    near, use = window(run, np.arange(-median_half, median_half + 1))
    steady = np.nanmedian(np.where(use[..., None], near, np.nan), axis=1)
    reach = int(np.ceil(2.5 * sigma))
    offsets = np.arange(-reach, reach + 1)
    near, use = window(steady, offsets)
    weights = np.exp(-0.5 * (offsets / sigma) ** 2)[None, :, None] * use
    return np.sum(weights[..., None] * near, axis=1) / np.sum(weights, axis=1)[..., None]
