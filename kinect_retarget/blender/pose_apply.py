"""Set a FramePose on an armature's pose bones (live; main thread only)."""
from __future__ import annotations

import bpy

from ..core.pipeline import FramePose
from ..core.rotation_modes import channel_values


def apply_frame_pose(obj: bpy.types.Object, pose: FramePose) -> None:
    pose_bones = obj.pose.bones
    for k, bone in enumerate(pose.bone_names):
        pb = pose_bones[bone]
        suffix, values = channel_values(pose.quats[k], pb.rotation_mode)
        setattr(pb, suffix, values.tolist())
    if pose.root_bone is not None:
        pose_bones[pose.root_bone].location = pose.root_location.tolist()
    obj.update_tag()


def snapshot_pose(obj: bpy.types.Object) -> dict:
    """The pose channels live mode changes, to restore them when live stops."""
    return {pb.name: (tuple(pb.location), tuple(pb.rotation_quaternion), tuple(pb.rotation_euler),
                      tuple(pb.rotation_axis_angle)) for pb in obj.pose.bones}


def restore_pose(obj: bpy.types.Object, snapshot: dict) -> None:
    for pb in obj.pose.bones:
        if pb.name in snapshot:
            pb.location, pb.rotation_quaternion, pb.rotation_euler, pb.rotation_axis_angle = snapshot[pb.name]
    obj.update_tag()
