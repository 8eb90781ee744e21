"""Rigs whose bones hang from constraint-driven parents (issue 15): the probe learns the relations on an
armature copy, numpy solves every frame, and what it cannot learn Blender evaluates per frame (fallback)."""
import numpy as np
import pytest

from kinect_retarget.core.bake_options import BakeOptions
from kinect_retarget.core.pipeline import RetargetSettings
from kinect_retarget.core.quat import angle_between, from_matrix
from kinect_retarget.takes import load_take

from .conftest import add_unlearnable_parents

SAMPLES = __import__("pathlib").Path(__file__).resolve().parents[2] / "sample_takes"


def _evaluated_error(bpy, obj, motion, every=1) -> np.ndarray:
    """Degrees between each mapped bone's rotation as Blender evaluates the baked rig (the user's scene,
    frame by frame) and the solver's desired rotation."""
    names, desired = motion.bone_names, motion.extras["desired"]
    errs = []
    for i in range(0, len(motion.frames), every):
        bpy.context.scene.frame_set(int(motion.frames[i]))
        m = np.array([np.array(obj.pose.bones[n].matrix)[:3, :3] for n in names])
        m /= np.linalg.norm(m, axis=-2, keepdims=True)
        errs.append(np.degrees(angle_between(from_matrix(m), desired[i])))
    return np.array(errs)


def _state(bpy, obj):
    """What the bake must leave alone: scenes, objects, the rig's bones, constraints and unkeyed pose."""
    return ([s.name for s in bpy.data.scenes], sorted(o.name for o in bpy.data.objects),
            [(b.name, b.parent and b.parent.name, tuple(map(tuple, b.matrix_local))) for b in obj.data.bones],
            [(pb.name, [(c.type, c.influence) for c in pb.constraints], tuple(pb.rotation_quaternion),
              tuple(pb.location)) for pb in obj.pose.bones],
            sorted(d.data_path for d in obj.animation_data.drivers) if obj.animation_data else [])


def test_rigify_bake_is_exact_without_per_frame_evaluation(rigify_rig_path):
    import bpy
    from kinect_retarget.blender.bake_take import bake_take
    bpy.ops.wm.open_mainfile(filepath=str(rigify_rig_path))
    obj = bpy.data.objects["rig"]
    # the arm follows the root part way; the rig's own driver has not run yet, so its constraint's influence
    # shows 0 until Blender evaluates the user's rig, which the bake must not do
    obj.pose.bones["upper_arm_parent.L"]["FK_limb_follow"] = 0.4
    take = load_take(SAMPLES / "kinect_v2_ges01_wavehand.krtake").slice(slice(0, 60))
    before = _state(bpy, obj)
    reports = []
    res = bake_take(obj, take, preset="rigify", settings=RetargetSettings(filter="none"),
                    options=BakeOptions(hands="off"),  # the thumb would roll the hands off `desired`
                    report=lambda level, msg: reports.append(msg))
    model = res.motion.extras["parent_model"]
    assert model.fallback == () and model.error_deg < 0.001
    # Rigify's FK parents: the spine MCH bones blend toward the chest, neck and head follow the torso
    learned = set(model.learned_names)
    assert {"MCH-spine.002", "MCH-ROT-neck", "ORG-shoulder.L", "MCH-upper_arm_parent.L"} <= learned
    follow = model.follows[model.rig.index("MCH-upper_arm_parent.L")]
    assert model.rig.bone_names[follow.target] == "root" and abs(follow.weight - 0.4) < 1e-4
    assert "MCH-upper_arm_parent.R" not in learned   # follow 0 on the right: plain parenting
    assert any("relations learned" in m for m in reports)
    after = _state(bpy, obj)
    assert after[:3] == before[:3] and after[4] == before[4]   # no scene, object or bone left behind
    # the bake switched the limbs to FK in the action only; the unkeyed pose channels are the user's
    assert [p for p in after[3] if p[0] not in res.motion.bone_names] == \
        [p for p in before[3] if p[0] not in res.motion.bone_names]
    assert _evaluated_error(bpy, obj, res.motion, every=4).max() < 0.001
    bpy.ops.wm.read_factory_settings(use_empty=True)


