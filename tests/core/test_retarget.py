"""The retarget engine on real takes: bone directions, twist-free hinges, rest-pose independence, root motion."""
import numpy as np
import pytest

from kinect_retarget.core.conventions import kinect_to_blender
from kinect_retarget.core.kinect_rig_layout import generated_mapping, generated_rig, median_segment_lengths
from kinect_retarget.core.pipeline import RetargetPipeline, RetargetSettings
from kinect_retarget.core.presets import MAKEHUMAN, RIGIFY_METARIG, build_mapping, detect_preset
from kinect_retarget.core.quat import normalize
from kinect_retarget.core.skeletons import KINECT_V1
from kinect_retarget.core.target_rig import TargetRig, evaluate_pose
from kinect_retarget.takes import load_take
from tests.conftest import assert_quat_equal


@pytest.fixture(scope="module")
def hop(data_dir):
    return load_take(data_dir / "mocap_bvh" / "131_03.bvh").slice(slice(0, 600))


@pytest.fixture(scope="module")
def wave(data_dir):
    return load_take(data_dir / "kinect_v2" / "Ges01_wavehand.csv")


def _direction_errors(pipe, motion, take, rig):
    posed = evaluate_pose(rig, pipe.retargeter.bone_indices, motion.quats,
                          pipe.retargeter.root.index, motion.root_location)
    world = rig.object_rotation
    p = kinect_to_blender(take.positions[motion.samples])
    errs = []
    for m in pipe.retargeter.mapped:
        if m.is_root:
            continue
        src = normalize(p[:, m.tail] - p[:, m.head])
        got = normalize(posed[:, m.index, :3, 1] @ world.T)
        errs.append(np.degrees(np.arccos(np.clip(np.sum(src * got, -1), -1, 1))))
    return np.array(errs), posed


@pytest.mark.parametrize("which", ["hop", "wave"])
def test_generated_rig_follows_every_bone_direction_and_the_root(which, request):
    take = request.getfixturevalue(which)
    rig = generated_rig(take.skeleton, median_segment_lengths(take))
    pipe = RetargetPipeline(take.skeleton, rig, generated_mapping(take.skeleton), RetargetSettings(filter="none"))
    motion = pipe.process_take(take)
    errs, posed = _direction_errors(pipe, motion, take, rig)
    assert errs.max() < 1e-3
    head = posed[:, pipe.retargeter.root.index, :3, 3]
    src_root = kinect_to_blender(take.positions[motion.samples, take.skeleton.root])
    np.testing.assert_allclose(head - head[0], src_root - src_root[0], atol=1e-9)


def test_elbows_and_knees_bend_about_one_axis_without_twist(hop):
    rig = generated_rig(KINECT_V1, median_segment_lengths(hop))
    pipe = RetargetPipeline(KINECT_V1, rig, generated_mapping(KINECT_V1), RetargetSettings(filter="none"))
    motion = pipe.process_take(hop)
    for lower in ("WristLeft", "WristRight", "AnkleLeft", "AnkleRight", "HandLeft"):
        q = motion.quats[:, motion.bone_names.index(lower)]
        # no twist about the bone's own axis (Y); a bent limb hinges about X (no Z either)
        assert np.abs(q[:, 2]).max() < 1e-9, lower
    for lower in ("WristLeft", "AnkleRight"):
        q = motion.quats[:, motion.bone_names.index(lower)]
        bent = np.abs(q[:, 1]) > np.sin(np.radians(20) / 2)
        assert bent.any() and np.abs(q[bent, 3]).max() < np.sin(np.radians(2) / 2), lower


def _assert_bones_follow(pipe, posed, p, tol_deg=1e-3):
    """Every mapped non-root bone's armature-space Y axis along its source segment (p in armature space)."""
    for m in pipe.retargeter.mapped:
        if m.is_root:
            continue
        src = normalize(p[:, m.tail] - p[:, m.head])
        err = np.degrees(np.arccos(np.clip(np.sum(src * posed[:, m.index, :3, 1], -1), -1, 1)))
        assert err.max() < tol_deg, m.bone


def _a_pose_rig(take, scale=1.3, object_matrix=None):
    """A differently proportioned target in an A-pose with rolled bones, built from generated_rig's layout."""
    lengths = median_segment_lengths(take) * scale
    rig = generated_rig(take.skeleton, lengths, "APose")
    rest = rig.rest.copy()
    # lower the arms 40° about the forward axis around each shoulder, and roll every bone by 30°
    for side, sign in (("Left", -1), ("Right", 1)):
        pivot = rest[KINECT_V1.index("Elbow" + side), :3, 3]
        a = np.radians(40) * sign
        rot = np.array([[np.cos(a), 0, -np.sin(a)], [0, 1, 0], [np.sin(a), 0, np.cos(a)]])
        for j in ("Elbow", "Wrist", "Hand"):
            b = KINECT_V1.index(j + side)
            rest[b, :3, :3] = rot @ rest[b, :3, :3]
            rest[b, :3, 3] = pivot + rot @ (rest[b, :3, 3] - pivot)
    roll = np.radians(30)
    r = np.array([[np.cos(roll), 0, np.sin(roll)], [0, 1, 0], [-np.sin(roll), 0, np.cos(roll)]])
    rest[:, :3, :3] = rest[:, :3, :3] @ r
    return TargetRig("APose", rig.bone_names, rig.parents, rest, rig.lengths,
                     np.eye(4) if object_matrix is None else object_matrix)


