"""Body-part joint proposals into the fitted skeleton.

The kinematic fit (skeleton_fit.py) loses arms that move in front of the body; the forest's proposals
(part_proposals.py) see the elbow and hand parts wherever they are. A proposal is where its part is densest;
its joint sits a learned offset from there (Shotton et al. 2011 learn one per joint): `JOINT_OFFSETS`, in the
body's frame (outward, up, forward), learned on rendered MakeHuman bodies by tools/learn_joint_offsets.py.
Joints in DIRECT (head, shoulders; elbows and hands with ARMS = "direct") take a confident proposal near the
fit that is not nearer the other side's joint; the wrist then sits a hand's length before the hand, on the
line from the elbow. ARMS = "chain" instead moves only the arm joints the fit doubts, as a chain with the
calibrated bone lengths. Knees take confident proposals as found (the class-balanced forest's knee parts lie
about 8 cm from the SDK's knees on real legs; the first forest's sat 28 cm low), except for a performer turned
well away, where the forest confuses the legs' sides; hips never do (their parts' centres are not the SDK's
hip joints); feet do when no floor was found. Settings chosen on the real-depth benchmark's subjects 1-2
within the synthetic benchmark's bound (docs/depth_tracking.md).
"""
from __future__ import annotations

import os
from functools import lru_cache

import numpy as np

from ..assets import ASSETS_DIR
from ..core.skeletons import INFERRED, KINECT_V1, TRACKED
from . import body_model_fit as bm
from .two_bone import two_bone_candidates

