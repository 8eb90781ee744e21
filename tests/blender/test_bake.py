"""Round trips through Blender itself: bake a real take, evaluate the rig at keyed frames, compare bones."""
import subprocess
import sys

import numpy as np
import pytest

from kinect_retarget.core.conventions import kinect_to_blender
from kinect_retarget.core.bake_options import BakeOptions
from kinect_retarget.core.pipeline import RetargetSettings
from kinect_retarget.takes import load_take

SOLVER_ONLY = BakeOptions(feet="off")  # the solver's own directions: planted feet would bend the legs


def _bone_world_dir(obj, pb):
    d = np.array(obj.matrix_world @ pb.tail) - np.array(obj.matrix_world @ pb.head)
    return d / np.linalg.norm(d)


def _check_directions(bpy, obj, motion, take, pairs, every=1):
    scene = bpy.context.scene
    p = kinect_to_blender(take.positions[motion.samples])
    sk = take.skeleton
    errs = []
    for i in range(0, len(motion.frames), every):
        scene.frame_set(int(motion.frames[i]))
        for bone, (a, b) in pairs.items():
            src = p[i, sk.index(b)] - p[i, sk.index(a)]
            src /= np.linalg.norm(src)
            errs.append(np.degrees(np.arccos(np.clip(_bone_world_dir(obj, obj.pose.bones[bone]) @ src, -1, 1))))
    return np.array(errs)


@pytest.mark.parametrize("take_path", ["kinect_v2/Ges02_balancinghands.csv", "mocap_bvh/131_01.bvh"])
def test_generated_rig_round_trip(bpy_empty, data_dir, take_path):
    from kinect_retarget.blender.bake_take import bake_take, new_generated_rig
    bpy = bpy_empty
    take = load_take(data_dir / take_path)
    if take.frame_count > 300:
        take = take.slice(slice(0, 300))
    obj = new_generated_rig(bpy.context.scene, take)
    res = bake_take(obj, take, preset="kinect",
                   settings=RetargetSettings(filter="none", fps=take.rate),  # keys on the take's samples
                   options=SOLVER_ONLY)
    sk = take.skeleton
    pairs = {j: (sk.joints[sk.parents[i]], j) for i, j in enumerate(sk.joints) if sk.parents[i] >= 0}
    errs = _check_directions(bpy, obj, res.motion, take, pairs)
    assert errs.mean() < 0.05 and errs.max() < 0.5
    # the Action uses a slot and a channelbag (Blender 5.0 layered actions)
    ad = obj.animation_data
    assert ad.action_slot is not None and not hasattr(ad.action, "fcurves")
    from bpy_extras import anim_utils
    cb = anim_utils.animdata_get_channelbag_for_assigned_slot(ad)
    assert len(cb.fcurves) == 4 * len(sk) + 3
    assert len(cb.fcurves[0].keyframe_points) == len(res.motion.frames)
    # root head follows the root joint's displacement (n = 1)
    root = obj.pose.bones[sk.joints[sk.root]]
    heads = []
    for f in res.motion.frames[::10]:
        bpy.context.scene.frame_set(int(f))
        heads.append(np.array(obj.matrix_world @ root.head))
    heads = np.array(heads)
    src = kinect_to_blender(take.positions[res.motion.samples[::10], sk.root])
    np.testing.assert_allclose(heads - heads[0], src - src[0], atol=1e-4)


def test_rig_is_not_edited(bpy_empty, data_dir):
    from kinect_retarget.blender.bake_take import bake_take, new_generated_rig
    bpy = bpy_empty
    take = load_take(data_dir / "kinect_v2" / "Ges04_comehere.csv")
    obj = new_generated_rig(bpy.context.scene, take)
    before = [(b.name, tuple(map(tuple, b.matrix_local)), b.use_inherit_rotation, b.parent and b.parent.name)
              for b in obj.data.bones]
    bake_take(obj, take, preset="kinect")
    after = [(b.name, tuple(map(tuple, b.matrix_local)), b.use_inherit_rotation, b.parent and b.parent.name)
             for b in obj.data.bones]
    assert before == after


