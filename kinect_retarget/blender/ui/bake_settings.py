"""The bake options as Blender properties, one definition shared by the Bake Take operator (its file browser's
side panel and redo panel) and the sidebar (scene.kinect_retarget), and how both draw them."""
from __future__ import annotations

from dataclasses import replace

from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty

from ...core.bake_options import BakeOptions

DESTINATION_ITEMS = [
    ("NEW", "New Action", "Key a new Action and assign it (the rig's previous Action is kept in the file)"),
    ("CURRENT", "Current Action", "Key into the Action the rig plays now, replacing its keys in the baked range"),
    ("NLA", "NLA Strip", "Key a new Action and push it to the NLA as a strip named after the take"),
]
HAND_ITEMS = [("auto", "Auto", "Hands for takes with Kinect v2's hand joints, none for Kinect v1"),
              ("on", "On", "Roll the hand from the thumb, bend the fingers toward the hand tip, curl them from "
                           "the hand states (open, fist, lasso)"),
              ("off", "Off", "Leave the finger bones and the hand's roll alone")]
FEET_ITEMS = [("lock", "Lock Planted Feet", "Pin each foot where it lands while planted (two-bone IK on the "
               "leg, eased in and out) and keep the feet above the floor"),
              ("floor", "Floor Only", "Keep the feet at or above the floor, nothing else"),
              ("off", "Off", "Leave the feet as the performer's joints put them")]
RANGE_UNIT_ITEMS = [("seconds", "Seconds", "Take range in seconds from the take's start"),
                    ("frames", "Take Frames", "Take range in the take's own frames, counted from 0")]


class BakeOptionProps:
    """Mixin: the bake options as properties (for an Operator or a PropertyGroup)."""
    set_scene_fps: BoolProperty(
        name="Set Scene Frame Rate", default=False,
        description="Run the scene at the take's rate. Off: the scene keeps its rate and the take is resampled "
                    "to it (rotations by slerp)")
    extend_scene_range: BoolProperty(
        name="Extend Scene Range", default=False,
        description="Grow the scene's frame range to hold the baked keys (it is never shortened)")
    use_take_range: BoolProperty(name="Part of the Take", default=False,
                                 description="Bake only part of the take")
    range_unit: EnumProperty(name="Unit", items=RANGE_UNIT_ITEMS, default="seconds")
    range_start: FloatProperty(name="From", default=0.0, min=0.0, description="Start of the part to bake")
    range_end: FloatProperty(name="To", default=10.0, min=0.0, description="End of the part to bake (inclusive)")
    key_step: IntProperty(name="Key Step", default=1, min=1, soft_max=10,
                          description="Key every N scene frames")
    reduce_keys: BoolProperty(name="Reduce Keys", default=False,
                              description="Remove keys that linear interpolation reproduces within the tolerances")
    tolerance_deg: FloatProperty(name="Rotation Tolerance (°)", default=0.5, min=0.001, soft_max=5.0,
                                 description="Largest rotation error key reduction may leave, in degrees")
    tolerance_mm: FloatProperty(name="Location Tolerance (mm)", default=1.0, min=0.001, soft_max=50.0,
                                description="Largest root-location error key reduction may leave, in millimetres")
    destination: EnumProperty(name="Keys Into", items=DESTINATION_ITEMS, default="NEW")
    hands: EnumProperty(name="Hands", items=HAND_ITEMS, default="auto",
                        description="Kinect v2 hands on rigs with finger bones (Rigify, Mixamo, UE Mannequin)")
    feet: EnumProperty(name="Feet", items=FEET_ITEMS, default="lock",
                       description="Planted feet and the floor (bakes only; live leaves the feet as tracked)")
    root_motion: BoolProperty(name="Root Motion", default=False,
                              description="Put the performer's horizontal travel on the rig's root bone, the hips "
                                          "relative to it (game engines); the pose in the world is unchanged")
    root_motion_facing: BoolProperty(name="With Facing", default=False,
                                     description="Root motion carries the performer's heading too")
    root_bone: StringProperty(name="Root Bone", default="",
                              description="Bone to carry root motion (empty: the top ancestor of the hips bone)")


def options_from(owner) -> BakeOptions:
    """BakeOptions from an operator or the scene settings holding BakeOptionProps."""
    use = owner.use_take_range
    return BakeOptions(range_start=owner.range_start if use else None, range_end=owner.range_end if use else None,
                       range_unit=owner.range_unit, step=owner.key_step, reduce=owner.reduce_keys,
                       tolerance_deg=owner.tolerance_deg, tolerance_mm=owner.tolerance_mm,
                       into_current=owner.destination == "CURRENT", push_nla=owner.destination == "NLA",
                       set_scene_fps=owner.set_scene_fps, extend_scene_range=owner.extend_scene_range,
                       hands=owner.hands, feet=owner.feet,
                       root_motion=owner.root_motion, root_motion_facing=owner.root_motion_facing,
                       root_bone=owner.root_bone or None)


def recording_bake_options(scene) -> BakeOptions:
    """The sidebar's options for the bake when a recording stops: its keys land on the frames live showed
    them (no take range, no resampling), and the scene's rate is left alone."""
    if scene is None or getattr(scene, "kinect_retarget", None) is None:
        return BakeOptions(keys_on_samples=True, feet="off")
    return replace(options_from(scene.kinect_retarget), range_start=None, range_end=None, set_scene_fps=False,
                   keys_on_samples=True, feet="off")


def copy_options(src, dst) -> None:
    for name in BakeOptionProps.__annotations__:
        setattr(dst, name, getattr(src, name))


def draw_bake_options(layout, owner) -> None:
    col = layout.column(heading="Scene")
    col.prop(owner, "set_scene_fps")
    col.prop(owner, "extend_scene_range")
    col = layout.column(heading="Take")
    col.prop(owner, "use_take_range")
    sub = col.column(align=True)
    sub.active = owner.use_take_range
    sub.prop(owner, "range_unit")
    sub.prop(owner, "range_start")
    sub.prop(owner, "range_end")
    col = layout.column(heading="Keys")
    col.prop(owner, "key_step")
    col.prop(owner, "reduce_keys")
    sub = col.column(align=True)
    sub.active = owner.reduce_keys
    sub.prop(owner, "tolerance_deg")
    sub.prop(owner, "tolerance_mm")
    layout.prop(owner, "destination")
    layout.prop(owner, "hands")
    layout.prop(owner, "feet")
    col = layout.column(heading="Root Motion")
    col.prop(owner, "root_motion", text="Travel on Root Bone")
    sub = col.column(align=True)
    sub.active = owner.root_motion
    sub.prop(owner, "root_motion_facing")
    sub.prop(owner, "root_bone")
