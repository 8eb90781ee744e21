"""Menu entries, so the operators are found where Blender users look and by F3 (Blender 5.0's search lists
only operators that sit in a menu unless Developer Extras is on): File > Import > Kinect Take (bake onto a
rig), and Object > Animation > Kinect Retarget with live, record, calibrate, bake and auto-rig."""
from __future__ import annotations

import bpy

IMPORT_LABEL = "Kinect Take (bake onto a rig)"
# (operator, label, icon) in the Object > Animation > Kinect Retarget submenu
ANIMATION_ITEMS = (
    ("kinect_retarget.live_start", "Start Live", "PLAY"),
    ("kinect_retarget.live_stop", "Stop Live", "PAUSE"),
    ("kinect_retarget.record", "Record / Stop Recording", "REC"),
    ("kinect_retarget.calibrate", "Calibrate", "ARMATURE_DATA"),
    ("kinect_retarget.bake_take", "Bake Take…", "ACTION"),
    ("kinect_retarget.autorig_mesh", "Auto-Rig Mesh", "OUTLINER_OB_ARMATURE"),
)


class KINECT_RETARGET_MT_animation(bpy.types.Menu):
    bl_idname = "KINECT_RETARGET_MT_animation"
    bl_label = "Kinect Retarget"

    def draw(self, context):
        layout = self.layout
        for i, (op, label, icon) in enumerate(ANIMATION_ITEMS):
            if i in (2, 4):
                layout.separator()
            layout.operator(op, text=label, icon=icon)


def _object_animation(self, context):
    self.layout.separator()
    self.layout.menu(KINECT_RETARGET_MT_animation.bl_idname, icon="OUTLINER_OB_ARMATURE")


def _file_import(self, context):
    self.layout.operator("kinect_retarget.bake_take", text=IMPORT_LABEL)


MENU_HOOKS = (("VIEW3D_MT_object_animation", _object_animation), ("TOPBAR_MT_file_import", _file_import))


def register_extra() -> None:
    for menu, func in MENU_HOOKS:
        getattr(bpy.types, menu).append(func)


def unregister_extra() -> None:
    for menu, func in reversed(MENU_HOOKS):
        getattr(bpy.types, menu).remove(func)


CLASSES = (KINECT_RETARGET_MT_animation,)
