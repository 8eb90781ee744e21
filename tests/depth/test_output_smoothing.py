"""The tracker's reported joints are steadied like the SDK's (output_smoothing.py)."""
import numpy as np

from kinect_retarget.core.filters import jitter
from kinect_retarget.core.skeletons import INFERRED, KINECT_V1, NOT_TRACKED, TRACKED
from kinect_retarget.depth import output_smoothing
from kinect_retarget.depth.output_smoothing import (ARMS, BODY, KNEES_ANKLES, MAX_TRAIL, REST_MAX_MOVE, OutputSmoothing,
                                                    _robust_line_end)

J = KINECT_V1.index


def still_pose() -> np.ndarray:
    rng = np.random.default_rng(4)
    return np.array([0.0, 0.0, 2.5]) + rng.uniform(-0.5, 0.5, (20, 3)) * [0.5, 1.6, 0.2]


def _run(frames, states=None, times=None) -> np.ndarray:
    smooth = OutputSmoothing()
    out = []
    for i, p in enumerate(frames):
        p = np.array(p, dtype=np.float64)
        st = np.full(20, TRACKED, np.uint8) if states is None else states[i]
        smooth.apply(p, st, i / 30.0 if times is None else times[i])
        out.append(p)
    return np.array(out)


def test_a_performer_standing_still_jitters_far_less():
    rng = np.random.default_rng(7)
    raw = still_pose() + rng.normal(0.0, 0.015, (90, 20, 3))   # 1.5 cm of noise on every joint
    steady = _run(raw)
    assert jitter(steady[:, BODY]) < 0.25 * jitter(raw[:, BODY])
    assert jitter(steady[:, ARMS]) < 0.6 * jitter(raw[:, ARMS])
    assert np.abs(steady[30:].mean(axis=0) - still_pose()).max() < 0.01   # steadied where the joints are


def test_arms_follow_a_quick_move_sooner_than_the_body():
    pose = still_pose()
    moving = [pose + [0.04 * k, 0.0, 0.0] for k in range(1, 9)]   # everything sideways at 1.2 m/s
    out = _run([pose] * 10 + moving)
    left_behind = np.linalg.norm(out[-3] - moving[-3], axis=1)
    assert left_behind[ARMS].max() < left_behind[BODY].min()
    behind = np.linalg.norm(out[-8:] - moving, axis=-1)
    assert behind.max() <= MAX_TRAIL + REST_MAX_MOVE + 1e-12   # never far behind (a start from rest is held most)
    assert behind[-3:].max() <= MAX_TRAIL + 1e-12   # and once moving, the line lets go


def test_a_still_knee_ignores_single_frames_off_and_a_moving_one_is_not_held_back(monkeypatch):
    pose = still_pose()
    frames = [pose.copy() for _ in range(30)]
    knee = J("KneeLeft")
    for k in (10, 14, 20, 21):   # single frames (and a pair) 8 cm off, as the fit's and the part's knees differ
        frames[k][knee] += [0.0, -0.08, 0.0]
    out = _run(frames)
    assert np.linalg.norm(out[:, knee] - pose[knee], axis=1).max() < 0.01
    walking = [pose + [0.0, 0.0, 0.04 * k] for k in range(30)]   # 1.2 m/s toward the sensor
    lag = np.linalg.norm(_run(walking)[:, KNEES_ANKLES] - np.array(walking)[:, KNEES_ANKLES], axis=-1)
    assert lag.max() <= MAX_TRAIL + 1e-12
    monkeypatch.setattr(output_smoothing, "REST_FRAMES", 1)   # without the line, the filter lets them through
    assert np.linalg.norm(_run(frames)[:, knee] - pose[knee], axis=1).max() > 0.04


def test_the_robust_line_follows_a_steady_move_and_ignores_one_place_off():
    times = np.arange(7) / 30.0
    window = np.zeros((7, 2, 3))
    window[:, 0, 0] = np.arange(7) * 0.01          # 0.3 m/s along x
    window[3, 1] = [0.0, 0.5, 0.0]                 # one place far off
    end, speed = _robust_line_end(window, times, 1.0)
    np.testing.assert_allclose(end, [[0.06, 0.0, 0.0], [0.0, 0.0, 0.0]], atol=1e-12)
    np.testing.assert_allclose(speed, [0.3, 0.0], atol=1e-9)
    half, _ = _robust_line_end(window, times, 0.5)
    np.testing.assert_allclose(half[0], [0.045, 0.0, 0.0], atol=1e-12)   # half the slope: 1.5 frames behind


def test_the_first_frame_and_a_forgotten_performer_start_from_their_raw_joints():
    smooth = OutputSmoothing()
    first = still_pose()
    p = first.copy()
    smooth.apply(p, np.full(20, TRACKED, np.uint8), 0.0)
    np.testing.assert_array_equal(p, first)
    smooth.apply(first + 0.2, np.full(20, TRACKED, np.uint8), 1 / 30)
    smooth.reset()
    other = still_pose() + [1.0, 0.0, 0.5]
    p = other.copy()
    smooth.apply(p, np.full(20, INFERRED, np.uint8), 2 / 30)
    np.testing.assert_array_equal(p, other)


def test_an_untracked_joint_holds_its_place_and_bad_timestamps_are_one_frame():
    pose = still_pose()
    states = [np.full(20, TRACKED, np.uint8) for _ in range(4)]
    states[3] = states[3].copy()
    states[3][J("HandLeft")] = NOT_TRACKED
    frames = [pose, pose, pose, pose + 0.5]
    out = _run(frames, states, times=[0.0, float("nan"), float("inf"), 0.1])
    assert np.all(np.isfinite(out))
    np.testing.assert_allclose(out[3, J("HandLeft")], pose[J("HandLeft")])
    assert np.linalg.norm(out[3, J("HandRight")] - pose[J("HandRight")]) > 0.05   # the others move on


def test_the_tracker_steadies_what_it_reports_and_reports_raw_joints_when_asked(rendered):
    """The same rendered frames tracked twice: the steadied joints are the raw ones filtered, nothing else."""
    from kinect_retarget.depth.skeleton_tracker import SkeletonTracker, TrackerSettings
    seq, _ = rendered
    runs = {}
    for steady in (True, False):
        tracker = SkeletonTracker(gravity=seq.gravity, settings=TrackerSettings(steady_output=steady))
        runs[steady] = [tracker.update(d, t) for d, t in zip(seq.mm, seq.times)]
    raw = np.array([p for p, _ in runs[False]])
    states = [s for _, s in runs[False]]
    np.testing.assert_array_equal(np.array([s for _, s in runs[True]]), np.array(states))
    expected = _run(raw, states, seq.times)
    np.testing.assert_allclose(np.array([p for p, _ in runs[True]]), expected, atol=1e-12)
    trail = np.linalg.norm(expected - raw, axis=-1)
    assert 0.005 < trail.max() <= MAX_TRAIL + REST_MAX_MOVE + 1e-12   # it did something, and never lags far behind
