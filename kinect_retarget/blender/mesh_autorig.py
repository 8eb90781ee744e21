"""Auto-rig a mesh object: it gets a Kinect-named armature in its own pose, vertex groups and an Armature
modifier (paper 003 via kinect_retarget.autorig); nothing changes on failure. The operator is
ui/autorig_operator.py; the `autorig` command calls autorig_to_file."""
from __future__ import annotations

import json
from contextlib import contextmanager

import bpy
import numpy as np

from ..autorig import AutoRig, Mesh, MeshError, autorig
from ..autorig.auto_rigger import bind_mesh
from ..autorig.weights import bone_segments

AUTORIG_TAG = "kinect_retarget_autorig"
def mesh_world_arrays(obj: bpy.types.Object) -> tuple[np.ndarray, np.ndarray]:
    """(V, 3) vertex positions in world space and (T, 3) triangles of the object's own mesh data."""
    me = obj.data
    me.calc_loop_triangles()
    co = np.empty(len(me.vertices) * 3, dtype=np.float64)
    me.vertices.foreach_get("co", co)
    tris = np.empty(len(me.loop_triangles) * 3, dtype=np.int64)
    me.loop_triangles.foreach_get("vertices", tris)
    m = np.array(obj.matrix_world, dtype=np.float64)
    return co.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3], tris.reshape(-1, 3)


def new_mesh_object(name: str, vertices: np.ndarray, faces: np.ndarray, collection) -> bpy.types.Object:
    """A mesh object from (V, 3) positions and (T, 3) triangles (bulk foreach_set, no per-vertex Python)."""
    me = bpy.data.meshes.new(name)
    me.vertices.add(len(vertices))
    me.vertices.foreach_set("co", np.asarray(vertices, dtype=np.float32).ravel())
    me.loops.add(faces.size)
    me.loops.foreach_set("vertex_index", np.asarray(faces, dtype=np.int32).ravel())
    me.polygons.add(len(faces))
    me.polygons.foreach_set("loop_start", np.arange(0, faces.size, 3, dtype=np.int32))
    me.polygons.foreach_set("loop_total", np.full(len(faces), 3, dtype=np.int32))
    me.update()
    me.validate()
    obj = bpy.data.objects.new(name, me)
    collection.objects.link(obj)
    return obj


def build_armature(context, rig: AutoRig, name: str, collection) -> bpy.types.Object:
    """Armature at the world origin whose rest pose is the extracted skeleton: bone j runs from joint j's
    parent to joint j and is named after joint j; the root bone (the hip centre) is a stub up the trunk.
    Rolls put each bone's Z axis toward the character's front, so both sides bend alike."""
    arm = bpy.data.armatures.new(name)
    obj = bpy.data.objects.new(name, arm)
    collection.objects.link(obj)
    obj["kinect_retarget_skeleton"] = rig.skeleton.name
    heads, tails = bone_segments(rig.joints)
    up, front = np.asarray(rig.features.up), np.asarray(rig.features.front)
    with armature_edit(context, obj):
        edit = []
        for j, joint in enumerate(rig.skeleton.joints):
            eb = arm.edit_bones.new(joint)
            eb.head, eb.tail = heads[j].tolist(), tails[j].tolist()
            axis = tails[j] - heads[j]
            axis /= max(np.linalg.norm(axis), 1e-12)
            eb.align_roll((front if abs(axis @ front) < 0.9 else up).tolist())
            edit.append(eb)
        for j, p in enumerate(rig.skeleton.parents):
            if p >= 0:
                edit[j].parent = edit[p]
    return obj


@contextmanager
def armature_edit(context, obj: bpy.types.Object):
    """Edit Mode on `obj` for the block (its edit bones can be made), then Object Mode and the previously
    active object back, whatever happens."""
    view_layer = context.view_layer
    previous = view_layer.objects.active
    view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    try:
        yield obj.data
    finally:
        bpy.ops.object.mode_set(mode="OBJECT")
        view_layer.objects.active = previous


