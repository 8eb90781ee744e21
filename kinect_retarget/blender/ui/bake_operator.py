"""Bake Take operator: gathers settings, calls bake_take() with report=self.report (the io_anim_bvh way)."""
from __future__ import annotations

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty
from bpy_extras.io_utils import ImportHelper

from ...core.pipeline import RetargetSettings
from ...core.presets import load_mapping_file
from ...core.take import TakeError
from ...takes import body_count, load_take
from ..bake_take import bake_take, take_display_name
from .bake_settings import BakeOptionProps, copy_options, draw_bake_options, options_from
from .mapping_table import table_overrides
from .performers import MAX_BODY, other_performers
from .preferences import FILTER_ITEMS
from .properties import PRESET_ITEMS, ROOT_ITEMS, ROOT_SCALE_DESC, target_armature


class KINECT_RETARGET_OT_bake_take(bpy.types.Operator, ImportHelper, BakeOptionProps):
    """Bake a recorded take (Kinect CSV/JSON, NTU, MSRC-12, UTKinect, BVH, .krtake) onto the target armature"""

    bl_idname = "kinect_retarget.bake_take"
    bl_label = "Bake Take"
    bl_options = {"REGISTER", "UNDO"}

    filter_glob: StringProperty(default="*.krtake;*.csv;*.json;*.skeleton;*.txt;*.bvh", options={"HIDDEN"})
    preset: EnumProperty(name="Preset", items=PRESET_ITEMS, default="auto")
    mapping_file: StringProperty(name="Mapping JSON", subtype="FILE_PATH", default="")
    filter: EnumProperty(name="Filter", items=FILTER_ITEMS, default="default")
    root: EnumProperty(name="Root Motion", items=ROOT_ITEMS, default="xyz")
    fps: FloatProperty(name="Key Rate", default=0.0, min=0.0,
                       description="Keys per second (0: the scene's rate, or the take's with Set Scene Frame Rate)")
    frame_start: IntProperty(name="Start Frame", default=1, description="Scene frame of the take's (part's) start")
    mirror: BoolProperty(name="Mirror", description="Swap the performer's left and right", default=False)
    root_scale: FloatProperty(name="Root Scale", default=0.0, min=0.0, soft_max=10.0, precision=3,
                              description=ROOT_SCALE_DESC)
    body: IntProperty(name="Body", default=0, min=0, max=MAX_BODY,
                      description="Which performer of a take with several (NTU, Kinectron) the target follows")
    with_performers: BoolProperty(name="Other Performers", default=True,
                                  description="Also bake each of the sidebar's other performers' bodies onto "
                                              "their rigs (takes with several bodies)")
    scale: FloatProperty(name="BVH Scale", description="BVH only: metres per file unit (0: guess from the "
                         "figure's standing height)", default=0.0, min=0.0, precision=4)

    @classmethod
    def poll(cls, context):
        if target_armature(context) is None:
            cls.poll_message_set("Select an armature to bake onto")
            return False
        return True

    def invoke(self, context, event):
        # start from the sidebar's choices; the file browser shows them for this bake
        s = getattr(context.scene, "kinect_retarget", None)
        if s is not None:
            self.preset, self.filter, self.root, self.mirror = s.preset, s.filter, s.root, s.mirror
            self.root_scale, self.body = s.root_scale, s.body
            copy_options(s, self)
            self.frame_start = context.scene.frame_start
        return super().invoke(context, event)

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        for name in ("preset", "mapping_file", "filter", "root", "root_scale", "mirror", "fps", "frame_start", "body",
                     "with_performers"):
            layout.prop(self, name)
        draw_bake_options(layout, self)

    def execute(self, context):
        obj = target_armature(context)
        wm = context.window_manager
        try:
            take = load_take(self.filepath, scale=self.scale or None, body=self.body)
            take.metadata.setdefault("name", take_display_name(self.filepath))
            others = [(o, b) for o, b in other_performers(context.scene) if o != obj and b < body_count(take)] \
                if self.with_performers and body_count(take) > 1 else []
            # the sidebar's mapping table, then a mapping file on top
            s = getattr(context.scene, "kinect_retarget", None)
            table = (table_overrides(s) or {}) if s is not None else {}
            overrides = {b: j for b, j in table.items() if b in obj.pose.bones}  # rows for this rig only
            if self.mapping_file:
                overrides.update(load_mapping_file(bpy.path.abspath(self.mapping_file)))
            settings = RetargetSettings(filter=self.filter, root_mode=self.root, fps=self.fps or None,
                                        frame_start=self.frame_start, mirror=self.mirror,
                                        root_scale=self.root_scale or None)  # 0: auto (leg-length ratio)
            options = options_from(self)
        except (TakeError, ValueError) as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        wm.progress_begin(0, 100)
        try:
            bake_take(obj, take, preset=self.preset, overrides=overrides or None, settings=settings,
                      options=options, report=self.report, progress=lambda x: wm.progress_update(int(100 * x)))
            for other, body in others:  # each other performer's body onto its own rig, its preset's mapping
                each = load_take(self.filepath, body=body)
                each.metadata.setdefault("name", f"{take_display_name(self.filepath)}_body{body}")
                bake_take(other, each, preset=self.preset, settings=settings, options=options, report=self.report)
        except (TakeError, ValueError) as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        return {"FINISHED"}


CLASSES = (KINECT_RETARGET_OT_bake_take,)