def test_a_pose_target_with_rolls_and_rotated_object_still_follows_directions(hop):
    c, s = np.cos(np.radians(90)), np.sin(np.radians(90))
    obj = np.array([[2 * c, -2 * s, 0, 5], [2 * s, 2 * c, 0, 1], [0, 0, 2, 0], [0, 0, 0, 1.0]])
    rig = _a_pose_rig(hop, object_matrix=obj)
    pipe = RetargetPipeline(KINECT_V1, rig, generated_mapping(KINECT_V1), RetargetSettings(filter="none"))
    motion = pipe.process_take(hop)
    # source directions are turned with the object: compare in armature space
    posed = evaluate_pose(rig, pipe.retargeter.bone_indices, motion.quats, pipe.retargeter.root.index,
                          motion.root_location)
    p = kinect_to_blender(hop.positions[motion.samples]) @ rig.object_rotation
    _assert_bones_follow(pipe, posed, p)
    # root displacement scaled by n = target leg / source leg (1.3 here), in armature space
    head = posed[:, pipe.retargeter.root.index, :3, 3]
    n = pipe.retargeter.scale_for(pipe.source_leg)
    assert n == pytest.approx(1.3, rel=1e-6)
    np.testing.assert_allclose(head - head[0], n * (p[:, 0] - p[0, 0]), atol=1e-9)


def test_same_pose_on_a_and_t_pose_rigs_gives_same_world_rotations_up_to_rest(hop):
    """Rest pose differences are absorbed: posed bone frames relative to their rest frames agree."""
    t_rig = generated_rig(KINECT_V1, median_segment_lengths(hop))
    a_rig = _a_pose_rig(hop, scale=1.0)
    out = []
    for rig in (t_rig, a_rig):
        pipe = RetargetPipeline(KINECT_V1, rig, generated_mapping(KINECT_V1), RetargetSettings(filter="none"))
        m = pipe.process_take(hop)
        posed = evaluate_pose(rig, pipe.retargeter.bone_indices, m.quats)
        out.append(posed[:, :, :3, 1])
    np.testing.assert_allclose(out[0], out[1], atol=1e-9)


def test_root_modes(hop):
    rig = generated_rig(KINECT_V1, median_segment_lengths(hop))
    for mode in ("xy", "none"):
        pipe = RetargetPipeline(KINECT_V1, rig, generated_mapping(KINECT_V1),
                                RetargetSettings(filter="none", root_mode=mode))
        loc = pipe.process_take(hop).root_location
        posed_z = loc @ rig.rest[0, :3, :3].T
        assert np.abs(posed_z[:, 2]).max() < 1e-12
        if mode == "none":
            assert np.abs(loc).max() == 0


def test_timing_contract_and_untracked_frames_not_keyed(wave):
    take = wave.slice(slice(0, 60))
    take.states[10:15] = 0  # nothing tracked for five samples
    rig = generated_rig(take.skeleton, median_segment_lengths(take))
    pipe = RetargetPipeline(take.skeleton, rig, generated_mapping(take.skeleton),
                            RetargetSettings(filter="default", fps=24, frame_start=101))
    m = pipe.process_take(take)
    expected = 101 + np.round((take.times - take.times[0]) * 24).astype(int)
    keep = np.ones(60, bool)
    keep[10:15] = False
    exp = expected[keep]
    exp = exp[np.concatenate([[True], np.diff(exp) > 0])]
    np.testing.assert_array_equal(m.frames, exp)
    assert not set(range(10, 15)) & set(m.samples.tolist())


def test_live_frames_equal_bake(wave):
    rig = generated_rig(wave.skeleton, median_segment_lengths(wave))
    settings = RetargetSettings(filter="default")
    bake = RetargetPipeline(wave.skeleton, rig, generated_mapping(wave.skeleton), settings)
    m = bake.process_take(wave)
    live = RetargetPipeline(wave.skeleton, rig, generated_mapping(wave.skeleton), settings)
    live.source_leg = bake.source_leg
    live.reset(wave.rate)
    poses = [live.process_frame(wave.positions[i], wave.states[i], wave.times[i]) for i in range(wave.frame_count)]
    got = np.array([poses[i].quats for i in m.samples])
    assert_quat_equal(got, m.quats, atol=1e-12)
    np.testing.assert_allclose([poses[i].root_location for i in m.samples], m.root_location, atol=1e-12)


