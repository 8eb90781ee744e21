"""The default filter halves jitter on the real Kinect v2 takes and lags at most one frame; live == bake."""
import numpy as np
import pytest

from kinect_retarget.core.filters import DoubleExponentialFilter, OneEuroFilter, jitter, lag_frames, make_filter
from kinect_retarget.takes import load_take

REAL = ["Ges01_wavehand.csv", "Ges02_balancinghands.csv", "Ges03_drawlines.csv", "Ges04_comehere.csv",
        "Ges05_demopoint.csv", "Ges06_chickenwing.csv", "joints.csv"]


@pytest.mark.parametrize("name", REAL)
def test_default_filter_halves_jitter_within_one_frame_of_lag(data_dir, name):
    take = load_take(data_dir / "kinect_v2" / name)
    out = make_filter("default", take.rate).run(take.positions, take.states, take.times)
    assert jitter(out) <= 0.5 * jitter(take.positions)
    assert lag_frames(take.positions, out) <= 1.0


def test_step_and_run_agree(data_dir):
    take = load_take(data_dir / "kinect_v2" / "Ges03_drawlines.csv")
    for make in (OneEuroFilter, DoubleExponentialFilter):
        batch = make().run(take.positions, take.states, take.times)
        f = make()
        live = np.array([f.step(take.positions[i], take.states[i], take.times[i]) for i in range(take.frame_count)])
        np.testing.assert_array_equal(batch, live)


def test_untracked_joints_hold_and_restart(data_dir):
    take = load_take(data_dir / "kinect_v2" / "Ges01_wavehand.csv")
    states = take.states.copy()
    positions = take.positions.copy()
    states[50:60, 7] = 0
    positions[50:60, 7] = 0.0  # the SDK writes zeros for joints it lost
    out = make_filter("default").run(positions, states, take.times)
    np.testing.assert_array_equal(out[50:60, 7], np.repeat(out[49:50, 7], 10, axis=0))
    assert np.all(np.isfinite(out))
    assert np.linalg.norm(out[60, 7] - positions[60, 7]) < 1e-12  # comes back at its raw position


def test_lag_measure_detects_a_known_delay(rng):
    t = np.arange(300)
    raw = np.sin(t / 10.0)[:, None, None] * np.ones((1, 2, 3)) + rng.normal(0, 1e-3, (300, 2, 3))
    delayed = np.concatenate([raw[:2], raw[:-2]])
    assert lag_frames(raw, delayed) == pytest.approx(2.0, abs=0.1)


def test_a_bounded_one_euro_never_trails_by_more_than_its_bound(data_dir):
    take = load_take(data_dir / "kinect_v2" / "Ges03_drawlines.csv")
    moved = take.positions.copy()
    moved[60:] += [0.5, 0.0, 0.0]   # the whole body half a metre aside at once
    free = OneEuroFilter(min_cutoff=1.0, beta=1.5).run(moved, take.states, take.times)
    bounded = OneEuroFilter(min_cutoff=1.0, beta=1.5, max_deviation=0.03).run(moved, take.states, take.times)
    trail = lambda out: np.linalg.norm(out - moved, axis=-1)
    assert trail(free)[60].max() > 0.2                    # the unbounded filter is left far behind
    assert trail(bounded).max() <= 0.03 + 1e-12
    assert jitter(bounded[:60]) < 0.7 * jitter(take.positions[:60])   # and still steadies small moves
    f = OneEuroFilter(min_cutoff=1.0, beta=1.5, max_deviation=0.03)   # live == bake with a bound too
    live = np.array([f.step(moved[i], take.states[i], take.times[i]) for i in range(take.frame_count)])
    np.testing.assert_array_equal(bounded, live)
