"""The scene is the user's: a bake leaves its frame rate and range alone unless asked, and the bake options
(take range, key step, key reduction, current Action, NLA strip) do what they say, in Blender itself."""
import numpy as np
import pytest

from kinect_retarget.core.bake_options import BakeOptions
from kinect_retarget.core.pipeline import RetargetSettings
from kinect_retarget.core.quat import angle_between
from kinect_retarget.takes import load_take

TAKE = "sample_takes/kinect_v2_ges05_demopoint.krtake"  # 30 fps, 192 frames


def _rig(bpy):
    from kinect_retarget.blender.bake_take import new_generated_rig
    take = load_take(TAKE)
    scene = bpy.context.scene
    scene.render.fps, scene.render.fps_base = 24, 1.0
    scene.frame_start, scene.frame_end = 1, 250
    return new_generated_rig(scene, take), take


def _bake(obj, take, **options):
    from kinect_retarget.blender.bake_take import bake_take
    messages = []
    res = bake_take(obj, take, preset="kinect", settings=RetargetSettings(filter="none"),
                    options=BakeOptions(**options), report=lambda level, msg: messages.append(msg))
    return res, messages[-1]


def _keys(obj, bone="ElbowLeft", action=None):
    from bpy_extras import anim_utils
    ad = obj.animation_data
    cb = anim_utils.action_get_channelbag_for_slot(action or ad.action, ad.action_slot) if action else \
        anim_utils.animdata_get_channelbag_for_assigned_slot(ad)
    fc = cb.fcurves.find(f'pose.bones["{bone}"].rotation_quaternion', index=0)
    co = np.empty(2 * len(fc.keyframe_points), dtype=np.float32)
    fc.keyframe_points.foreach_get("co", co)
    return co[0::2]


def _pose_quats(bpy, obj, frames, bone="ElbowLeft"):
    out = []
    for f in frames:
        bpy.context.scene.frame_set(int(f))
        out.append(np.array(obj.pose.bones[bone].rotation_quaternion))
    return np.array(out)


def test_default_bake_leaves_scene_rate_and_range_and_resamples(bpy_empty):
    bpy = bpy_empty
    obj, take = _rig(bpy)
    res, msg = _bake(obj, take)
    scene = bpy.context.scene
    assert (scene.render.fps, scene.render.fps_base, scene.frame_start, scene.frame_end) == (24, 1.0, 1, 250)
    # 191 intervals of 1/30 s = 6.37 s -> 153 keys at 24 fps: the take plays at its own speed
    assert res.motion.fps == 24.0 and res.frame_range == (1, 154)
    np.testing.assert_array_equal(_keys(obj), np.arange(1, 155))
    assert "scene unchanged (24 fps, frames 1-250)" in msg and "frames 1-154" in msg
    # the same bake at the take's rate: frame 1 + 24 k (second k) holds what take frame 30 k held
    ref_obj, _ = _rig(bpy)
    ref, _ = _bake(ref_obj, take, set_scene_fps=True)
    assert bpy.context.scene.render.fps == 30 and ref.frame_range == (1, 192)
    k = np.arange(1, 7)
    scene.render.fps = 24
    a = _pose_quats(bpy, obj, 1 + 24 * k)
    scene.render.fps = 30
    b = _pose_quats(bpy, ref_obj, 1 + 30 * k)
    assert np.degrees(angle_between(a, b)).max() < 0.01  # the take's clock jitters by well under a frame


def test_extend_scene_range_grows_but_never_shortens(bpy_empty):
    bpy = bpy_empty
    obj, take = _rig(bpy)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 10, 50
    res, msg = _bake(obj, take, extend_scene_range=True)
    assert (scene.frame_start, scene.frame_end) == (1, 154) and "range set" in msg
    scene.frame_start, scene.frame_end = 0, 400
    _bake(obj, take, extend_scene_range=True)
    assert (scene.frame_start, scene.frame_end) == (0, 400)
    assert scene.render.fps == 24


def test_take_range_step_and_start_frame(bpy_empty):
    from kinect_retarget.blender.bake_take import bake_take
    bpy = bpy_empty
    obj, take = _rig(bpy)
    res = bake_take(obj, take, preset="kinect", settings=RetargetSettings(filter="none", frame_start=101),
                    options=BakeOptions(range_start=60, range_end=119, range_unit="frames", step=2))
    # take frames 60-119 = 59/30 s -> 47.2 frames at 24 fps, keyed every 2nd frame from 101; the last key
    # rounds to the nearest step (offset 48) and holds the range's last sample
    np.testing.assert_array_equal(_keys(obj), np.arange(101, 150, 2))
    assert res.motion.samples[0] == 0  # samples count from the range's start
    part, _ = _bake(obj, take, range_start=2.0, range_end=3.0)
    assert part.frame_range == (1, 25)