def assign_weights(mesh_obj: bpy.types.Object, rig: AutoRig, index: np.ndarray | None = None,
                   weight: np.ndarray | None = None) -> None:
    """One vertex group per bone from (V, 4) influences, the rig's own by default (existing groups of
    those names are replaced)."""
    index = rig.weight_index if index is None else index
    weight = rig.weight if weight is None else weight
    groups = mesh_obj.vertex_groups
    for name in rig.bone_names:
        if name in groups:
            groups.remove(groups[name])
    for b, name in enumerate(rig.bone_names):
        group = groups.new(name=name)
        rows, slots = np.nonzero((index == b) & (weight > 0))
        w = weight[rows, slots]
        # vertex_group.add takes one weight per call: batch the vertices that share a (rounded) weight
        key = np.round(w, 4)
        order = np.argsort(key, kind="stable")
        values, starts = np.unique(key[order], return_index=True)
        for value, chunk in zip(values, np.split(rows[order], starts[1:])):
            group.add(chunk.tolist(), float(value), "REPLACE")


def _heat_weights(context, mesh_obj, arm_obj, rig: AutoRig) -> str:
    """Blender's bone-heat weights, limited to 4 influences and normalized; vertices heat leaves empty
    (a known failure on meshes with intersecting pieces) keep the projection weights. Returns a note."""
    view_layer = context.view_layer
    for o in view_layer.objects:
        o.select_set(False)
    mesh_obj.select_set(True)
    arm_obj.select_set(True)
    view_layer.objects.active = arm_obj
    bpy.ops.object.parent_set(type="ARMATURE_AUTO")
    view_layer.objects.active = mesh_obj
    bpy.ops.object.vertex_group_limit_total(limit=4)
    bpy.ops.object.vertex_group_normalize_all(lock_active=False)
    names = set(rig.bone_names)
    total = np.zeros(len(mesh_obj.data.vertices))
    for v in mesh_obj.data.vertices:
        total[v.index] = sum(g.weight for g in v.groups if mesh_obj.vertex_groups[g.group].name in names)
    empty = np.flatnonzero(total < 1e-6)
    if len(empty):
        for k, b in enumerate(rig.weight_index[empty].T):
            for v, bone, w in zip(empty.tolist(), b.tolist(), rig.weight[empty, k].tolist()):
                if w > 0:
                    mesh_obj.vertex_groups[rig.bone_names[bone]].add([v], w, "REPLACE")
        return f"; heat left {len(empty)} vertices unweighted, they use bone projection"
    return ""


def _parent_with_modifier(obj: bpy.types.Object, arm_obj: bpy.types.Object) -> None:
    world = obj.matrix_world.copy()
    obj.parent = arm_obj
    obj.matrix_parent_inverse = arm_obj.matrix_world.inverted()
    obj.matrix_world = world
    # (rig_mesh_object takes no mesh that already has an Armature modifier)
    mod = obj.modifiers.new("Armature", "ARMATURE")
    mod.object = arm_obj


def _roll_back(saved, arm_obj) -> None:
    """Undo a half-done rig: modifiers, vertex groups and parents as they were, the armature gone."""
    for obj, parent, parent_inverse, world, groups in saved:
        for mod in [m for m in obj.modifiers if m.type == "ARMATURE" and m.object == arm_obj]:
            obj.modifiers.remove(mod)
        for group in [g for g in obj.vertex_groups if g.name not in groups]:
            obj.vertex_groups.remove(group)
        obj.parent = parent
        obj.matrix_parent_inverse = parent_inverse
        obj.matrix_world = world
    bpy.data.objects.remove(arm_obj)


