"""Honest tracking states: demote a fitted joint to INFERRED when the depth data does not back it up.

The fit marks a joint TRACKED when it rests on evidence (torso patch, extremity, level set). These checks,
run after the fit, catch the cases where that evidence was misleading, as the SDK does: a joint that
disagrees with the motion of the previous frames (a torso patch that slid, an extremity handed to the wrong
limb), a limb joint that projects off the person or in front of the surface (occluded, or placed where the
body is not), every limb when the torso is seen edge-on (a narrow chest: the sides overlap in depth) or fewer
than three of the five extremities show, to the fit or the body-part forest (side-on, curled up: what was
found may be labelled wrongly), the hips when the head is not seen (the torso was then placed from the
shoulders alone), the limbs of a person just found (the fit settles over the first frames), and a joint that
only just recovered from being flagged (one good frame is not yet evidence, unless the fit and the forest
both see it again).
"""
from __future__ import annotations

import numpy as np

from ..core.skeletons import INFERRED, KINECT_V1, TRACKED
from .arm_search import J
from . import body_model_fit as bm

TORSO = [J[n] for n in ("HipCenter", "Spine", "ShoulderCenter", "Head")]
LOWER_TORSO = [J[n] for n in ("HipCenter", "Spine", "HipLeft", "HipRight")]
SIDE_TORSO = [J[f"{p}{s}"] for p in ("Shoulder", "Hip") for s in ("Left", "Right")]
# limb chains, root first: a doubted joint demotes everything beyond it
CHAINS = [[J[f"{n}{s}"] for n in names] for s in ("Left", "Right")
          for names in (("Elbow", "Wrist", "Hand"), ("Knee", "Ankle", "Foot"))]
LIMB = [j for chain in CHAINS for j in chain]
# how far (m) a joint may land from its constant-velocity prediction before the fit is doubted: the torso
# moves smoothly; hands and feet swing fast
PREDICTION_SLACK = np.full(20, 0.25)
PREDICTION_SLACK[TORSO + SIDE_TORSO] = 0.10
VELOCITY_DAMPING = 0.5   # a fraction of the last frame's velocity is carried on (prediction, not extrapolation)
# The sensor's frame interval. A tracker slower than the sensor takes its newest frame, so it sees every second
# or third one, unevenly: the prediction counts the sensor frames that passed, and so does the torso's tight
# slack (the limbs' wide one stays: grown too, it let a hopping leg 20-40 cm off stay tracked). Without that, a
# hop streamed to a slow 2-core machine (10 frames/s tracked) had its torso demoted whenever a step of 4
# frames followed one of 2.
SENSOR_FRAME_S = 1.0 / 30.0
MAX_FRAMES_COUNTED = 4   # a tracker at 7.5 frames/s; a longer gap is frames lost, and no motion carries over it
SLACK_PER_FRAME = np.isin(np.arange(20), TORSO + SIDE_TORSO)
MIN_EXTREMITIES = 3      # of head, hands and feet; fewer and the labelling of what was found is a guess
WARMUP_FRAMES = 6        # frames after (re)acquisition before the fit counts as settled (0.2 s)
# frames after (re)acquisition during which limbs are reported inferred (0.1 s): on real depth the limbs of
# frames 4-6 lay 3-8 cm from the SDK's, as near as later ones; the first frames have little history to check
LIMB_WARMUP_FRAMES = 3
RECOVERY_FRAMES = 1      # frames a joint stays flagged after its checks pass again
RECOVER_SEEN_AT_ONCE = True   # ... unless both the fit and the forest see it in this frame
LIMB_DEPTH_INSIDE = np.array([bm.DEPTH_INSIDE[KINECT_V1.joints[j].replace("Left", "").replace("Right", "")]
                              for j in LIMB])
OFF_SURFACE = 0.2        # Projector.cost at or above this: off the person's silhouette or well in front of it


