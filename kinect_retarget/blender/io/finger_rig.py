"""Hands on the rig: the finger bones of Rigify, Mixamo and UE Mannequin rigs (a renamed Rigify rig's found by
structure: core/control_rig_fingers.py), their curl axes from the rig's rest pose, and the bake step that rolls
the hand from Kinect v2's thumb, bends the fingers toward its hand tip and curls them from the hand states
(core/hand_pose.py). The rig itself is never changed."""
from __future__ import annotations

from dataclasses import dataclass, replace

import bpy
import numpy as np

from ...core.control_rig_fingers import finger_chains_by_structure
from ...core.conventions import kinect_to_blender
from ...core.hand_pose import (CURL_DEG, FINGERS, finger_chains, finger_curls, finger_quats, fingers_bend,
                               hand_roll, twist_quats)
from ...core.quat import make_continuous, normalize, to_matrix
from .rig_reader import target_rig_from_object


@dataclass
class HandRig:
    side: str                       # "Left" / "Right" (the performer's side the hand bone is mapped to)
    hand: str                       # the hand bone
    thumb_local: np.ndarray         # (3,) the thumb's side of the hand, in the hand bone's rest frame
    curl_local: np.ndarray          # (3,) the fingers' curl axis, in the hand bone's rest frame
    chains: dict[str, list[str]]    # finger -> bones, base to tip
    axes: dict[str, np.ndarray]     # finger bone -> (3,) curl axis in its own rest frame


def _perp(v: np.ndarray, axis: np.ndarray) -> np.ndarray:
    return normalize(v - np.dot(v, axis) * axis)


def _fingers_by_structure(obj: bpy.types.Object, hand: str) -> dict[str, list[str]] | None:
    """A control rig's finger controls found without names (a renamed Rigify rig), else None."""
    rig = target_rig_from_object(obj)
    found = finger_chains_by_structure(rig.parents, rig.heads, rig.tails, rig.links, rig.index(hand))
    return None if found is None else {f: [rig.bone_names[b] for b in chain] for f, chain in found.items()}


def hand_rig(obj: bpy.types.Object, hand: str, side: str) -> HandRig | None:
    """The hand's finger rig from the armature's rest pose, or None when it has no four-finger chains."""
    bones = obj.data.bones
    if hand not in bones:
        return None
    chains = finger_chains(bones.keys(), side) or _fingers_by_structure(obj, hand)
    if chains is None:
        return None
    rest = np.array(bones[hand].matrix_local)[:3, :3]
    head = np.array(bones[hand].head_local)
    y = rest[:, 1]
    lateral = _perp(np.array(bones[chains["pinky"][0]].head_local) - np.array(bones[chains["index"][0]].head_local),
                    y)
    palm = normalize(np.cross(y, lateral))
    tip = np.array(bones[chains["thumb"][-1]].tail_local) if "thumb" in chains else head + palm
    if np.dot(palm, tip - head) < 0:  # the thumb sits on the palm's side
        palm = -palm
    axes = {}
    for chain in chains.values():
        for b in chain:
            m = np.array(bones[b].matrix_local)[:3, :3]
            axes[b] = m.T @ normalize(np.cross(m[:, 1], palm))  # turning the bone's Y toward the palm
    return HandRig(side, hand, rest.T @ _perp(tip - head, y), rest.T @ normalize(np.cross(y, palm)), chains, axes)


def hands_on_rig(obj: bpy.types.Object, mapped) -> list[HandRig]:
    """HandRigs for the bones mapped to HandLeft/HandRight (retargeter.mapped) that have fingers."""
    out = []
    for m in mapped:
        for side in ("Left", "Right"):
            if m.tail_name == f"Hand{side}":
                rig = hand_rig(obj, m.bone, side)
                if rig is not None:
                    out.append(rig)
    return out


