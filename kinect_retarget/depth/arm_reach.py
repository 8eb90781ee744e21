"""A hand reported beyond its forearm's reach is brought back to it (reported joints only).

On real depth the fit sometimes gives a hand to an extremity of the other arm, or the forest labels the other
hand, crossing the body, as this one: the elbow stays near its place and the hand lands half a metre from it
(3 % of the real benchmark's hand samples, 15 % of its hands' and wrists' error). No forearm reaches that far,
so such a hand is reported at forearm's length from its elbow: on its own part's proposal if that lies within
reach, else hanging below the elbow, where an arm the fit lost most often is. Joints the fit reports tracked
are left alone, and the fit's history keeps its own pose.
"""
from __future__ import annotations

import numpy as np

from ..core.skeletons import KINECT_V1, TRACKED
from . import body_model_fit as bm
from .part_fit import SDK_HAND

J = KINECT_V1.index
ELBOW_TO_HAND = bm.FOREARM + SDK_HAND   # of standing height (the SDK's elbow to hand)
REACH_MAX = 1.45 * ELBOW_TO_HAND        # no hand is farther from its elbow than this
PROPOSAL_REACH = (0.1, 0.21)            # a hand proposal this far from the elbow is a hand on this forearm


def fold_overreaching_hands(positions: np.ndarray, states: np.ndarray, proposals: np.ndarray | None,
                            height: float) -> np.ndarray:
    """Move, in place, each untracked hand (and its wrist) farther than REACH_MAX from its elbow back to
    forearm's length. `proposals`: (20, 3) joint proposals (rows of zeros: none). Returns the hands moved."""
    up = positions[J("ShoulderCenter")] - positions[J("HipCenter")]
    up = up / max(float(np.linalg.norm(up)), 1e-9)
    moved = np.zeros(20, bool)
    for s in ("Left", "Right"):
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
