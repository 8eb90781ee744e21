"""The torso's left-right direction from the forest's parts (part_lines): the line between its shoulder parts
(else the chest's normals), checked by the line between its upper torso quarters. On real depth the chest's
normals read a turned performer as facing the sensor (Kinect v1's depth steps make flat patches that face it),
the parts did not; an arm raised before its shoulder carries the shoulder's part with it, the torso's quarters
stay on the chest."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from kinect_retarget.core.skeletons import KINECT_V1
from kinect_retarget.depth import skeleton_fit
from kinect_retarget.depth.body_parts import PART, PARTS
from kinect_retarget.depth.depth_camera import DepthCamera
from kinect_retarget.depth.part_lines import (LINE_AGREE_DEG, NORMALS_AGREE_DEG, SHOULDER_LINE_CONFIDENCE,
                                              TORSO_LINE_MASS, checked_by_torso, line_facing, shoulder_line,
                                              torso_line)
from kinect_retarget.depth.part_proposals import Proposals
from kinect_retarget.depth.skeleton_tracker import SkeletonTracker, TrackerSettings

LEFT, RIGHT = KINECT_V1.index("ShoulderLeft"), KINECT_V1.index("ShoulderRight")
UP = np.array([0.0, 1.0, 0.0])
TOWARD = np.array([0.0, 0.0, -1.0])   # from the performer to the sensor


def _proposals(left, right, confidence=2 * SHOULDER_LINE_CONFIDENCE) -> Proposals:
    pos, conf = np.zeros((20, 3)), np.zeros(20)
    pos[LEFT], pos[RIGHT] = left, right
    conf[[LEFT, RIGHT]] = confidence
    return Proposals(pos, conf, (np.zeros(0, int), np.zeros(0, int)), np.zeros((0, len(PARTS))), np.zeros((0, 3)),
                     np.zeros(0))


def _turned(deg: float) -> np.ndarray:
    """Right -> left shoulder of a performer facing the sensor, turned `deg` about the vertical (+: toward
    their left, the left shoulder moving away from the sensor)."""
    a = np.radians(deg)
    return np.array([-np.cos(a), 0.0, np.sin(a)])   # the performer's left is the sensor's right (-x)


def _angle(a, b) -> float:
    return float(np.degrees(np.arccos(np.clip(a @ b / np.linalg.norm(a) / np.linalg.norm(b), -1, 1))))


def test_the_line_needs_both_shoulders_seen_a_shoulder_width_apart():
    centre = np.array([0.1, 0.4, 2.5])
    line = shoulder_line(_proposals(centre + 0.19 * _turned(30), centre - 0.19 * _turned(30)))
    assert line is not None and _angle(line, _turned(30)) < 1e-6
    assert shoulder_line(None) is None
    assert shoulder_line(_proposals(centre + 0.19 * _turned(0), centre, 0.5 * SHOULDER_LINE_CONFIDENCE)) is None
    assert shoulder_line(_proposals(centre + 0.05 * _turned(0), centre - 0.05 * _turned(0))) is None   # one part
    assert shoulder_line(_proposals(centre + 0.5 * _turned(0), centre - 0.5 * _turned(0))) is None     # 1 m apart


def test_the_facing_is_square_to_the_line_and_toward_the_sensor():
    for deg in (0.0, 30.0, -50.0, 80.0):
        facing = line_facing(_turned(deg) + [0.0, 0.05, 0.0], UP, TOWARD)   # a dropped shoulder: the same
        assert facing is not None and abs(facing @ UP) < 1e-9
        assert abs(_angle(facing, TOWARD) - abs(deg)) < 1e-6
    assert line_facing(_turned(120.0), UP, TOWARD) is None   # would face away: the sides are mirrored
    assert line_facing(None, UP, TOWARD) is None


def test_the_fitted_torso_turns_with_the_shoulder_line(rendered, monkeypatch):
    seq, _ = rendered

    def lateral():
        tracker = SkeletonTracker(gravity=seq.gravity, settings=TrackerSettings(steady_output=False))
        tracker.update(seq.mm[0], seq.times[0])
        return tracker.last_good.lateral

    from_chest = lateral()
    line = _turned(35.0)
    assert _angle(from_chest, line) > 20.0   # the rendered performer faces the sensor more squarely
    monkeypatch.setattr(skeleton_fit, "shoulder_line", lambda props: line)
    assert _angle(lateral(), line - (line @ UP) * UP) < 5.0


GRID = SimpleNamespace(step=4, camera=DepthCamera())   # cells of 4 pixels: about 1.7 cm across at 2.5 m


def _quarters(left_centre, right_centre, cells=40, p=0.9, rng=None) -> Proposals:
    """Proposals whose first `cells` cells are the upper torso's left quarter (around `left_centre`), the
    next ones its right quarter, each with part probability `p`."""
    rng = rng or np.random.default_rng(0)
    xyz = np.concatenate([c + rng.normal(0.0, 0.04, (cells, 3)) for c in (left_centre, right_centre)])
    probs = np.zeros((2 * cells, len(PARTS)))
    probs[:cells, PART["torso_upper_left"]] = p
    probs[cells:, PART["torso_upper_right"]] = p
    probs[:, PART["head"]] = 1.0 - p
    areas = xyz[:, 2] ** 2 * (GRID.step / GRID.camera.f) ** 2   # a cell stands for more surface farther away
    cells_rc = (np.zeros(2 * cells, int), np.arange(2 * cells))
    return Proposals(np.zeros((20, 3)), np.zeros(20), cells_rc, probs, xyz, areas)


def test_the_torso_line_joins_the_upper_quarters_centres():
    centre = np.array([0.1, 0.4, 2.5])
    props = _quarters(centre + 0.1 * _turned(40), centre - 0.1 * _turned(40))
    line = torso_line(props)
    pts = props.points
    w = pts[:, 2] ** 2   # a cell stands for more surface the farther it is
    left, right = (np.average(pts[k], axis=0, weights=w[k]) for k in (slice(0, 40), slice(40, 80)))
    assert line is not None and np.allclose(line, left - right)
    assert _angle(line, _turned(40)) < 5.0
    assert torso_line(None) is None


def test_the_torso_line_needs_both_quarters_seen():
    centre = np.array([0.0, 0.3, 2.5])
    area = 2.5 ** 2 * (GRID.step / GRID.camera.f) ** 2   # square metres one cell stands for at 2.5 m
    few = int(TORSO_LINE_MASS / (0.9 * area) * 0.5)      # half the mass a quarter needs
    assert torso_line(_quarters(centre + 0.1 * _turned(0), centre - 0.1 * _turned(0), cells=few)) is None
    enough = int(TORSO_LINE_MASS / (0.9 * area) * 2) + 1
    assert torso_line(_quarters(centre + 0.1 * _turned(0), centre - 0.1 * _turned(0), cells=enough)) is not None
    # cells no likelier than the proposals' threshold are not the part's
    assert torso_line(_quarters(centre + 0.1 * _turned(0), centre - 0.1 * _turned(0), cells=200, p=0.1)) is None


def _facing(deg: float) -> np.ndarray:
    """A facing turned `deg` from the sensor about the vertical: square to _turned(deg)."""
    return line_facing(_turned(deg), UP, TOWARD)


@pytest.mark.parametrize("reading, torso, taken", [
    (0.0, 40.0, "torso"),        # the shoulders' line on an arm raised before its shoulder: read as facing the sensor
    (-30.0, 40.0, "torso"),      # the mirror image of the turn
    (35.0, 40.0, "reading"),     # agrees
    (65.0, 40.0, "reading"),     # turned further: the quarters read less than the whole turn
    (-12.0, 15.0, "reading"),    # the quarters read too little of a turn to judge
    (-40.0, -70.0, "torso"),     # either way round
    (None, 40.0, "torso"),
    (20.0, None, "reading"),
])
def test_the_upper_torso_checks_a_reading_that_misses_its_turn(reading, torso, taken):
    r = None if reading is None else _facing(reading)
    t = None if torso is None else _facing(torso)
    out = checked_by_torso(r, t, UP, TOWARD)
    assert out is (t if taken == "torso" else r)


def test_the_chest_normals_are_checked_more_closely():
    """On real depth the chest's normals are the worse reading (Kinect v1's depth steps): the quarters
    overrule them from a smaller disagreement than they overrule the shoulders' line."""
    assert NORMALS_AGREE_DEG < LINE_AGREE_DEG
    r, t = _facing(0.0), _facing(NORMALS_AGREE_DEG + 5.0)
    assert checked_by_torso(r, t, UP, TOWARD, NORMALS_AGREE_DEG) is t
    assert checked_by_torso(r, t, UP, TOWARD) is r


def test_a_turned_performer_s_torso_quarters_read_the_turn(data_dir):
    """On a rendered performer turned about 40 degrees, the forest's upper torso quarters read the turn the
    right way. The quarters' centres lie on the surface the sensor sees, whose near side shows more of
    itself, so the line reads less than the whole turn (25 of 43 degrees here): a reading turned further is
    kept (checked_by_torso)."""
    from kinect_retarget.sim.synthetic_depth import Scenario, render_sequence
    seq = render_sequence(str(data_dir / "mocap_bvh" / "131_02.bvh"), str(data_dir / "meshes" / "makehuman"),
                          Scenario(turn_deg=40.0, seed=8), start=0, frames=1)
    tracker = SkeletonTracker(gravity=seq.gravity, settings=TrackerSettings(steady_output=False))
    tracker.update(seq.mm[0], seq.times[0])
    line = torso_line(tracker.last_proposals)
    gt = seq.joints[0]
    assert line is not None
    turn = lambda v: float(np.degrees(np.arctan2(v[2], -v[0])))   # yaw from a line facing the sensor
    truth = turn(gt[LEFT] - gt[RIGHT])
    assert truth > 30.0
    assert 0.4 * truth < turn(line) < truth + 5.0
