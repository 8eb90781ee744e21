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


def _merge_keys(fc, co: np.ndarray, interp: np.ndarray) -> None:
    """Replace fc's keys within the new keys' frame range by the new ones; keys outside stay as they were."""
    kp = fc.keyframe_points
    n_old = len(kp)
    old = np.empty(2 * n_old, dtype=np.float32)
    kp.foreach_get("co", old)
    first, last = co[0, 0], co[-1, 0]
    for i in reversed(np.flatnonzero((old[0::2] >= first - 0.5) & (old[0::2] <= last + 0.5))):
        kp.remove(kp[int(i)], fast=True)
    n_kept = len(kp)
    kp.add(len(co))
    flat = np.empty(2 * len(kp), dtype=np.float32)
    kp.foreach_get("co", flat)
    flat[2 * n_kept:] = co.ravel()
    kp.foreach_set("co", flat)
    modes = np.empty(len(kp), dtype=np.int32)
    kp.foreach_get("interpolation", modes)
    modes[n_kept:] = interp
    kp.foreach_set("interpolation", modes)
    fc.update()  # sort the appended keys in among the kept ones


def _write_curves(channelbag, data_path: str, group: str, frames: np.ndarray, values: np.ndarray,
                  keys=None, merge: bool = False) -> None:
    """values (N, C): one F-Curve per component, N linear keys each (only the indices `keys` when given).
    merge: key into existing F-Curves, replacing their keys in the baked frame range."""
    if keys is not None:
        frames, values = frames[keys], values[keys]
    n = frames.shape[0]
    co = np.empty((n, 2), dtype=np.float32)  # float32: foreach_set converts float64 at a cost
    co[:, 0] = frames
    interp = np.full(n, LINEAR, dtype=np.int32)
    for c in range(values.shape[1]):
        co[:, 1] = values[:, c]
        fc = channelbag.fcurves.find(data_path, index=c) if merge else None
        if fc is not None:
            _merge_keys(fc, co, interp)
            continue
        fc = channelbag.fcurves.new(data_path, index=c, group_name=group)
        kp = fc.keyframe_points
        kp.add(n)
        kp.foreach_set("co", co.ravel())
        kp.foreach_set("interpolation", interp)
        # no fcurve.update(): keys are written in order, unique and linear (as Blender's own bake does,
        # bpy_extras.anim_utils.KeyframesCo.insert_keyframes_into_new_action)


def keep_alive(action: bpy.types.Action | None) -> None:
    """An Action about to be unassigned keeps a user, so saving the file does not drop it."""
    if action is not None and action.users <= 1 and not action.use_fake_user:
        action.use_fake_user = True


def _current_action(obj: bpy.types.Object, action_name: str):
    """The Action and slot the object plays now (a slot is added when it has none), or a new Action."""
    ad = obj.animation_data
    if ad is None or ad.action is None:
        return _new_action(obj, action_name)
    action = ad.action
    slot = ad.action_slot or action.slots.new(obj.id_type, obj.name)
    return action, slot, anim_utils.action_ensure_channelbag_for_slot(action, slot)


def bake_motion(obj: bpy.types.Object, motion: BakedMotion, action_name: str,
                extra_curves: list[tuple[str, str, np.ndarray]] = (), *, keys=None,
                into_current: bool = False) -> bpy.types.Action:
    """Create an Action with one slot for `obj`, key every mapped bone, assign it. Returns the Action.

    extra_curves: (data_path, group, values (C,)) constant channels keyed once at the first frame (e.g.
    Rigify's FK switches). The Action the object had stays in the file (it gets a fake user if this bake
    would leave it with none), so baking never loses the user's animation.
    keys: a key_reduction.Reduction (indices kept per bone, for the root location and for root motion's root
    bone), or None for all.
    into_current: key into the Action the object plays (replacing its keys in the baked frame range).
    """
    if into_current:
        action, slot, channelbag = _current_action(obj, action_name)
    else:
        action, slot, channelbag = _new_action(obj, action_name)
    frames = motion.frames.astype(np.float32)
    pose_bones = obj.pose.bones
    for k, bone in enumerate(motion.bone_names):
        pb = pose_bones[bone]
        suffix, values = channel_values(motion.quats[:, k], pb.rotation_mode)
        _write_curves(channelbag, f'pose.bones["{escape_identifier(bone)}"].{suffix}', bone, frames, values,
                      keys.rotation_keys[k] if keys is not None else None, into_current)
    if motion.root_bone is not None:
        path = f'pose.bones["{escape_identifier(motion.root_bone)}"].location'
        _write_curves(channelbag, path, motion.root_bone, frames, motion.root_location,
                      keys.location_keys if keys is not None else None, into_current)
    for bone, location in motion.extras.get("locations", {}).items():  # root motion's root bone
        _write_curves(channelbag, f'pose.bones["{escape_identifier(bone)}"].location', bone, frames, location,
                      keys.other_location_keys.get(bone) if keys is not None else None, into_current)
    for data_path, group, values in extra_curves:
        _write_curves(channelbag, data_path, group, frames[:1], np.reshape(values, (1, -1)), None, into_current)
    ad = obj.animation_data or obj.animation_data_create()
    if ad.action != action:
        keep_alive(ad.action)
        ad.action = action
    ad.action_slot = slot
    return action


def push_to_nla(obj: bpy.types.Object, name: str, start: int) -> bpy.types.NlaStrip:
    """Blender's Push Down: the object's Action becomes a strip named `name` on a new NLA track (above the
    others) starting at frame `start`; the object is left with no active Action."""
    ad = obj.animation_data
    action, slot = ad.action, ad.action_slot
    track = ad.nla_tracks.new()
    track.name = name
    strip = track.strips.new(name, int(start), action)
    if slot is not None and strip.action_slot != slot:
        strip.action_slot = slot
    ad.action = None
    return strip


def bake_channels(obj: bpy.types.Object, action_name: str, frames: np.ndarray,
                  channels: list[tuple[str, str, np.ndarray]]) -> bpy.types.Action:
    """A new Action for `obj` keyed in bulk with (data_path, group, values (N, C)) channels at `frames`
    (N,), assigned to it (the Action it had keeps a user)."""
    action, slot, channelbag = _new_action(obj, action_name)
    for data_path, group, values in channels:
        _write_curves(channelbag, data_path, group, np.asarray(frames, np.float32), np.asarray(values))
    ad = obj.animation_data or obj.animation_data_create()
    keep_alive(ad.action)
    ad.action = action
    ad.action_slot = slot
    return action