def test_key_reduction_within_tolerance_in_blender(bpy_empty):
    bpy = bpy_empty
    obj, take = _rig(bpy)
    full, _ = _bake(obj, take)
    want = _pose_quats(bpy, obj, full.motion.frames)
    res, msg = _bake(obj, take, reduce=True, tolerance_deg=0.5, tolerance_mm=1.0)
    assert res.reduction.removed > 0 and "key reduction removed" in msg
    assert len(_keys(obj)) < len(full.motion.frames)
    got = _pose_quats(bpy, obj, full.motion.frames)
    err = np.degrees(angle_between(got, want))
    assert err.max() <= 0.5 + 1e-3 and res.reduction.max_deg <= 0.5 + 1e-9


def test_into_current_action_keeps_keys_outside_the_range(bpy_empty):
    bpy = bpy_empty
    obj, take = _rig(bpy)
    first, _ = _bake(obj, take)
    action = obj.animation_data.action
    res, _ = _bake(obj, take, into_current=True, range_start=0.0, range_end=1.0)
    assert res.action == action and obj.animation_data.action == action and len(bpy.data.actions) == 1
    frames = _keys(obj)
    np.testing.assert_array_equal(frames, np.arange(1, 155))  # keys 1-25 replaced, 26-154 kept, in order


def test_push_to_nla_strip_named_after_the_take(bpy_empty):
    bpy = bpy_empty
    obj, take = _rig(bpy)
    take.metadata["name"] = "demopoint"
    res, msg = _bake(obj, take, push_nla=True)
    ad = obj.animation_data
    assert ad.action is None and res.strip == "demopoint" and "NLA strip 'demopoint'" in msg
    strip = ad.nla_tracks[-1].strips[0]
    assert strip.name == "demopoint" and strip.action == res.action and strip.frame_start == 1
    bpy.context.scene.frame_set(40)  # the strip drives the rig
    want = res.motion.quats[39, res.motion.bone_names.index("ElbowLeft")]
    assert np.degrees(angle_between(np.array(obj.pose.bones["ElbowLeft"].rotation_quaternion), want)) < 1e-3


def test_operator_defaults_leave_scene_alone_and_options_reach_the_bake(registered):
    bpy = registered
    obj, _ = _rig(bpy)
    bpy.context.view_layer.objects.active = obj
    assert bpy.ops.kinect_retarget.bake_take(filepath=TAKE, preset="kinect") == {"FINISHED"}
    scene = bpy.context.scene
    assert (scene.render.fps, scene.frame_start, scene.frame_end) == (24, 1, 250)
    assert bpy.ops.kinect_retarget.bake_take(filepath=TAKE, preset="kinect", set_scene_fps=True,
                                             extend_scene_range=True, key_step=3,
                                             destination="NLA") == {"FINISHED"}
    assert scene.render.fps == 30 and scene.frame_end == 250
    assert obj.animation_data.action is None and len(obj.animation_data.nla_tracks) == 1
    with pytest.raises(RuntimeError, match="holds no sample"):
        bpy.ops.kinect_retarget.bake_take(filepath=TAKE, preset="kinect", use_take_range=True,
                                          range_start=50.0, range_end=60.0)


def test_cli_leaves_the_rig_files_scene_alone_and_takes_the_options(bpy_empty, tmp_path):
    import json
    import subprocess
    import sys
    bpy = bpy_empty
    _rig(bpy)  # a 24 fps scene, frames 1-250
    rig = tmp_path / "rig.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(rig))
    out = tmp_path / "out.blend"
    r = subprocess.run([sys.executable, "-m", "kinect_retarget", "bake", TAKE, "--rig", str(rig), "--out", str(out),
                        "--take-start", "1", "--take-end", "3", "--frame-start", "10", "--step", "2", "--reduce",
                        "--tolerance-deg", "1", "--tolerance-mm", "2", "--nla"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    result = json.loads(r.stdout.strip().splitlines()[-1])
    assert result["frame_range"] == [10, 58] and result["keys_removed"] > 0 and result["max_error_deg"] <= 1.0
    assert result["nla_strip"] == "kinect_v2_ges05_demopoint"
    bpy.ops.wm.open_mainfile(filepath=str(out))
    scene = bpy.context.scene
    assert (scene.render.fps, scene.frame_start, scene.frame_end) == (24, 1, 250)
    obj = bpy.data.objects["KinectRig"]
    assert obj.animation_data.action is None and obj.animation_data.nla_tracks[0].strips[0].frame_start == 10
    r = subprocess.run([sys.executable, "-m", "kinect_retarget", "bake", TAKE, "--rig", str(rig), "--out", str(out),
                        "--set-scene-fps", "--extend-range"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    bpy.ops.wm.open_mainfile(filepath=str(out))
    assert (bpy.context.scene.render.fps, bpy.context.scene.frame_end) == (30, 250)  # 192 frames fit: not shortened
    r = subprocess.run([sys.executable, "-m", "kinect_retarget", "bake", TAKE, "--out", str(out), "--step", "0"],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "key step" in r.stderr
