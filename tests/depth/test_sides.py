"""Left/right labels of hand and foot candidates (depth.sides)."""
from __future__ import annotations

import numpy as np

from kinect_retarget.core.skeletons import INFERRED, KINECT_V1, TRACKED
from kinect_retarget.depth.sides import assign_sides

J = KINECT_V1.index
LAT = np.array([-1.0, 0.0, 0.0])   # the performer's left, seen from the sensor: the image's right


def _cand(p):
    p = np.asarray(p, float)
    return ((0, 0), p, 1.0, float(p[1]), float(p @ LAT))


def _prev(hand_left, hand_right, left_state, right_state):
    pos, st = np.zeros((20, 3)), np.full(20, TRACKED, np.uint8)
    pos[J("HandLeft")], pos[J("HandRight")] = hand_left, hand_right
    st[J("HandLeft")], st[J("HandRight")] = left_state, right_state
    return pos, st


def test_one_seen_hand_keeps_its_candidate():
    """Turned away, a raised right hand sits left of a knee that sticks out like a hand: by body side it would be
    the left hand; the right hand seen last frame says it is the right one."""
    right_hand, knee = _cand([0.50, 0.30, 1.58]), _cand([0.64, -0.18, 1.72])
    pos, st = _prev([0.21, -0.10, 1.57], [0.64, 0.41, 1.66], INFERRED, TRACKED)
    by_body = assign_sides([right_hand, knee], None, None, "Hand")
    assert by_body["Left"] is right_hand
    got = assign_sides([right_hand, knee], pos, st, "Hand")
    assert got["Right"] is right_hand and got["Left"] is knee


def test_one_seen_hand_far_from_both_falls_back_to_body_side():
    a, b = _cand([-0.3, 0.0, 2.0]), _cand([0.3, 0.0, 2.0])
    pos, st = _prev([0.0, 0.0, 2.0], [0.0, 1.0, 2.0], INFERRED, TRACKED)   # 1 m from both candidates
    got = assign_sides([a, b], pos, st, "Hand")
    assert got["Left"] is a and got["Right"] is b
