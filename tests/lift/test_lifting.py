"""Lifting 2D to 3D on real optical mocap projected through a known camera."""
from __future__ import annotations

import numpy as np
import pytest

from kinect_retarget.core.skeletons import INFERRED, KINECT_V1, NOT_TRACKED, TRACKED
from kinect_retarget.lift import LiftError, LiftSettings, lift
from kinect_retarget.lift.bones import lengths_from_take
from kinect_retarget.sim.lift_scoring import (mpjpe, procrustes_align, root_relative, sign_error_rate,
                                             tracks_from_take)

from .mocap import FOCAL, IMAGE, camera, rigid, seen_from, true_signs, walking_take

LIMBS = np.array([KINECT_V1.index(n) for n in ("ElbowLeft", "WristLeft", "ElbowRight", "WristRight",
                                               "KneeLeft", "AnkleLeft", "KneeRight", "AnkleRight")])
EXACT = dict(smooth_2d_s=0.0, smooth_depth_s=0.0, noise_aware=False)


@pytest.fixture(scope="module")
def walk(data_dir):
    return walking_take(data_dir, 6.0)


@pytest.mark.parametrize("azimuth", [0.0, 70.0, 200.0])
def test_round_trip_exact_with_true_scale_and_signs(walk, azimuth):
    truth = seen_from(rigid(walk), azimuth)
    tracks = tracks_from_take(truth, camera(), IMAGE)
    st = LiftSettings(lengths=lengths_from_take(truth), focal_px=FOCAL, **EXACT)
    res = lift(tracks, st, scale=FOCAL / truth.positions[:, 0, 2], signs=true_signs(truth.positions))
    err = np.linalg.norm(res.take.positions - truth.positions, axis=-1)
    assert err.max() < 1e-6  # metres: exact up to rounding
    assert np.all(res.take.states == TRACKED)


def test_orthographic_round_trip_is_exact_for_an_orthographic_camera(walk):
    """Paper 004 eq. 1: with u = s x, v = s y the lift is exact given s and the signs."""
    truth = seen_from(rigid(walk), 30.0)
    s = 220.0
    pos = truth.positions
    uv = np.stack([640 - s * pos[..., 0], 360 - s * pos[..., 1]], axis=-1)
    from kinect_retarget.lift.tracks2d import Tracks2D
    tracks = Tracks2D(uv, np.ones(uv.shape[:2]), truth.times, IMAGE)
    res = lift(tracks, LiftSettings(lengths=lengths_from_take(truth), **EXACT), scale=np.full(len(pos), s),
               signs=true_signs(pos, perspective=False))
    err = np.linalg.norm(root_relative(res.take.positions) - root_relative(pos), axis=-1)
    assert err.max() < 1e-6


def test_estimated_scale_follows_depth(walk):
    truth = seen_from(walk, 45.0)
    tracks = tracks_from_take(truth, camera(), IMAGE)
    res = lift(tracks, LiftSettings(lengths=lengths_from_take(walk), focal_px=FOCAL))
    rel = res.scale * truth.positions[:, 0, 2] / FOCAL
    assert np.median(np.abs(rel - 1)) < 0.05


def test_walking_signs_beat_no_disambiguation(walk, rng):
    """Noisy 2D (2 px) of a walk seen from the front-left: our whole-take choice of depth signs keeps the
    limbs on the right side far more often than pointing every bone at the camera, and the pose is close."""
    truth = seen_from(walk, 30.0)
    tracks = tracks_from_take(truth, camera(), IMAGE, noise_px=2.0, rng=rng)
    lengths = lengths_from_take(walk)
    ours = lift(tracks, LiftSettings(lengths=lengths, focal_px=FOCAL))
    naive = lift(tracks, LiftSettings(lengths=lengths, focal_px=FOCAL, signs="camera"))
    par = KINECT_V1.parent_array
    wrong_ours = sign_error_rate(ours.take.positions, truth.positions, par, LIMBS)
    wrong_naive = sign_error_rate(naive.take.positions, truth.positions, par, LIMBS)
    assert wrong_ours < 0.5 * wrong_naive
    assert wrong_ours < 0.25
    pa = mpjpe(procrustes_align(ours.take.positions, truth.positions), truth.positions)
    assert pa < 0.060
    assert pa < mpjpe(procrustes_align(naive.take.positions, truth.positions), truth.positions)


