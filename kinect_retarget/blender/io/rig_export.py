"""Write a baked rig (and the meshes it deforms) through Blender's own exporters, with the settings game
engines import correctly (docs/export.md: Unity, Unreal, Godot)."""
from __future__ import annotations

import os

import bpy

from ..headless import blender_message

FORMATS = {".blend": "blend", ".fbx": "fbx", ".glb": "gltf", ".gltf": "gltf", ".bvh": "bvh"}


def check_export_path(path: str) -> str:
    """The output kind for `path` by its extension; ValueError for one no exporter writes."""
    ext = os.path.splitext(path)[1].lower()
    if ext not in FORMATS:
        raise ValueError(f"{path}: cannot write {ext or 'a file without extension'} "
                         f"(choose {', '.join(FORMATS)})")
    return FORMATS[ext]


def _select_rig(obj: bpy.types.Object) -> None:
    """Only the rig and its children (skinned meshes) are selected, so use_selection exports just them."""
    view_layer = bpy.context.view_layer
    for o in view_layer.objects:
        o.select_set(False)
    for o in (obj, *obj.children_recursive):
        if o.name in view_layer.objects:
            o.select_set(True)
    view_layer.objects.active = obj


def _fbx(obj, path: str, nla: bool) -> None:
    bpy.ops.export_scene.fbx(
        filepath=path, use_selection=True, object_types={"ARMATURE", "MESH"},
        apply_scale_options="FBX_SCALE_UNITS",  # scale 1 on the root in Unity, centimetres in Unreal
        add_leaf_bones=False,                   # engines make their own end bones
        bake_anim=True, bake_anim_use_all_bones=True, bake_anim_use_all_actions=False,
        bake_anim_use_nla_strips=nla, bake_anim_force_startend_keying=True, bake_anim_step=1.0,
        bake_anim_simplify_factor=0.0,          # every baked frame as is (the bake's own reduction decides)
        axis_forward="-Z", axis_up="Y")


def _gltf(obj, path: str, nla: bool) -> None:
    bpy.ops.export_scene.gltf(
        filepath=path, export_format="GLB" if path.lower().endswith(".glb") else "GLTF_SEPARATE",
        use_selection=True, export_animations=True, export_yup=True,
        export_animation_mode="NLA_TRACKS" if nla else "ACTIVE_ACTIONS",
        export_force_sampling=True, export_optimize_animation_size=False, export_anim_slide_to_zero=False)


def _bvh(obj, path: str, frame_range: tuple[int, int]) -> None:
    bpy.ops.export_anim.bvh(filepath=path, frame_start=frame_range[0], frame_end=frame_range[1],
                            rotate_mode="NATIVE", root_transform_only=False)


def export_rig(obj: bpy.types.Object, path: str, frame_range: tuple[int, int]) -> None:
    """Export `obj` (an armature with its animation) to `path` by its extension."""
    kind = check_export_path(path)
    path = os.path.abspath(path)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    _select_rig(obj)
    ad = obj.animation_data
    nla = ad is not None and ad.action is None and len(ad.nla_tracks) > 0  # the bake went to an NLA strip
    try:
        if kind == "fbx":
            _fbx(obj, path, nla)
        elif kind == "gltf":
            _gltf(obj, path, nla)
        elif kind == "bvh":
            _bvh(obj, path, frame_range)
        else:
            raise ValueError(f"{path}: export_rig writes exported formats, not .blend")
    except RuntimeError as exc:
        raise ValueError(f"{path}: the {kind} exporter failed ({blender_message(exc)})") from None
