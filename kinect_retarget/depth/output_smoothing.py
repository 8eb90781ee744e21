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


class OutputSmoothing:
    """One-Euro filters over the reported joints: a slow one for the body, a quicker one for the arms."""

    def __init__(self) -> None:
        self.body = OneEuroFilter(min_cutoff=BODY_CUTOFF, beta=BODY_BETA, max_deviation=MAX_TRAIL)
        self.arms = OneEuroFilter(min_cutoff=ARM_CUTOFF, beta=ARM_BETA, max_deviation=MAX_TRAIL)

    def reset(self) -> None:
        self.body.reset()
        self.arms.reset()

    def apply(self, positions: np.ndarray, states: np.ndarray, timestamp: float) -> None:
        """Filter (20, 3) `positions` in place; `timestamp` in seconds (not finite: one frame at 30 Hz)."""
        t = float(timestamp) if math.isfinite(timestamp) else None
        positions[BODY] = self.body.step(positions[BODY], states[BODY], t)
        positions[ARMS] = self.arms.step(positions[ARMS], states[ARMS], t)
