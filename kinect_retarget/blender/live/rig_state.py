"""What live changes on the rig (pose, action, Rigify IK/FK switches), saved by name before live starts and put
back when it stops: undo during live invalidates bpy references, names survive it."""
from __future__ import annotations

import bpy

from ..io.pose_apply import restore_pose, snapshot_pose
from ..io.rig_reader import fk_switch_bones


def save_rig_state(obj) -> dict:
    ad = obj.animation_data
    action = ad.action if ad else None
    state = {"pose": snapshot_pose(obj),
             "ik_fk": {n: obj.pose.bones[n]["IK_FK"] for n in fk_switch_bones(obj)},
             "action": action.name if action else None,
             "slot": ad.action_slot.identifier if action is not None and ad.action_slot else None,
             "fake_user": action.use_fake_user if action is not None else False}
    if action is not None:
        # unassigned while live (it would overwrite the live pose on every evaluation), but held by a fake
        # user so that saving during live, or a crash, does not drop it; the user's flag comes back on stop
        action.use_fake_user = True
        ad.action = None
    return state


def switch_limbs_to_fk(obj) -> None:
    """The presets drive Rigify's FK controls: switch the limbs to FK while live (restored on stop)."""
    for name in fk_switch_bones(obj):
        obj.pose.bones[name]["IK_FK"] = 1.0


def restore_rig_state(obj, state: dict, keep_animation: bool) -> None:
    for name, value in state["ik_fk"].items():
        if name in obj.pose.bones:
            obj.pose.bones[name]["IK_FK"] = value
    action = bpy.data.actions.get(state["action"]) if state["action"] else None
    if keep_animation:  # the baked recording now animates the rig
        if action is not None:
            action.use_fake_user = state.get("fake_user", False)
            if action.users == 0:
                action.use_fake_user = True  # the rig's previous action must not vanish on the next save
        return
    restore_pose(obj, state["pose"])
    if action is not None:
        ad = obj.animation_data or obj.animation_data_create()
        ad.action = action
        slot = next((sl for sl in action.slots if sl.identifier == state["slot"]), None)
        if slot is not None:
            ad.action_slot = slot
        action.use_fake_user = state.get("fake_user", False)
