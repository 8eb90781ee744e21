"""The sidebar's takes list: the recordings of this .blend (name, length, date), each with Bake, Rename,
Reveal (in the system's file browser) and Delete (from disk, after a confirmation)."""
from __future__ import annotations

import os
import time

import bpy
from bpy.props import IntProperty, StringProperty

from ...core.take import TakeError
from ...takes import load_take
from .bake_settings import BakeOptionProps
from .sidebar_panel import KinectSidebarPanel


def add_take(scene: bpy.types.Scene, path: str) -> None:
    """List a recording just written (newest last, made active)."""
    s = scene.kinect_retarget
    item = s.takes.add()
    item.name, item.path = os.path.splitext(os.path.basename(path))[0], path
    item.date = time.strftime("%Y-%m-%d %H:%M")
    try:
        take = load_take(path)
        item.seconds, item.frames = take.duration, take.frame_count
    except (TakeError, OSError):
        pass  # listed anyway: the file is what the user has
    s.takes_index = len(s.takes) - 1


def _item(context, index: int):
    s = context.scene.kinect_retarget
    return s.takes[index] if 0 <= index < len(s.takes) else None


class KINECT_RETARGET_UL_takes(bpy.types.UIList):
    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index):
        row = layout.row(align=True)
        missing = not os.path.isfile(bpy.path.abspath(item.path))
        row.label(text=item.name, icon="ERROR" if missing else "FILE_MOVIE")
        sub = row.row(align=True)
        sub.alignment = "RIGHT"
        sub.label(text=f"{item.seconds:.1f} s")
        sub.label(text=item.date)


class _TakeOperator:
    index: IntProperty(default=-1, options={"HIDDEN", "SKIP_SAVE"})

    def take(self, context):
        s = context.scene.kinect_retarget
        return _item(context, self.index if self.index >= 0 else s.takes_index)

    def file_or_report(self, context):
        item = self.take(context)
        if item is None:
            self.report({"ERROR"}, "No take selected")
            return None, None
        path = bpy.path.abspath(item.path)
        if not os.path.isfile(path):
            self.report({"ERROR"}, f"{item.name}: the file {path} is gone")
            return item, None
        return item, path


class KINECT_RETARGET_OT_take_bake(_TakeOperator, bpy.types.Operator):
    """Bake this take onto the target armature with the sidebar's preset, filter and bake options"""
    bl_idname = "kinect_retarget.take_bake"
    bl_label = "Bake Take"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        item, path = self.file_or_report(context)
        if path is None:
            return {"CANCELLED"}
        s = context.scene.kinect_retarget
        options = {name: getattr(s, name) for name in BakeOptionProps.__annotations__}
        try:
            return bpy.ops.kinect_retarget.bake_take("EXEC_DEFAULT", filepath=path, preset=s.preset, filter=s.filter,
                                                     root=s.root, mirror=s.mirror, root_scale=s.root_scale,
                                                     **options)
        except RuntimeError as exc:
            self.report({"ERROR"}, str(exc).removeprefix("Error: ").strip())
            return {"CANCELLED"}


class KINECT_RETARGET_OT_take_rename(_TakeOperator, bpy.types.Operator):
    """Rename this take and its file"""
    bl_idname = "kinect_retarget.take_rename"
    bl_label = "Rename Take"
    bl_options = {"REGISTER", "UNDO"}

    new_name: StringProperty(name="Name")

    def invoke(self, context, event):
        item = self.take(context)
        if item is not None:
            self.new_name = item.name
        return context.window_manager.invoke_props_dialog(self)

    def execute(self, context):
        item, path = self.file_or_report(context)
        if path is None:
            return {"CANCELLED"}
        name = self.new_name.strip().replace("/", "_").replace("\\", "_")  # a name, never a path
        if not name:
            self.report({"ERROR"}, "Give the take a name")
            return {"CANCELLED"}
        target = os.path.join(os.path.dirname(path), name + os.path.splitext(path)[1])
        if os.path.exists(target) and os.path.abspath(target) != os.path.abspath(path):
            self.report({"ERROR"}, f"{target} already exists")
            return {"CANCELLED"}
        os.replace(path, target)
        item.name, item.path = name, target
        return {"FINISHED"}


class KINECT_RETARGET_OT_take_reveal(_TakeOperator, bpy.types.Operator):
    """Show this take's file in the system's file browser"""
    bl_idname = "kinect_retarget.take_reveal"
    bl_label = "Reveal Take"
    bl_options = {"REGISTER"}

    def execute(self, context):
        item, path = self.file_or_report(context)
        if path is None:
            return {"CANCELLED"}
        bpy.ops.wm.path_open(filepath=os.path.dirname(path))
        return {"FINISHED"}


class KINECT_RETARGET_OT_take_delete(_TakeOperator, bpy.types.Operator):
    """Delete this take's file from disk (after a confirmation) and remove it from the list"""
    bl_idname = "kinect_retarget.take_delete"
    bl_label = "Delete Take"
    bl_options = {"REGISTER", "UNDO"}

    def invoke(self, context, event):
        item = self.take(context)
        name = item.name if item is not None else "the take"
        return context.window_manager.invoke_confirm(self, event, title=f"Delete {name}?",
                                                     message="The file is deleted from disk", confirm_text="Delete",
                                                     icon="WARNING")

    def execute(self, context):
        item = self.take(context)
        if item is None:
            self.report({"ERROR"}, "No take selected")
            return {"CANCELLED"}
        path = bpy.path.abspath(item.path)
        if os.path.isfile(path):
            os.remove(path)
        s = context.scene.kinect_retarget
        s.takes.remove(list(s.takes).index(item))
        s.takes_index = min(s.takes_index, len(s.takes) - 1)
        self.report({"INFO"}, f"Deleted {path}")
        return {"FINISHED"}


class KINECT_RETARGET_PT_takes(KinectSidebarPanel, bpy.types.Panel):
    bl_label = "Takes"
    bl_parent_id = "KINECT_RETARGET_PT_main"

    def draw(self, context):
        layout = self.layout
        s = context.scene.kinect_retarget
        if not len(s.takes):
            layout.label(text="Recordings of this file appear here", icon="INFO")
            return
        row = layout.row()
        row.template_list("KINECT_RETARGET_UL_takes", "", s, "takes", s, "takes_index", rows=4)
        col = row.column(align=True)
        col.operator("kinect_retarget.take_bake", icon="ACTION", text="")
        col.operator("kinect_retarget.take_rename", icon="GREASEPENCIL", text="")
        col.operator("kinect_retarget.take_reveal", icon="FILEBROWSER", text="")
        col.separator()
        col.operator("kinect_retarget.take_delete", icon="TRASH", text="")


CLASSES = (KINECT_RETARGET_UL_takes, KINECT_RETARGET_OT_take_bake, KINECT_RETARGET_OT_take_rename,
           KINECT_RETARGET_OT_take_reveal, KINECT_RETARGET_OT_take_delete, KINECT_RETARGET_PT_takes)