def test_rigify_generated_rig_limbs_follow(data_dir, rigify_rig_path):
    import bpy
    from kinect_retarget.blender.bake_take import bake_take
    bpy.ops.wm.open_mainfile(filepath=str(rigify_rig_path))
    obj = bpy.data.objects["rig"]
    take = load_take(data_dir / "kinect_v2" / "Ges01_wavehand.csv").slice(slice(0, 40))
    res = bake_take(obj, take, preset="auto",
                   settings=RetargetSettings(filter="none", fps=take.rate))  # keys on the take's samples
    assert res.preset == "rigify"
    pairs = {f"DEF-{b}.{s[0]}": (f"{a}{s}", f"{c}{s}") for s in ("Left", "Right") for b, a, c in
             (("upper_arm", "Shoulder", "Elbow"), ("forearm", "Elbow", "Wrist"), ("thigh", "Hip", "Knee"),
              ("shin", "Knee", "Ankle"))}
    errs = _check_directions(bpy, obj, res.motion, take, pairs, every=3)
    assert errs.mean() < 2.0
    # the trunk follows the performer's spine too (Rigify's torso/chest controls rest horizontal)
    spine = {"DEF-spine.001": ("SpineBase", "SpineMid"), "DEF-spine.003": ("SpineMid", "SpineShoulder")}
    assert _check_directions(bpy, obj, res.motion, take, spine, every=3).max() < 10.0
    # switched to FK in the action, rig structure untouched
    assert obj.pose.bones["upper_arm_parent.L"]["IK_FK"] == pytest.approx(1.0)
    bpy.ops.wm.read_factory_settings(use_empty=True)


def test_operator_bakes_onto_active_armature(registered, data_dir):
    from kinect_retarget.blender.bake_take import new_generated_rig
    bpy = registered
    take_path = data_dir / "kinect_v2" / "Ges05_demopoint.csv"
    obj = new_generated_rig(bpy.context.scene, load_take(take_path))
    bpy.context.view_layer.objects.active = obj
    result = bpy.ops.kinect_retarget.bake_take(filepath=str(take_path), preset="kinect", fps=24.0)
    assert result == {"FINISHED"}
    assert obj.animation_data.action is not None
    assert bpy.context.scene.render.fps == 24


def test_operator_reports_bad_file_and_leaves_scene(registered, tmp_path):
    from kinect_retarget.blender.bake_take import new_generated_rig
    from kinect_retarget.core.skeletons import KINECT_V1
    bpy = registered
    bad = tmp_path / "broken.csv"
    bad.write_text("hello,world\n1,2\n")
    obj = new_generated_rig(bpy.context.scene, _tiny_take(KINECT_V1))
    bpy.context.view_layer.objects.active = obj
    with pytest.raises(RuntimeError, match="broken.csv"):
        bpy.ops.kinect_retarget.bake_take(filepath=str(bad))
    assert obj.animation_data is None and len(bpy.data.actions) == 0


def test_operator_refuses_non_armature(registered):
    bpy = registered
    mesh = bpy.data.objects.new("Cube", bpy.data.meshes.new("Cube"))
    bpy.context.scene.collection.objects.link(mesh)
    bpy.context.view_layer.objects.active = mesh
    assert not bpy.ops.kinect_retarget.bake_take.poll()


def _tiny_take(skeleton):
    from kinect_retarget.core.kinect_rig_layout import rest_joint_positions
    from kinect_retarget.core.conventions import blender_to_kinect
    from kinect_retarget.core.take import Take
    pos = blender_to_kinect(rest_joint_positions(skeleton, np.full(len(skeleton), 0.3)))
    return Take(skeleton, np.repeat(pos[None], 3, 0), np.full((3, len(skeleton)), 2), np.arange(3) / 30, 30.0)


