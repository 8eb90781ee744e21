"""core/floor_plane.py on a synthetic figure (seeded): feet stepping around a floor, the head above them."""
from __future__ import annotations

import numpy as np
import pytest

from kinect_retarget.core import floor_plane
from kinect_retarget.core.floor_plane import estimate_up

FEET = ((1, 2), (3, 4))  # (ankle, toe) of each leg; node 0 is the top of the head


def _walker(frames=240, seed=0, lying=None, box=None, jump=None, spot=3.0):
    """(F, 5, 3) Z-up positions: the feet step to random spots over a `spot`-metre square, ankles 8 cm and
    toes 2 cm above the floor when planted, the swinging foot 15 cm up; the head 1.6 m above the ankles, or
    lying on the floor over the frames `lying`; `box`: frames where the right foot rests 30 cm up on a box;
    `jump`: frames where both feet are 25 cm up."""
    rng = np.random.default_rng(seed)
    pos = np.zeros((frames, 5, 3))
    steps = rng.uniform(-spot / 2, spot / 2, size=(frames // 20 + 1, 2, 2))
    for f in range(frames):
        for leg, (ankle, toe) in enumerate(FEET):
            xy = steps[f // 20, leg] + [0.0, 0.2 * leg]
            lift = 0.15 if (f // 10) % 2 == leg and f % 10 in (4, 5, 6) else 0.0
            lift += 0.3 if box is not None and leg == 1 and f in box else 0.0
            lift += 0.25 if jump is not None and f in jump else 0.0
            pos[f, ankle] = [*xy, 0.08 + lift]
            pos[f, toe] = [xy[0] + 0.15, xy[1], 0.02 + lift]
    mid = pos[:, [1, 3]].mean(axis=1)
    pos[:, 0] = mid + [0.0, 0.0, 1.6] + rng.normal(0, 0.03, (frames, 3))
    if lying is not None:
        pos[lying, 0] = mid[lying] + [1.6, 0.0, 0.02]
    return pos + rng.normal(0, 0.004, pos.shape)


def _tilt(pos, degrees):
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    r = np.array([[1.0, 0, 0], [0, c, -s], [0, s, c]])
    return pos @ r.T, r @ [0.0, 0, 1]


def _angle(a, b):
    return float(np.degrees(np.arccos(np.clip(a @ b, -1, 1))))


@pytest.mark.parametrize("degrees", [0.0, 3.0, 8.0, 20.0])
def test_floor_gives_up_and_snaps_small_tilts(degrees):
    pos, truth = _tilt(_walker(), degrees)
    est = estimate_up(pos, 0, FEET)
    assert est.how.startswith("floor under the feet")
    if degrees <= floor_plane.LEVEL_DEG:
        assert np.array_equal(est.up, [0.0, 0, 1]) and (est.axis, est.sign) == (2, 1.0)
    else:
        assert _angle(est.up, truth) < 0.5 and "not level" in est.how


def test_lifted_feet_jumps_and_a_foot_on_a_box_do_not_tilt_the_floor():
    pos, truth = _tilt(_walker(box=range(0, 120), jump=range(200, 215)), 12.0)
    est = estimate_up(pos, 0, FEET)
    assert _angle(est.up, truth) < 0.5


def test_lying_for_most_of_the_take_still_stands_up(monkeypatch):
    pos, truth = _tilt(_walker(lying=slice(40, 200)), 12.0)
    est = estimate_up(pos, 0, FEET)
    assert _angle(est.up, truth) < 0.5 and "lies or bends" in est.how
    monkeypatch.setattr(floor_plane, "MIN_CONTACTS", 10**9)  # head over feet alone: the head lies sideways
    head_only = estimate_up(pos, 0, FEET)
    assert "no floor estimate" in head_only.how and head_only.axis != 2


def test_standing_on_one_spot_falls_back_to_head_over_feet():
    pos, _ = _tilt(_walker(spot=0.05), 12.0)
    est = estimate_up(pos, 0, FEET)
    assert est.how.startswith("head above the feet (no floor estimate: the feet stay on a patch too small")
    assert np.array_equal(est.up, [0.0, 0, 1])  # the nearest axis: a 12 degree tilt is not seen without a floor


def test_a_single_pose_has_no_floor():
    est = estimate_up(_walker()[:1], 0, FEET)
    assert "1 frame(s): too few to find the floor" in est.how and np.array_equal(est.up, [0.0, 0, 1])
