"""Joint proposals into the fitted skeleton (depth/part_fit.py): the learned part-to-joint offsets, arms taken
directly, feet without a floor, and the refusals that keep left and right apart."""
from __future__ import annotations

import numpy as np
import pytest

from kinect_retarget.core.skeletons import INFERRED, KINECT_V1, TRACKED
from kinect_retarget.depth import part_fit
from kinect_retarget.depth.body_parts import PARTS
from kinect_retarget.depth.part_proposals import Proposals
from kinect_retarget.depth.skeleton_tracker import SkeletonTracker

j = KINECT_V1.index
FACING = part_fit.body_frame(np.array([-1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))   # facing the sensor


def _proposals(pos, conf=0.01):
    return Proposals(pos.copy(), np.full(20, conf), (np.zeros(0, int), np.zeros(0, int)), np.zeros((0, len(PARTS))),
                     np.zeros((0, 3)), np.zeros(0))


def _standing_pose():
    pos = np.zeros((20, 3))
    pos[:, 2] = 2.5
    for s, x in (("Left", -0.17), ("Right", 0.17)):   # the performer's left on the sensor's right (-X)
        pos[j(f"Shoulder{s}")] = [x, 0.4, 2.5]
        pos[j(f"Elbow{s}")] = [x, 0.12, 2.5]
        pos[j(f"Wrist{s}")] = [x, -0.12, 2.5]
        pos[j(f"Hand{s}")] = [x, -0.2, 2.5]
        pos[j(f"Hip{s}")] = [x / 2, -0.1, 2.5]
        pos[j(f"Knee{s}")] = [x / 2, -0.5, 2.45]
        pos[j(f"Ankle{s}")] = [x / 2, -0.9, 2.5]
        pos[j(f"Foot{s}")] = [x / 2, -0.95, 2.45]
    return pos, np.full(20, TRACKED, np.uint8)


def test_shipped_offsets_are_small_and_mirrored():
    off = part_fit.load_offsets()
    assert off.shape == (20, 3) and np.any(off != 0), f"{part_fit.OFFSETS_PATH} is missing or unreadable"
    assert np.all(np.abs(off) < 0.08)   # a part's centre lies within a limb's radius of its joint
    for n in KINECT_V1.joints:
        if "Left" in n:   # (outward, up, forward): the same for both sides of a symmetric body
            assert np.allclose(off[j(n)], off[j(n.replace("Left", "Right"))]), n
    assert off[j("ShoulderLeft"), 2] > 0.01   # the shoulder joint sits in front of the shoulder part's centre


def test_unreadable_offsets_are_zero(tmp_path):
    bad = tmp_path / "offsets.npz"
    bad.write_bytes(b"not offsets")
    assert np.array_equal(part_fit.load_offsets(str(bad)), np.zeros((20, 3)))


def test_offsets_turn_with_the_body_and_mirror_outward():
    off = np.zeros((20, 3))
    off[j("HandLeft")] = off[j("HandRight")] = [0.02, 0.0, 0.03]   # outward 2 cm, forward 3 cm
    pos, _ = _standing_pose()
    out = part_fit.joint_positions(_proposals(pos), FACING, off)
    # facing the sensor: the left is -X, forward is toward the sensor (-Z)
    assert np.allclose(out[j("HandLeft")] - pos[j("HandLeft")], [-0.02, 0.0, -0.03])
    assert np.allclose(out[j("HandRight")] - pos[j("HandRight")], [0.02, 0.0, -0.03])
    turned = part_fit.body_frame(np.array([0.0, 0.0, 1.0]), np.array([0.0, 1.0, 0.0]))   # turned 90 degrees
    out = part_fit.joint_positions(_proposals(pos), turned, off)
    assert np.allclose(out[j("HandLeft")] - pos[j("HandLeft")], [-0.03, 0.0, 0.02])
    assert np.array_equal(part_fit.joint_positions(_proposals(pos), None, off), pos)


@pytest.fixture
def no_offsets(monkeypatch):
    monkeypatch.setattr(part_fit, "load_offsets", lambda path=None: np.zeros((20, 3)))


def test_arms_take_proposals_directly_and_never_across_sides(no_offsets):
    pos, st = _standing_pose()
    props = _proposals(pos)
    props.positions[j("ElbowLeft")] = [-0.37, 0.3, 2.4]      # the left arm raised sideways
    props.positions[j("HandLeft")] = [-0.38, 0.0, 2.4]
    props.positions[j("HandRight")] = [-0.2, -0.15, 2.5]     # nearer the left hand: left and right confused
    before = pos.copy()
    part_fit.apply_proposals(pos, st, props, 1.7, frame=FACING)
    assert np.allclose(pos[j("ElbowLeft")], [-0.37, 0.3, 2.4]) and np.allclose(pos[j("HandLeft")], [-0.38, 0.0, 2.4])
    # the wrist a hand's length before the hand, on the line from the elbow
    fore = pos[j("HandLeft")] - pos[j("ElbowLeft")]
    w = pos[j("WristLeft")] - pos[j("ElbowLeft")]
    assert np.isclose(np.linalg.norm(pos[j("HandLeft")] - pos[j("WristLeft")]), part_fit.WRIST_BEFORE_HAND * 1.7)
    assert np.isclose(w @ fore, np.linalg.norm(w) * np.linalg.norm(fore))
    # moved far from the fit's tracked joint: no longer claimed tracked
    assert st[j("ElbowLeft")] == INFERRED and st[j("HandLeft")] == INFERRED
    assert np.array_equal(pos[j("HandRight")], before[j("HandRight")]) and st[j("HandRight")] == TRACKED
    assert np.allclose(pos[j("ShoulderLeft")], before[j("ShoulderLeft")]) and st[j("ShoulderLeft")] == TRACKED


def test_turned_performer_moves_only_doubted_arm_joints_as_a_chain(no_offsets):
    pos, st = _standing_pose()
    st[j("ElbowLeft")] = INFERRED
    props = _proposals(pos)
    props.positions[j("ElbowLeft")] = [-0.37, 0.35, 2.4]
    props.positions[j("HandRight")] = [0.3, 0.3, 2.4]        # the fit tracks this hand: it stays
    before = pos.copy()
    part_fit.apply_proposals(pos, st, props, 1.7, frame=FACING, turned=True)
    moved = pos[j("ElbowLeft")] - pos[j("ShoulderLeft")]
    assert np.isclose(np.linalg.norm(moved), part_fit.bm.UPPER_ARM * 1.7)   # the calibrated upper arm
    assert moved[0] < -0.15 and st[j("ElbowLeft")] == INFERRED
    assert np.array_equal(pos[j("HandRight")], before[j("HandRight")]) and st[j("HandRight")] == TRACKED


def test_feet_without_a_floor_follow_their_proposals_together_or_apart(no_offsets):
    pos, st = _standing_pose()
    fit = pos.copy()
    fit[j("FootLeft")] = fit[j("FootRight")] + [0.02, 0, 0]   # the fit put both feet on the right one
    props = _proposals(pos)
    props.confidence[[j("KneeLeft"), j("KneeRight")]] = 0.0   # no knee parts seen (those would place the knee)
    p, s = fit.copy(), st.copy()
    part_fit.apply_proposals(p, s, props, 1.7, no_floor=True, frame=FACING)
    assert np.allclose(p[j("FootLeft")], pos[j("FootLeft")])
    thigh = np.linalg.norm(p[j("HipLeft")] - p[j("KneeLeft")])   # the knee re-solved with the calibrated thigh
    assert np.isclose(thigh, part_fit.bm.THIGH * 1.7)
    props.positions[j("FootLeft")] = props.positions[j("FootRight")] + [-0.03, 0, 0]   # feet together
    p = fit.copy()
    part_fit.apply_proposals(p, st.copy(), props, 1.7, no_floor=True, frame=FACING)
    assert np.allclose(p[j("FootLeft")], props.positions[j("FootLeft")])
    props.positions[j("FootLeft")] = props.positions[j("FootRight")] + [0.10, 0, 0]   # left of right: crossed
    p = fit.copy()
    s = st.copy()
    s[j("FootLeft")] = INFERRED
    part_fit.apply_proposals(p, s, props, 1.7, no_floor=True, frame=FACING)
    assert np.array_equal(p[j("FootLeft")], fit[j("FootLeft")]) and s[j("FootLeft")] == INFERRED
    st_f = st.copy()
    st_f[j("FootLeft")] = INFERRED
    p = fit.copy()   # a confident foot proposal, apart from the other and in the leg's reach: tracked, on its
    _, own = part_fit.apply_proposals(p, st_f, _proposals(pos), 1.7, no_floor=True, frame=FACING)   # own evidence
    assert st_f[j("FootLeft")] == TRACKED   # (the knees rest on their own confident parts too)
    assert set(np.flatnonzero(own)) == {j("FootLeft"), j("FootRight"), j("KneeLeft"), j("KneeRight")}
    p = fit.copy()   # with a floor in view the fit's feet stand
    part_fit.apply_proposals(p, st.copy(), _proposals(pos), 1.7, no_floor=False, frame=FACING)
    assert np.array_equal(p[j("FootLeft")], fit[j("FootLeft")])


def test_learned_offsets_bring_proposals_nearer_rendered_joints(rendered):
    """On rendered frames the offsets (learned on other clips) move confident proposals toward the true joints."""
    seq, _ = rendered
    tracker = SkeletonTracker(gravity=seq.gravity)
    raw, moved = [], []
    names = [n for n in part_fit.DIRECT + ("ElbowLeft", "ElbowRight", "HandLeft", "HandRight")]
    for f in range(len(seq.mm)):
        tracker.update(seq.mm[f], seq.times[f])
        props, fit = tracker.last_proposals, tracker.last_good
        frame = part_fit.body_frame(fit.lateral, fit.axis)
        ok = [j(n) for n in names if props.confidence[j(n)] >= part_fit.USE_CONFIDENCE]
        raw.append(np.linalg.norm(props.positions[ok] - seq.joints[f, ok], axis=1))
        moved.append(np.linalg.norm(part_fit.joint_positions(props, frame)[ok] - seq.joints[f, ok], axis=1))
    raw, moved = np.concatenate(raw), np.concatenate(moved)
    assert len(raw) > 40
    assert moved.mean() < raw.mean() - 0.005 and moved.mean() < 0.06


def test_ankle_sits_where_the_sdk_puts_it_above_and_behind_the_proposed_foot(no_offsets, monkeypatch):
    monkeypatch.setattr(part_fit, "ANKLE_FROM_FOOT", True)
    pos, st = _standing_pose()
    p = pos.copy()
    part_fit.apply_proposals(p, st.copy(), _proposals(pos), 1.7, no_floor=True, frame=FACING)
    # facing the sensor, behind the foot is away from it (+Z)
    expect = pos[j("FootLeft")] + np.array([0.0, part_fit.SDK_ANKLE_ABOVE_FOOT, part_fit.SDK_ANKLE_BEHIND_FOOT]) * 1.7
    assert np.allclose(p[j("AnkleLeft")], expect)


def test_joints_far_from_confident_proposals_are_not_reported_tracked(no_offsets):
    pos, st = _standing_pose()
    props = _proposals(pos)
    props.positions[j("HandLeft")] += [0.0, 0.3, 0.0]    # the forest sees the hand 30 cm higher
    props.positions[j("KneeLeft")] += [0.0, -0.3, 0.0]   # knee parts are not trusted to judge the fit
    props.confidence[j("ElbowRight")] = 0.0              # no confident proposal: nothing to disagree with
    props.positions[j("ElbowRight")] += [0.3, 0.0, 0.0]
    far = part_fit.disagreeing(pos, props, FACING)
    assert set(np.flatnonzero(far)) == {j("HandLeft"), j("WristLeft")}
    # an elbow the proposal moved far: the fit's wrist and hand beyond it are not claimed tracked
    props = _proposals(pos)
    props.positions[j("ElbowLeft")] += [-0.2, 0.05, 0.0]
    doubt, own = part_fit.apply_proposals(pos, st, props, 1.7, frame=FACING)
    assert set(np.flatnonzero(doubt)) == {j("HandLeft"), j("WristLeft")} and st[j("ElbowLeft")] == INFERRED
    assert set(np.flatnonzero(own)) == {j("KneeLeft"), j("KneeRight")}   # only the knees on their own parts


def test_a_doubted_arm_takes_a_less_confident_proposal(no_offsets):
    pos, st = _standing_pose()
    st[j("ElbowLeft")] = INFERRED
    props = _proposals(pos, conf=0.5 * (part_fit.USE_CONFIDENCE + part_fit.DOUBTED_ARM_CONFIDENCE))
    props.positions[j("ElbowLeft")] += [-0.1, 0.05, 0.0]
    props.positions[j("ElbowRight")] += [0.1, 0.05, 0.0]    # the fit tracks this elbow: it stays
    before = pos.copy()
    part_fit.apply_proposals(pos, st, props, 1.7, frame=FACING)
    assert np.allclose(pos[j("ElbowLeft")], props.positions[j("ElbowLeft")])
    assert np.array_equal(pos[j("ElbowRight")], before[j("ElbowRight")])


def test_an_elbow_proposal_by_the_shoulder_is_refused(no_offsets):
    """A less confident elbow part seen next to the shoulder (a hand on the face folds the arm there) is not the
    elbow: it must lie about an upper arm's length from the shoulder."""
    pos, st = _standing_pose()
    st[j("ElbowRight")] = INFERRED
    props = _proposals(pos, conf=0.5 * (part_fit.USE_CONFIDENCE + part_fit.DOUBTED_ARM_CONFIDENCE))
    props.positions[j("ElbowRight")] = pos[j("ShoulderRight")] + [0.0, -0.15, -0.05]   # 0.68 upper arms away
    before = pos.copy()
    part_fit.apply_proposals(pos, st, props, 1.7, frame=FACING)
    assert np.array_equal(pos[j("ElbowRight")], before[j("ElbowRight")])


def test_knees_take_confident_proposals_as_found_unless_turned(no_offsets):
    pos, st = _standing_pose()
    props = _proposals(pos)
    props.positions[j("KneeLeft")] = [-0.12, -0.48, 2.38]    # the left knee lifted forward
    props.positions[j("KneeRight")] = [-0.06, -0.5, 2.45]    # nearer the left knee: sides confused, refused
    offsets = np.zeros((20, 3))
    offsets[[j("KneeLeft"), j("KneeRight")]] = [0.0, -0.05, 0.0]   # knees are used as found, without offsets
    props_pos = props.positions.copy()
    before = pos.copy()
    part_fit.apply_proposals(pos, st, props, 1.7, frame=FACING)
    assert np.allclose(pos[j("KneeLeft")], props_pos[j("KneeLeft")])
    assert st[j("KneeLeft")] == TRACKED   # on its own confident part: seen
    assert np.allclose(pos[j("KneeRight")], before[j("KneeRight")])
    assert np.allclose(part_fit.joint_positions(props, FACING, offsets)[j("KneeLeft")], props_pos[j("KneeLeft")])
    pos, st = _standing_pose()
    part_fit.apply_proposals(pos, st, props, 1.7, frame=FACING, turned=True)   # turned: the fit's knees stay
    assert np.allclose(pos[j("KneeLeft")], before[j("KneeLeft")])


def test_an_elbow_proposal_at_its_own_hand_is_refused(no_offsets):
    pos, st = _standing_pose()
    props = _proposals(pos)
    st[[j("ElbowRight"), j("WristRight"), j("HandRight")]] = INFERRED   # the fit lost the raised arm
    props.positions[j("HandRight")] = [0.1, 0.55, 2.4]       # the right hand raised to the face
    props.positions[j("ElbowRight")] = [0.12, 0.5, 2.4]      # a hand part taken for the elbow, beside it
    part_fit.apply_proposals(pos, st, props, 1.7, frame=FACING)
    assert np.allclose(pos[j("HandRight")], [0.1, 0.55, 2.4])
    # not the hand part: the fit's hanging elbow, out of the forearm's reach of the sure hand, solved between
    # shoulder and hand instead
    assert np.linalg.norm(pos[j("ElbowRight")] - props.positions[j("ElbowRight")]) > 0.1
    assert np.isclose(np.linalg.norm(pos[j("HandRight")] - pos[j("ElbowRight")]), part_fit.ELBOW_TO_HAND * 1.7)
    props.positions[j("ElbowRight")] = [0.3, 0.25, 2.4]      # an elbow a forearm away from that hand is taken
    part_fit.apply_proposals(pos, st, props, 1.7, frame=FACING)
    assert np.allclose(pos[j("ElbowRight")], [0.3, 0.25, 2.4])


def test_a_hand_part_seen_only_up_the_forearm_is_moved_out_to_the_forearm_length(no_offsets):
    pos, st = _standing_pose()
    props = _proposals(pos)
    props.positions[j("HandLeft")] = [-0.17, 0.0, 2.5]    # 12 cm below the elbow: the forearm's middle
    part_fit.apply_proposals(pos, st, props, 1.7, frame=FACING)
    reach = (part_fit.bm.FOREARM + part_fit.WRIST_BEFORE_HAND) * 1.7
    assert np.allclose(pos[j("HandLeft")], [-0.17, 0.12 - reach, 2.5])
    assert np.allclose(pos[j("HandRight")], [0.17, -0.2, 2.5])   # a full forearm away: as proposed
    pos, st = _standing_pose()   # from an elbow by the shoulder the forearm's direction is unknown: left as seen
    st[[j("ElbowLeft"), j("WristLeft"), j("HandLeft")]] = INFERRED
    props.positions[j("ElbowLeft")] = [-0.2, 0.36, 2.45]
    props.positions[j("HandLeft")] = [-0.3, 0.22, 2.45]
    part_fit.apply_proposals(pos, st, props, 1.7, frame=FACING)
    assert np.allclose(pos[j("ElbowLeft")], [-0.2, 0.36, 2.45])
    assert np.allclose(pos[j("HandLeft")], [-0.3, 0.22, 2.45])


def test_joints_moved_onto_their_confident_part_nearby_are_seen(no_offsets):
    """An elbow the fit doubted, moved 8 cm onto its confident part, is reported tracked (the wrist with its
    hand); one moved 25 cm is not (the fit and the forest disagree), nor a weak part, nor a turned performer."""
    pos, st = _standing_pose()
    st[[j("ElbowLeft"), j("WristLeft"), j("HandLeft"), j("ElbowRight")]] = INFERRED
    props = _proposals(pos)
    props.positions[j("ElbowLeft")] += [0.0, 0.08, 0.0]
    props.positions[j("HandLeft")] += [0.0, 0.06, 0.0]
    props.positions[j("ElbowRight")] += [0.0, 0.25, 0.0]
    before = pos.copy()
    _, own = part_fit.apply_proposals(pos, st, props, 1.7, frame=FACING)
    seen = part_fit.seen_on_parts(before, pos, props, FACING, own, turned=False)
    assert seen[[j("ElbowLeft"), j("HandLeft"), j("WristLeft")]].all()
    assert np.allclose(pos[j("ElbowRight")], props.positions[j("ElbowRight")]) and not seen[j("ElbowRight")]
    assert not seen[[j("Head"), j("ShoulderLeft")]].any()   # not moved: nothing new was seen
    assert not part_fit.seen_on_parts(before, pos, props, FACING, own, turned=True).any()
    props.confidence[:] = part_fit.TRACK_CONFIDENCE / 2
    assert not part_fit.seen_on_parts(before, pos, props, FACING, own, turned=False)[j("ElbowLeft")]


def test_a_knee_between_a_seen_foot_and_its_confident_part_is_seen(no_offsets):
    """A knee the proposals did not move is seen where its leg's foot lies on its own part and the knee's
    confident part is within 15 cm; 20 cm away, or with the foot not on its own part, it is not."""
    pos, _ = _standing_pose()
    props = _proposals(pos)
    props.positions[j("KneeLeft")] += [0.0, 0.08, 0.0]
    props.positions[j("KneeRight")] += [0.0, 0.20, 0.0]
    own = np.zeros(20, bool)
    own[[j("FootLeft"), j("FootRight")]] = True
    seen = part_fit.seen_on_parts(pos, pos, props, FACING, own, turned=False)
    assert seen[j("KneeLeft")] and not seen[j("KneeRight")]
    assert seen[[j("AnkleLeft"), j("AnkleRight")]].all()   # with their feet
    own[j("FootLeft")] = False
    seen = part_fit.seen_on_parts(pos, pos, props, FACING, own, turned=False)
    assert not seen[[j("KneeLeft"), j("AnkleLeft")]].any()


def test_a_tracked_joint_moved_past_agreement_is_not_seen(no_offsets):
    """The fit tracked the left knee; its part lies 12 cm away (beyond AGREE): the proposal moves it, the fit
    and the forest disagree, and it is not reported seen. Had the fit doubted it, the move would count (not
    for an elbow, held to ELBOW_AGREE either way: test below)."""
    pos, st = _standing_pose()
    props = _proposals(pos)
    props.positions[j("KneeLeft")] += [-0.12, 0.0, 0.0]
    before, before_st = pos.copy(), st.copy()
    _, own = part_fit.apply_proposals(pos, st, props, 1.7, frame=FACING)
    assert np.allclose(pos[j("KneeLeft")], props.positions[j("KneeLeft")]) and st[j("KneeLeft")] == INFERRED
    assert not part_fit.seen_on_parts(before, pos, props, FACING, own, False, before_st)[j("KneeLeft")]
    doubted = before_st.copy()
    doubted[j("KneeLeft")] = INFERRED
    assert part_fit.seen_on_parts(before, pos, props, FACING, own, False, doubted)[j("KneeLeft")]


def test_a_shoulder_or_head_moved_onto_its_part_is_seen_however_far(no_offsets):
    """The forest's torso-top parts are its surest: a tracked shoulder or head its part moves 20 cm is seen
    on it (a tracked knee or elbow moved as far is not: tests above)."""
    pos, st = _standing_pose()
    pos[j("Head")] = [0.0, 0.7, 2.5]
    props = _proposals(pos)
    props.positions[j("ShoulderLeft")] += [0.0, 0.2, 0.0]
    props.positions[j("Head")] += [0.2, 0.0, 0.0]
    before, before_st = pos.copy(), st.copy()
    _, own = part_fit.apply_proposals(pos, st, props, 1.7, frame=FACING)
    seen = part_fit.seen_on_parts(before, pos, props, FACING, own, False, before_st)
    assert seen[[j("ShoulderLeft"), j("Head")]].all() and not seen[j("ShoulderRight")]   # (not moved)


def test_a_hand_moved_out_along_a_short_forearm_and_a_wrist_on_its_own_part_are_seen(no_offsets):
    """A hand part seen up the forearm is moved out to the forearm's length (a few cm off its part): still on
    it, so seen. A wrist whose own confident part lies within 8 cm of it is seen though its hand is not; 12 cm
    away, or from a weak part, it is not."""
    pos, st = _standing_pose()
    st[[j("ElbowLeft"), j("WristLeft"), j("HandLeft")]] = INFERRED
    props = _proposals(pos)
    reach = (part_fit.bm.FOREARM + part_fit.WRIST_BEFORE_HAND) * 1.7
    props.positions[j("HandLeft")] = [-0.17, 0.12 - reach + 0.03, 2.5]   # 3 cm short of the forearm's length
    before = pos.copy()
    _, own = part_fit.apply_proposals(pos, st, props, 1.7, frame=FACING)
    assert np.isclose(np.linalg.norm(pos[j("HandLeft")] - props.positions[j("HandLeft")]), 0.03)
    assert part_fit.seen_on_parts(before, pos, props, FACING, own, turned=False)[j("HandLeft")]
    pos, _ = _standing_pose()
    props = _proposals(pos)
    props.confidence[[j("HandLeft"), j("HandRight")]] = 0.0   # no hand seen
    props.positions[j("WristLeft")] += [0.0, 0.06, 0.0]
    props.positions[j("WristRight")] += [0.0, 0.12, 0.0]
    seen = part_fit.seen_on_parts(pos, pos, props, FACING, np.zeros(20, bool), turned=False)
    assert seen[j("WristLeft")] and not seen[j("WristRight")] and not seen[[j("HandLeft"), j("HandRight")]].any()
    props.confidence[j("WristLeft")] = part_fit.WRIST_SEEN_CONFIDENCE / 2
    assert not part_fit.seen_on_parts(pos, pos, props, FACING, np.zeros(20, bool), turned=False)[j("WristLeft")]


def test_shoulders_move_onto_confident_parts_before_the_arms_and_nothing_else(no_offsets):
    pos, st = _standing_pose()
    props = _proposals(pos)
    props.positions[j("ShoulderLeft")] = [-0.15, 0.34, 2.58]    # the part 6 cm lower and further back
    props.positions[j("ShoulderRight")] = [-0.02, 0.4, 2.5]     # nearer the left shoulder than its own: refused
    props.positions[j("ElbowLeft")] = [-0.37, 0.3, 2.4]         # arms wait for the fit and apply_proposals
    before, before_st = pos.copy(), st.copy()
    part_fit.shoulders_on_parts(pos, st, props, np.array([-1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))
    assert np.allclose(pos[j("ShoulderLeft")], [-0.15, 0.34, 2.58])
    moved = np.flatnonzero(np.any(pos != before, axis=1))
    assert moved.tolist() == [j("ShoulderLeft")] and np.array_equal(st, before_st)
    # sure enough for apply_proposals, not to fit the arms from: the fit's shoulders stay
    unsure = _proposals(before, conf=1.5 * part_fit.USE_CONFIDENCE)
    assert part_fit.SHOULDER_FIRST_CONFIDENCE > 1.5 * part_fit.USE_CONFIDENCE
    unsure.positions[j("ShoulderLeft")] = [-0.15, 0.34, 2.58]
    again = before.copy()
    part_fit.shoulders_on_parts(again, st, unsure, np.array([-1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))
    assert np.array_equal(again, before)


def test_elbows_are_held_to_closer_agreement_than_other_joints(no_offsets):
    """An elbow is the least sure of the seen parts: a tracked elbow its part moves 9.5 cm is demoted (a hand
    moved as far keeps its state), a doubted elbow moved 12 cm onto its part is not seen there (a knee moved as
    far is), and an elbow 20 cm from a part only DOUBTED_ARM_CONFIDENCE sure is doubted (a hand is not)."""
    pos, st = _standing_pose()
    props = _proposals(pos)
    props.positions[j("ElbowLeft")] += [0.0, 0.095, 0.0]
    props.positions[j("HandRight")] += [0.0, 0.095, 0.0]
    part_fit.apply_proposals(pos, st, props, 1.7, frame=FACING)
    assert st[j("ElbowLeft")] == INFERRED and st[j("HandRight")] == TRACKED

    pos, st = _standing_pose()
    st[[j("ElbowLeft"), j("KneeLeft")]] = INFERRED
    props = _proposals(pos)
    props.positions[j("ElbowLeft")] += [0.0, 0.12, 0.0]
    props.positions[j("KneeLeft")] += [0.0, 0.12, 0.0]
    before = pos.copy()
    _, own = part_fit.apply_proposals(pos, st, props, 1.7, frame=FACING)
    assert np.allclose(pos[j("ElbowLeft")], props.positions[j("ElbowLeft")])
    seen = part_fit.seen_on_parts(before, pos, props, FACING, own, turned=False)
    assert seen[j("KneeLeft")] and not seen[j("ElbowLeft")]

    pos, _ = _standing_pose()
    props = _proposals(pos, conf=(part_fit.DOUBTED_ARM_CONFIDENCE + part_fit.USE_CONFIDENCE) / 2)
    props.positions[j("ElbowLeft")] += [0.0, 0.2, 0.0]
    props.positions[j("HandRight")] += [0.0, 0.2, 0.0]
    assert set(np.flatnonzero(part_fit.disagreeing(pos, props, FACING))) == {j("ElbowLeft")}
    props.confidence[:] = part_fit.DOUBTED_ARM_CONFIDENCE / 2   # too weak even for an elbow
    assert not part_fit.disagreeing(pos, props, FACING).any()


def test_a_hand_is_backed_by_its_seen_wrist_or_its_own_part_nearby():
    pos, _ = _standing_pose()
    props = _proposals(pos, conf=part_fit.DOUBTED_ARM_CONFIDENCE)
    props.positions[j("HandLeft")] += [0.0, 0.2, 0.0]      # the left hand's part 20 cm away
    seen = np.zeros(20, bool)
    backed = part_fit.hands_backed(pos, props, seen)
    assert set(np.flatnonzero(backed)) == {j("HandRight")}
    seen[j("WristLeft")] = True                             # ... but its wrist is seen on its own part
    assert part_fit.hands_backed(pos, props, seen)[j("HandLeft")]
    props.confidence[j("HandRight")] = part_fit.DOUBTED_ARM_CONFIDENCE / 2   # a part too weak to back it
    assert not part_fit.hands_backed(pos, props, seen)[j("HandRight")]


def test_an_elbow_out_of_its_forearm_reach_of_a_sure_hand_is_solved_between_shoulder_and_hand(no_offsets,
                                                                                               monkeypatch):
    """The left arm pushed 50 cm forward: the forest sees the hand surely, the fit had the arm hanging and the
    elbow's only part is a weak one on the trunk, 62 cm from the hand. The forearm is rigid: the elbow goes on
    its circle between shoulder and hand. An elbow whose own part is sure stays on it."""
    pos, st = _standing_pose()
    st[[j("ElbowLeft"), j("WristLeft"), j("HandLeft")]] = INFERRED
    props = _proposals(pos, conf=part_fit.USE_CONFIDENCE)
    props.positions[j("HandLeft")] = [-0.17, 0.3, 2.0]
    props.positions[j("ElbowLeft")] = [-0.17, 0.15, 2.6]
    props.confidence[j("ElbowLeft")] = part_fit.DOUBTED_ARM_CONFIDENCE
    h = 1.7
    reach, upper = part_fit.ELBOW_TO_HAND * h, part_fit.bm.UPPER_ARM * h
    solved_pos, solved_st = pos.copy(), st.copy()
    part_fit.apply_proposals(solved_pos, solved_st, props, h, frame=FACING)
    hand, elbow, shoulder = (solved_pos[j(f"{n}Left")] for n in ("Hand", "Elbow", "Shoulder"))
    assert np.allclose(hand, props.positions[j("HandLeft")])
    assert np.isclose(np.linalg.norm(hand - elbow), reach) and np.isclose(np.linalg.norm(elbow - shoulder), upper)
    assert solved_st[j("ElbowLeft")] == INFERRED

    sure = props.confidence.copy()
    props.confidence[j("ElbowLeft")] = part_fit.USE_CONFIDENCE   # the elbow's own part is sure: kept
    kept = pos.copy()
    part_fit.apply_proposals(kept, st.copy(), props, h, frame=FACING)
    assert np.allclose(kept[j("ElbowLeft")], props.positions[j("ElbowLeft")])
    props.confidence[:] = sure
    monkeypatch.setattr(part_fit, "ELBOW_HAND_MAX", np.inf)   # the rule off: the weak trunk part is taken
    off = pos.copy()
    part_fit.apply_proposals(off, st.copy(), props, h, frame=FACING)
    assert np.allclose(off[j("ElbowLeft")], props.positions[j("ElbowLeft")])


def test_a_searched_arm_keeps_its_elbow_against_a_part_its_hand_cannot_reach(no_offsets, monkeypatch):
    """The baseball swing's wind-up: the left arm crosses the chest to the grip at the right shoulder, where the
    fit's search placed it (the hand doubted); the forest sees no left hand there and a left elbow hanging
    on the trunk's left edge, 46 cm from that hand. The elbow stays: taking it would break the forearm."""
    h = 1.7
    pos, st = _standing_pose()
    st[[j("ElbowLeft"), j("WristLeft"), j("HandLeft")]] = INFERRED
    pos[j("ElbowLeft")], pos[j("HandLeft")] = [0.0, 0.3, 2.3], [0.15, 0.42, 2.35]
    props = _proposals(pos, conf=part_fit.USE_CONFIDENCE)
    props.positions[j("ElbowLeft")] = [-0.19, 0.15, 2.5]
    props.confidence[j("HandLeft")] = 0.0
    assert np.linalg.norm(props.positions[j("ElbowLeft")] - pos[j("HandLeft")]) > part_fit.REACH_MAX_SHARE * \
        part_fit.ELBOW_TO_HAND * h

    def elbow_after(states, **patch):
        for name, value in patch.items():
            monkeypatch.setattr(part_fit, name, value)
        out = pos.copy()
        part_fit.apply_proposals(out, states.copy(), props, h, frame=FACING)
        return out[j("ElbowLeft")]

    assert np.allclose(elbow_after(st), pos[j("ElbowLeft")])
    elbow_seen = st.copy()
    elbow_seen[j("ElbowLeft")] = TRACKED   # the search explained the arm well and reported its elbow tracked
    assert np.allclose(elbow_after(elbow_seen), pos[j("ElbowLeft")])
    hand_found = st.copy()
    hand_found[j("HandLeft")] = TRACKED   # the fit's hand an extremity it found, not a searched arm's: taken
    assert np.allclose(elbow_after(hand_found), props.positions[j("ElbowLeft")])
    assert np.allclose(elbow_after(st, SEARCHED_ARM_KEEPS_ELBOW=False), props.positions[j("ElbowLeft")])
    monkeypatch.setattr(part_fit, "SEARCHED_ARM_KEEPS_ELBOW", True)
    props.confidence[j("HandLeft")] = part_fit.USE_CONFIDENCE   # a sure hand part of its own: the elbow is taken
    props.positions[j("HandLeft")] = [-0.05, 0.2, 2.4]
    assert np.allclose(elbow_after(st), props.positions[j("ElbowLeft")])