def test_cli_bake_and_info(data_dir, tmp_path):
    take = data_dir / "mocap_bvh" / "131_03.bvh"
    out = tmp_path / "hop.blend"
    info = subprocess.run([sys.executable, "-m", "kinect_retarget", "info", str(take), "--json"],
                          capture_output=True, text=True, check=True)
    assert '"frames": 1102' in info.stdout and '"skeleton": "kinect_v1"' in info.stdout
    r = subprocess.run([sys.executable, "-m", "kinect_retarget", "bake", str(take), "--out", str(out),
                        "--fps", "30", "--filter", "none"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert out.is_file() and '"preset": "kinect"' in r.stdout
    bad = subprocess.run([sys.executable, "-m", "kinect_retarget", "info", str(tmp_path / "missing.csv")],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and "missing.csv" in bad.stderr


def test_rigify_metarig_preset(bpy_empty, data_dir):
    import addon_utils
    from kinect_retarget.blender.bake_take import bake_take
    bpy = bpy_empty
    addon_utils.enable("rigify", default_set=True)
    bpy.ops.object.armature_human_metarig_add()
    obj = bpy.context.object
    take = load_take(data_dir / "mocap_bvh" / "01_01.bvh").slice(slice(0, 480, 4))
    res = bake_take(obj, take, preset="auto",
                   settings=RetargetSettings(filter="none", fps=take.rate),  # keys on the take's samples
                   options=SOLVER_ONLY)
    assert res.preset == "rigify-metarig" and res.motion.root_bone == "spine"
    pairs = {f"{b}.{s[0]}": (f"{a}{s}", f"{c}{s}") for s in ("Left", "Right") for b, a, c in
             (("upper_arm", "Shoulder", "Elbow"), ("forearm", "Elbow", "Wrist"), ("thigh", "Hip", "Knee"),
              ("shin", "Knee", "Ankle"), ("foot", "Ankle", "Foot"))}
    errs = _check_directions(bpy, obj, res.motion, take, pairs, every=5)
    assert errs.max() < 0.5


def test_cli_mapping_override_unmaps_bones(data_dir, tmp_path):
    import json
    mapping = tmp_path / "map.json"
    mapping.write_text(json.dumps({"ElbowLeft": "", "WristLeft": None}))
    out = tmp_path / "wave.blend"
    take = data_dir / "kinect_v2" / "Ges01_wavehand.csv"
    r = subprocess.run([sys.executable, "-m", "kinect_retarget", "bake", str(take), "--out", str(out),
                        "--mapping", str(mapping)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert '"bones": 23' in r.stdout  # 25 Kinect v2 bones less the two unmapped ones
    bad = tmp_path / "bad.json"
    bad.write_text("[1, 2]")
    r = subprocess.run([sys.executable, "-m", "kinect_retarget", "bake", str(take), "--out", str(out),
                        "--mapping", str(bad)], capture_output=True, text=True)
    assert r.returncode == 2 and "bad.json" in r.stderr


def test_baking_again_keeps_the_previous_action_in_the_file(bpy_empty, data_dir, tmp_path):
    from kinect_retarget.blender.bake_take import bake_take, new_generated_rig
    bpy = bpy_empty
    take = load_take(data_dir / "kinect_v2" / "Ges02_balancinghands.csv")
    obj = new_generated_rig(bpy.context.scene, take)
    first = bake_take(obj, take, preset="kinect", action_name="first").action
    bake_take(obj, take, preset="kinect", action_name="second")
    path = tmp_path / "two.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.open_mainfile(filepath=str(path))
    assert {"first", "second"} <= set(bpy.data.actions.keys())
    assert first is not None


def test_euler_and_axis_angle_bones_are_keyed_in_their_own_channels(bpy_empty, data_dir):
    """The rig's rotation modes are kept; Blender's evaluation of Euler/axis-angle keys matches the take."""
    from kinect_retarget.blender.bake_take import bake_take, new_generated_rig
    bpy = bpy_empty
    take = load_take(data_dir / "kinect_v2" / "Ges06_chickenwing.csv")
    obj = new_generated_rig(bpy.context.scene, take)
    modes = {"ElbowLeft": "ZXY", "WristLeft": "XYZ", "ElbowRight": "AXIS_ANGLE", "KneeLeft": "YZX"}
    for bone, mode in modes.items():
        obj.pose.bones[bone].rotation_mode = mode
    res = bake_take(obj, take, preset="kinect",
                   settings=RetargetSettings(filter="none", fps=take.rate),  # keys on the take's samples
                   options=SOLVER_ONLY)
    assert all(obj.pose.bones[b].rotation_mode == m for b, m in modes.items())
    from bpy_extras import anim_utils
    paths = {fc.data_path for fc in anim_utils.animdata_get_channelbag_for_assigned_slot(obj.animation_data).fcurves}
    assert 'pose.bones["ElbowLeft"].rotation_euler' in paths and 'pose.bones["ElbowRight"].rotation_axis_angle' in paths
    sk = take.skeleton
    pairs = {b: (sk.joints[sk.parents[sk.index(b)]], b) for b in list(modes) + ["HandLeft", "AnkleLeft"]}
    errs = _check_directions(bpy, obj, res.motion, take, pairs, every=4)
    assert errs.max() < 0.5


def test_cli_rig_errors_and_visible_armature(bpy_empty, data_dir, tmp_path):
    from kinect_retarget.blender.bake_take import new_generated_rig
    bpy = bpy_empty
    take_path = data_dir / "kinect_v2" / "Ges04_comehere.csv"
    take = load_take(take_path)
    keep = new_generated_rig(bpy.context.scene, take, name="Visible")
    hidden = new_generated_rig(bpy.context.scene, take, name="Hidden")
    hidden.hide_set(True)
    rig = tmp_path / "two.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(rig))
    out = tmp_path / "out.blend"
    r = subprocess.run([sys.executable, "-m", "kinect_retarget", "bake", str(take_path), "--rig", str(rig),
                        "--out", str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert '"armature": "Visible"' in r.stdout and keep.name == "Visible"
    junk = tmp_path / "junk.blend"
    junk.write_text("not a blend file")
    r = subprocess.run([sys.executable, "-m", "kinect_retarget", "bake", str(take_path), "--rig", str(junk),
                        "--out", str(out)], capture_output=True, text=True)
    assert r.returncode == 2 and "junk.blend: not a readable .blend file" in r.stderr
    assert "Traceback" not in r.stderr
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "no_rig.blend"))
    r = subprocess.run([sys.executable, "-m", "kinect_retarget", "bake", str(take_path), "--rig",
                        str(tmp_path / "no_rig.blend"), "--out", str(out)], capture_output=True, text=True)
    assert r.returncode == 2 and "no armature in the file" in r.stderr and "--armature" not in r.stderr


def test_operator_uses_the_sidebar_target_and_mapping_table(registered, data_dir):
    from kinect_retarget.blender.bake_take import new_generated_rig
    bpy = registered
    take_path = data_dir / "kinect_v2" / "Ges05_demopoint.csv"
    take = load_take(take_path)
    target = new_generated_rig(bpy.context.scene, take, name="Target")
    other = new_generated_rig(bpy.context.scene, take, name="Other")
    bpy.context.view_layer.objects.active = other
    s = bpy.context.scene.kinect_retarget
    s.armature = target
    row = s.mapping.add()
    row.bone, row.joint, row.enabled = "ElbowLeft", "ElbowLeft", False  # unmapped in the table
    assert bpy.ops.kinect_retarget.bake_take(filepath=str(take_path), preset="kinect") == {"FINISHED"}
    assert other.animation_data is None and target.animation_data.action is not None
    from bpy_extras import anim_utils
    paths = {fc.data_path for fc in anim_utils.animdata_get_channelbag_for_assigned_slot(target.animation_data).fcurves}
    assert 'pose.bones["ElbowLeft"].rotation_quaternion' not in paths
    assert 'pose.bones["WristLeft"].rotation_quaternion' in paths


def test_root_scale_from_the_operator_and_the_cli(registered, data_dir, tmp_path):
    """Paper 000 eq. 13's n: 0 = auto (1 on a generated rig); 2 doubles the root's travel. The CLI takes a
    number or 'auto' and refuses anything else before Blender starts."""
    from kinect_retarget.blender.bake_take import new_generated_rig
    from kinect_retarget.cli import main
    bpy = registered
    take_path = data_dir / "kinect_v2" / "Ges05_demopoint.csv"
    travel = {}
    for n in (0.0, 2.0):
        bpy.ops.wm.read_factory_settings(use_empty=True)
        obj = new_generated_rig(bpy.context.scene, load_take(take_path))
        bpy.context.view_layer.objects.active = obj
        assert bpy.ops.kinect_retarget.bake_take(filepath=str(take_path), preset="kinect", filter="none",
                                                 root_scale=n, feet="off") == {"FINISHED"}  # no height shift
        curves = [fc for fc in obj.animation_data.action.layers[0].strips[0].channelbags[0].fcurves
                  if fc.data_path.endswith(".location")]
        travel[n] = np.array([[k.co[1] for k in fc.keyframe_points] for fc in curves])
    np.testing.assert_allclose(travel[2.0], 2 * travel[0.0], atol=1e-5)
    assert np.abs(travel[0.0]).max() > 0.01
    with pytest.raises(SystemExit) as stop:  # argparse's usage error
        main(["bake", str(take_path), "--out", str(tmp_path / "o.blend"), "--root-scale", "-1"])
    assert stop.value.code == 2
    assert not (tmp_path / "o.blend").exists()
