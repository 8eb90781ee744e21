"""Resampling a baked motion to the scene's rate, key reduction within tolerance, and take sub-ranges."""
import numpy as np
import pytest

from kinect_retarget.core.bake_options import BakeOptions, take_range
from kinect_retarget.core.key_reduction import channel_matrices, reduce_keys, rotation_error
from kinect_retarget.core.pipeline import BakedMotion
from kinect_retarget.core.quat import angle_between, from_matrix, make_continuous, normalize, to_matrix
from kinect_retarget.core.resample import interpolate_quats, resample_motion, slerp
from kinect_retarget.core.rotation_modes import EULER_ORDERS, channel_values
from kinect_retarget.core.skeletons import KINECT_V1
from kinect_retarget.core.take import Take, TakeError
from tests.conftest import assert_quat_equal


def _axis_angle(axis, angle):
    axis = np.asarray(axis, dtype=np.float64) / np.linalg.norm(axis)
    return np.concatenate([[np.cos(angle / 2)], np.sin(angle / 2) * axis])


def _motion(n=31, rate=30.0, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(n) / rate
    # two bones turning at constant angular speed about fixed axes: slerp between samples is exact
    axes = normalize(rng.normal(size=(2, 3)))
    speed = np.array([1.3, -2.1])
    quats = np.stack([[_axis_angle(axes[b], speed[b] * ti) for b in range(2)] for ti in t])
    loc = np.stack([t, 2 * t, np.zeros(n)], axis=1)
    return BakedMotion(np.arange(n) + 1, ("a", "b"), quats, "a", loc, rate, np.arange(n),
                       {"desired": quats.copy()}), t, axes, speed


def test_slerp_halfway_and_short_way():
    a, b = _axis_angle([0, 0, 1], 0.0), _axis_angle([0, 0, 1], 1.0)
    assert_quat_equal(slerp(a, b, 0.5), _axis_angle([0, 0, 1], 0.5))
    assert_quat_equal(slerp(a, -b, 0.25), _axis_angle([0, 0, 1], 0.25))  # -b is the same rotation
    assert_quat_equal(slerp(a, a, 0.3), a)


def test_resample_30_to_24_keeps_speed_and_is_exact_for_constant_turns():
    motion, t, axes, speed = _motion()
    out = resample_motion(motion, t, 24.0, frame_start=1)
    assert out.fps == 24.0
    np.testing.assert_array_equal(out.frames, np.arange(1, 26))  # 1 s of take -> 24 frames + the first
    tk = (out.frames - 1) / 24.0
    for b in range(2):
        want = np.stack([_axis_angle(axes[b], speed[b] * x) for x in tk])
        assert np.degrees(angle_between(out.quats[:, b], want)).max() < 1e-6
    np.testing.assert_allclose(out.root_location[:, 1], 2 * tk, atol=1e-12)
    assert out.extras["desired"].shape == out.quats.shape


def test_resample_at_the_take_rate_is_the_identity():
    motion, t, *_ = _motion()
    out = resample_motion(motion, t, 30.0, frame_start=1)
    np.testing.assert_array_equal(out.frames, motion.frames)
    assert_quat_equal(out.quats, motion.quats)
    np.testing.assert_array_equal(out.samples, motion.samples)


def test_resample_with_step_and_start():
    motion, t, *_ = _motion()
    out = resample_motion(motion, t, 30.0, frame_start=101, step=3)
    np.testing.assert_array_equal(out.frames, 101 + np.arange(0, 31, 3))
    assert_quat_equal(out.quats, motion.quats[::3])


def test_interpolate_quats_between_samples():
    q = np.stack([_axis_angle([1, 0, 0], 0.0), _axis_angle([1, 0, 0], 1.0)])[:, None]
    mid = interpolate_quats(np.array([0.0, 1.0]), q, np.array([0.25, 2.0]))
    assert_quat_equal(mid[0, 0], _axis_angle([1, 0, 0], 0.25))
    assert_quat_equal(mid[1, 0], q[1, 0])  # past the end: the last sample


@pytest.mark.parametrize("mode", EULER_ORDERS + ("QUATERNION", "AXIS_ANGLE"))
def test_channel_matrices_invert_channel_values(mode):
    rng = np.random.default_rng(1)
    q = normalize(rng.normal(size=(50, 4)))
    _, values = channel_values(q, mode)
    m = channel_matrices(values, mode)
    np.testing.assert_allclose(m, to_matrix(q), atol=1e-9)
    assert np.degrees(rotation_error(m, to_matrix(q))).max() < 1e-6


@pytest.mark.parametrize("mode", ("QUATERNION", "XYZ"))
def test_reduction_stays_within_tolerance_and_removes_keys(mode):
    rng = np.random.default_rng(2)
    n = 200
    t = np.arange(n) / 30.0
    angles = np.stack([np.sin(t * 2), 0.5 * np.cos(t * 3), 0.2 * t], 1) + rng.normal(0, 1e-4, (n, 3))
    q = from_matrix(channel_matrices(angles, "XYZ"))
    _, values = channel_values(make_continuous(q), mode)
    loc = np.stack([np.sin(t), t, np.zeros(n)], 1)
    red = reduce_keys(np.arange(n), [(values, mode)], loc, deg=0.5, mm=1.0)
    keys = red.rotation_keys[0]
    assert keys[0] == 0 and keys[-1] == n - 1 and len(keys) < n // 2
    assert red.removed == (n - len(keys)) * values.shape[1] + (n - len(red.location_keys)) * 3
    # what Blender plays back: every channel linear between the kept keys
    back = np.stack([np.interp(np.arange(n), keys, values[keys, c]) for c in range(values.shape[1])], 1)
    err = np.degrees(rotation_error(channel_matrices(back, mode), channel_matrices(values, mode)))
    assert err.max() <= 0.5 + 1e-9 and red.max_deg == pytest.approx(err.max(), abs=1e-9)
    lk = red.location_keys
    lback = np.stack([np.interp(np.arange(n), lk, loc[lk, c]) for c in range(3)], 1)
    assert np.linalg.norm(lback - loc, axis=1).max() * 1000 <= 1.0 + 1e-9
    tighter = reduce_keys(np.arange(n), [(values, mode)], None, deg=0.05, mm=1.0)
    assert len(tighter.rotation_keys[0]) > len(keys)


def _take(n=90, rate=30.0):
    j = len(KINECT_V1)
    return Take(KINECT_V1, np.zeros((n, j, 3)), np.full((n, j), 2), np.arange(n) / rate, rate)


def test_take_range_seconds_and_frames():
    take = _take()
    part, label = take_range(take, BakeOptions(range_start=1.0, range_end=2.0))
    assert part.frame_count == 31 and part.times[0] == pytest.approx(1.0) and "1-2 s" in label
    part, _ = take_range(take, BakeOptions(range_start=10, range_end=19, range_unit="frames"))
    assert part.frame_count == 10 and part.times[0] == pytest.approx(10 / 30)
    whole, label = take_range(take, BakeOptions())
    assert whole is take and label == ""
    with pytest.raises(TakeError, match="holds no sample"):
        take_range(take, BakeOptions(range_start=5.0))


def test_bake_options_refuse_nonsense():
    with pytest.raises(ValueError, match="step"):
        BakeOptions(step=0)
    with pytest.raises(ValueError, match="before it starts"):
        BakeOptions(range_start=2, range_end=1)
    with pytest.raises(ValueError, match="choose one"):
        BakeOptions(into_current=True, push_nla=True)
    with pytest.raises(ValueError, match="unit"):
        BakeOptions(range_unit="minutes")
