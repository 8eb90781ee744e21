"""Paper 004's result in Blender: a 16-joint H-Anim armature keyed with the Euler angles of its IK
(lift/hanim.py), one rotation_euler channel per joint ('XYZ' mode: X first, then Y = β = 0, then Z) and
the pelvis's location."""
from __future__ import annotations

import bpy
import numpy as np
from bpy.utils import escape_identifier

from ...core.conventions import kinect_to_blender
from ...core.skeletons import KINECT_V1
from ...core.take import Take
from ...lift import hanim
from .action_writer import bake_channels


def build_hanim_figure(context, take: Take, name: str = "HAnim", frame_start: int = 1) -> bpy.types.Object:
    """An armature named `name` in the scene's collection, rest = H-Anim's default posture with the
    take's bone lengths, keyed over the take's frames (one key per take frame from frame_start)."""
    if take.skeleton.joints != KINECT_V1.joints:
        raise ValueError(f"the H-Anim figure is driven by Kinect v1 joints (a lifted take); this take has "
                         f"the {take.skeleton.name} skeleton")
    pos = kinect_to_blender(np.where(take.states[..., None] > 0, take.positions, np.nan))
    lengths = hanim.bone_lengths(pos)
    heads, tails = hanim.rest_pose(lengths, pos)
    rest = hanim.rest_frames(heads, tails)
    euler = hanim.solve_euler(pos, rest)
    arm = bpy.data.armatures.new(name)
    obj = bpy.data.objects.new(name, arm)
    context.scene.collection.objects.link(obj)
    obj["kinect_retarget_hanim"] = "paper 004: 16-joint H-Anim figure, Euler angles from IK (beta = 0)"
    from ..mesh_autorig import armature_edit
    with armature_edit(context, obj):
        edit = []
        for k, joint in enumerate(hanim.NAMES):
            eb = arm.edit_bones.new(joint)
            eb.head, eb.tail = heads[k].tolist(), tails[k].tolist()
            eb.align_roll(rest[k][:, 2].tolist())  # the bone's Z axis: the frame the angles are measured in
            if hanim.PARENTS[k] >= 0:
                eb.parent = edit[hanim.PARENTS[k]]
                eb.use_connect = False
            edit.append(eb)
    for pb in obj.pose.bones:
        pb.rotation_mode = "XYZ"
    frames = frame_start + np.arange(take.frame_count)
    channels = [(f'pose.bones["{escape_identifier(j)}"].rotation_euler', j, euler[:, k])
                for k, j in enumerate(hanim.NAMES)]
    pelvis = pos[:, hanim.AT[0]]
    ok = np.isfinite(pelvis).all(axis=1)
    if ok.any():  # the root bone's location is in its own rest frame
        pelvis = np.where(ok[:, None], pelvis, pelvis[ok][0])
        channels.append(('pose.bones["sacroiliac"].location', "sacroiliac", (pelvis - heads[0]) @ rest[0]))
    bake_channels(obj, f"{take.metadata.get('name', 'lift')}_HAnim", frames, channels)
    return obj


def hanim_to_file(take: Take, out_path: str) -> dict:
    """Headless: a fresh scene at the take's rate holding only the keyed H-Anim figure, saved to out_path."""
    from ..headless import save_blend

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = max(1, int(round(take.rate)))
    scene.frame_start, scene.frame_end = 1, max(1, take.frame_count)
    obj = build_hanim_figure(bpy.context, take, "HAnim")
    save_blend(out_path)
    return {"hanim": out_path, "armature": obj.name, "joints": len(obj.data.bones),
            "action": obj.animation_data.action.name}
