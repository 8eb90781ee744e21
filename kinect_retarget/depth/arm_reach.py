"""Hands reported beyond their forearm's reach, and arms moving faster than arms move, are brought back (reported
joints only).

On real depth the fit sometimes gives a hand to an extremity of the other arm, or the forest labels the other
hand, crossing the body, as this one: the elbow stays near its place and the hand lands half a metre from it
(3 % of the real benchmark's hand samples, 15 % of its hands' and wrists' error). No forearm reaches that far,
so such a hand is reported at forearm's length from its elbow: on its own part's proposal if that lies within
reach, else hanging below the elbow, where an arm the fit lost most often is. Joints the fit reports tracked
are left alone, and the fit's history keeps its own pose.

Likewise an arm none of whose joints is tracked, one of which jumps farther in a frame than arms move: on the
real benchmark the SDK's own elbows step more than 20 cm in a 30 Hz frame in 0.2 % of frames, the tracker's in
4 % (the forest or the fit taking another part for the arm for a few frames). Such an arm keeps its last place
relative to its shoulder for up to HOLD_S, then follows what is seen again; a jump back to where it was in
the last RETURN_S (the arm leaving a mistake) is taken at once. An arm whose elbow is tracked but neither its
wrist nor its hand is held the same way below the elbow: on real depth a hand raised to its shoulder (an arm
curl) or across the chest is often taken, for a few frames, from a hand part the forest sees by the hip, while
the elbow stays where it was (holding them: hands and wrists 10.60 -> 10.42 cm against the SDK, limbs 12.90 ->
12.76 degrees, subjects 1-2 of trial 1).
"""
from __future__ import annotations

import numpy as np

from ..core.skeletons import KINECT_V1, TRACKED
from . import body_model_fit as bm
from .part_fit import ELBOW_TO_HAND, REACH_MAX_SHARE, SIDES

J = KINECT_V1.index
SHOULDERS = np.array([J(f"Shoulder{s}") for s in SIDES])
ARMS = np.array([[J(f"{n}{s}") for n in ("Elbow", "Wrist", "Hand")] for s in SIDES])   # below each shoulder
REACH_MAX = REACH_MAX_SHARE * ELBOW_TO_HAND   # no hand is farther from its elbow than this
PROPOSAL_REACH = (0.1, 0.21)            # a hand proposal this far from the elbow is a hand on this forearm
MAX_ARM_SPEED = 7.5     # m/s (25 cm in a 30 Hz frame)
HOLD_S = 0.15           # an arm is held at most this long (5 frames at 30 Hz) before what is seen is taken
GAP_S = 0.2             # frames farther apart than this are not compared
SETTLE_FRAMES = 5       # nothing is held until this many frames were seen (the first fits settle)
RETURN_S = 0.5          # a jump back to where the arm was (relative to its shoulder) this recently is taken ...
RETURN_NEAR = 0.15      # ... within this many metres: the hand leaving a mistake, not making one


def fold_overreaching_hands(positions: np.ndarray, states: np.ndarray, proposals: np.ndarray | None,
                            height: float) -> np.ndarray:
    """Move, in place, each untracked hand (and its wrist) farther than REACH_MAX from its elbow back to
    forearm's length. `proposals`: (20, 3) joint proposals (rows of zeros: none). Returns the hands moved."""
    up = positions[J("ShoulderCenter")] - positions[J("HipCenter")]
    up = up / max(float(np.linalg.norm(up)), 1e-9)
    moved = np.zeros(20, bool)
    for s in SIDES:
        e, w, h = J(f"Elbow{s}"), J(f"Wrist{s}"), J(f"Hand{s}")
        if states[h] == TRACKED or np.linalg.norm(positions[h] - positions[e]) <= REACH_MAX * height:
            continue
        direction = -up
        if proposals is not None and np.any(proposals[h]):
            to_prop = proposals[h] - positions[e]
            reach = np.linalg.norm(to_prop) / height
            if PROPOSAL_REACH[0] < reach < PROPOSAL_REACH[1]:
                direction = to_prop / np.linalg.norm(to_prop)
        positions[h] = positions[e] + ELBOW_TO_HAND * height * direction
        positions[w] = positions[e] + bm.FOREARM * height * direction
        moved[h] = True
    return moved


class ArmSpeedGate:
    """Holds an untracked arm (elbow, wrist and hand) of which a joint moved faster than MAX_ARM_SPEED relative
    to its shoulder at its last place there, for up to HOLD_S in a row; below a tracked elbow, its untracked
    wrist and hand likewise, relative to the elbow. Call `apply` on each frame's reported joints."""

    def __init__(self):
        self.reset()

    def reset(self) -> None:
        self._last: np.ndarray | None = None
        self._time = float("nan")
        self._held = np.zeros(len(SIDES))   # seconds each arm has been held in a row
        self._recent: list[tuple[float, np.ndarray]] = []   # (time, _relative(positions)) of the last RETURN_S

    def apply(self, positions: np.ndarray, states: np.ndarray, timestamp: float) -> np.ndarray:
        """Move, in place, the arms that jumped. Returns the joints held."""
        held = np.zeros(20, bool)
        dt = timestamp - self._time
        if self._last is not None and 0.0 < dt <= GAP_S and len(self._recent) >= SETTLE_FRAMES:
            rel = _relative(positions)
            for i, (root, arm) in enumerate(zip(SHOULDERS, ARMS)):
                tracked = states[arm] == TRACKED
                if not tracked.any():
                    free = arm   # held relative to the shoulder
                elif tracked[0] and not tracked[1:].any():
                    root, free = arm[0], arm[1:]   # wrist and hand, relative to the tracked elbow
                else:
                    free = arm[:0]
                step = np.linalg.norm(positions[free] - self._last[free], axis=1).max(initial=0.0)
                back = any(np.linalg.norm(rel[i] - r[i], axis=1).max() < RETURN_NEAR for _, r in self._recent)
                if step > MAX_ARM_SPEED * dt and not back and self._held[i] < HOLD_S:
                    positions[free] = positions[root] + self._last[free] - self._last[root]
                    self._held[i] += dt
                    held[free] = True
                else:
                    self._held[i] = 0.0
        if np.isfinite(timestamp):
            self._last, self._time = positions.copy(), float(timestamp)
            self._recent = [(t, r) for t, r in self._recent if 0.0 < timestamp - t <= RETURN_S]
            self._recent.append((timestamp, _relative(positions)))
        return held


def _relative(positions: np.ndarray) -> np.ndarray:
    """(2, 3, 3): each arm's elbow, wrist and hand relative to its shoulder."""
    return positions[ARMS] - positions[SHOULDERS][:, None]