J = KINECT_V1.index
SIDES = ("Left", "Right")
OFFSETS_PATH = os.fspath(ASSETS_DIR / "part_joint_offsets.npz")
USE_CONFIDENCE = 0.0006     # square metres of likely part around a proposal from which it is used
DOUBTED_ARM_CONFIDENCE = 0.0003   # ... for an elbow or hand the fit doubts (direct arms)
# ... and from which its joint is reported tracked: a proposal sure enough to move a joint is sure enough to
# see it (8 cm² before: on the real benchmark's subjects 1-2 the knees 73 -> 80 % tracked, 5.9 -> 6.0 cm)
TRACK_CONFIDENCE = USE_CONFIDENCE
DIRECT: tuple[str, ...] = ("Head", "ShoulderCenter", "ShoulderLeft", "ShoulderRight")   # taken as proposed
# ... and the shoulders' from this confidence before the arms are fitted from them (80 % of the real moves)
SHOULDER_FIRST_CONFIDENCE = 2 * USE_CONFIDENCE
ARMS = "direct"             # "direct": elbows and hands as proposed; "chain": doubted arm joints as a chain
CHAIN = True                # (chain mode) with calibrated bone lengths (else elbows and wrists as proposed)
WRISTS = True
FEET = False                # feet (and ankles with them) from proposals, also when a floor is in view
ONLY_INFERRED = True        # (chain mode) proposals only for joints the fit itself doubts
PROMOTE = False             # a joint moved to a confident proposal is reported tracked
HANDS = True                # the hand from its own proposal (else along the forearm from the wrist)
AGREE = 0.10                # a tracked joint moved farther than this (m) by a proposal is reported inferred
MAX_MOVE = 0.35             # m a proposal may move its joint from the fit (farther: another part mistaken)
ARM_REACH = True            # an arm joint the fit doubts may move farther, within the arm's reach of its shoulder
# The Kinect SDK's conventions, measured on its own skeletons (Kinect v2, redistributable: tools/
# measure_sdk_proportions.py), fractions of standing height: its hand joint sits this far beyond the wrist
# (MakeHuman's 0.056), its ankle this far above and behind its foot joint (MakeHuman's foot is the toes' base)
SDK_HAND = 0.037
SDK_ANKLE_ABOVE_FOOT, SDK_ANKLE_BEHIND_FOOT = 0.041, 0.041
WRIST_BEFORE_HAND = SDK_HAND   # the wrist of a proposed hand sits this far before it (fraction of height)
ELBOW_TO_HAND = bm.FOREARM + WRIST_BEFORE_HAND   # the elbow to the hand joint, the forearm being rigid
# without a floor, the ankle where the SDK puts it relative to the proposed foot (else moved with the foot):
# on the real benchmark's subjects 1-2 ankles 9.5 -> 7.5 cm but the shins' directions 1.6 degrees worse; off
ANKLE_FROM_FOOT = False
FEET_TRACKED = True         # without a floor, a foot on a confident proposal (TRACK_CONFIDENCE) is reported tracked
ELBOW_REACH = (0.85, 1.45)  # less confident elbow proposal to shoulder, in upper arms (the SDK's upper arm is 1.1-1.2 of ours)
FOREARM_MIN = 1.0           # a hand proposal nearer its elbow than this share of elbow-to-hand is moved out to it
ELBOW_HAND_MIN = 0.6        # an elbow proposal nearer its hand's than this many forearms is refused
KNEES = True                # knees from confident proposals (a forest whose knee parts are right on real legs)
KNEES_TRACKED = True        # ... reported tracked from TRACK_CONFIDENCE where within AGREE of the fit's knee
NO_OFFSET = ("AnkleLeft", "AnkleRight", "FootLeft", "FootRight", "KneeLeft", "KneeRight")   # proposals used as found (see below)
DISAGREE = 0.15             # m from a confident proposal beyond which a joint is reported inferred
KNEE_NEAR_PART = True       # ... and a knee whose foot is on its own part and whose confident part is as near
SEEN_WITHIN = 0.15          # m: a joint moved onto its confident proposal no farther than this is reported tracked
HAND_ON_PART = 0.04         # m: a hand this near its part's proposal is on it (moved out along a forearm seen short)
HAND_PART_NEAR = 0.10       # m: a hand this near its part's centre has evidence of its own (hands_backed)
# a wrist this near (m) its own part's proposal, from this confidence (m²), is seen whatever its hand: two parts
# agree on it (on the real benchmark's subjects 1-2, wrists 32 -> 52 % tracked, their error 6.9 -> 6.3 cm)
WRIST_ON_PART, WRIST_SEEN_CONFIDENCE = 0.08, 0.0004
# joints seen on their own part (wrists and ankles go with their hands and feet: seen_on_parts)
SEEN = np.array([n.startswith(("Head", "Shoulder", "Elbow", "Hand", "Knee")) for n in KINECT_V1.joints])
# ... those taken as proposed (DIRECT) however far the fit had them: on real depth, shoulders the fit tracked
# 10-25 cm from their confident parts, moved onto them, lay 4-6 cm from the SDK's
SEEN_ANY_MOVE = np.isin(np.arange(len(KINECT_V1.joints)), [J(n) for n in DIRECT])
HAND_JOINTS = [J(f"Hand{s}") for s in SIDES]
ELBOW_JOINTS = [J(f"Elbow{s}") for s in SIDES]
# elbows are held to more: a tracked elbow a proposal moved farther than ELBOW_AGREE (m) is demoted, one moved
# onto its part farther is not seen there, and one left beyond DISAGREE of its part is doubted from
# DOUBTED_ARM_CONFIDENCE (disagreeing). With the torso seeded where the forest sees it (part_proposals), the
# synthetic hop's elbows sat on the edge of 15 cm tracked-but-wrong at AGREE and USE_CONFIDENCE
ELBOW_AGREE = 0.09
# a sure hand (USE_CONFIDENCE) beyond this many elbow-to-hand lengths from an elbow without a sure part of its
# own: the elbow is solved between shoulder and hand (on real depth the fit lost an arm pushed forward to a
# hanging pose, its elbow took a weak part on the trunk 60 cm from the hand, and the hand was folded back)
ELBOW_HAND_MAX = 1.3
# no hand is farther from its elbow than this many elbow-to-hand lengths (arm_reach folds one that is back)
REACH_MAX_SHARE = 1.45
# ... so an arm whose hand the fit doubts (placed with its elbow, as arm_search places a whole arm on the
# depth, reporting a well-explained elbow tracked) keeps its elbow against an elbow part that far from its
# hand, when the hand has no sure part of its own: the part alone would break the forearm, and the hand be
# folded down to it. In the real baseball swing's wind-up the left arm crosses the chest to the grip at the
# right shoulder; the forest gives it to the right arm and sees a left elbow on the trunk's left edge, which
# hung the searched arm (all 216 real sequences: limbs 8.56 -> 8.49 degrees, the swing 20.0 -> 19.2)
SEARCHED_ARM_KEEPS_ELBOW = True
# joints whose proposals check the fit's states (not hips, knees or spine: the fit's states stand for those)
CHECKED = np.array([not n.startswith(("Hip", "Knee", "Spine")) for n in KINECT_V1.joints])
OUTWARD = np.array([1.0 if "Left" in n else -1.0 if "Right" in n else 0.0 for n in KINECT_V1.joints])


