"""The sidebar's performers: the target's body and more rigs, each following one body of a source with
several (an NTU or Kinectron take with two people, NI mate's numbered OSC users). Live drives them all from
one source; Bake Take bakes each body onto its rig."""
from __future__ import annotations

import bpy
from bpy.props import IntProperty, PointerProperty

MAX_BODY = 15  # bodies from 0; sensors track up to 6, OSC bridges number a few more


def is_armature(self, obj) -> bool:
    return obj.type == "ARMATURE"


class KinectRetargetPerformer(bpy.types.PropertyGroup):
    """One more rig and the body it follows."""
    armature: PointerProperty(name="Armature", type=bpy.types.Object, poll=is_armature,
                              description="Rig this performer drives")
    body: IntProperty(name="Body", default=1, min=0, max=MAX_BODY,
                      description="Which performer of the source (from 0: NTU's and Kinectron's bodies in order, "
                                  "NI mate's user N is body N-1)")


class KINECT_RETARGET_UL_performers(bpy.types.UIList):
    def draw_item(self, context, layout, data, item, icon, active_data, active_property, index=0, flt_flag=0):
        row = layout.row(align=True)
        row.prop(item, "armature", text="")
        row.prop(item, "body")
        row.operator("kinect_retarget.performer_remove", text="", icon="X", emboss=False).index = index


class KINECT_RETARGET_OT_performer_add(bpy.types.Operator):
    """Add a rig that follows another performer of the source"""
    bl_idname = "kinect_retarget.performer_add"
    bl_label = "Add Performer"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        s = context.scene.kinect_retarget
        taken = [s.body, *(p.body for p in s.performers)]
        item = s.performers.add()
        item.body = min(max(taken) + 1, MAX_BODY)  # the next body nobody follows yet
        s.performers_index = len(s.performers) - 1
        return {"FINISHED"}


class KINECT_RETARGET_OT_performer_remove(bpy.types.Operator):
    """Remove this performer (its rig keeps whatever was baked onto it)"""
    bl_idname = "kinect_retarget.performer_remove"
    bl_label = "Remove Performer"
    bl_options = {"REGISTER", "UNDO", "INTERNAL"}

    index: IntProperty(options={"HIDDEN"})

    def execute(self, context):
        performers = context.scene.kinect_retarget.performers
        if not 0 <= self.index < len(performers):
            self.report({"ERROR"}, f"no performer {self.index} in the list")
            return {"CANCELLED"}
        performers.remove(self.index)
        return {"FINISHED"}


def draw_performers(layout, s) -> None:
    """Under the target: its body, and the other performers' rigs."""
    layout.prop(s, "body", text="Follows Body")
    layout.label(text="Other Performers")
    layout.template_list("KINECT_RETARGET_UL_performers", "", s, "performers", s, "performers_index", rows=2)
    layout.operator("kinect_retarget.performer_add", icon="ADD")


def other_performers(scene) -> list[tuple[bpy.types.Object, int]]:
    """(armature, body) of the sidebar's other performers that name an armature."""
    s = getattr(scene, "kinect_retarget", None)
    return [] if s is None else [(p.armature, p.body) for p in s.performers if p.armature is not None]


CLASSES = (KinectRetargetPerformer, KINECT_RETARGET_UL_performers, KINECT_RETARGET_OT_performer_add,
           KINECT_RETARGET_OT_performer_remove)
