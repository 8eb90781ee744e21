"""The 3D View sidebar tab "Kinect": source and status, target and mapping, options, live controls, bake."""
from __future__ import annotations

import bpy

from ..io.armature_probe import fallback_bones
from ..live import live_runtime, record_countdown
from ..live.osc_access import osc_host
from .bake_settings import draw_bake_options
from .performers import draw_performers
from .preferences import get_preferences
from .properties import target_armature
from .sidebar_panel import KinectSidebarPanel
from .source_overlay import draw_settings as draw_source_settings


class KINECT_RETARGET_PT_main(KinectSidebarPanel, bpy.types.Panel):
    bl_label = "Kinect Retarget"

    def draw(self, context):
        layout = self.layout
        s = context.scene.kinect_retarget
        st = live_runtime.status()
        running = live_runtime.controller() is not None

        box = layout.box()
        col = box.column()
        col.enabled = not running
        col.row().prop(s, "source", expand=True)
        if s.source == "TAKE":
            col.prop(s, "take_path")
            row = col.row(align=True)
            row.prop(s, "speed")
            row.prop(s, "loop", toggle=True)
        elif s.source == "OSC":
            col.prop(s, "osc_port")
            refused = osc_host(get_preferences(context))[1]
            if refused:
                col.label(text=refused, icon="INTERNET_OFFLINE")
        else:
            col.label(text="Skeletons from the depth tracker (devices: USB Kinect below)", icon="INFO")
        self._draw_status(box, st)
        draw_source_settings(layout, s)

        col = layout.column(align=True)
        row = col.row(align=True)
        row.scale_y = 1.4
        if running:
            row.operator("kinect_retarget.live_stop", text="Stop Live", icon="PAUSE", depress=True)
        else:
            row.operator("kinect_retarget.live_start", text="Start Live", icon="PLAY")
        recording = st.get("state") == "recording"
        counting = record_countdown.label()
        row.operator("kinect_retarget.record", icon="REC", depress=recording or bool(counting),
                     text="Stop Recording" if recording else "Cancel Countdown" if counting else "Record")
        if counting:
            big = col.row()
            big.alert = True
            big.scale_y = 1.6
            big.label(text=counting, icon="TIME")
        row = col.row(align=True)
        row.operator("kinect_retarget.calibrate", icon="ARMATURE_DATA")
        row.operator("kinect_retarget.bake_take", text="Bake Take…", icon="ACTION")

    @staticmethod
    def _draw_status(layout, st):
        col = layout.column(align=True)
        if st.get("error"):
            err = col.row()
            err.alert = True
            err.label(text=st["error"], icon="ERROR")
        if st.get("warning") and not st.get("error"):
            col.label(text=st["warning"], icon="ERROR")  # not fatal: live goes on
        stats = st.get("stats")
        if st.get("state") in ("running", "recording"):
            col.label(text=st.get("message", ""), icon="REC" if st["state"] == "recording" else "PLAY")
            if stats:
                col.label(text=f"{stats['fps']:.1f} fps · {st.get('tracked', 0)}/{st.get('joints', 0)} joints "
                               f"tracked")
                p99 = stats["latency_p99_ms"]
                col.label(text=f"applied {stats['applied']} · dropped {stats['dropped']} · "
                               f"latency p99 {p99 if p99 is not None else '–'} ms")
            if st.get("progress"):
                col.label(text="take frame {} / {}".format(*st["progress"]), icon="FILE_MOVIE")
            if st.get("device"):
                col.label(text=st["device"], icon="OUTLINER_OB_CAMERA")
            if st.get("calibrating"):
                col.label(text="Calibrating: stand still…", icon="TIME")
        elif st.get("message") and not st.get("error"):
            col.label(text=st["message"], icon="INFO")


class KINECT_RETARGET_PT_target(KinectSidebarPanel, bpy.types.Panel):
    bl_label = "Target"
    bl_parent_id = "KINECT_RETARGET_PT_main"

    def draw(self, context):
        layout = self.layout
        s = context.scene.kinect_retarget
        layout.enabled = live_runtime.controller() is None
        layout.prop(s, "armature")
        obj = target_armature(context)
        if obj is None:
            layout.label(text="No armature: pick one or make one active", icon="ERROR")
        elif s.armature is None:
            layout.label(text=f"Active: {obj.name}", icon="ARMATURE_DATA")
        if obj is not None and obj.get("kinect_retarget_calibration"):
            layout.label(text="Calibrated for this rig", icon="CHECKMARK")
        layout.prop(s, "preset")
        draw_performers(layout, s)


class KINECT_RETARGET_PT_mapping(KinectSidebarPanel, bpy.types.Panel):
    bl_label = "Bone Mapping"
    bl_parent_id = "KINECT_RETARGET_PT_main"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = self.layout
        s = context.scene.kinect_retarget
        layout.enabled = live_runtime.controller() is None
        row = layout.row()
        row.template_list("KINECT_RETARGET_UL_mapping", "", s, "mapping", s, "mapping_index", rows=6)
        col = row.column(align=True)
        col.operator("kinect_retarget.mapping_add", icon="ADD", text="")
        col.operator("kinect_retarget.mapping_remove", icon="REMOVE", text="")
        col.separator()
        col.operator("kinect_retarget.mapping_clear", icon="X", text="")
        row = layout.row(align=True)
        row.operator("kinect_retarget.mapping_from_preset", text="From Preset", icon="PRESET")
        row.operator("kinect_retarget.mapping_load", text="Load", icon="FILEBROWSER")
        row.operator("kinect_retarget.mapping_save", text="Save", icon="FILE_TICK")
        if not len(s.mapping):
            layout.label(text="Empty table: the preset maps every bone", icon="INFO")


class KINECT_RETARGET_PT_options(KinectSidebarPanel, bpy.types.Panel):
    bl_label = "Filter, Root and Recording"
    bl_parent_id = "KINECT_RETARGET_PT_main"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        s = context.scene.kinect_retarget
        col = layout.column()
        col.enabled = live_runtime.controller() is None
        col.prop(s, "filter")
        col.prop(s, "root")
        col.prop(s, "root_scale", text="Root Scale (0 = Auto)")
        col.prop(s, "mirror")
        obj = target_armature(context)
        if obj is not None and fallback_bones(obj.name):  # only a rig with bones no relation explains needs it
            col.prop(s, "exact_constrained")
        col = layout.column(heading="Recording")
        col.prop(s, "record_dir")
        col.prop(s, "record_countdown")
        col.prop(s, "play_on_record")
        col.prop(s, "bake_on_stop")


class KINECT_RETARGET_PT_bake(KinectSidebarPanel, bpy.types.Panel):
    """Options of Bake Take and of the bake when a recording stops (the take range applies to Bake Take)."""
    bl_label = "Bake"
    bl_parent_id = "KINECT_RETARGET_PT_main"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        draw_bake_options(layout, context.scene.kinect_retarget)
        layout.operator("kinect_retarget.bake_take", text="Bake Take…", icon="ACTION")


CLASSES = (KINECT_RETARGET_PT_main, KINECT_RETARGET_PT_target, KINECT_RETARGET_PT_mapping,
           KINECT_RETARGET_PT_options, KINECT_RETARGET_PT_bake)
