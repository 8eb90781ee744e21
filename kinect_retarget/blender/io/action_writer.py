"""Write a BakedMotion into an Action in bulk (Blender 5.0 slotted actions; keyframe_points.add + foreach_set,
never per-frame keyframe_insert). Keys go into the rotation channel each pose bone already uses."""
from __future__ import annotations

import bpy
import numpy as np
from bpy.utils import escape_identifier
from bpy_extras import anim_utils

from ...core.pipeline import BakedMotion
from ...core.rotation_modes import channel_values

LINEAR = 1  # Keyframe.interpolation enum value


def _new_action(obj: bpy.types.Object, name: str):
    action = bpy.data.actions.new(name)
    slot = action.slots.new(obj.id_type, obj.name)
    channelbag = anim_utils.action_ensure_channelbag_for_slot(action, slot)
    return action, slot, channelbag


def _write_curves(channelbag, data_path: str, group: str, frames: np.ndarray, values: np.ndarray) -> None:
    """values (N, C): one F-Curve per component, N linear keys each."""
    n = frames.shape[0]
    co = np.empty((n, 2), dtype=np.float32)  # float32: foreach_set converts float64 at a cost
    co[:, 0] = frames
    interp = np.full(n, LINEAR, dtype=np.int32)
    for c in range(values.shape[1]):
        fc = channelbag.fcurves.new(data_path, index=c, group_name=group)
        kp = fc.keyframe_points
        kp.add(n)
        co[:, 1] = values[:, c]
        kp.foreach_set("co", co.ravel())
        kp.foreach_set("interpolation", interp)
        # no fcurve.update(): keys are written in order, unique and linear (as Blender's own bake does,
        # bpy_extras.anim_utils.KeyframesCo.insert_keyframes_into_new_action)


def keep_alive(action: bpy.types.Action | None) -> None:
    """An Action about to be unassigned keeps a user, so saving the file does not drop it."""
    if action is not None and action.users <= 1 and not action.use_fake_user:
        action.use_fake_user = True


def bake_motion(obj: bpy.types.Object, motion: BakedMotion, action_name: str,
                extra_curves: list[tuple[str, str, np.ndarray]] = ()) -> bpy.types.Action:
    """Create an Action with one slot for `obj`, key every mapped bone, assign it. Returns the Action.

    extra_curves: (data_path, group, values (C,)) constant channels keyed once at the first frame (e.g.
    Rigify's FK switches). The Action the object had stays in the file (it gets a fake user if this bake
    would leave it with none), so baking never loses the user's animation.
    """
    action, slot, channelbag = _new_action(obj, action_name)
    frames = motion.frames.astype(np.float32)
    pose_bones = obj.pose.bones
    for k, bone in enumerate(motion.bone_names):
        pb = pose_bones[bone]
        suffix, values = channel_values(motion.quats[:, k], pb.rotation_mode)
        _write_curves(channelbag, f'pose.bones["{escape_identifier(bone)}"].{suffix}', bone, frames, values)
    if motion.root_bone is not None:
        path = f'pose.bones["{escape_identifier(motion.root_bone)}"].location'
        _write_curves(channelbag, path, motion.root_bone, frames, motion.root_location)
    for data_path, group, values in extra_curves:
        _write_curves(channelbag, data_path, group, frames[:1], np.reshape(values, (1, -1)))
    ad = obj.animation_data or obj.animation_data_create()
    keep_alive(ad.action)
    ad.action = action
    ad.action_slot = slot
    return action
