"""The tracker's last stage: reported joints steadied as the Kinect SDK steadies its own skeleton.

The fit, the proposals and the rules after them leave every joint jittering. On real Kinect v1 depth (all 216
UTD-MHAD sequences) the tracker's joints moved far less steadily than the SDK's own skeleton of the same frames
(mean frame-to-frame acceleration 5.8 cm/frame² against 1.0; the torso 3.0 against 0.3, the knees 9.4 against
0.5), and jitter turns bones. A One-Euro filter (Casiez et al. 2012, the project's `core.filters`) steadies
them. The torso, head and legs move slowly and take a 1 Hz cutoff; the elbows, wrists and hands move fast, and
at 1 Hz they trailed the SDK's by a frame, so they take 5 Hz. No joint trails what was found by more than
MAX_TRAIL (the SDK's filter bounds its output likewise): unbounded, fast feet and hands of the synthetic walk,
hop and jumps lagged more than 15 cm behind their truth. Real depth, trial 1 of subjects 1-2, scored at each
sequence's lag as the raw joints fit it best: limbs 12.6 -> 11.8 degrees, hands and wrists 10.2 -> 10.1 cm
(docs/depth_tracking.md, step 14).

Before the filter, knees, ankles, elbows, wrists and hands at rest follow a robust line through their last
places (below), which a single frame off does not move; all 216 real sequences, limbs 11.6 -> 11.4 degrees,
hands and wrists 8.8 -> 8.7 cm.

Reported joints only: the fit's history keeps its own pose. The filter forgets with the tracker (a new
performer starts from their raw joints), and an untracked joint holds its last place, as `core.filters` does.
"""
from __future__ import annotations

import math

import numpy as np

from ..core.filters import OneEuroFilter
from ..core.skeletons import KINECT_V1
from . import arm_reach

ARMS = arm_reach.ARMS.ravel()   # elbows, wrists and hands
BODY = np.setdiff1d(np.arange(len(KINECT_V1.joints)), ARMS)   # torso, head, shoulders, legs
BODY_CUTOFF = 1.0   # Hz, at rest
ARM_CUTOFF = 5.0    # Hz: arms move fast, and a 1 Hz arm lags the performer by a frame
BODY_BETA = 1.5     # cutoff rise per m/s of speed
ARM_BETA = 3.0
MAX_TRAIL = 0.03    # m: no joint trails what the fit found by more than this (the SDK's filter bounds it at 4 cm)
# Joints at rest first follow a robust line through their last places (REST_FRAMES of them): on real depth a
# still knee or ankle jumped between where its body part was found and where the leg's fit put it (the SDK's
# stood still), single frames 5-9 cm off that the bounded filter let through. The line's slope (each
# coordinate's median pairwise slope) is followed by half, and a joint faster than its rest speed skips it:
# the synthetic walk's and hop's swinging feet were tracked 15 cm behind with a window median or a faster limit.
KNEES_ANKLES = np.array([KINECT_V1.index(f"{n}{s}") for s in ("Left", "Right") for n in ("Knee", "Ankle")])
RESTING = np.r_[KNEES_ANKLES, ARMS]
REST_SPEED = np.r_[np.full(len(KNEES_ANKLES), 0.3), np.full(len(ARMS), 0.15)]   # m/s
REST_FRAMES = 7
REST_SLOPE = 0.5
REST_MAX_MOVE = 0.06   # m: nor does the line move a joint farther than this from where it was found


class OutputSmoothing:
    """One-Euro filters over the reported joints: a slow one for the body, a quicker one for the arms."""

    def __init__(self) -> None:
        self.body = OneEuroFilter(min_cutoff=BODY_CUTOFF, beta=BODY_BETA, max_deviation=MAX_TRAIL)
        self.arms = OneEuroFilter(min_cutoff=ARM_CUTOFF, beta=ARM_BETA, max_deviation=MAX_TRAIL)
        self._recent: list[tuple[float, np.ndarray]] = []   # (time, the resting joints' places), oldest first

    def reset(self) -> None:
        self.body.reset()
        self.arms.reset()
        self._recent = []

    def apply(self, positions: np.ndarray, states: np.ndarray, timestamp: float) -> None:
        """Filter (20, 3) `positions` in place; `timestamp` in seconds (not finite: one frame at 30 Hz)."""
        t = float(timestamp) if math.isfinite(timestamp) else None
        now = t if t is not None else (self._recent[-1][0] + 1 / 30.0 if self._recent else 0.0)
        found = positions[RESTING]   # (a copy)
        self._recent = (self._recent + [(now, found)])[-REST_FRAMES:]
        if len(self._recent) >= 3:
            times = np.array([when for when, _ in self._recent])
            end, speed = _robust_line_end(np.stack([p for _, p in self._recent]), times, REST_SLOPE)
            move = end - found
            move *= np.minimum(1.0, REST_MAX_MOVE / np.maximum(np.linalg.norm(move, axis=1), 1e-9))[:, None]
            slow = speed <= REST_SPEED
            positions[RESTING[slow]] = found[slow] + move[slow]
        positions[BODY] = self.body.step(positions[BODY], states[BODY], t)
        positions[ARMS] = self.arms.step(positions[ARMS], states[ARMS], t)


def _robust_line_end(window: np.ndarray, times: np.ndarray, slope_share: float) -> tuple[np.ndarray, np.ndarray]:
    """Theil-Sen lines through (n, k, 3) places at `times` (s): each coordinate's slope the median of its
    pairwise slopes, followed by `slope_share`, its intercept the median of what remains. Returns the lines'
    places at the newest time (k, 3) and the joints' speeds by the full slopes (k,), m/s."""
    a, b = np.triu_indices(len(window), 1)
    dt = np.maximum(times[b] - times[a], 1e-3)[:, None, None]
    slope = np.median((window[b] - window[a]) / dt, axis=0)
    dt_now = (times - times[-1])[:, None, None]
    followed = slope * slope_share
    return np.median(window - followed * dt_now, axis=0), np.linalg.norm(slope, axis=1)
