"""Auto-Rig Mesh (Object menu): a thin operator over mesh_autorig.rig_mesh_object, one undo step."""
from __future__ import annotations

import bpy
from bpy.props import BoolProperty, EnumProperty, IntProperty, StringProperty

from ...autorig import MeshError
from ..mesh_autorig import rig_mesh_object

JOINT_ITEMS = [("FRACTIONS", "Geodesic Fractions", "Rings at fixed fractions of the body's geodesic length, "
                "moved onto the limbs' axes (default: the more accurate, docs/autorig.md)"),
               ("PAPER", "Paper's Skeleton Points", "Joints on the chain of the paper's level-set centroids "
                "(eq. 7-9) with its shoulder/ankle adjustment (§4.2): Levels (K) and Normalization move them")]
NORMALIZATION_ITEMS = [("SEGMENT", "Per Segment", "Eq. 6 over each feature point's segment: every limb gets K "
                        "levels (default)"),
                       ("GLOBAL", "Global (as printed)", "Eq. 6 over all vertices: short limbs get fewer levels")]
WEIGHT_ITEMS = [("PROJECTION", "Bone Projection", "The paper's bone-projection weights (fast, pure numpy)"),
                ("HEAT", "Heat (Blender)", "Blender's automatic weights (bone heat); slower, smoother")]


class KINECT_RETARGET_OT_autorig_mesh(bpy.types.Operator):
    """Build a Kinect-named armature for the active humanoid mesh in its current pose, with skin weights,
    ready for takes and live streams"""

    bl_idname = "kinect_retarget.autorig_mesh"
    bl_label = "Auto-Rig Mesh"
    bl_options = {"REGISTER", "UNDO"}

    weights: EnumProperty(name="Weights", items=WEIGHT_ITEMS, default="PROJECTION")
    joints: EnumProperty(name="Joints", items=JOINT_ITEMS, default="FRACTIONS")
    levels: IntProperty(name="Levels (K)", description="Topological levels of the paper's skeleton points "
                        "(moves the joints with the paper's rule; shapes the paper skeleton)", default=4, min=2, max=7)
    normalization: EnumProperty(name="Normalization", items=NORMALIZATION_ITEMS, default="SEGMENT",
                                description="Eq. 6: geodesic distance normalized per segment or over all vertices")
    paper_skeleton: BoolProperty(name="Build Paper Skeleton", default=False,
                                 description="Also build the paper's skeleton points and their tree as an armature "
                                             "(one bone per connection) beside the Kinect-named rig")
    rig_name: StringProperty(name="Armature Name", description="Empty: '<mesh>_Rig'", default="")
    bind_selected: BoolProperty(name="Bind Other Selected Meshes", default=True,
                                description="Clothes, eyes or hair kept as separate objects follow the new rig")

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        if obj is None or obj.type != "MESH":
            cls.poll_message_set("Select a mesh to auto-rig")
            return False
        if context.mode != "OBJECT":
            cls.poll_message_set("Auto-rig works in Object Mode")
            return False
        return True

    def draw(self, context):
        layout = self.layout
        layout.prop(self, "weights")
        layout.prop(self, "joints")
        layout.prop(self, "paper_skeleton")
        # K and the normalization act only on the paper's skeleton points: shown only when something uses them
        col = layout.column()
        col.active = self.joints == "PAPER" or self.paper_skeleton
        col.prop(self, "levels")
        col.prop(self, "normalization")
        layout.prop(self, "rig_name")
        layout.prop(self, "bind_selected")

    def execute(self, context):
        mesh_obj = context.active_object
        try:
            extra = context.selected_objects if self.bind_selected else ()
            arm_obj, _, summary = rig_mesh_object(context, mesh_obj, self.weights, self.levels,
                                                  self.rig_name or None, extra, self.joints, self.normalization,
                                                  self.paper_skeleton)
        except MeshError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        except (RuntimeError, ValueError, MemoryError) as exc:  # rolled back already; say what happened
            self.report({"ERROR"}, f"Auto-rig failed, nothing was changed: {exc}")
            return {"CANCELLED"}
        for o in context.view_layer.objects:
            o.select_set(False)
        arm_obj.select_set(True)
        context.view_layer.objects.active = arm_obj
        self.report({"INFO"}, f"{arm_obj.name}: {summary}")
        return {"FINISHED"}


def _menu(self, context):
    self.layout.operator(KINECT_RETARGET_OT_autorig_mesh.bl_idname, icon="ARMATURE_DATA")


def register_extra() -> None:
    bpy.types.VIEW3D_MT_object.append(_menu)


def unregister_extra() -> None:
    bpy.types.VIEW3D_MT_object.remove(_menu)


CLASSES = (KINECT_RETARGET_OT_autorig_mesh,)
