"""Per-scene Kinect settings (scene.kinect_retarget): source, target, mapping table, filter, record options.

Live status is runtime state (blender/live/live_runtime.py), not stored here, so live never dirties the file or undo.
"""
from __future__ import annotations

import bpy
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty, FloatVectorProperty,
                       IntProperty, PointerProperty, StringProperty)

from ...core.presets import PRESET_NAMES
from ...core.retarget import ROOT_MODES
from ..live.record_countdown import COUNTDOWN_ITEMS
from .bake_settings import BakeOptionProps
from .performers import MAX_BODY, KinectRetargetPerformer, is_armature
from .preferences import FILTER_ITEMS, SOURCE_ITEMS, get_preferences

PRESET_ITEMS = [(p, p.replace("-", " ").title() if p != "auto" else "Auto", f"Bone-mapping preset: {p}")
                for p in PRESET_NAMES]
ROOT_ITEMS = [("xyz", "XYZ", "Root follows the performer in all axes"),
              ("xy", "Horizontal", "No vertical root motion"), ("none", "None", "Root stays in place")]
assert tuple(r[0] for r in ROOT_ITEMS) == ROOT_MODES


def _redraw_views(self, context) -> None:
    screen = getattr(context, "screen", None)
    for area in screen.areas if screen is not None else ():
        if area.type == "VIEW_3D":
            area.tag_redraw()


class KinectRetargetBoneMap(bpy.types.PropertyGroup):
    """One row of the bone-mapping table: target bone <- source joint."""
    bone: StringProperty(name="Bone", description="Bone of the target armature")
    joint: StringProperty(name="Joint", description="Kinect joint driving it (the joint at the bone's tail)")
    enabled: BoolProperty(name="Enabled", default=True, description="Drive this bone")


class KinectRetargetTake(bpy.types.PropertyGroup):
    """One recording of this .blend in the sidebar's takes list (the file stays where it was written)."""
    name: StringProperty(name="Name", description="The take's file name without its extension")
    path: StringProperty(name="File", subtype="FILE_PATH")
    seconds: FloatProperty(name="Length", unit="TIME_ABSOLUTE")
    frames: IntProperty(name="Frames")
    date: StringProperty(name="Recorded", description="When the recording stopped (local time)")


ROOT_SCALE_DESC = ("Paper 000 eq. 13: factor from the performer's root travel (metres) to the rig's; "
                   "0 = auto (the rig's leg length over the performer's, 1 on a generated rig)")


class KinectRetargetSettings(bpy.types.PropertyGroup, BakeOptionProps):
    initialised: BoolProperty(default=False, options={"HIDDEN"})
    source: EnumProperty(name="Source", items=SOURCE_ITEMS, default="TAKE")
    take_path: StringProperty(name="Take", subtype="FILE_PATH", description="Take to play live")
    speed: FloatProperty(name="Speed", default=1.0, min=0.05, max=20.0, description="Playback speed")
    loop: BoolProperty(name="Loop", default=True, description="Play the take again when it ends")
    osc_port: IntProperty(name="Port", default=7000, min=1, max=65535)
    armature: PointerProperty(name="Armature", type=bpy.types.Object, poll=is_armature,
                              description="Rig to drive (empty: the active armature)")
    body: IntProperty(name="Body", default=0, min=0, max=MAX_BODY,
                      description="Which performer of the source drives the target (from 0: NTU's and "
                                  "Kinectron's bodies in order, NI mate's user N is body N-1)")
    performers: CollectionProperty(type=KinectRetargetPerformer)
    show_source: BoolProperty(name="Show Source Skeleton", default=False, update=_redraw_views,
                              description="Draw the performer's skeleton as the source delivers it beside each "
                                          "character (live, or the take at the current frame): green joints "
                                          "tracked, amber inferred")
    source_offset: FloatVectorProperty(name="Source Offset", size=3, subtype="TRANSLATION", unit="LENGTH",
                                       default=(1.0, 0.0, 0.0), update=_redraw_views,
                                       description="Where the source skeleton stands, from the character's origin")
    performers_index: IntProperty(default=0)
    preset: EnumProperty(name="Preset", items=PRESET_ITEMS, default="auto")
    mapping: CollectionProperty(type=KinectRetargetBoneMap)
    mapping_index: IntProperty(default=0)
    filter: EnumProperty(name="Filter", items=FILTER_ITEMS, default="default")
    root: EnumProperty(name="Root Motion", items=ROOT_ITEMS, default="xyz")
    mirror: BoolProperty(name="Mirror", default=False, description="Swap the performer's left and right")
    root_scale: FloatProperty(name="Root Scale", default=0.0, min=0.0, soft_max=10.0, precision=3,
                              description=ROOT_SCALE_DESC)
    exact_constrained: BoolProperty(
        name="Exact on Constrained Rigs", default=False,
        description="On rigs with constraint-driven parents no learned relation explains (shown only for "
                    "those), evaluate them on a copy of the armature every live frame as the bake does, so live "
                    "equals the baked pose; costs a few evaluations of the armature per frame")
    record_dir: StringProperty(name="Folder", subtype="DIR_PATH", default="//kinect_takes/")
    play_on_record: BoolProperty(name="Play Timeline", default=True,
                                 description="Start timeline playback when recording starts (keeps audio in sync)")
    record_countdown: EnumProperty(name="Countdown", items=COUNTDOWN_ITEMS, default="0",
                                   description="Seconds to wait after Record before recording starts (time to walk "
                                               "into the sensor's view)")
    takes: CollectionProperty(type=KinectRetargetTake)
    takes_index: IntProperty(default=0)
    bake_on_stop: BoolProperty(name="Bake on Stop", default=True,
                               description="Bake the recording to an Action on the rig when recording stops")


def ensure_defaults(scene: bpy.types.Scene, context=None) -> None:
    """Copy the add-on preferences into a scene's settings the first time they are used."""
    s = scene.kinect_retarget
    if s.initialised:
        return
    prefs = get_preferences(context)
    if prefs is not None:
        s.source, s.osc_port, s.filter = prefs.default_source, prefs.osc_port, prefs.default_filter
        s.record_dir = prefs.recordings_dir
    s.initialised = True


def target_armature(context) -> bpy.types.Object | None:
    """The sidebar's target armature when the add-on's settings exist and name one, else the active armature."""
    s = getattr(context.scene, "kinect_retarget", None)
    if s is not None and s.armature is not None:
        return s.armature
    obj = context.active_object
    return obj if obj is not None and obj.type == "ARMATURE" else None


def register_extra() -> None:
    bpy.types.Scene.kinect_retarget = PointerProperty(type=KinectRetargetSettings)


def unregister_extra() -> None:
    del bpy.types.Scene.kinect_retarget


CLASSES = (KinectRetargetBoneMap, KinectRetargetTake, KinectRetargetSettings)