@lru_cache(maxsize=2)
def load_offsets(path: str = OFFSETS_PATH) -> np.ndarray:
    """(20, 3) offsets from part centre to joint, metres in the body frame (outward, up, forward); zeros
    when the file is missing or unreadable (proposals then stand for their joints as found)."""
    try:
        with np.load(path, allow_pickle=False) as d:
            off = np.asarray(d["offsets"], dtype=np.float64)
        return off if off.shape == (20, 3) and np.all(np.isfinite(off)) else np.zeros((20, 3))
    except (OSError, KeyError, ValueError):
        return np.zeros((20, 3))


def body_frame(lateral: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """(3, 3) rows: the performer's left, up (the torso axis), forward (out of the chest)."""
    up = _unit(axis)
    left = _unit(lateral - (lateral @ up) * up)
    return np.stack([left, up, np.cross(left, up)])


def joint_positions(props, frame: np.ndarray | None, offsets: np.ndarray | None = None) -> np.ndarray:
    """(20, 3) joints from the proposals: each part's centre moved by its joint's learned offset, turned
    into camera space by the body `frame` (body_frame; None: the centres as found)."""
    if frame is None:
        return props.positions.copy()
    off = (load_offsets() if offsets is None else offsets).copy()
    # MakeHuman's foot joint is the toe's base, the SDK's sits further back: as found, foot proposals were
    # 3.9-5.3 cm from the SDK's feet on real depth, with the learned offset (4 cm forward) worse; knees as
    # found sat nearer the SDK's than with MakeHuman's offset (3.4 cm down): 7.6-9.5 against 9.2-10.0 cm
    off[[J(n) for n in NO_OFFSET]] = 0.0
    local = off * np.stack([np.where(OUTWARD == 0, 1.0, OUTWARD), np.ones(20), np.ones(20)], axis=1)
    return props.positions + local @ frame


def _unit(v):
    return v / max(float(np.linalg.norm(v)), 1e-9)


def _state(c: float) -> int:
    return TRACKED if PROMOTE and c >= TRACK_CONFIDENCE else INFERRED


def _usable(conf, p, pos, st, no_floor: bool, in_view, chain: bool, height=None):
    """(20,) bool: confident proposals near their joint of the fit, and not nearer the other side's joint
    (left and right parts confused: taking it would swap the limbs)."""
    move = np.linalg.norm(p - pos, axis=1)
    near = move <= MAX_MOVE
    if ARM_REACH and height is not None:
        for s in SIDES:
            sh = pos[J(f"Shoulder{s}")]
            for n, r in (("Elbow", bm.UPPER_ARM), ("Hand", bm.UPPER_ARM + bm.FOREARM + bm.HAND)):
                k = J(f"{n}{s}")
                near[k] |= st[k] != TRACKED and np.linalg.norm(p[k] - sh) < 1.15 * r * height + 0.05
    sure = conf >= USE_CONFIDENCE
    if not chain:   # an arm the fit doubts: a less confident proposal is still the better guess
        arms = np.array([n.startswith(("Elbow", "Hand")) for n in KINECT_V1.joints]) & (st != TRACKED)
        sure |= arms & (conf >= DOUBTED_ARM_CONFIDENCE)
    ok = sure & near & in_view
    if not chain:
        h = height or 1.7
        for s in SIDES:
            el, ha = J(f"Elbow{s}"), J(f"Hand{s}")
            # a less confident elbow proposal lies about an upper arm from its shoulder (not a part seen beside it)
            ok[el] &= bool(conf[el] >= USE_CONFIDENCE or _in_elbow_reach(p[el], pos[J(f"Shoulder{s}")], h))
            # one by its own hand's is a hand part taken for the elbow (the forearm is rigid): with a hand on the
            # face the class-balanced forest saw one there, 24 cm off
            ok[el] &= not (ok[ha] and np.linalg.norm(p[el] - p[ha]) < ELBOW_HAND_MIN * bm.FOREARM * h)
    if ONLY_INFERRED and chain:
        arms = [J(f"{n}{s}") for n in ("Elbow", "Wrist", "Hand") for s in SIDES]
        ok[arms] &= st[arms] != TRACKED
    for s, o in (("Left", "Right"), ("Right", "Left")):
        for n in ("Shoulder", "Elbow", "Wrist", "Hand", "Knee", "Ankle", "Foot"):
            j, k = J(f"{n}{s}"), J(f"{n}{o}")
            ok[j] &= bool(np.linalg.norm(p[j] - pos[k]) > move[j]) or (ARM_REACH and st[j] != TRACKED and st[k] != TRACKED)
    return ok


def _in_elbow_reach(elbow: np.ndarray, shoulder: np.ndarray, height: float) -> bool:
    """The elbow lies ELBOW_REACH upper arms from its shoulder (where an elbow can be)."""
    ratio = np.linalg.norm(elbow - shoulder) / (bm.UPPER_ARM * height)
    return bool(ELBOW_REACH[0] <= ratio <= ELBOW_REACH[1])


def _arm_chain(pos, st, p, conf, use, s, height) -> None:
    sh, el, wr, ha = (J(f"{n}{s}") for n in ("Shoulder", "Elbow", "Wrist", "Hand"))
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


def _arm_direct(pos, st, p, conf, use, s, height) -> None:
    el, wr, ha = (J(f"{n}{s}") for n in ("Elbow", "Wrist", "Hand"))
    keep_elbow = (SEARCHED_ARM_KEEPS_ELBOW and st[ha] != TRACKED and use[el] and not use[ha]
                  and np.linalg.norm(p[el] - pos[ha]) > REACH_MAX_SHARE * ELBOW_TO_HAND * height)
    if use[el] and not keep_elbow:
        pos[el], st[el] = p[el], _state(conf[el])
    if use[ha]:
        pos[ha], st[ha] = p[ha], _state(conf[ha])
        reach = ELBOW_TO_HAND * height
        # a hand part seen only up the forearm, from an elbow where an elbow can be (from one by the shoulder
        # the forearm's direction is unknown: real frames nearer than any training image put hands off the body)
        if (np.linalg.norm(pos[ha] - pos[el]) < FOREARM_MIN * reach
                and _in_elbow_reach(pos[el], pos[J(f"Shoulder{s}")], height)):
            pos[ha] = pos[el] + _unit(pos[ha] - pos[el]) * reach
        if (conf[ha] >= USE_CONFIDENCE and not (use[el] and conf[el] >= USE_CONFIDENCE)
                and np.linalg.norm(pos[ha] - pos[el]) > ELBOW_HAND_MAX * reach):
            # the forearm is rigid: the elbow on its circle between shoulder and hand, nearest where it was
            cands, _ = two_bone_candidates(pos[J(f"Shoulder{s}")], pos[ha], bm.UPPER_ARM * height, reach)
            pos[el] = cands[int(np.argmin(np.linalg.norm(cands - pos[el], axis=1)))]
            st[el] = INFERRED
        pos[wr] = pos[ha] - _unit(pos[ha] - pos[el]) * WRIST_BEFORE_HAND * height
        st[wr] = _state(min(conf[el], conf[ha]))


def _foot(pos, st, p, conf, in_view, s, height, frame) -> bool:
    """The foot from its proposal, the ankle moved with it and the knee re-solved between hip and ankle. The
    fit's feet are no gate here (without a floor they are the least sure part of it: a third of its real feet
    lay more than 35 cm off, or nearer the other foot): both foot proposals must be confident, within the leg's
    reach of the hip, and on their own side of each other. They may lie together: performers stand with their
    feet together (the SDK's own feet were within 8 cm of each other in 25-65 % of three real performers'
    frames), and refusing proposals nearer than 8 cm as one foot seen twice left those feet inferred."""
    o = "Right" if s == "Left" else "Left"
    hip, kn, an, ft = (J(f"{n}{s}") for n in ("Hip", "Knee", "Ankle", "Foot"))
    other = J(f"Foot{o}")
    reach = (bm.THIGH + bm.SHIN + bm.FOOT) * height + 0.10
    side = 1.0 if s == "Left" else -1.0
    apart = p[ft] - p[other]
    ok = (conf[ft] >= USE_CONFIDENCE and conf[other] >= USE_CONFIDENCE and bool(np.atleast_1d(in_view)[ft] if
          np.ndim(in_view) else in_view)
          and np.linalg.norm(p[ft] - pos[hip]) < reach and (frame is None or side * (apart @ frame[0]) > -0.05))
    if not ok:
        return False
    delta = p[ft] - pos[ft]
    pos[an], pos[ft] = pos[an] + delta, p[ft]
    cands, _ = two_bone_candidates(pos[hip], pos[an], bm.THIGH * height, bm.SHIN * height)
    guess = pos[kn] + 0.5 * delta
    pos[kn] = cands[int(np.argmin(np.linalg.norm(cands - guess, axis=1)))]
    if frame is not None and ANKLE_FROM_FOOT:   # (the knee was solved with the body's own shin)
        pos[an] = p[ft] + (SDK_ANKLE_ABOVE_FOOT * frame[1] - SDK_ANKLE_BEHIND_FOOT * frame[2]) * height
    if FEET:
        st[ft], st[an] = _state(conf[ft]), _state(conf[ft])
    return True


def shoulders_on_parts(pos: np.ndarray, st: np.ndarray, props, lateral: np.ndarray, axis: np.ndarray,
                       in_view=True) -> None:
    """The fit's shoulders moved onto their confident parts, in place, before the arms are fitted from them,
    with the gates apply_proposals uses for them (it takes them as proposed afterwards anyway). The arm search
    and the limb fit start from the shoulders: on real depth the body model's lay 5.8 cm from their parts,
    median (14 % of frames more than 10 cm). Only the surer parts (SHOULDER_FIRST_CONFIDENCE): an arm fitted
    from a wrong shoulder goes wrong with it (the synthetic hop's hands swapped for 5 frames, and a jump's
    wrist was tracked 16 cm off, from shoulder parts of 6-11 cm² 8-14 cm off)."""
    p = joint_positions(props, body_frame(lateral, axis))
    use = _usable(props.confidence, p, pos, st, False, in_view, True)
    for s in SIDES:
        j = J(f"Shoulder{s}")
        if use[j] and f"Shoulder{s}" in DIRECT and props.confidence[j] >= SHOULDER_FIRST_CONFIDENCE:
            pos[j] = p[j]


def apply_proposals(pos: np.ndarray, st: np.ndarray, props, height: float, no_floor: bool = False,
                    in_view=True, frame: np.ndarray | None = None,
                    turned: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Move joints to confident proposals, in place (positions (20, 3), states (20,)). `frame`: the body's
    frame (body_frame) for the learned offsets (None: proposals stand for their joints as found).
    `no_floor`: no floor was found, so nothing removed what lies below the feet (a pre-segmented frame keeps
    shadows and floor specks there, where the foot's extremity lands): the feet take their proposals whatever
    the fit says. `in_view` ((20,) bool): joints the fit placed inside the image (one continued past its edge
    keeps its place: the part seen at the edge is not its end). `turned`: the performer is turned well away
    from the sensor, where the forest confuses the arms' sides (the synthetic hop's 55 degree turn swapped the
    hands): arms then move as a chain, only where the fit doubts them. Returns two (20,) bool masks: joints not
    to be reported tracked though the fit's history keeps its states (wrist and hand beyond an elbow the
    proposal moved: the fit's arm was elsewhere), and joints resting on their own part's evidence, not on the
    limb above them (feet placed on confident proposals without a floor)."""
    conf, p = props.confidence, joint_positions(props, frame)
    chain = ARMS == "chain" or turned
    use = _usable(conf, p, pos, st, no_floor, in_view, chain, height)
    before, before_st = pos.copy(), st.copy()
    for name in DIRECT:
        j = J(name)
        if use[j]:
            pos[j], st[j] = p[j], _state(conf[j])
    feet: list[int] = []
    knees: list[int] = []   # knees placed on their proposals
    for s in SIDES:
        (_arm_chain if chain else _arm_direct)(pos, st, p, conf, use, s, height)
        if (FEET or no_floor) and _foot(pos, st, p, conf, in_view, s, height, frame):
            feet.append(J(f"Foot{s}"))
        k = J(f"Knee{s}")
        if KNEES and use[k] and not turned:   # turned, the forest confuses the legs' sides as it does the arms'
            pos[k], st[k] = p[k], _state(conf[k])
            knees.append(k)
    # the fit's tracked joints stay tracked where the proposal agrees with them (elbows: within ELBOW_AGREE)
    moved = np.linalg.norm(pos - before, axis=1)
    agree = np.full(20, AGREE)
    agree[ELBOW_JOINTS] = ELBOW_AGREE
    st[(before_st == TRACKED) & (moved <= agree)] = TRACKED
    if not PROMOTE:
        st[(before_st == TRACKED) & (moved > agree)] = INFERRED
    # joints seen on their own confident part, reported tracked whatever the limb above them says: feet (both
    # feet's parts apart and within the legs' reach: as sure as the SDK's feet) and knees where the fit agrees
    seen = [f for f in feet if FEET_TRACKED and conf[f] >= TRACK_CONFIDENCE]
    seen += [k for k in knees if KNEES_TRACKED and conf[k] >= TRACK_CONFIDENCE and moved[k] <= AGREE]
    st[seen] = TRACKED
    own = np.zeros(20, bool)
    own[seen] = True
    if not chain:   # a wrist placed from its hand and elbow is no surer than they are
        for s in SIDES:
            el, wr, ha = (J(f"{n}{s}") for n in ("Elbow", "Wrist", "Hand"))
            if use[ha]:
                st[wr] = min(st[wr], st[el], st[ha])
    doubt = np.zeros(20, bool)
    for s in SIDES:
        if moved[J(f"Elbow{s}")] > AGREE:
            doubt[[J(f"Wrist{s}"), J(f"Hand{s}")]] = True
    return doubt, own


def seen_on_parts(before: np.ndarray, pos: np.ndarray, props, frame: np.ndarray | None, own: np.ndarray,
                  turned: bool, before_states: np.ndarray | None = None) -> np.ndarray:
    """(20,) bool: joints to report tracked as the SDK does, for a joint it sees: moved onto a confident
    proposal of their own part (apply_proposals: `before` -> `pos`) no farther than SEEN_WITHIN from where the
    fit had them (AGREE where the fit tracked it, `before_states`: moved farther, it was demoted for the fit
    and the forest disagreeing), so both agree on the limb. On real depth those joints lay 7-8 cm from the
    SDK's (farther moves, or a confident proposal left unused, 10-48 cm). The head, shoulder centre and
    shoulders (DIRECT, the forest's surest parts) are seen however far they moved. A hand moved out along a
    forearm seen short is on its part within HAND_ON_PART. A wrist goes with its seen hand, or is seen within
    WRIST_ON_PART of its own part's proposal; an ankle goes with its foot placed on its own part (`own`: both
    moved together), and a knee is seen whose confident part lies within SEEN_WITHIN where that foot is seen
    (the leg's end and middle both seen: 8 cm from the SDK's). Not for a performer turned away, where the
    forest confuses the sides. For the reported states only: the fit's history keeps its own."""
    if turned:
        return np.zeros(20, bool)
    moved = np.linalg.norm(pos - before, axis=1)
    off_part = np.linalg.norm(pos - joint_positions(props, frame), axis=1)
    confident = props.confidence >= TRACK_CONFIDENCE
    within = np.full(20, SEEN_WITHIN)
    if before_states is not None:
        within[before_states == TRACKED] = AGREE
    within[SEEN_ANY_MOVE] = MAX_MOVE
    within[ELBOW_JOINTS] = np.minimum(within[ELBOW_JOINTS], ELBOW_AGREE)
    on_part = off_part < 1e-6
    on_part[HAND_JOINTS] = off_part[HAND_JOINTS] < HAND_ON_PART
    seen = SEEN & on_part & (moved > 0) & (moved <= within) & confident
    for s in SIDES:
        wr = J(f"Wrist{s}")
        seen[wr] = seen[J(f"Hand{s}")] and moved[wr] <= within[wr]
        seen[wr] |= bool(props.confidence[wr] >= WRIST_SEEN_CONFIDENCE and off_part[wr] < WRIST_ON_PART)
        seen[J(f"Ankle{s}")] = own[J(f"Foot{s}")]
        k = J(f"Knee{s}")
        if KNEE_NEAR_PART:
            seen[k] |= bool(own[J(f"Foot{s}")] and confident[k] and off_part[k] <= SEEN_WITHIN)
    return seen


def ends_seen(props) -> frozenset:
    """The extremities (head, hands, feet; labelled as the fit labels its own) whose parts the forest saw
    confidently: on real depth, hands held against the body are no geodesic extremity but are seen."""
    ends = {"head": "Head", **{f"{n}{s}": f"{n}{s}" for n in ("Hand", "Foot") for s in SIDES}}
    return frozenset(label for label, joint in ends.items() if props.confidence[J(joint)] >= TRACK_CONFIDENCE)


def hands_backed(pos: np.ndarray, props, seen: np.ndarray) -> np.ndarray:
    """(20,) bool: hands with evidence of their own beside the arm above them: their wrist seen on its part
    (`seen`, seen_on_parts) or their part's centre within HAND_PART_NEAR, from DOUBTED_ARM_CONFIDENCE. A hand
    reported tracked only for hanging off a tracked elbow and wrist (arm_search.hands_at_tracked_wrists) needs
    it: without, the synthetic hop's hand off a wrongly tracked elbow was reported tracked 15 cm off."""
    near = np.linalg.norm(props.positions - pos, axis=1) < HAND_PART_NEAR
    out = np.zeros(20, bool)
    for s in SIDES:
        h = J(f"Hand{s}")
        out[h] = bool(seen[J(f"Wrist{s}")] or (near[h] and props.confidence[h] >= DOUBTED_ARM_CONFIDENCE))
    return out


def disagreeing(pos: np.ndarray, props, frame: np.ndarray | None) -> np.ndarray:
    """(20,) bool: joints left far from a confident proposal of their own part (the fit's evidence and the
    forest's disagree: not to be reported tracked); an elbow's part counts from DOUBTED_ARM_CONFIDENCE; a wrist
    goes with its hand. For the reported states only: the fit's own states carry its history (fed back, this
    demotion swapped the synthetic hop's hands)."""
    p = joint_positions(props, frame)
    sure = props.confidence >= USE_CONFIDENCE
    sure[ELBOW_JOINTS] = props.confidence[ELBOW_JOINTS] >= DOUBTED_ARM_CONFIDENCE
    far = sure & (np.linalg.norm(pos - p, axis=1) > DISAGREE)
    for s in SIDES:
        far[J(f"Wrist{s}")] |= far[J(f"Hand{s}")]
    return far & CHECKED
