"""Root motion (issue 16): travel (and facing) on the root bone, the hips relative to it, and the pose in the
world identical to the in-place bake."""
from __future__ import annotations

import copy

import numpy as np
import pytest

from kinect_retarget.assets import motion_clip
from kinect_retarget.core.pipeline import RetargetPipeline, RetargetSettings
from kinect_retarget.core.presets import PRESETS
from kinect_retarget.core.root_motion import RootMotionError, apply_root_motion
from kinect_retarget.core.target_rig import evaluate_pose
from kinect_retarget.takes import load_take
from tests.rigs.humanoid_rigs import build
from tests.rigs.layouts import LAYOUTS


@pytest.fixture(scope="module")
def baked():
    take = load_take(motion_clip("131_03")).slice(slice(0, 360, 3))  # start, hop forward, stop
    rig = build(LAYOUTS["ue4-mannequin"], a_pose_deg=30).target("UE4")
    pipe = RetargetPipeline(take.skeleton, rig, PRESETS["ue4-mannequin"], RetargetSettings(filter="none"))
    return rig, pipe.process_take(take)


def _posed(rig, motion):
    idx = np.array([rig.index(b) for b in motion.bone_names])
    locs = {rig.index(b): v for b, v in motion.extras.get("locations", {}).items()}
    return evaluate_pose(rig, idx, motion.quats, rig.index(motion.root_bone), motion.root_location, locs)


@pytest.mark.parametrize("facing", [False, True])
def test_root_carries_travel_and_the_world_pose_is_unchanged(baked, facing):
    rig, motion = baked
    moved = copy.deepcopy(motion)
    note = apply_root_motion(moved, rig, facing=facing)
    assert "'root'" in note and moved.bone_names[-1] == "root"
    before, after = _posed(rig, motion), _posed(rig, moved)
    root, hips = rig.index("root"), rig.index("pelvis")
    others = [b for b in range(len(rig.bone_names)) if b != root]
    np.testing.assert_allclose(after[:, others], before[:, others], atol=1e-9)
    travel = before[:, hips, :3, 3] - before[0, hips, :3, 3]
    np.testing.assert_allclose(after[:, root, :2, 3] - after[0, root, :2, 3], travel[:, :2], atol=1e-9)
    np.testing.assert_allclose(after[:, root, 2, 3], rig.rest[root, 2, 3], atol=1e-12)  # on the floor
    assert np.linalg.norm(travel[-1, :2]) > 0.3  # the take travels: the root really moves
    rel = np.linalg.inv(after[:, root]) @ after[:, hips]   # hips relative to the root
    if facing:  # the root turns with the hips: their heading relative to it stays at the rest heading
        fwd = rel[:, :3, :3] @ rig.rest[hips, :3, :3].T @ np.array([0, -1.0, 0])
        assert np.degrees(np.abs(np.arctan2(fwd[:, 0], -fwd[:, 1]))).max() < 1e-6
    else:
        np.testing.assert_allclose(rel[:, :2, 3], rel[:1, :2, 3].repeat(len(rel), 0), atol=1e-9)


def test_rig_without_a_root_bone_is_a_clear_error(baked):
    _, motion = baked
    rig = build(LAYOUTS["auto-rig-pro"]).target("ARP")  # its hips bone is the top of the hierarchy
    pipe = RetargetPipeline(load_take(motion_clip("131_03")).slice(slice(0, 30)).skeleton, rig,
                            PRESETS["auto-rig-pro"], RetargetSettings(filter="none"))
    m = pipe.process_take(load_take(motion_clip("131_03")).slice(slice(0, 30)))
    with pytest.raises(RootMotionError, match="needs a root bone above the hips"):
        apply_root_motion(m, rig)
    with pytest.raises(RootMotionError, match="no bone named 'floor'"):
        apply_root_motion(m, rig, named="floor")
    with pytest.raises(RootMotionError, match="not an ancestor of the hips"):
        apply_root_motion(m, rig, named="hand.l")
