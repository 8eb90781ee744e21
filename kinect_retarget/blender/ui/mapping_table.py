"""The editable bone-mapping table: fill from a preset, edit per bone, save and load as JSON."""
from __future__ import annotations

import json

import bpy
from bpy.props import StringProperty
from bpy_extras.io_utils import ExportHelper, ImportHelper

from ...core.presets import build_mapping, load_mapping_file
from ..io.rig_reader import target_rig_from_object
from .properties import target_armature


def table_overrides(settings) -> dict[str, str] | None:
    """The table as overrides for build_mapping: rows win over the preset, disabled rows unmap."""
    if not len(settings.mapping):
        return None
    return {row.bone: (row.joint if row.enabled else "") for row in settings.mapping if row.bone}


def fill_table(settings, mapping: dict[str, str]) -> None:
    settings.mapping.clear()
    for bone, joint in mapping.items():
        row = settings.mapping.add()
        row.bone, row.joint, row.enabled = bone, joint or "", bool(joint)
    settings.mapping_index = 0


class KINECT_RETARGET_UL_mapping(bpy.types.UIList):
    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index):
        row = layout.row(align=True)
        row.prop(item, "enabled", text="")
        obj = target_armature(context)
        sub = row.row(align=True)
        sub.active = item.enabled
        if obj is not None:
            sub.prop_search(item, "bone", obj.data, "bones", text="")
        else:
            sub.prop(item, "bone", text="")
        sub.label(icon="BACK")
        sub.prop(item, "joint", text="")


class KINECT_RETARGET_OT_mapping_from_preset(bpy.types.Operator):
    """Fill the bone-mapping table from the preset (auto: detected from the armature's bone names, or found from
    its hierarchy and rest pose when no preset names them); every row can then be edited"""
    bl_idname = "kinect_retarget.mapping_from_preset"
    bl_label = "Fill Mapping from Preset"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        if target_armature(context) is None:
            cls.poll_message_set("Pick a target armature first")
            return False
        return True

    def execute(self, context):
        s = context.scene.kinect_retarget
        obj = target_armature(context)
        try:
            used, mapping = build_mapping(s.preset, [b.name for b in obj.data.bones], None,
                                          target_rig_from_object(obj))
        except ValueError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        present = {b.name for b in obj.data.bones}
        fill_table(s, {b: j for b, j in mapping.items() if b in present})
        how = ("found from the armature's structure (python -m kinect_retarget info --rig says how)"
               if used == "structure" else f"from preset {used!r}")
        self.report({"INFO"}, f"Mapping {how}: {len(s.mapping)} bones")
        return {"FINISHED"}


class KINECT_RETARGET_OT_mapping_add(bpy.types.Operator):
    """Add a row to the bone-mapping table"""
    bl_idname = "kinect_retarget.mapping_add"
    bl_label = "Add Mapping Row"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        s = context.scene.kinect_retarget
        s.mapping.add()
        s.mapping_index = len(s.mapping) - 1
        return {"FINISHED"}


class KINECT_RETARGET_OT_mapping_remove(bpy.types.Operator):
    """Remove the selected row of the bone-mapping table"""
    bl_idname = "kinect_retarget.mapping_remove"
    bl_label = "Remove Mapping Row"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return len(context.scene.kinect_retarget.mapping) > 0

    def execute(self, context):
        s = context.scene.kinect_retarget
        s.mapping.remove(s.mapping_index)
        s.mapping_index = max(0, min(s.mapping_index, len(s.mapping) - 1))
        return {"FINISHED"}


class KINECT_RETARGET_OT_mapping_clear(bpy.types.Operator):
    """Empty the table: the preset alone decides the mapping"""
    bl_idname = "kinect_retarget.mapping_clear"
    bl_label = "Clear Mapping"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        context.scene.kinect_retarget.mapping.clear()
        return {"FINISHED"}


class KINECT_RETARGET_OT_mapping_save(bpy.types.Operator, ExportHelper):
    """Save the bone-mapping table as JSON (usable with --mapping on the command line)"""
    bl_idname = "kinect_retarget.mapping_save"
    bl_label = "Save Mapping"
    filename_ext = ".json"
    filter_glob: StringProperty(default="*.json", options={"HIDDEN"})

    @classmethod
    def poll(cls, context):
        return len(context.scene.kinect_retarget.mapping) > 0

    def execute(self, context):
        s = context.scene.kinect_retarget
        data = {"format": "kinect_retarget.mapping", "version": 1, "preset": s.preset,
                "mapping": table_overrides(s)}
        try:
            with open(self.filepath, "w", encoding="utf-8") as fh:
                json.dump(data, fh, indent=2)
        except OSError as exc:
            self.report({"ERROR"}, f"Cannot write {self.filepath}: {exc.strerror or exc}")
            return {"CANCELLED"}
        self.report({"INFO"}, f"Saved {len(s.mapping)} mapping rows to {self.filepath}")
        return {"FINISHED"}


class KINECT_RETARGET_OT_mapping_load(bpy.types.Operator, ImportHelper):
    """Load a bone-mapping JSON file into the table"""
    bl_idname = "kinect_retarget.mapping_load"
    bl_label = "Load Mapping"
    bl_options = {"REGISTER", "UNDO"}
    filename_ext = ".json"
    filter_glob: StringProperty(default="*.json", options={"HIDDEN"})

    def execute(self, context):
        s = context.scene.kinect_retarget
        try:
            mapping = load_mapping_file(self.filepath)
        except ValueError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        fill_table(s, mapping)
        obj = target_armature(context)
        if obj is not None:
            missing = [b for b in mapping if b not in obj.data.bones]
            if missing:
                self.report({"WARNING"}, f"{len(missing)} mapped bones are not in {obj.name!r}: "
                                         f"{', '.join(missing[:5])}")
        self.report({"INFO"}, f"Loaded {len(mapping)} mapping rows")
        return {"FINISHED"}


CLASSES = (KINECT_RETARGET_UL_mapping, KINECT_RETARGET_OT_mapping_from_preset, KINECT_RETARGET_OT_mapping_add,
           KINECT_RETARGET_OT_mapping_remove, KINECT_RETARGET_OT_mapping_clear, KINECT_RETARGET_OT_mapping_save,
           KINECT_RETARGET_OT_mapping_load)
