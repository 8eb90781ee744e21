"""Body-part joint proposals into the fitted skeleton.

The kinematic fit (skeleton_fit.py) loses arms that move in front of the body; the forest's proposals
(part_proposals.py) see the elbow and wrist parts wherever they are. A joint the fit itself doubts (reported
inferred) moves to a confident proposal nearby that is not nearer the other side's joint: the arm as a chain
with the calibrated bone lengths (shoulder -> elbow -> wrist -> hand). Options below (chosen on the real-
depth benchmark's subjects 1-2 within the synthetic benchmark's bound, docs/depth_tracking.md) also take
head, shoulders and feet from proposals and report confident proposals tracked. Hips and knees never do
(their proposals sat 20-25 cm low on real depth).
"""
from __future__ import annotations

import numpy as np

from ..core.skeletons import INFERRED, KINECT_V1, TRACKED
from . import body_model_fit as bm

J = KINECT_V1.index
SIDES = ("Left", "Right")
USE_CONFIDENCE = 0.0006     # square metres of likely part around a proposal from which it is used
TRACK_CONFIDENCE = 0.0008   # ... and from which its joint is reported tracked
# What takes proposals. Chosen on the real-depth benchmark's subjects 1-2 under the synthetic benchmark's bound
# (no regression, no tracked sample beyond 15 cm): head, shoulders and feet taken from proposals measured far
# better against the SDK (feet 20 -> 5 cm) but worse against the MakeHuman joints of the synthetic benchmark
# (its joints sit elsewhere in the parts: no learned per-joint offset yet), and promoting confident proposals
# to tracked let 2-3 samples per synthetic motion beyond 15 cm.
DIRECT: tuple[str, ...] = ()   # joints taken as proposed (e.g. "Head", "ShoulderLeft")
CHAIN = True                # arms as a chain with calibrated bone lengths (else elbows and wrists as proposed)
WRISTS = True
FEET = False                # feet (and ankles with them) from proposals, also when a floor is in view
ONLY_INFERRED = True        # proposals only for joints the fit itself doubts (its tracked joints stay)
PROMOTE = False             # a joint moved to a confident proposal is reported tracked
HANDS = True                # the hand from its own proposal (else along the forearm from the wrist)
AGREE = 0.10                # a tracked joint moved farther than this (m) by a proposal is reported inferred
MAX_MOVE = 0.35             # m a proposal may move its joint from the fit (farther: another part mistaken)


def _unit(v):
    return v / max(float(np.linalg.norm(v)), 1e-9)


def _state(c: float) -> int:
    return TRACKED if PROMOTE and c >= TRACK_CONFIDENCE else INFERRED


def _usable(conf, p, pos, st, no_floor: bool, in_view):
    """(20,) bool: confident proposals near their joint of the fit, and not nearer the other side's joint
    (left and right parts confused: taking it would swap the limbs)."""
    move = np.linalg.norm(p - pos, axis=1)
    ok = (conf >= USE_CONFIDENCE) & (move <= MAX_MOVE) & in_view
    if ONLY_INFERRED:
        feet = [J(f"{n}{s}") for n in ("Foot", "Ankle") for s in SIDES]
        keep = ok[feet].copy()
        ok &= st != TRACKED
        if no_floor:
            ok[feet] = keep
    for s, o in (("Left", "Right"), ("Right", "Left")):
        for n in ("Shoulder", "Elbow", "Wrist", "Hand", "Ankle", "Foot"):
            j, k = J(f"{n}{s}"), J(f"{n}{o}")
            ok[j] &= bool(np.linalg.norm(p[j] - pos[k]) > move[j])
    return ok


def apply_proposals(pos: np.ndarray, st: np.ndarray, props, height: float, no_floor: bool = False,
                    in_view=True) -> None:
    """Move joints to confident proposals, in place (positions (20, 3), states (20,)). `no_floor`: no floor
    was found, so nothing removed what lies below the feet (a pre-segmented frame keeps shadows and floor
    specks there, where the foot's extremity lands): the feet take their proposals whatever the fit says.
    `in_view` ((20,) bool): joints the fit placed inside the image (one continued past its edge keeps its
    place: the part seen at the edge is not its end)."""
    conf, p = props.confidence, props.positions
    use = _usable(conf, p, pos, st, no_floor, in_view)
    before_st = st.copy()
    for name in DIRECT:
        j = J(name)
        if use[j]:
            pos[j], st[j] = p[j], _state(conf[j])
    for s in SIDES:
        sh, el, wr, ha = (J(f"{n}{s}") for n in ("Shoulder", "Elbow", "Wrist", "Hand"))
        before = pos.copy()
        if use[el]:
            pos[el] = pos[sh] + _unit(p[el] - pos[sh]) * bm.UPPER_ARM * height if CHAIN else p[el]
            st[el] = _state(conf[el])
        if WRISTS and use[wr]:
            pos[wr] = pos[el] + _unit(p[wr] - pos[el]) * bm.FOREARM * height if CHAIN else p[wr]
            pos[ha] = pos[wr] + _unit(pos[wr] - pos[el]) * bm.HAND * height
            st[wr] = st[ha] = _state(conf[wr])
        if HANDS and use[ha]:
            pos[ha] = pos[wr] + _unit(p[ha] - pos[wr]) * bm.HAND * height if CHAIN else p[ha]
            st[ha] = _state(conf[ha])
        for j in (el, wr, ha):   # the fit's tracked joints stay tracked only where the proposal agrees
            if before_st[j] == TRACKED and np.linalg.norm(pos[j] - before[j]) > AGREE:
                st[j] = INFERRED
            elif before_st[j] == TRACKED:
                st[j] = TRACKED
        ft, an = J(f"Foot{s}"), J(f"Ankle{s}")
        if (FEET or no_floor) and use[ft]:
            pos[an] = pos[an] + (p[ft] - pos[ft])
            pos[ft] = p[ft]
            if FEET:
                st[ft], st[an] = _state(conf[ft]), _state(max(conf[ft], conf[an]))
