"""Hands beyond their forearm's reach, and arms faster than arms move, are brought back (arm_reach.py)."""
import numpy as np

from kinect_retarget.core.skeletons import INFERRED, KINECT_V1, TRACKED
from kinect_retarget.depth.arm_reach import ELBOW_TO_HAND, ArmSpeedGate, fold_overreaching_hands

J = KINECT_V1.index
H = 1.75


def standing() -> tuple[np.ndarray, np.ndarray]:
    """A performer 2.5 m away with the arms hanging, every joint inferred."""
    p = np.zeros((20, 3))
    p[J("HipCenter")], p[J("ShoulderCenter")] = [0, 0.0, 2.5], [0, 0.5, 2.5]
    for s, x in (("Left", -0.2), ("Right", 0.2)):
        p[J(f"Shoulder{s}")], p[J(f"Elbow{s}")] = [x, 0.45, 2.5], [x, 0.18, 2.5]
        p[J(f"Wrist{s}")], p[J(f"Hand{s}")] = [x, -0.06, 2.5], [x, -0.12, 2.5]
    return p, np.full(20, INFERRED, np.uint8)


def test_a_hand_on_the_other_hand_hangs_below_its_elbow():
    p, st = standing()
    p[J("HandLeft")] = p[J("WristLeft")] = p[J("HandRight")] + [0.02, 0.0, 0.0]   # half a metre off
    moved = fold_overreaching_hands(p, st, None, H)
    assert moved[J("HandLeft")] and not moved[J("HandRight")]
    np.testing.assert_allclose(p[J("HandLeft")], p[J("ElbowLeft")] - [0, ELBOW_TO_HAND * H, 0], atol=1e-9)
    assert p[J("ElbowLeft")][1] > p[J("WristLeft")][1] > p[J("HandLeft")][1]


def test_a_proposal_within_reach_is_taken():
    p, st = standing()
    p[J("HandLeft")] = [0.3, 0.1, 2.0]
    props = np.zeros((20, 3))
    props[J("HandLeft")] = p[J("ElbowLeft")] + [0.0, 0.05, -0.29]   # forearm pointing at the sensor
    fold_overreaching_hands(p, st, props, H)
    d = props[J("HandLeft")] - p[J("ElbowLeft")]
    np.testing.assert_allclose(p[J("HandLeft")], p[J("ElbowLeft")] + ELBOW_TO_HAND * H * d / np.linalg.norm(d))


def test_hands_within_reach_or_tracked_are_left_alone():
    p, st = standing()
    p[J("HandRight")] = p[J("ElbowRight")] + [0.0, 0.3, 0.0]   # raised, within reach
    p[J("HandLeft")] = [0.3, 0.1, 2.0]
    st[J("HandLeft")] = TRACKED
    before = p.copy()
    assert not fold_overreaching_hands(p, st, None, H).any()
    np.testing.assert_array_equal(p, before)


def _run_gate(hand_left_path, tracked_at=(), elbow_tracked=False, elbow_shift=(0.0, 0.0, 0.0)):
    """Feed a standing performer whose left hand follows `hand_left_path` (one point a 30 Hz frame)."""
    gate = ArmSpeedGate()
    out = []
    for i, hand in enumerate(hand_left_path):
        p, st = standing()
        p[J("HandLeft")] = hand
        p[J("ElbowLeft")] += np.multiply(i, elbow_shift)
        st[J("ElbowLeft")] = TRACKED if elbow_tracked else st[J("ElbowLeft")]
        if i in tracked_at:
            st[J("HandLeft")] = TRACKED
        gate.apply(p, st, i / 30.0)
        out.append(p[J("HandLeft")].copy())
    return np.array(out)


def test_a_hand_jumping_onto_another_part_is_held_for_a_few_frames_only():
    p, _ = standing()
    rest, away = p[J("HandLeft")], p[J("HandRight")] + [0.0, 0.3, -0.2]   # 60 cm off in one frame
    out = _run_gate([rest] * 5 + [away] * 10)
    np.testing.assert_allclose(out[5:10], np.repeat(rest[None], 5, axis=0))   # held 5 frames (HOLD_S)...
    np.testing.assert_allclose(out[10:], np.repeat(away[None], 5, axis=0))    # ... then what is seen is taken
    early = _run_gate([rest] * 2 + [away] * 3)   # the first frames of a fit settle: nothing held
    np.testing.assert_allclose(early[2:], np.repeat(away[None], 3, axis=0))


def test_a_hand_jumping_below_a_tracked_elbow_is_held_to_the_elbow():
    p, _ = standing()
    rest, away = p[J("HandLeft")], p[J("HandLeft")] + [0.1, -0.45, 0.05]   # an arm curl's hand taken by the hip
    shift = np.array([0.01, 0.0, 0.0])   # the tracked elbow drifts 1 cm a frame: the held hand goes with it
    out = _run_gate([rest] * 5 + [away] * 10, elbow_tracked=True, elbow_shift=shift)
    np.testing.assert_allclose(out[5:10], rest + np.arange(1, 6)[:, None] * shift)   # held 5 frames, with the elbow
    np.testing.assert_allclose(out[10:], np.repeat(away[None], 5, axis=0))           # ... then what is seen
    seen = _run_gate([rest] * 5 + [away] * 3, tracked_at={5, 6, 7}, elbow_tracked=True)   # the hand tracked: taken
    np.testing.assert_allclose(seen[5:], np.repeat(away[None], 3, axis=0))


def test_a_jump_back_or_a_tracked_or_slow_hand_is_taken():
    p, _ = standing()
    rest, away = p[J("HandLeft")], p[J("HandLeft")] + [0.6, 0.0, 0.0]
    back = _run_gate([rest] * 3 + [away] * 3 + [rest] * 3, tracked_at={3})   # the jump out was seen on its part
    np.testing.assert_allclose(back[3:6], np.repeat(away[None], 3, axis=0))
    np.testing.assert_allclose(back[6:], np.repeat(rest[None], 3, axis=0))   # back where it was: taken
    slow = [rest + [0.03 * k, 0.0, 0.0] for k in range(10)]   # 3 cm a frame
    np.testing.assert_allclose(_run_gate(slow), np.array(slow))


def test_a_tracker_that_forgets_its_performer_forgets_the_gates_history():
    """With no person in view and no usable timestamp the tracker forgets the pose at once; its arm gate must
    too, or the next performer's first frames are held to the last one's arms."""
    from kinect_retarget.depth.skeleton_tracker import SkeletonTracker, TrackerSettings
    tracker = SkeletonTracker(settings=TrackerSettings(part_forest=None))
    for i in range(6):
        tracker.arm_gate.apply(*standing(), i / 30.0)
    tracker.update(np.zeros((480, 640), np.uint16), float("nan"))   # nobody there
    p, st = standing()
    p[J("HandLeft")] = p[J("HandRight")] + [0.0, 0.3, -0.2]   # 60 cm from the last performer's hand
    assert not tracker.arm_gate.apply(p, st, 6 / 30.0).any()
