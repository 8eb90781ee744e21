"""The Movie Clip editor's Track menu: Track Joints (paper 004's colour particle filter) and Lift Clip Tracks
to 3D, thin operators over clip_lift's functions."""
from __future__ import annotations

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, StringProperty

from ...core.presets import PRESET_NAMES
from ...core.take import TakeError
from ...lift import LiftError
from ..clip_lift import NEW_HANIM, NEW_RIG, lift_clip_and_bake, track_clip_joints


def _armature_items(self, context):
    items = [(NEW_RIG, "New Kinect Rig", "Generate an armature matching the lifted skeleton"),
             (NEW_HANIM, "New H-Anim Figure (paper)", "Paper 004's output: a 16-joint H-Anim armature keyed "
                                                     "with Euler angles from its inverse kinematics")]
    items += [(o.name, o.name, "Bake onto this armature") for o in context.scene.objects if o.type == "ARMATURE"]
    return items


class KINECT_RETARGET_OT_lift_clip(bpy.types.Operator):
    """Lift the active Movie Clip's joint tracks (named like 'l_elbow' or 'ElbowLeft') to 3D and bake them onto a rig"""

    bl_idname = "kinect_retarget.lift_clip"
    bl_label = "Lift Clip Tracks to 3D"
    bl_options = {"REGISTER", "UNDO"}

    armature: EnumProperty(name="Rig", items=_armature_items,
                           description="Armature to bake onto, or a new Kinect rig")
    preset: EnumProperty(name="Preset", items=[(p, p, f"Bone-mapping preset {p}") for p in PRESET_NAMES],
                         default="auto")
    height: FloatProperty(name="Performer Height", default=1.70, min=0.5, max=2.6, unit="LENGTH",
                          description="Sets the bone lengths used to lift the tracks")
    use_clip_camera: BoolProperty(name="Use Clip Camera", default=True,
                                  description="Perspective lifting with the clip's focal length (turn off "
                                              "when the camera settings were never set)")
    method: EnumProperty(name="Method", default="ours", items=[
        ("ours", "Ours", "Perspective when the clip's camera is known, smoothed, depth signs over the whole take"),
        ("paper", "Paper (as published)", "Paper 004: scaled orthographic camera, eq. 3 scale, plain depth "
                                          "with signs by continuity, no smoothing (Depth Choice and the "
                                          "clip camera are not used)")])
    signs: EnumProperty(name="Depth Choice", default="viterbi", items=[
        ("viterbi", "Whole Take", "Choose limb depths over the whole take (best)"),
        ("greedy", "Frame by Frame", "Choose limb depths causally, frame after frame"),
        ("camera", "Toward Camera", "No disambiguation: every bone toward the camera")])
    take_path: StringProperty(name="Save Take", subtype="FILE_PATH", default="",
                              description="Also save the lifted take (.krtake) here")

    @classmethod
    def poll(cls, context):
        if _active_clip(context) is None:
            cls.poll_message_set("Open a tracked Movie Clip (Clip Editor) or set the scene's active clip")
            return False
        return True

    def invoke(self, context, event):
        obj = context.active_object
        if obj is not None and obj.type == "ARMATURE":
            self.armature = obj.name
        return context.window_manager.invoke_props_dialog(self)

    def draw(self, context):
        layout = self.layout
        layout.prop(self, "armature")
        col = layout.column()
        col.active = self.armature != NEW_HANIM  # the H-Anim figure is keyed directly, no preset
        col.prop(self, "preset")
        layout.prop(self, "method")
        layout.prop(self, "height")
        col = layout.column()
        col.active = self.method != "paper"  # the paper's camera is orthographic and its signs its own
        col.prop(self, "use_clip_camera")
        col.prop(self, "signs")
        layout.prop(self, "take_path")

    def execute(self, context):
        clip = _active_clip(context)
        try:
            result = lift_clip_and_bake(context, clip, self.armature, self.preset, self.height,
                                        self.use_clip_camera, self.signs, bpy.path.abspath(self.take_path),
                                        self.report, method=self.method)
        except (LiftError, TakeError, ValueError) as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        return {"FINISHED"} if result is not None else {"CANCELLED"}


def _active_clip(context):
    return getattr(context, "edit_movieclip", None) or context.scene.active_clip


class KINECT_RETARGET_OT_track_clip_joints(bpy.types.Operator):
    """Follow joint-named tracks from the current frame with paper 004's colour particle-filter tracker
    (image-sequence clips); writes their markers"""

    bl_idname = "kinect_retarget.track_clip_joints"
    bl_label = "Track Joints (Colour Particle Filter)"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        clip = _active_clip(context)
        if clip is None or clip.source != "SEQUENCE":
            cls.poll_message_set("Needs an image-sequence Movie Clip with joint-named tracks")
            return False
        return True

    def execute(self, context):
        clip = _active_clip(context)
        start = context.scene.frame_current - clip.frame_start + 1
        try:
            track_clip_joints(clip, start, report=self.report)
        except (LiftError, ValueError) as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        return {"FINISHED"}


def _menu(self, context):
    self.layout.separator()
    self.layout.operator(KINECT_RETARGET_OT_track_clip_joints.bl_idname, icon="TRACKING_FORWARDS")
    self.layout.operator(KINECT_RETARGET_OT_lift_clip.bl_idname, icon="ARMATURE_DATA")


def register_extra() -> None:
    bpy.types.CLIP_MT_track.append(_menu)


def unregister_extra() -> None:
    bpy.types.CLIP_MT_track.remove(_menu)


CLASSES = (KINECT_RETARGET_OT_lift_clip, KINECT_RETARGET_OT_track_clip_joints)
