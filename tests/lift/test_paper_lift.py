"""Paper 004 as published (lift/paper_lift.py) and its H-Anim output (lift/hanim.py)."""
from __future__ import annotations

import numpy as np
import pytest

from kinect_retarget.lift import LiftError, LiftSettings, hanim, lift
from kinect_retarget.lift.bones import lengths_from_take
from kinect_retarget.sim.lift_scoring import root_relative

from .mocap import IMAGE, rigid, seen_from, true_signs, walking_take


@pytest.fixture(scope="module")
def walk(data_dir):
    return walking_take(data_dir, 4.0)


def _ortho_tracks(truth, s=220.0):
    from kinect_retarget.lift.tracks2d import Tracks2D
    pos = truth.positions
    uv = np.stack([640 - s * pos[..., 0], 360 - s * pos[..., 1]], axis=-1)
    return Tracks2D(uv, np.ones(uv.shape[:2]), truth.times, IMAGE)


def test_paper_method_is_the_paper_alone(walk):
    """method="paper": orthographic (focal ignored), eq. 3 scale, continuity signs, nothing smoothed; its
    plain depth with the true scale and signs reproduces an orthographic view exactly."""
    truth = seen_from(rigid(walk), 30.0)
    tracks = _ortho_tracks(truth)
    st = LiftSettings(lengths=lengths_from_take(truth), focal_px=1000.0, method="paper")
    res = lift(tracks, st)
    meta = res.take.metadata
    assert (meta["method"], meta["scale_method"], meta["sign_method"], meta["focal_known"]) == \
        ("paper", "paper", "continuity", False)
    exact = lift(tracks, st, scale=np.full(truth.frame_count, 220.0),
                 signs=true_signs(truth.positions, perspective=False))
    err = np.linalg.norm(root_relative(exact.take.positions) - root_relative(truth.positions), axis=-1)
    assert err.max() < 1e-6
    ours = lift(tracks, LiftSettings(lengths=lengths_from_take(truth)))
    assert not np.allclose(ours.take.positions, res.take.positions, equal_nan=True)


def test_continuity_signs_keep_depth_continuous(walk):
    """The paper's ± by continuity: no joint's depth relative to the pelvis jumps by more than its bone
    between frames when the true scale is given (each sign is the nearer of the two places)."""
    truth = seen_from(rigid(walk), 70.0)
    res = lift(_ortho_tracks(truth), LiftSettings(lengths=lengths_from_take(truth), method="paper"),
               scale=np.full(truth.frame_count, 220.0))
    z = root_relative(res.take.positions)[..., 2]
    assert np.all(np.abs(np.diff(z, axis=0)) < 0.35)


def test_unknown_method_refused(walk):
    with pytest.raises(LiftError, match="method"):
        lift(_ortho_tracks(walk), LiftSettings(method="magic"))


def test_hanim_figure_names_and_hierarchy():
    assert len(hanim.NAMES) == 16 and hanim.NAMES[0] == "sacroiliac"
    parent = {n: (hanim.NAMES[p] if p >= 0 else None) for n, p in zip(hanim.NAMES, hanim.PARENTS)}
    assert parent["l_hip"] == "sacroiliac" and parent["skullbase"] == "vt1" and parent["r_shoulder"] == "vt1"
    assert parent["l_wrist"] == "l_elbow" and parent["r_ankle"] == "r_knee" and parent["vl5"] == "sacroiliac"
    assert all(p < k for k, p in enumerate(hanim.PARENTS))  # parents first


def test_ik_euler_angles_reproduce_every_bone_direction(walk, rng):
    """Eq. 4-5: down the tree, each joint's Euler rotation (β = 0) turns its rest bone onto the observed
    direction; forward kinematics with those angles gives back every bone's direction."""
    from kinect_retarget.core.conventions import kinect_to_blender
    pos = kinect_to_blender(walk.positions[::10])
    lengths = hanim.bone_lengths(pos)
    heads, tails = hanim.rest_pose(lengths, pos)
    rest = hanim.rest_frames(heads, tails)
    euler = hanim.solve_euler(pos, rest)
    assert np.all(euler[..., 1] == 0.0)  # β fixed at 0
    world = np.zeros(euler.shape[:2] + (3, 3))
    for k, p in enumerate(hanim.PARENTS):
        base = rest[k] if p < 0 else world[:, p] @ (rest[p].T @ rest[k])
        world[:, k] = base @ hanim.euler_matrix(euler[:, k])
    for k in np.flatnonzero(hanim.TO >= 0):
        d = pos[:, hanim.TO[k]] - pos[:, hanim.AT[k]]
        d /= np.linalg.norm(d, axis=-1, keepdims=True)
        np.testing.assert_allclose(world[:, k, :, 1], d, atol=1e-9)