def test_unlearnable_constraints_bake_exactly_through_the_fallback(bpy_empty):
    from kinect_retarget.blender.bake_take import bake_take, new_generated_rig
    bpy = bpy_empty
    take = load_take(SAMPLES / "kinect_v2_ges03_drawlines.krtake").slice(slice(0, 45))
    obj = new_generated_rig(bpy.context.scene, take)
    add_unlearnable_parents(bpy, obj, (1, 45))
    bpy.context.view_layer.update()
    before = _state(bpy, obj)
    reports = []
    res = bake_take(obj, take, preset="kinect", settings=RetargetSettings(filter="none"),
                    report=lambda level, msg: reports.append(msg))
    model = res.motion.extras["parent_model"]
    assert set(model.fallback_names) == {"MCH-aim", "MCH-knee"}
    assert any("MCH-aim" in m and "per frame" in m for m in reports)
    after = _state(bpy, obj)
    assert after[:3] == before[:3] and after[4] == before[4]
    errs = _evaluated_error(bpy, obj, res.motion)
    assert errs.max() < 0.001, errs.max()


def test_bake_into_the_current_action_keeps_its_other_channels_playing(bpy_empty):
    """A follow property keyed in the rig's own Action still plays after a bake into that Action, so the
    probe's copy plays it too: the relation changes over the take, falls back, and the bake is exact."""
    from kinect_retarget.blender.bake_take import bake_take, new_generated_rig
    from kinect_retarget.core.bake_options import BakeOptions
    bpy = bpy_empty
    take = load_take(SAMPLES / "kinect_v2_ges03_drawlines.krtake").slice(slice(0, 45))
    obj = new_generated_rig(bpy.context.scene, take)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    eb = obj.data.edit_bones
    b = eb.new("MCH-knee")
    b.head, b.tail, b.roll, b.parent = eb["KneeLeft"].head, eb["KneeLeft"].tail, eb["KneeLeft"].roll, eb["HipLeft"]
    eb["KneeLeft"].parent = b
    bpy.ops.object.mode_set(mode="OBJECT")
    rot = obj.pose.bones["MCH-knee"].constraints.new("COPY_ROTATION")
    rot.target, rot.subtarget = obj, "SpineBase"
    fc = rot.driver_add("influence")
    var = fc.driver.variables.new()
    var.type, var.targets[0].id_type, var.targets[0].id = "SINGLE_PROP", "OBJECT", obj
    var.targets[0].data_path = '["follow"]'
    fc.driver.expression = var.name
    obj["follow"] = 0.0
    obj.keyframe_insert('["follow"]', frame=1)
    obj["follow"] = 1.0
    obj.keyframe_insert('["follow"]', frame=40)
    action = obj.animation_data.action
    res = bake_take(obj, take, preset="kinect", settings=RetargetSettings(filter="none", fps=30.0),
                    options=BakeOptions(into_current=True))
    assert obj.animation_data.action == action and action.name in bpy.data.actions
    assert len(bpy.data.actions) == 1   # the probe's copy of the Action is gone
    assert res.motion.extras["parent_model"].fallback_names == ["MCH-knee"]
    assert _evaluated_error(bpy, obj, res.motion).max() < 0.001


def test_a_probe_that_fails_while_preparing_leaves_no_copy_behind(bpy_empty):
    from kinect_retarget.blender.bake_take import new_generated_rig
    from kinect_retarget.blender.io.armature_probe import ArmatureEvaluator
    bpy = bpy_empty
    take = load_take(SAMPLES / "kinect_v2_ges03_drawlines.krtake").slice(slice(0, 5))
    obj = new_generated_rig(bpy.context.scene, take)
    before = (len(bpy.data.scenes), len(bpy.data.objects), len(bpy.data.armatures), len(bpy.data.actions))
    with pytest.raises(KeyError):
        ArmatureEvaluator(obj, ["NoSuchBone"])   # fails after the copy and its scene exist
    assert (len(bpy.data.scenes), len(bpy.data.objects), len(bpy.data.armatures), len(bpy.data.actions)) == before
    with ArmatureEvaluator(obj, [b.name for b in obj.pose.bones]):
        assert len(bpy.data.scenes) == before[0] + 1
    assert len(bpy.data.scenes) == before[0]
