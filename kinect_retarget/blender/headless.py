"""Headless entry points (bpy as a module): open or build a rig, bake, save."""
from __future__ import annotations

import os
import sys
from dataclasses import replace

import bpy

from ..core.bake_options import BakeOptions
from ..core.pipeline import RetargetSettings
from ..core.take import Take
from .bake_take import bake_take, new_generated_rig


def find_armature(name: str | None) -> bpy.types.Object:
    """The named armature, or the only one, or the only one visible in the view layer (a Rigify file holds
    the hidden metarig beside the generated rig)."""
    arms = [o for o in bpy.data.objects if o.type == "ARMATURE"]
    listing = ", ".join(o.name for o in arms) or "none"
    if name:
        obj = bpy.data.objects.get(name)
        if obj is None or obj.type != "ARMATURE":
            raise ValueError(f"no armature named {name!r} (armatures: {listing})")
        return obj
    if len(arms) > 1:
        view_layer = bpy.context.view_layer
        visible = [o for o in arms if o.name in view_layer.objects and o.visible_get(view_layer=view_layer)]
        arms = visible if len(visible) == 1 else arms
    if not arms:
        raise ValueError("no armature in the file: save the rig (an Armature object) in it")
    if len(arms) != 1:
        raise ValueError(f"{len(arms)} armatures in the file ({listing}): name one with --armature")
    return arms[0]


def blender_message(exc: Exception) -> str:
    """The text of an error a bpy operator raised, without Blender's "Error: " prefix."""
    return str(exc).strip().removeprefix("Error: ").strip()


def save_blend(path: str) -> None:
    """Save the open file as `path`, making its folder when needed."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(path), check_existing=False)


def open_blend(path: str) -> None:
    """Open a .blend, with a one-line error for a missing or unreadable file."""
    if not os.path.isfile(path):
        raise ValueError(f"{path}: rig file not found")
    try:
        bpy.ops.wm.open_mainfile(filepath=os.path.abspath(path), load_ui=False)
    except RuntimeError as exc:
        message = blender_message(exc).splitlines()[-1]
        raise ValueError(f"{path}: not a readable .blend file ({message})") from None


def append_armature(path: str, name: str | None) -> bpy.types.Object:
    """Append the objects of another rig file into this scene (in a collection named after the file) and
    return its named (or only) armature; a name already taken here gets Blender's .001 suffix."""
    if not os.path.isfile(path):
        raise ValueError(f"{path}: rig file not found")
    try:
        with bpy.data.libraries.load(os.path.abspath(path), link=False) as (source, target):
            names = list(source.objects)
            target.objects = list(names)  # filled in place with the objects
    except OSError as exc:
        raise ValueError(f"{path}: not a readable .blend file ({exc})") from None
    collection = bpy.data.collections.new(os.path.splitext(os.path.basename(path))[0])
    bpy.context.scene.collection.children.link(collection)
    loaded = {n: o for n, o in zip(names, target.objects) if o is not None}
    for obj in loaded.values():
        collection.objects.link(obj)
    arms = {n: o for n, o in loaded.items() if o.type == "ARMATURE"}
    listing = ", ".join(arms) or "none"
    if name:
        if name not in arms:
            raise ValueError(f"{path}: no armature named {name!r} (armatures: {listing})")
        return arms[name]
    shown = [o for o in arms.values() if not o.hide_viewport and not o.hide_get()]
    pick = list(arms.values()) if len(arms) <= 1 else shown
    if len(pick) != 1:
        raise ValueError(f"{path}: " + ("no armature in the file" if not arms else
                                        f"several armatures ({listing}): name one with --armature"))
    return pick[0]


def open_target(rig_path: str | None, armature: str | None, preset: str, generate) -> tuple[bpy.types.Object, str]:
    """(armature, preset) to drive: the named (or only) armature of `rig_path`, or the rig `generate(scene)`
    builds in an empty file, for which preset "auto" means its own ("kinect")."""
    if rig_path:
        open_blend(rig_path)
        return find_armature(armature), preset
    bpy.ops.wm.read_factory_settings(use_empty=True)
    return generate(bpy.context.scene), "kinect" if preset == "auto" else preset