class ConfidenceCheck:
    """Per-tracker state (the last two output poses, recent flags, how long the performer has been in view
    and facing the sensor) and the per-frame demotion."""

    def __init__(self):
        self.reset()

    def reset(self) -> None:
        self._history: list[np.ndarray] = []
        self._times: list[float] = []   # their timestamps (s; nan where unknown)
        self._flag_age = np.full(20, RECOVERY_FRAMES + 1)
        self._frames = 0
        self._facing_frames = 0   # frames in a row the fit faced the sensor (not turned, not side-on)

    @property
    def settled(self) -> bool:
        """Past the first frames after (re)acquisition."""
        return self._frames >= WARMUP_FRAMES

    @property
    def facing_steady(self) -> bool:
        """Settled, and facing the sensor for as long: a turn's mirror image has left the history."""
        return self._facing_frames >= WARMUP_FRAMES

    def frames_since(self, timestamp: float | None) -> int:
        """Sensor frames from the last output pose to `timestamp` (1 where either time is unknown)."""
        return _sensor_frames(self._times[-1] if self._times else None, timestamp)

    def predict(self, timestamp: float | None = None) -> np.ndarray | None:
        """Where the motion so far puts the joints at `timestamp` (None: one sensor frame after the last)."""
        if not self._history:
            return None
        if len(self._history) == 1:
            return self._history[-1]
        a, b = self._history[-2], self._history[-1]
        ratio = self.frames_since(timestamp) / _sensor_frames(self._times[-2], self._times[-1])
        return b + VELOCITY_DAMPING * ratio * (b - a)

    def assess(self, positions: np.ndarray, states: np.ndarray, fit, own=None, ends_seen=frozenset(),
               fresh=None, timestamp: float | None = None) -> np.ndarray:
        """States after the checks (never promotes a joint). `fit` is the frame's FitResult; `own` ((20,) bool):
        joints placed on their own evidence (a foot on its body-part proposal), not hanging on the limb above;
        `ends_seen`: extremities ("head", "HandLeft", ...) the body-part forest saw, counted with the fit's;
        `fresh` ((20,) bool): joints seen anew this frame (on their own part, where the fit had them), which
        need no recovery frame once their checks pass. `timestamp` (s): the frame's, where known; the motion
        check predicts for the sensor frames passed since the last output (the torso's slack per frame)."""
        st = states.copy()
        doubt = np.zeros(20, bool)
        pred = self.predict(timestamp)
        if pred is not None:
            n = self.frames_since(timestamp)
            doubt |= np.linalg.norm(positions - pred, axis=1) > np.where(SLACK_PER_FRAME, n, 1) * PREDICTION_SLACK
        proj = getattr(fit, "projector", None)
        if proj is not None:
            doubt[LIMB] |= proj.cost(positions[LIMB], LIMB_DEPTH_INSIDE) >= OFF_SURFACE
        if getattr(fit, "edge_on", False):   # side-on, the sides overlap in depth: limbs, shoulder/hip lines
            doubt[LIMB + SIDE_TORSO] = True
        found = {label for label, _ in getattr(fit, "extrema", [])}
        if "head" not in found:   # the torso was placed from the shoulder tops alone: the hips are far from it
            doubt[LOWER_TORSO] = True
        # not the shape of a person facing the sensor (side-on, curled up); a hand against the body is no
        # geodesic extremity, but the forest sees it
        if len(found | set(ends_seen)) < MIN_EXTREMITIES:
            doubt[LIMB + SIDE_TORSO] = True
        for chain in CHAINS:   # beyond a doubtful joint the chain hangs on a guess
            bad = np.cumsum(doubt[chain]) > 0   # (an elbow the fit merely inferred leaves the hand its own evidence)
            doubt[chain] |= bad & (st[chain] == TRACKED) & (True if own is None else ~own[chain])
        self._frames += 1
        turned = getattr(fit, "turned", False) or getattr(fit, "edge_on", False)
        self._facing_frames = 0 if turned else self._facing_frames + 1
        if self._frames <= LIMB_WARMUP_FRAMES:   # a person just found: limbs settle over the first frames
            doubt[LIMB] = True
        self._flag_age = np.where(doubt, 0, self._flag_age + 1)
        recovering = (self._flag_age <= RECOVERY_FRAMES) & ~doubt
        if fresh is not None and RECOVER_SEEN_AT_ONCE:
            recovering &= ~fresh
        st[(doubt | recovering) & (st == TRACKED)] = INFERRED
        return st

    def remember(self, positions: np.ndarray, timestamp: float | None = None) -> None:
        """The pose the tracker output (after its filter) at `timestamp` (s, where known): the motion model
        predicts from these."""
        self._history = (self._history + [positions.copy()])[-2:]
        self._times = (self._times + [float("nan") if timestamp is None else float(timestamp)])[-2:]


def _sensor_frames(earlier: float | None, later: float | None) -> int:
    """Whole sensor frames between two timestamps, 1 to MAX_FRAMES_COUNTED (1 where either is unknown)."""
    if earlier is None or later is None or not np.isfinite(earlier) or not np.isfinite(later):
        return 1
    return int(np.clip(round((later - earlier) / SENSOR_FRAME_S), 1, MAX_FRAMES_COUNTED))
