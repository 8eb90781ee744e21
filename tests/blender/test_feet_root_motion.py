"""Feet and root motion in Blender (issue 16): an Unreal-Mannequin-named armature built from its bone list,
a hopping take baked with root motion (the world pose equals the in-place bake, the root bone travels) and
with the feet locked (Blender's own evaluation keeps a planted ankle in place and above its rest height);
the CLI's --feet and --root-motion."""
import json
import subprocess
import sys

import numpy as np
import pytest

from kinect_retarget.core.bake_options import BakeOptions
from kinect_retarget.core.foot_contacts import intervals
from kinect_retarget.core.pipeline import RetargetSettings
from kinect_retarget.takes import load_take
from tests.conftest import SAMPLE_TAKES
from tests.rigs.humanoid_rigs import build
from tests.rigs.layouts import LAYOUTS

HOP = SAMPLE_TAKES / "kinect_v1_cmu_131_03_hop.krtake"


def _armature(bpy, name="UE4"):
    from kinect_retarget.blender.mesh_autorig import armature_edit
    rig = build(LAYOUTS["ue4-mannequin"], a_pose_deg=30)
    arm = bpy.data.armatures.new(name)
    obj = bpy.data.objects.new(name, arm)
    bpy.context.scene.collection.objects.link(obj)
    with armature_edit(bpy.context, obj) as data:
        for n, h, t in zip(rig.names, rig.heads, rig.tails):
            b = data.edit_bones.new(n)
            b.head, b.tail = h.tolist(), t.tolist()
        for n, p in zip(rig.names, rig.parents):
            if p >= 0:
                data.edit_bones[n].parent = data.edit_bones[rig.names[p]]
    return obj


def _world(bpy, obj, frames):
    out = []
    for f in frames:
        bpy.context.scene.frame_set(int(f))
        out.append([np.array(obj.matrix_world @ pb.matrix) for pb in obj.pose.bones])
    return np.array(out)


def test_root_motion_and_locked_feet_as_blender_evaluates_them(bpy_empty):
    from kinect_retarget.blender.bake_take import bake_take
    bpy = bpy_empty
    obj = _armature(bpy)
    take = load_take(HOP)
    settings = RetargetSettings(fps=take.rate)
    plain = bake_take(obj, take, settings=settings, options=BakeOptions(feet="off"))
    assert plain.preset == "ue4-mannequin"
    frames = plain.motion.frames[::15]
    in_place = _world(bpy, obj, frames)
    moved = bake_take(obj, take, settings=settings, options=BakeOptions(feet="off", root_motion=True))
    travel = _world(bpy, obj, frames)
    root = obj.pose.bones.find("root")
    others = [i for i in range(len(obj.pose.bones)) if i != root]
    np.testing.assert_allclose(travel[:, others], in_place[:, others], atol=2e-5)  # the same pose in the world
    assert np.linalg.norm(travel[-1, root, :2, 3] - travel[0, root, :2, 3]) > 0.3    # the root travels
    np.testing.assert_allclose(travel[:, root, 2, 3], 0.0, atol=1e-6)                # on the floor
    assert list(moved.motion.extras["locations"]) == ["root"]
    locked = bake_take(obj, take, settings=settings)  # feet lock by default
    assert locked.feet is not None and locked.feet.mode == "lock"
    leg = next(g for g in locked.feet.legs if g.side == "Left")
    foot = obj.pose.bones.find("foot_l")
    rest_height = obj.data.bones["foot_l"].head_local[2]
    for a, b in intervals(leg.contact)[:2]:
        ankle = _world(bpy, obj, locked.motion.frames[a:b + 1])[:, foot, :3, 3]
        assert np.linalg.norm(ankle[:, :2] - ankle[:, :2].mean(axis=0), axis=-1).max() < 0.01
        assert ankle[:, 2].min() >= rest_height - 1e-4


