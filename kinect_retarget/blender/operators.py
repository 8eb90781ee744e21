"""Bake Take operator: gathers settings, calls bake_take() with report=self.report (the io_anim_bvh way)."""
from __future__ import annotations

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty
from bpy_extras.io_utils import ImportHelper

from ..core.filters import FILTERS
from ..core.pipeline import RetargetSettings
from ..core.presets import PRESET_NAMES, load_mapping_file
from ..core.retarget import ROOT_MODES
from ..core.take import TakeError
from ..takes import load_take
from .bake_take import bake_take, take_display_name

PRESET_ITEMS = [(p, p, f"Bone-mapping preset {p}") for p in PRESET_NAMES]
FILTER_ITEMS = [(f, f, f"Jitter filter {f}") for f in FILTERS]
ROOT_ITEMS = [("xyz", "XYZ", "Root follows the performer in all axes"),
              ("xy", "XY", "Horizontal root motion only"), ("none", "None", "Root stays in place")]
assert tuple(r[0] for r in ROOT_ITEMS) == ROOT_MODES


class KINECT_RETARGET_OT_bake_take(bpy.types.Operator, ImportHelper):
    """Bake a recorded take (Kinect CSV/JSON, NTU, MSRC-12, UTKinect, BVH, .krtake) onto the active armature"""

    bl_idname = "kinect_retarget.bake_take"
    bl_label = "Bake Take"
    bl_options = {"REGISTER", "UNDO"}

    filter_glob: StringProperty(default="*.krtake;*.csv;*.json;*.skeleton;*.txt;*.bvh", options={"HIDDEN"})
    preset: EnumProperty(name="Preset", items=PRESET_ITEMS, default="auto")
    mapping_file: StringProperty(name="Mapping JSON", subtype="FILE_PATH", default="")
    filter: EnumProperty(name="Filter", items=FILTER_ITEMS, default="default")
    root: EnumProperty(name="Root Motion", items=ROOT_ITEMS, default="xyz")
    fps: FloatProperty(name="FPS", description="Scene rate (0: the take's rate)", default=0.0, min=0.0)
    frame_start: IntProperty(name="Start Frame", default=1)
    mirror: BoolProperty(name="Mirror", description="Swap the performer's left and right", default=False)

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        if obj is None or obj.type != "ARMATURE":
            cls.poll_message_set("Select an armature to bake onto")
            return False
        return True

    def execute(self, context):
        obj = context.active_object
        wm = context.window_manager
        try:
            take = load_take(self.filepath)
            take.metadata.setdefault("name", take_display_name(self.filepath))
            overrides = load_mapping_file(bpy.path.abspath(self.mapping_file)) if self.mapping_file else None
            settings = RetargetSettings(filter=self.filter, root_mode=self.root, fps=self.fps or None,
                                        frame_start=self.frame_start, mirror=self.mirror)
        except (TakeError, ValueError) as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        wm.progress_begin(0, 100)
        try:
            bake_take(obj, take, preset=self.preset, overrides=overrides, settings=settings,
                      report=self.report, progress=lambda x: wm.progress_update(int(100 * x)))
        except (TakeError, ValueError) as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        return {"FINISHED"}


CLASSES = (KINECT_RETARGET_OT_bake_take,)
