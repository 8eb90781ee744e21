"""Build the generated Kinect rig (core/kinect_rig_layout.py) as a Blender armature."""
from __future__ import annotations

import bpy
import numpy as np
from mathutils import Matrix

from ...core.kinect_rig_layout import generated_rig
from ...core.skeletons import Skeleton
from .rig_reader import GENERATED_TAG


def build_kinect_rig(scene: bpy.types.Scene, skeleton: Skeleton, segment_lengths: np.ndarray,
                     name: str = "KinectRig") -> bpy.types.Object:
    """A new armature object linked to the scene's collection: bone j named after joint j, head at its
    parent joint; the root bone named after the root joint, starting at it, pointing up."""
    layout = generated_rig(skeleton, segment_lengths, name)
    arm = bpy.data.armatures.new(name)
    obj = bpy.data.objects.new(name, arm)
    scene.collection.objects.link(obj)
    obj[GENERATED_TAG] = True
    obj["kinect_retarget_skeleton"] = skeleton.name
    view_layer = bpy.context.view_layer
    previous_active = view_layer.objects.active
    view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    try:
        edit = {}
        for j, joint in enumerate(skeleton.joints):
            eb = arm.edit_bones.new(joint)
            eb.head = (0.0, 0.0, 0.0)
            eb.tail = (0.0, 1.0, 0.0)
            eb.matrix = Matrix(layout.rest[j].tolist())  # sets head, direction and roll together
            eb.length = float(layout.lengths[j])
            edit[j] = eb
        for j, p in enumerate(layout.parents):
            if p >= 0:
                edit[j].parent = edit[int(p)]
    finally:
        bpy.ops.object.mode_set(mode="OBJECT")
        view_layer.objects.active = previous_active or obj
    for pb in obj.pose.bones:
        pb.rotation_mode = "QUATERNION"
    return obj