def test_cli_bake_with_feet_and_root_motion(bpy_empty, tmp_path):
    bpy = bpy_empty
    _armature(bpy)
    rig_path = tmp_path / "ue4.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(rig_path))
    out = tmp_path / "out.blend"
    r = subprocess.run([sys.executable, "-m", "kinect_retarget", "bake", str(HOP), "--rig", str(rig_path), "--out",
                        str(out), "--feet", "floor", "--root-motion-facing", "--take-end", "2"],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    summary = json.loads(r.stdout.strip().splitlines()[-1])
    text = json.dumps(summary)
    assert "feet (floor" in text and "root motion on 'root' with facing" in text
    bad = subprocess.run([sys.executable, "-m", "kinect_retarget", "bake", str(HOP), "--out", str(tmp_path / "x.blend"),
                          "--root-motion"], capture_output=True, text=True, timeout=300)
    assert bad.returncode != 0 and "root bone above the hips" in bad.stderr  # the generated rig has none


def _pose_errors(a, b):
    """Largest position (m) and rotation (degrees) difference between stacks of 4x4 matrices."""
    ra, rb = a[..., :3, :3], b[..., :3, :3]
    ra, rb = ra / np.linalg.norm(ra, axis=-2, keepdims=True), rb / np.linalg.norm(rb, axis=-2, keepdims=True)
    rel = np.swapaxes(ra, -1, -2).astype(np.float64) @ rb
    cos = (np.trace(rel, axis1=-2, axis2=-1) - 1) / 2      # arccos alone loses float32 matrices' small angles
    sin = np.linalg.norm(rel - np.swapaxes(rel, -1, -2), axis=(-2, -1)) / (2 * np.sqrt(2))
    return float(np.abs(a[..., :3, 3] - b[..., :3, 3]).max()), float(np.degrees(np.arctan2(sin, cos)).max())


def test_root_motion_on_rigify_keys_root_and_keeps_the_world_pose(rigify_rig_path):
    """Rigify's torso follows root through MCH-torso.parent's Armature constraint: root carries the travel
    (and facing), torso is keyed so that every bone's world pose, as Blender evaluates the user's rig, is
    the in-place bake's; an arm that follows the root part way is turned back too."""
    import bpy

    from kinect_retarget.blender.bake_take import bake_take
    bpy.ops.wm.open_mainfile(filepath=str(rigify_rig_path))
    obj = bpy.data.objects["rig"]
    obj.pose.bones["upper_arm_parent.L"]["FK_limb_follow"] = 0.4
    take = load_take(HOP).slice(slice(0, 240))
    settings = RetargetSettings(fps=take.rate)
    opts = dict(feet="off", hands="off")
    plain = bake_take(obj, take, preset="rigify", settings=settings, options=BakeOptions(**opts))
    frames = plain.motion.frames[::12]
    # the keyed bones and the deforming ones (the IK controls and the torso's parent ride on root, as they should)
    names = [pb.name for pb in obj.pose.bones if pb.name in plain.motion.bone_names or pb.name.startswith("DEF-")]
    keep = [obj.pose.bones.find(n) for n in names]
    in_place = _world(bpy, obj, frames)[:, keep]
    root = obj.pose.bones.find("root")
    for facing in (False, True):
        reports: list[str] = []
        moved = bake_take(obj, take, preset="rigify", settings=settings,
                          options=BakeOptions(**opts, root_motion=True, root_motion_facing=facing),
                          report=lambda level, msg, seen=reports: seen.append(msg))
        assert "root" in moved.motion.bone_names and list(moved.motion.extras["locations"]) == ["root"]
        assert any("root motion on 'root'" in m for m in reports)
        world = _world(bpy, obj, frames)
        metres, degrees = _pose_errors(world[:, keep], in_place)
        assert metres < 1e-4 and degrees < 0.01, (facing, metres, degrees)
        assert np.linalg.norm(world[-1, root, :2, 3] - world[0, root, :2, 3]) > 0.3   # the root travels
        np.testing.assert_allclose(world[:, root, 2, 3], 0.0, atol=1e-6)               # on the floor
        if facing:   # the root turns with the performer
            assert np.ptp(np.degrees(np.arctan2(world[:, root, 1, 0], world[:, root, 0, 0]))) > 1.0
        else:
            np.testing.assert_allclose(world[:, root, :3, :3], np.broadcast_to(np.eye(3), (len(frames), 3, 3)),
                                       atol=1e-6)
    # the torso's parent switched away from root: the relation does not verify, a clear refusal
    obj.pose.bones["torso"]["torso_parent"] = 0
    with pytest.raises(ValueError, match="do not move rigidly"):
        bake_take(obj, take, preset="rigify", settings=settings, options=BakeOptions(**opts, root_motion=True))
    bpy.ops.wm.read_factory_settings(use_empty=True)


def test_key_reduction_thins_the_root_motion_keys_within_its_tolerance(bpy_empty):
    """Root motion's root bone location keys go through key reduction with the same tolerance as the hips'
    location: far fewer keys, and the root's path as Blender plays the keys back stays within 1 mm."""
    from bpy_extras import anim_utils

    from kinect_retarget.blender.bake_take import bake_take
    bpy = bpy_empty
    obj = _armature(bpy)
    take = load_take(HOP)
    settings = RetargetSettings(fps=take.rate)
    root = obj.pose.bones.find("root")

    def bake(**kw):
        res = bake_take(obj, take, settings=settings, options=BakeOptions(feet="off", root_motion=True, **kw))
        curves = anim_utils.animdata_get_channelbag_for_assigned_slot(obj.animation_data).fcurves
        keys = [len(fc.keyframe_points) for fc in curves if fc.data_path == 'pose.bones["root"].location']
        frames = np.arange(res.motion.frames[0], res.motion.frames[-1] + 1)
        return res, keys, _world(bpy, obj, frames)[:, root, :3, 3]

    full, full_keys, full_path = bake()
    thin, thin_keys, thin_path = bake(reduce=True, tolerance_deg=0.5, tolerance_mm=1.0)
    n = len(full.motion.frames)
    assert full_keys == [n, n, n]
    assert len(thin_keys) == 3 and max(thin_keys) < 0.8 * n        # the root's keys were thinned (276 -> 195)
    assert thin.reduction is not None and set(thin.reduction.other_location_keys) == {"root"}
    assert np.linalg.norm(full_path[-1, :2] - full_path[0, :2]) > 0.3     # the root travels
    err = np.linalg.norm(thin_path - full_path, axis=-1).max()
    assert err <= 1e-3 + 1e-5, err                                     # within the stated tolerance
    assert thin.reduction.max_mm <= 1.0 + 1e-6


def test_cli_bake_keeps_the_toes_of_feet_pointing_down_on_the_floor(bpy_empty, tmp_path):
    """A walk whose feet point 40 degrees further down than the performer's: baked with --feet off the toes
    go under the floor; with --feet lock and --feet floor the foot's and ball's tails stay at or above it at
    every key, as Blender evaluates the baked file."""
    from bpy_extras import anim_utils

    from kinect_retarget.takes import krtake
    from tests.takes.steep_feet import steep_feet
    bpy = bpy_empty
    _armature(bpy)
    rig_path, take_path = tmp_path / "ue4.blend", tmp_path / "steep.krtake"
    bpy.ops.wm.save_as_mainfile(filepath=str(rig_path))
    krtake.write(take_path, steep_feet(load_take(SAMPLE_TAKES / "kinect_v1_cmu_131_02_walk.krtake")))
    lowest = {}
    for mode in ("off", "lock", "floor"):
        out = tmp_path / f"{mode}.blend"
        r = subprocess.run([sys.executable, "-m", "kinect_retarget", "bake", str(take_path), "--rig", str(rig_path),
                            "--out", str(out), "--feet", mode, "--take-end", "4"],
                           capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, r.stderr
        bpy.ops.wm.open_mainfile(filepath=str(out))
        obj = bpy.data.objects["UE4"]
        floor = min(min(b.head_local[2], b.tail_local[2]) for b in obj.data.bones)
        curves = anim_utils.animdata_get_channelbag_for_assigned_slot(obj.animation_data).fcurves
        keys = next(fc for fc in curves if fc.data_path.startswith('pose.bones["foot_l"].rotation')).keyframe_points
        tails = []
        for k in keys:  # at every key (between keys Blender interpolates each channel)
            f = k.co[0]
            bpy.context.scene.frame_set(int(f), subframe=f - int(f))
            tails.append([(obj.matrix_world @ obj.pose.bones[b].tail)[2] for b in ("foot_l", "ball_l", "foot_r",
                                                                                 "ball_r")])
        lowest[mode] = float(np.min(tails) - floor)
    assert lowest["off"] < -0.03, lowest                                    # the toes dip without the pass
    assert lowest["lock"] >= -1e-4 and lowest["floor"] >= -1e-4, lowest  # and stay on the floor with it


def test_the_sidebar_bake_operator_takes_feet_and_root_motion(registered, tmp_path):
    """The Bake Take operator (the sidebar's Bake Take…) with its Feet and Root Motion options: Floor Only on a
    walk whose feet point down keeps the toes on the floor, Off leaves them under it; Root Motion keys the
    root bone's travel."""
    from bpy_extras import anim_utils

    from kinect_retarget.takes import krtake
    from tests.takes.steep_feet import steep_feet
    bpy = registered
    obj = _armature(bpy)
    bpy.context.view_layer.objects.active = obj
    take_path = tmp_path / "steep.krtake"
    krtake.write(take_path, steep_feet(load_take(SAMPLE_TAKES / "kinect_v1_cmu_131_02_walk.krtake")))
    floor = min(min(b.head_local[2], b.tail_local[2]) for b in obj.data.bones)
    lowest = {}
    for feet in ("off", "floor"):
        assert bpy.ops.kinect_retarget.bake_take(filepath=str(take_path), fps=30.0, feet=feet,
                                                 root_motion=True) == {"FINISHED"}
        curves = anim_utils.animdata_get_channelbag_for_assigned_slot(obj.animation_data).fcurves
        paths = {fc.data_path for fc in curves}
        assert 'pose.bones["root"].location' in paths                            # root motion keyed
        root_x = next(fc for fc in curves if fc.data_path == 'pose.bones["root"].location' and fc.array_index == 1)
        assert abs(root_x.keyframe_points[-1].co[1] - root_x.keyframe_points[0].co[1]) > 0.3  # it travels
        keys = next(fc for fc in curves if fc.data_path.startswith('pose.bones["foot_l"].rotation')).keyframe_points
        low = []
        for k in list(keys)[::3]:
            bpy.context.scene.frame_set(int(k.co[0]))
            low.append(min((obj.matrix_world @ obj.pose.bones[b].tail)[2] for b in ("foot_l", "ball_l", "foot_r",
                                                                                    "ball_r")))
        lowest[feet] = min(low) - floor
    assert lowest["off"] < -0.03 and lowest["floor"] >= -1e-4, lowest
