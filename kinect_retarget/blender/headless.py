"""Headless entry points (bpy as a module): open or build a rig, bake, save."""
from __future__ import annotations

import os

import bpy

from ..core.pipeline import RetargetSettings
from ..core.take import Take
from .bake_take import bake_take, new_generated_rig


def find_armature(name: str | None) -> bpy.types.Object:
    arms = [o for o in bpy.data.objects if o.type == "ARMATURE"]
    if name:
        obj = bpy.data.objects.get(name)
        if obj is None or obj.type != "ARMATURE":
            raise ValueError(f"no armature named {name!r} (armatures: {', '.join(o.name for o in arms) or 'none'})")
        return obj
    if len(arms) != 1:
        raise ValueError(f"{len(arms)} armatures in the file ({', '.join(o.name for o in arms) or 'none'}): "
                         "name one with --armature")
    return arms[0]


def bake_to_file(take: Take, out_path: str, *, rig_path: str | None = None, armature: str | None = None,
                 preset: str = "auto", overrides: dict | None = None,
                 settings: RetargetSettings | None = None) -> dict:
    """Bake onto the armature of rig_path (or a generated Kinect rig) and save out_path. Returns a summary."""
    messages: list[str] = []
    if rig_path:
        if not os.path.isfile(rig_path):
            raise ValueError(f"{rig_path}: rig file not found")
        bpy.ops.wm.open_mainfile(filepath=os.path.abspath(rig_path), load_ui=False)
        obj = find_armature(armature)
    else:
        bpy.ops.wm.read_factory_settings(use_empty=True)
        obj = new_generated_rig(bpy.context.scene, take)
        preset = "kinect" if preset == "auto" else preset
    bpy.context.view_layer.objects.active = obj
    result = bake_take(obj, take, preset=preset, overrides=overrides, settings=settings,
                       report=lambda level, msg: messages.append(msg))
    os.makedirs(os.path.dirname(os.path.abspath(out_path)), exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(out_path), check_existing=False)
    return {"out": out_path, "armature": obj.name, "preset": result.preset, "action": result.action.name,
            "frames": len(result.motion.frames), "frame_range": list(result.frame_range),
            "bones": len(result.motion.bone_names), "message": messages[-1] if messages else ""}
