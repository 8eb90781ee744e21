"""Left or right: which side's hand (or foot) each extremity found in a frame is (numpy only)."""
from __future__ import annotations

import numpy as np

from ..core.skeletons import TRACKED
from .arm_search import SIDES, J

CONTINUITY_RADIUS = 0.25    # m a lone hand/foot may move from a tracked one and still be taken for it


def assign_sides(found, prev, prev_states, tip) -> dict:
    """{side: candidate} for the hand (or foot, `tip`) candidates `found`, each (cell, point, geodesic
    distance, height along the torso, offset toward the performer's left). Feet well apart go by body side
    (feet do not cross); otherwise continuity with `prev` (the caller passes where the motion predicts the
    joints now), counting only sides whose hand/foot was tracked: both sides, the pairing nearest them;
    one side, the candidate nearest it is that side's and the other the other's; else by body side."""
    if not found:
        return {}
    if tip == "Foot" and len(found) == 2 and found[0][4] * found[1][4] < 0 \
            and abs(found[0][4] - found[1][4]) > 0.25:
        return dict(zip(SIDES, found if found[0][4] > 0 else found[::-1]))
    # only a previous position that rested on evidence says where a side's hand/foot is now
    seen = {s: prev is not None and prev_states is not None and prev_states[J[f"{tip}{s}"]] == TRACKED
            for s in SIDES}
    have_prev = all(seen.values())
    if len(found) == 2:
        if have_prev:
            a = sum(np.linalg.norm(f[1] - prev[J[f"{tip}{s}"]]) for f, s in zip(found, SIDES))
            b = sum(np.linalg.norm(f[1] - prev[J[f"{tip}{s}"]]) for f, s in zip(found[::-1], SIDES))
            # body side wins when continuity is ambiguous (both hands near each other)
            side_a = (found[0][4] - found[1][4])
            if abs(a - b) < 0.05:
                return dict(zip(SIDES, found if side_a > 0 else found[::-1]))
            return dict(zip(SIDES, found if a <= b else found[::-1]))
        for s, other in (SIDES, SIDES[::-1]):
            if seen[s]:  # one side seen: the candidate nearest its hand/foot is it, the other is the other
                near = [np.linalg.norm(f[1] - prev[J[f"{tip}{s}"]]) for f in found]
                k = int(np.argmin(near))
                if near[k] < CONTINUITY_RADIUS:
                    return {s: found[k], other: found[1 - k]}
        return dict(zip(SIDES, found if found[0][4] >= found[1][4] else found[::-1]))
    f = found[0]
    near = {s: np.linalg.norm(f[1] - prev[J[f"{tip}{s}"]]) for s in SIDES if seen[s]}
    if near and min(near.values()) < CONTINUITY_RADIUS:
        return {min(near, key=near.get): f}
    return {"Left" if f[4] >= 0 else "Right": f}