def test_paper_scale_recursion_respects_eq2(walk):
    truth = seen_from(walk, 0.0)
    tracks = tracks_from_take(truth, camera(), IMAGE)
    lengths = lengths_from_take(walk)
    res = lift(tracks, LiftSettings(lengths=lengths, scale="paper", signs="greedy", smooth_2d_s=0.0))
    xy = tracks.uv
    par = KINECT_V1.parent_array
    d = np.linalg.norm(xy[:, 1:] - xy[:, par[1:]], axis=-1)
    from kinect_retarget.lift.scale import SCALE_BONES
    idx = np.array([KINECT_V1.index(n) for n in SCALE_BONES])
    assert np.all(res.scale[:, None] >= d[:, idx - 1] / lengths[idx] - 1e-9)


def test_missing_joints_are_inferred_and_marked(walk):
    truth = seen_from(walk, 20.0)
    tracks = tracks_from_take(truth, camera(), IMAGE)
    wl, fl = KINECT_V1.index("WristLeft"), KINECT_V1.index("FootLeft")
    tracks.confidence[10:14, wl] = 0  # a short occlusion: interpolated
    tracks.confidence[:, fl] = 0      # never seen: placed by default direction
    tracks.uv[tracks.confidence == 0] = np.nan
    res = lift(tracks, LiftSettings(lengths=lengths_from_take(walk), focal_px=FOCAL))
    st = res.take.states
    assert np.all(st[10:14, wl] == INFERRED) and np.all(st[:, fl] == INFERRED)
    assert np.all(st[:10, wl] == TRACKED)
    err = np.linalg.norm(res.take.positions[10:14, wl] - truth.positions[10:14, wl], axis=-1)
    assert err.max() < 0.15
    foot = res.take.positions[:, fl] - res.take.positions[:, KINECT_V1.index("AnkleLeft")]
    assert np.allclose(np.linalg.norm(foot, axis=-1), lengths_from_take(walk)[fl])
    assert np.all(np.isfinite(res.take.positions))


def test_frames_without_hips_are_untracked_and_reported(walk):
    truth = seen_from(walk, 0.0)
    tracks = tracks_from_take(truth, camera(), IMAGE)
    tracks.confidence[40:70] = 0  # a second without anybody (longer than the gap filled)
    tracks.confidence[80, :] = 0
    tracks.confidence[80, KINECT_V1.index("Head")] = 1  # only the head seen
    tracks.uv[tracks.confidence == 0] = np.nan
    res = lift(tracks, LiftSettings(lengths=lengths_from_take(walk), focal_px=FOCAL))
    assert np.all(res.take.states[40:70] == NOT_TRACKED)
    assert np.all(res.take.states[80] != NOT_TRACKED)  # one lost frame: filled from its neighbours
    assert np.all(res.take.states[:40] == TRACKED)


def test_no_limb_ever_visible_is_a_clear_error(walk):
    truth = seen_from(walk, 0.0)
    tracks = tracks_from_take(truth, camera(), IMAGE)
    keep = [KINECT_V1.index(n) for n in ("HipCenter", "Head")]
    mask = np.zeros(tracks.confidence.shape, bool)
    mask[:, keep] = True
    tracks.confidence[~mask] = 0
    tracks.uv[~mask] = np.nan
    with pytest.raises(LiftError, match="scale cannot be measured"):
        lift(tracks, LiftSettings(focal_px=FOCAL))


def test_unknown_focal_still_gives_the_pose(walk, rng):
    truth = seen_from(walk, 0.0)
    tracks = tracks_from_take(truth, camera(), IMAGE, noise_px=1.0, rng=rng)
    res = lift(tracks, LiftSettings(lengths=lengths_from_take(walk)))  # focal unknown
    assert not res.take.metadata["focal_known"]
    assert mpjpe(procrustes_align(res.take.positions, truth.positions), truth.positions) < 0.06


def test_hips_never_visible_is_a_clear_error(walk):
    truth = seen_from(walk, 0.0)
    tracks = tracks_from_take(truth, camera(), IMAGE)
    for name in ("HipCenter", "HipLeft", "HipRight"):
        tracks.confidence[:, KINECT_V1.index(name)] = 0
    with pytest.raises(LiftError, match="hips .* are never visible"):
        lift(tracks, LiftSettings(focal_px=FOCAL))

