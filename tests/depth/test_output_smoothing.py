"""The tracker's reported joints are steadied like the SDK's (output_smoothing.py)."""
import numpy as np

from kinect_retarget.core.filters import jitter
from kinect_retarget.core.skeletons import INFERRED, KINECT_V1, NOT_TRACKED, TRACKED
from kinect_retarget.depth.output_smoothing import ARMS, BODY, MAX_TRAIL, OutputSmoothing

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
    moved = pose + [0.3, 0.0, 0.0]   # everything 30 cm to the side at once
    out = _run([pose] * 10 + [moved] * 4)
    left_behind = np.linalg.norm(out[-3] - moved, axis=1)
    assert left_behind[ARMS].max() < left_behind[BODY].min()
    assert np.linalg.norm(out[-4:] - moved, axis=-1).max() <= MAX_TRAIL + 1e-12   # never far behind


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
    assert 0.005 < trail.max() <= MAX_TRAIL + 1e-12   # the filter did something, and never lags far behind
