"""The torso's left-right direction from the line between the forest's shoulder parts (skeleton_fit.shoulder_line):
on real depth the chest's normals read a turned performer as facing the sensor (Kinect v1's depth steps make flat
patches that face it), the shoulders' parts did not."""
from __future__ import annotations

import numpy as np

from kinect_retarget.core.skeletons import KINECT_V1
from kinect_retarget.depth import skeleton_fit
from kinect_retarget.depth.body_parts import PARTS
from kinect_retarget.depth.part_proposals import Proposals
from kinect_retarget.depth.skeleton_fit import SHOULDER_LINE_CONFIDENCE, _line_facing, shoulder_line
from kinect_retarget.depth.skeleton_tracker import SkeletonTracker, TrackerSettings

LEFT, RIGHT = KINECT_V1.index("ShoulderLeft"), KINECT_V1.index("ShoulderRight")
UP = np.array([0.0, 1.0, 0.0])
TOWARD = np.array([0.0, 0.0, -1.0])   # from the performer to the sensor


def _proposals(left, right, confidence=2 * SHOULDER_LINE_CONFIDENCE) -> Proposals:
    pos, conf = np.zeros((20, 3)), np.zeros(20)
    pos[LEFT], pos[RIGHT] = left, right
    conf[[LEFT, RIGHT]] = confidence
    return Proposals(pos, conf, (np.zeros(0, int), np.zeros(0, int)), np.zeros((0, len(PARTS))))


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
        facing = _line_facing(_turned(deg) + [0.0, 0.05, 0.0], UP, TOWARD)   # a dropped shoulder: the same
        assert facing is not None and abs(facing @ UP) < 1e-9
        assert abs(_angle(facing, TOWARD) - abs(deg)) < 1e-6
    assert _line_facing(_turned(120.0), UP, TOWARD) is None   # would face away: the sides are mirrored
    assert _line_facing(None, UP, TOWARD) is None


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
