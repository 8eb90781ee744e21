"""A hand reported beyond its forearm's reach is brought back to it (arm_reach.py)."""
import numpy as np

from kinect_retarget.core.skeletons import INFERRED, KINECT_V1, TRACKED
from kinect_retarget.depth.arm_reach import ELBOW_TO_HAND, fold_overreaching_hands

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
