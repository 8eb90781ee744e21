"""Fixtures for tests that use the real bpy 5.0.1 wheel. bpy is imported inside fixtures only."""
from __future__ import annotations

from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture
def bpy_empty():
    """A fresh empty scene (factory settings) for each test."""
    import bpy
    bpy.ops.wm.read_factory_settings(use_empty=True)
    yield bpy
    bpy.ops.wm.read_factory_settings(use_empty=True)


@pytest.fixture
def registered(bpy_empty):
    """The add-on registered from the working tree, unregistered afterwards."""
    import kinect_retarget
    kinect_retarget.register()
    yield bpy_empty
    kinect_retarget.unregister()


@pytest.fixture(scope="session")
def rigify_rig_path(tmp_path_factory):
    """A Rigify rig generated headless from Blender's human metarig, saved once per session."""
    import bpy  # noqa: I001 (addon_utils is importable only after bpy)
    import addon_utils
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("rigify", default_set=True)  # after the factory reset, which would disable it
    bpy.ops.object.armature_human_metarig_add()
    bpy.ops.pose.rigify_generate()
    path = tmp_path_factory.mktemp("rigs") / "rigify.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    return path


def add_unlearnable_parents(bpy, obj, frames: tuple[int, int]):
    """Give the generated Kinect rig two parents no relation explains (issue 15's fallback): the left
    elbow hangs from a bone with a Damped Track to an empty, the left knee from a bone whose Copy Rotation
    influence is driven by a custom property of another empty, keyed to change over `frames`. The
    rig is the test's own, so editing its bones here is fine."""
    scene = bpy.context.scene
    aim = bpy.data.objects.new("Aim", None)
    aim.location = (0.8, -1.5, 2.0)
    knob = bpy.data.objects.new("Knob", None)
    for o in (aim, knob):
        scene.collection.objects.link(o)
    knob["follow"] = 0.0
    knob.keyframe_insert('["follow"]', frame=frames[0])
    knob["follow"] = 1.0
    knob.keyframe_insert('["follow"]', frame=frames[1])
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    eb = obj.data.edit_bones
    for mch, parent, child in (("MCH-aim", "ShoulderLeft", "ElbowLeft"), ("MCH-knee", "HipLeft", "KneeLeft")):
        b = eb.new(mch)
        b.head, b.tail, b.roll = eb[child].head, eb[child].tail, eb[child].roll
        b.parent = eb[parent]
        eb[child].parent = b
    bpy.ops.object.mode_set(mode="OBJECT")
    pb = obj.pose.bones
    track = pb["MCH-aim"].constraints.new("DAMPED_TRACK")
    track.target = aim
    rot = pb["MCH-knee"].constraints.new("COPY_ROTATION")
    rot.target, rot.subtarget = obj, "SpineBase"
    fc = rot.driver_add("influence")
    var = fc.driver.variables.new()
    var.name, var.type = "var", "SINGLE_PROP"
    var.targets[0].id_type, var.targets[0].id, var.targets[0].data_path = "OBJECT", knob, '["follow"]'
    fc.driver.expression = "var"
    return aim, knob


@pytest.fixture
def generated_live_rig(tmp_path):
    """The add-on registered and a generated Kinect v2 rig as the sidebar's target, recording into tmp_path
    without timeline playback. Yields (the first 60 frames of a v2 sample take, the scene's settings)."""
    import bpy
    import kinect_retarget
    from kinect_retarget.blender.io.kinect_rig import build_kinect_rig
    from kinect_retarget.blender.live import live_runtime
    from kinect_retarget.core.kinect_rig_layout import median_segment_lengths
    from kinect_retarget.takes import load_take
    bpy.ops.wm.read_factory_settings(use_empty=True)
    kinect_retarget.register()
    take = load_take(REPO / "sample_takes" / "kinect_v2_ges03_drawlines.krtake").slice(slice(0, 60))
    scene = bpy.context.scene
    obj = build_kinect_rig(scene, take.skeleton, median_segment_lengths(take), "KinectRig")
    bpy.context.view_layer.objects.active = obj
    s = scene.kinect_retarget
    s.initialised, s.armature, s.record_dir, s.play_on_record = True, obj, str(tmp_path), False
    yield take, s
    live_runtime.stop_live(bake=False)
    kinect_retarget.unregister()
    bpy.ops.wm.read_factory_settings(use_empty=True)
