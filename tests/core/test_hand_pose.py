"""Kinect v2 hands, pure numpy: finger chains by rig family, hand-state curls blended over time, the
hand's roll from the thumb."""
import numpy as np
import pytest

from kinect_retarget.core.hand_pose import (CLOSED, LASSO, NOT_TRACKED, OPEN, UNKNOWN, finger_chains, finger_curls,
                                            hand_roll, signed_angle, twist_quats)
from kinect_retarget.core.quat import to_matrix


def _names(family):
    if family == "rigify":
        return [f"{f}.0{i}{s}" for f in ("thumb", "f_index", "f_middle", "f_ring", "f_pinky") for i in (1, 2, 3)
                for s in (".L", ".R")] + ["hand.L"]
    if family == "mixamo":
        return [f"mixamorig:{s}Hand{f}{i}" for f in ("Thumb", "Index", "Middle", "Ring", "Pinky") for i in (1, 2, 3)
                for s in ("Left", "Right")]
    return [f"{f}_0{i}_{s}" for f in ("thumb", "index", "middle", "ring", "pinky") for i in (1, 2, 3)
            for s in ("l", "r")]


@pytest.mark.parametrize("family, left_index", [("rigify", "f_index.01.L"), ("mixamo", "mixamorig:LeftHandIndex1"),
                                                ("ue", "index_01_l")])
def test_finger_chains_for_each_rig_family(family, left_index):
    chains = finger_chains(_names(family), "Left")
    assert chains["index"][0] == left_index and len(chains["pinky"]) == 3 and len(chains) == 5
    right = finger_chains(_names(family), "Right")
    assert right["index"][0] != left_index
    assert finger_chains(["hand.L", "forearm.L"], "Left") is None


def test_hand_states_curl_fingers_with_a_smooth_blend():
    t = np.arange(60) / 30.0
    states = np.array([OPEN] * 10 + [CLOSED] * 20 + [UNKNOWN] * 5 + [LASSO] * 20 + [NOT_TRACKED] * 5)
    c = finger_curls(states, t)
    assert np.allclose(c[:10], 0.0)
    assert c[29, 1:].min() > 0.95 and c[29, 0] == pytest.approx(0.6, abs=0.03)  # a fist: every finger, thumb less
    assert np.all(np.diff(c[29:35, 1:], axis=0) >= 0)  # unknown holds the last target: the fist stays closed
    assert c[54, 1] < 0.05 and c[54, 2] < 0.05 and c[54, 3] > 0.95 and c[54, 4] > 0.95  # lasso: two fingers out
    np.testing.assert_allclose(c[55:], np.broadcast_to(c[54], c[55:].shape), atol=0.02)  # not tracked: holds
    step = np.abs(np.diff(c, axis=0)).max()
    assert step < 0.3  # never a snap: at 30 fps a state change moves a curl by at most 28 % per frame
    assert c[10, 1] > 0.2 and c[10, 1] < 0.3


def test_hand_roll_turns_the_thumb_side_to_the_performers_thumb():
    rng = np.random.default_rng(3)
    q = rng.normal(size=(20, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    desired = to_matrix(q)
    thumb_local = np.array([1.0, 0.0, 0.0])
    want = rng.uniform(-1.5, 1.5, 20)  # radians about the bone's Y
    c, s = np.cos(want), np.sin(want)
    turned_local = np.stack([c, np.zeros(20), -s], 1)  # Ry(want) @ x
    thumb_dir = np.einsum("fij,fj->fi", desired, turned_local) + 0.3 * desired[:, :, 1]  # plus some along Y
    roll = hand_roll(desired, thumb_local, thumb_dir)
    np.testing.assert_allclose(roll, want, atol=1e-9)
    after = to_matrix(twist_quats(q, roll))
    np.testing.assert_allclose(after[:, :, 1], desired[:, :, 1], atol=1e-9)  # the hand still points the same way
    y = np.array([0.0, 1.0, 0.0])
    assert signed_angle(np.array([1.0, 0, 0]), np.array([0, 0, -1.0]), y) == pytest.approx(np.pi / 2)
