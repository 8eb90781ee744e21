"""A recorded take's zero-phase cleanup (take_smoothing.py): no lag, short mistakes dropped, found limbs kept."""
from __future__ import annotations

import numpy as np

from kinect_retarget.core.skeletons import INFERRED, NOT_TRACKED, TRACKED
from kinect_retarget.depth.take_smoothing import smooth_recorded_joints

RATE = 30.0


def _take(frames: int = 40, state: int = TRACKED):
    """Two joints: joint 0 moves steadily along x (1.2 m/s), joint 1 stands still."""
    t = np.arange(frames) / RATE
    pos = np.zeros((frames, 2, 3))
    pos[:, 0, 0] = 1.2 * t
    pos[:, :, 2] = 2.5
    return pos, np.full((frames, 2), state, np.uint8), t


def test_a_steady_move_passes_without_lag():
    for state in (TRACKED, INFERRED):
        pos, st, t = _take(state=state)
        out = smooth_recorded_joints(pos, st, t)
        np.testing.assert_allclose(out, pos, atol=1e-12)   # a causal filter would trail it
    rng = np.random.default_rng(0)
    noisy = pos + rng.normal(0.0, 0.01, pos.shape)
    out = smooth_recorded_joints(noisy, st, t)
    assert np.abs(out - pos)[3:-3].mean() < 0.6 * np.abs(noisy - pos)[3:-3].mean()   # jitter halved, about


def test_a_limb_wrong_for_one_or_two_frames_is_dropped():
    pos, st, t = _take(state=INFERRED)
    wrong = pos.copy()
    wrong[10, 1] += [0.0, 0.4, 0.0]                  # one frame 40 cm off
    wrong[20:22, 1] += [0.3, -0.3, 0.0]               # two frames
    out = smooth_recorded_joints(wrong, st, t)
    assert np.linalg.norm(out[:, 1] - pos[:, 1], axis=-1).max() < 1e-9
    apart = np.arange(40) * 0.5   # frames half a second apart: nothing is smoothed together
    np.testing.assert_array_equal(smooth_recorded_joints(wrong, st, apart), wrong)


def test_a_tracked_joint_is_not_pulled_toward_the_guesses_before_it():
    pos, st, t = _take()
    guessed = pos.copy()
    guessed[:15, 0] += [0.0, -0.3, 0.0]   # guessed 30 cm off while inferred, then found again
    st[:15, 0] = INFERRED
    out = smooth_recorded_joints(guessed, st, t)
    np.testing.assert_allclose(out[15:, 0], pos[15:, 0], atol=1e-12)
    assert np.all(out[12:15, 0, 1] > -0.3)   # the guesses next to it do lean toward where it was found


def test_frames_without_a_skeleton_and_gaps_in_time_split_the_take():
    pos, st, t = _take()
    pos[:, 1, 1] = np.where(np.arange(40) < 20, 0.0, 0.5)   # a step where the person was lost ...
    st[20:23] = NOT_TRACKED                                  # ... for three frames
    pos[20:23] = 0.0
    out = smooth_recorded_joints(pos, st, t)
    np.testing.assert_array_equal(out[20:23], pos[20:23])   # no skeleton: left as it was
    np.testing.assert_allclose(out[:20, 1], pos[:20, 1], atol=1e-12)   # neither side of the gap sees the other
    np.testing.assert_allclose(out[23:, 1], pos[23:, 1], atol=1e-12)
    st[20:23] = TRACKED
    late = t.copy()
    late[20:] += 1.0   # a second without frames
    stepped = pos.copy()
    stepped[20:23, 1] = [0.0, 0.5, 2.5]
    out = smooth_recorded_joints(stepped, st, late)
    np.testing.assert_allclose(out[:, 1], stepped[:, 1], atol=1e-12)
    across = smooth_recorded_joints(stepped, st, t)   # no gap: the step is smoothed across
    assert np.abs(across[18:22, 1] - stepped[18:22, 1]).max() > 0.05