def bake_to_file(take: Take, out_path: str, *, rig_path: str | None = None, armature: str | None = None,
                 preset: str = "auto", overrides: dict | None = None,
                 settings: RetargetSettings | None = None, options: BakeOptions | None = None) -> dict:
    """Bake onto the armature of rig_path (or a generated Kinect rig) and save out_path (.blend, or exported
    as .fbx, .glb/.gltf or .bvh). Returns a summary. The rig file's scene keeps its rate and range unless
    `options` ask; a generated rig's new scene runs at the bake's rate over exactly the baked frames."""
    from .io.rig_export import check_export_path, export_rig
    kind = check_export_path(out_path)  # a wrong extension fails before anything is opened
    obj, preset = open_target(rig_path, armature, preset, lambda scene: new_generated_rig(scene, take))
    summary, result = _bake_one(obj, take, rig_path is None, preset, overrides, settings, options)
    if kind == "blend":
        save_blend(out_path)
    else:
        export_rig(obj, out_path, result.frame_range)
    return {"out": out_path, **summary}


def bake_bodies_to_file(takes: list[Take], out_path: str, *, rig_path: str | None = None,
                        armatures: list[str | None] | None = None, preset: str = "auto",
                        overrides: dict | None = None, settings: RetargetSettings | None = None,
                        options: BakeOptions | None = None, rig_paths: list[str] | None = None) -> dict:
    """Several performers of one take (`takes[k]` one body each), each baked onto its own armature: the
    armatures named in rig_path, paired in order; or with rig_paths, each body's armature from its own file
    (the first file is opened, the others' objects appended); or a generated Kinect rig per body. Saves one
    .blend; returns {"out", "performers": [one summary per body]}."""
    from .io.rig_export import check_export_path
    if check_export_path(out_path) != "blend":
        raise ValueError(f"{out_path}: several performers go into one .blend; export one body per file "
                         f"(bake --body N --out NAME.fbx)")
    names = list(armatures or [None] * len(takes))
    if len(names) != len(takes):
        raise ValueError(f"{len(takes)} bodies need {len(takes)} armatures, got {len(names)}")
    if rig_paths:
        if len(rig_paths) != len(takes):
            raise ValueError(f"{len(takes)} bodies need {len(takes)} rig files, got {len(rig_paths)}")
        open_blend(rig_paths[0])
        objs = [find_armature(names[0])] + [append_armature(p, n) for p, n in zip(rig_paths[1:], names[1:])]
    elif rig_path:
        if any(n is None for n in names) or len(set(names)) != len(names):
            raise ValueError("name a different armature in the rig file for each body (--armature, in order)")
        open_blend(rig_path)
        objs = [find_armature(n) for n in names]
    else:
        bpy.ops.wm.read_factory_settings(use_empty=True)
        objs = [new_generated_rig(bpy.context.scene, t, f"KinectRig_body{t.metadata.get('body', 0)}")
                for t in takes]
        preset = "kinect" if preset == "auto" else preset
    summaries = []
    for obj, take in zip(objs, takes):
        summary, _ = _bake_one(obj, take, rig_path is None, preset, overrides, settings, options)
        summaries.append({"body": int(take.metadata.get("body", 0)), **summary})
    save_blend(out_path)
    return {"out": out_path, "performers": summaries}


def _bake_one(obj, take: Take, generated: bool, preset: str, overrides, settings, options):
    """Bake `take` onto `obj`; (summary, BakeResult)."""
    options = options or BakeOptions()
    messages: list[str] = []
    if generated:  # our own new scene: it runs at the bake's rate over exactly the baked frames
        options = replace(options, set_scene_fps=True, extend_scene_range=True)
        scene = bpy.context.scene
        scene.frame_start = scene.frame_end = (settings or RetargetSettings()).frame_start
    bpy.context.view_layer.objects.active = obj
    def report(level, msg):
        messages.append(msg)
        if "WARNING" in level:
            print(f"warning: {msg}", file=sys.stderr)
    result = bake_take(obj, take, preset=preset, overrides=overrides, settings=settings, options=options,
                       report=report)
    summary = {"armature": obj.name, "preset": result.preset, "action": result.action.name,
               "frames": len(result.motion.frames), "frame_range": list(result.frame_range),
               "bones": len(result.motion.bone_names),
               "dropped_joint_samples": int(take.metadata.get("dropped_joint_samples", 0)),
               "message": messages[-1] if messages else ""}
    if result.reduction is not None:
        summary.update(keys_removed=result.reduction.removed, max_error_deg=round(result.reduction.max_deg, 4),
                       max_error_mm=round(result.reduction.max_mm, 4))
    if result.strip:
        summary["nla_strip"] = result.strip
    if result.feet is not None:
        summary["feet"] = result.feet.summary()
    return summary, result
