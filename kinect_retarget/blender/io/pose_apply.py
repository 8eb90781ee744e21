"""Set a FramePose on an armature's pose bones (live; main thread only)."""
from __future__ import annotations

import bpy

from ...core.pipeline import FramePose
from ...core.rotation_modes import channel_values


def set_rotations(pose_bones, bone_names, quats) -> None:
    """quats (M, 4) into each pose bone's own rotation channel (quaternion, Euler order or axis-angle)."""
    for name, q in zip(bone_names, quats):
        pb = pose_bones[name]
        suffix, values = channel_values(q, pb.rotation_mode)
        setattr(pb, suffix, values.tolist())


def apply_frame_pose(obj: bpy.types.Object, pose: FramePose) -> None:
    pose_bones = obj.pose.bones
    set_rotations(pose_bones, pose.bone_names, pose.quats)
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