def test_mirror_swaps_sides(hop):
    rig = generated_rig(KINECT_V1, median_segment_lengths(hop))
    plain = RetargetPipeline(KINECT_V1, rig, generated_mapping(KINECT_V1), RetargetSettings(filter="none"))
    mirrored = RetargetPipeline(KINECT_V1, rig, generated_mapping(KINECT_V1),
                                RetargetSettings(filter="none", mirror=True))
    a, b = plain.process_take(hop), mirrored.process_take(hop)
    pa = evaluate_pose(rig, plain.retargeter.bone_indices, a.quats)
    pb = evaluate_pose(rig, mirrored.retargeter.bone_indices, b.quats)
    left, right = KINECT_V1.index("ElbowLeft"), KINECT_V1.index("ElbowRight")
    flip = np.array([-1.0, 1, 1])
    np.testing.assert_allclose(pb[:, left, :3, 1], pa[:, right, :3, 1] * flip, atol=1e-9)


def test_mapping_typos_are_reported():
    from kinect_retarget.core.presets import mapping_problems
    problems = mapping_problems(["upper_arm.L", "forearm.L"], {"upper_arm.L": "ElbowLeftt", "hand.X": "HandLeft",
                                                               "forearm.L": "ElbowLeft>WristLeft"})
    assert problems == ["mapping 'upper_arm.L' -> 'ElbowLeftt': no Kinect joint has that name",
                        "mapping names bone 'hand.X', which the armature does not have"]


def test_presets_detect_and_override():
    assert detect_preset(list(RIGIFY_METARIG)) == "rigify-metarig"
    assert detect_preset(list(MAKEHUMAN) + ["toe1-1.L"]) == "makehuman"
    with pytest.raises(ValueError, match=r"no bone-mapping preset fits this armature \(found at most 0 known"):
        detect_preset(["Bone", "Bone.001"])
    used, mapping = build_mapping("auto", list(RIGIFY_METARIG), {"spine.006": "", "custom": "HandLeft"})
    assert used == "rigify-metarig" and "spine.006" not in mapping and mapping["custom"] == "HandLeft"


def test_wrong_armature_is_a_clear_error(hop):
    rig = TargetRig("Chair", ("Leg", "Seat"), [-1, 0], np.tile(np.eye(4), (2, 1, 1)), [1.0, 1.0])
    with pytest.raises(ValueError, match="no bone of armature 'Chair' is mapped"):
        RetargetPipeline(KINECT_V1, rig, generated_mapping(KINECT_V1))


def test_unmapped_bones_and_inherit_rotation_flags(hop):
    """Unmapped bones in the chain stay at rest; bones that do not inherit rotation are solved too."""
    rig = generated_rig(KINECT_V1, median_segment_lengths(hop))
    mapping = generated_mapping(KINECT_V1)
    del mapping["ElbowLeft"]  # the upper arm stays at rest between shoulder and forearm
    inherit = np.ones(len(rig.bone_names), bool)
    inherit[KINECT_V1.index("ShoulderRight")] = False   # a mapped bone that ignores its parent's rotation
    inherit[KINECT_V1.index("ElbowLeft")] = False       # an unmapped one in the middle of a chain
    rig = TargetRig("Flags", rig.bone_names, rig.parents, rig.rest, rig.lengths, inherit_rotation=inherit)
    pipe = RetargetPipeline(KINECT_V1, rig, mapping, RetargetSettings(filter="none"))
    motion = pipe.process_take(hop)
    posed = evaluate_pose(rig, pipe.retargeter.bone_indices, motion.quats)
    _assert_bones_follow(pipe, posed, kinect_to_blender(hop.positions[motion.samples]))
    elbow = KINECT_V1.index("ElbowLeft")
    np.testing.assert_allclose(posed[:, elbow, :3, :3], np.broadcast_to(rig.rest[elbow, :3, :3], (len(posed), 3, 3)),
                               atol=1e-12)


def test_joints_without_positions_never_reach_the_keys(data_dir):
    """UI-PRMD has no hand joints (NaN, untracked): their bones are left alone, nothing NaN is keyed, live too."""
    take = load_take(data_dir / "kinect_v2_vicon_uiprmd" / "Kinect" / "m07_s01_e01_positions.txt")
    assert np.isnan(take.positions).any()
    rig = generated_rig(take.skeleton, median_segment_lengths(take))
    for flt in ("none", "default"):
        pipe = RetargetPipeline(take.skeleton, rig, generated_mapping(take.skeleton), RetargetSettings(filter=flt))
        m = pipe.process_take(take)
        assert np.isfinite(m.quats).all() and np.isfinite(m.root_location).all()
        assert set(m.extras["skipped_bones"]) == {"HandLeft", "HandRight", "HandTipLeft", "HandTipRight",
                                                  "ThumbLeft", "ThumbRight"}
        assert "ElbowLeft" in m.bone_names
        pipe.reset(take.rate)
        poses = [pipe.process_frame(take.positions[i], take.states[i], take.times[i]) for i in range(10)]
        assert all(np.isfinite(p.quats).all() for p in poses)