def hand_frames(rig: HandRig, hand_quats: np.ndarray, desired: np.ndarray, hand: np.ndarray, thumb: np.ndarray,
                tip: np.ndarray, curls: np.ndarray | None) -> tuple[np.ndarray, list[tuple[str, np.ndarray]]]:
    """One hand over F frames (bake: a take, live: one frame): the hand bone's pose quaternions (F, 4) rolled
    to the thumb, and (finger bone, (F, 4)) bent toward the hand tip and curled by `curls` (F, 5) or not.
    desired (F, 3, 3) the hand's armature-space rotation; hand, thumb, tip (F, 3) joints in armature space."""
    roll = hand_roll(desired, rig.thumb_local, thumb - hand)
    c, s = np.cos(roll), np.sin(roll)
    ry = np.zeros((len(roll), 3, 3))
    ry[:, 0, 0], ry[:, 0, 2], ry[:, 1, 1], ry[:, 2, 0], ry[:, 2, 2] = c, s, 1.0, -s, c
    bend = fingers_bend(desired @ ry, rig.curl_local, tip - hand)
    curls = np.zeros((len(roll), len(FINGERS))) if curls is None else curls
    fingers = []
    for f, finger in enumerate(FINGERS):
        for j, bone in enumerate(rig.chains.get(finger, ())):
            angle = np.radians(CURL_DEG) * curls[:, f] + (bend if j == 0 and finger != "thumb" else 0.0)
            fingers.append((bone, finger_quats(rig.axes[bone], angle)))
    return twist_quats(hand_quats, roll), fingers


def _has_hand_joints(rig: HandRig, index: dict) -> bool:
    return {f"Hand{rig.side}", f"HandTip{rig.side}", f"Thumb{rig.side}"} <= set(index)


def apply_hands(motion, rigs: list[HandRig], take, joints: tuple[str, ...], mirror: bool) -> list[str]:
    """Roll each hand from the thumb, bend and curl its fingers; the finger bones join the motion's keyed
    bones. joints: the take's joint names. Returns the finger bones added."""
    p = kinect_to_blender(motion.extras["positions"])  # armature space (the retarget's frame)
    index = {n: i for i, n in enumerate(joints)}
    added, quats = [], []
    for rig in rigs:
        if rig.hand not in motion.bone_names or not _has_hand_joints(rig, index):
            continue
        k = motion.bone_names.index(rig.hand)
        curls = None
        if take.hand_states is not None:
            column = (0 if rig.side == "Left" else 1) ^ int(mirror)  # mirrored takes swap the hands
            curls = finger_curls(take.hand_states[:, column], take.times)[motion.samples]
        joint = [p[:, index[f"{j}{rig.side}"]] for j in ("Hand", "Thumb", "HandTip")]
        motion.quats[:, k], fingers = hand_frames(rig, motion.quats[:, k], to_matrix(motion.extras["desired"][:, k]),
                                                  *joint, curls)
        added += [b for b, _ in fingers]
        quats += [q for _, q in fingers]
    if added:
        motion.bone_names = tuple(motion.bone_names) + tuple(added)
        motion.quats = make_continuous(np.concatenate([motion.quats, np.stack(quats, axis=1)], axis=1), axis=0)
    return added


def pose_with_hands(pose, rigs: list[HandRig], joints: tuple[str, ...]):
    """A live FramePose with the hands rolled and the fingers bent (live sources give no hand states), as
    the bake of its recording keys them."""
    if not rigs or pose.positions is None:
        return pose
    p = kinect_to_blender(pose.positions)
    index = {n: i for i, n in enumerate(joints)}
    names, quats = list(pose.bone_names), pose.quats.copy()
    for rig in rigs:
        if rig.hand not in names or not _has_hand_joints(rig, index):
            continue
        k = names.index(rig.hand)
        joint = [p[None, index[f"{j}{rig.side}"]] for j in ("Hand", "Thumb", "HandTip")]
        hand, fingers = hand_frames(rig, quats[k][None], to_matrix(pose.desired[k])[None], *joint, None)
        quats[k] = hand[0]
        names += [b for b, _ in fingers]
        quats = np.concatenate([quats, np.stack([q[0] for _, q in fingers])])
    return replace(pose, bone_names=tuple(names), quats=quats)