def rig_mesh_object(context, mesh_obj: bpy.types.Object, weights: str = "PROJECTION", levels: int = 4,
                    name: str | None = None, extra=(), joints: str = "fractions", normalization: str = "segment",
                    paper_skeleton: bool = False) -> tuple[bpy.types.Object, AutoRig, str]:
    """Rig `mesh_obj` in place; `extra` mesh objects (clothes, eyes, hair kept apart) are bound to the
    same armature; with paper_skeleton, the paper's skeleton points and tree are built beside it as a
    second armature ('<rig>_PaperSkeleton'). Raises MeshError (scene untouched) when no human skeleton
    can be built."""
    extra = [o for o in extra if o is not mesh_obj and o.type == "MESH" and len(o.data.polygons)
             and not any(m.type == "ARMATURE" for m in o.modifiers)]
    if mesh_obj is None or mesh_obj.type != "MESH":
        raise MeshError("select a mesh object to auto-rig")
    if any(m.type == "ARMATURE" for m in mesh_obj.modifiers):
        raise MeshError(f"{mesh_obj.name!r} already has an Armature modifier: remove it to rig the mesh again")
    verts, tris = mesh_world_arrays(mesh_obj)
    if len(tris) == 0:
        raise MeshError(f"{mesh_obj.name!r} has no faces: not a surface mesh")
    rig = autorig(Mesh(verts, tris, mesh_obj.name), levels=levels, joints=joints.lower(),
                  normalization=normalization.lower())  # may raise: nothing changed yet
    collection = mesh_obj.users_collection[0] if mesh_obj.users_collection else context.scene.collection
    arm_obj = build_armature(context, rig, name or f"{mesh_obj.name}_Rig", collection)
    saved = [(o, o.parent, o.matrix_parent_inverse.copy(), o.matrix_world.copy(), {g.name for g in o.vertex_groups})
             for o in [mesh_obj, *extra]]
    try:
        arm_obj[AUTORIG_TAG] = json.dumps({k: v for k, v in rig.report.items() if k != "timings"})
        _parent_with_modifier(mesh_obj, arm_obj)
        note = ""
        if weights == "HEAT":
            note = _heat_weights(context, mesh_obj, arm_obj, rig)
        else:
            assign_weights(mesh_obj, rig)
        for obj in extra:
            v, t = mesh_world_arrays(obj)
            index, weight = bind_mesh(rig, Mesh(v, t, obj.name))
            assign_weights(obj, rig, index, weight)
            _parent_with_modifier(obj, arm_obj)
        if extra:
            note += f"; bound {len(extra)} more mesh object(s): {', '.join(o.name for o in extra)}"
        if paper_skeleton:
            from .io.paper_skeleton import build_paper_skeleton
            points = build_paper_skeleton(context, rig.paper, f"{arm_obj.name}_PaperSkeleton", collection)
            arm_obj["kinect_retarget_paper_skeleton"] = points.name
            note += f"; paper skeleton: {points.name} ({len(points.data.bones)} connections)"
    except Exception:
        paper = bpy.data.objects.get(f"{arm_obj.name}_PaperSkeleton")
        if paper is not None:
            bpy.data.objects.remove(paper)
        _roll_back(saved, arm_obj)
        raise
    return arm_obj, rig, rig.summary() + note


def autorig_to_file(mesh: Mesh, out_path: str, *, take=None, render_dir: str | None = None, frames: int = 6,
                    weights: str = "PROJECTION", levels: int = 4, joints: str = "fractions",
                    normalization: str = "segment", paper_skeleton: bool = False) -> dict:
    """Headless: a fresh scene holding `mesh` rigged (and `take` baked on it), saved to out_path."""
    import os

    bpy.ops.wm.read_factory_settings(use_empty=True)
    context = bpy.context
    scene = context.scene
    obj = new_mesh_object(mesh.name, mesh.vertices, mesh.faces, scene.collection)
    context.view_layer.objects.active = obj
    arm, rig, summary = rig_mesh_object(context, obj, weights, levels, joints=joints,
                                        normalization=normalization, paper_skeleton=paper_skeleton)
    out = {"out": out_path, "mesh": obj.name, "armature": arm.name, "vertices": len(mesh.vertices),
           "height_m": round(float(np.ptp(mesh.vertices[:, 2])), 4), "summary": summary,
           "points_per_level": rig.report["points_per_level"], "joint_rule": rig.report["joint_rule"],
           "normalization": rig.report["normalization"]}
    if paper_skeleton:
        out["paper_skeleton"] = arm["kinect_retarget_paper_skeleton"]
    render_frames = [scene.frame_current]
    if take is not None:
        from .bake_take import bake_take
        messages: list[str] = []
        from ..core.bake_options import BakeOptions
        # our own new scene (like bake_to_file's): it runs at the take's rate over exactly the baked frames
        scene.frame_start = scene.frame_end = 1
        result = bake_take(arm, take, preset="kinect", report=lambda level, msg: messages.append(msg),
                           options=BakeOptions(set_scene_fps=True, extend_scene_range=True))
        first, last = result.frame_range
        render_frames = sorted({int(f) for f in np.linspace(first, last, max(1, frames))})
        out.update({"action": result.action.name, "frames": len(result.motion.frames),
                    "frame_range": [first, last], "bake": messages[-1] if messages else ""})
    if render_dir:
        from .io.workbench_render import stage_and_render
        os.makedirs(render_dir, exist_ok=True)
        note = f"auto-rigged {obj.name}" + (f" + {take.metadata.get('name', 'take')}" if take is not None else "")
        out["renders"] = stage_and_render(scene, [obj], render_frames, render_dir, obj.name, note=note)
    from .headless import save_blend
    save_blend(out_path)
    return out
