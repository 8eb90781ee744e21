"""A simple body for any humanoid armature: one capsule per body bone, weighted rigidly to that bone.

The mesh is a child of the armature with an Armature modifier (vertex group per bone), so it follows the
pose exactly as skinned characters do; the armature itself is never touched. Capsules are coloured by the
side of the character they sit on in the rest pose (Blender convention: the character's left is +X), so a
picture shows at a glance which arm is the character's right.
"""
from __future__ import annotations

import re

import bpy
import numpy as np

# Materials by side: the Workbench "Material" colour mode shows their viewport colour.
SIDE_COLOURS = {"centre": (0.80, 0.78, 0.74, 1.0), "left": (0.25, 0.45, 0.85, 1.0),
                "right": (0.85, 0.30, 0.20, 1.0)}
SIDES = tuple(SIDE_COLOURS)

# Bones that are detail rather than body (Rigify face and fingers, Mixamo fingers...): no capsule.
_DETAIL = re.compile(r"(^|[^a-z])(f_|thumb|palm|finger|index|middle|ring|pinky|lip|lid|brow|cheek|nose|ear|"
                     r"jaw|chin|tongue|teeth|eye|forehead|temple|breast|"
                     r"special|oris|levator|risorius|orbicularis|temporalis)",  # MakeHuman face bones
                     re.IGNORECASE)
_BODY_PARTS = (  # (pattern on the bone name, capsule radius as a fraction of the character's height)
    (re.compile(r"head|skull|spine\.006", re.I), 0.055),
    (re.compile(r"neck|spine\.00[45]|vc4", re.I), 0.030),
    (re.compile(r"spine|chest|torso|hips$|hipcenter|shouldercenter|sacroiliac|vl5|vt1|root|abdomen", re.I), 0.068),
    (re.compile(r"pelvis|^hip|[^a-z]hip", re.I), 0.040),
    (re.compile(r"sternoclav|clavicle|shoulder(?!.*(elbow|arm))", re.I), 0.028),
    (re.compile(r"thigh|upleg|upperleg|knee", re.I), 0.040),
    (re.compile(r"shin|[^p]leg|lowerleg|calf|ankle", re.I), 0.031),
    (re.compile(r"foot|toe", re.I), 0.022),
    (re.compile(r"forearm|lowerarm|wrist", re.I), 0.022),
    (re.compile(r"upper_?arm|elbow|(^|[^e])arm", re.I), 0.026),
    (re.compile(r"hand", re.I), 0.020),
)
MIN_BONE_FRACTION = 0.025  # bones shorter than this fraction of the height are detail (fingers, twist ends)


def rest_height(armature: bpy.types.Object) -> float:
    """The character's size: the largest extent of its rest skeleton in armature space (its height, or its
    arm span in a T-pose, about the same), whichever axis is up (FBX rigs are often Y-up inside)."""
    heads, tails = _rest_points(armature.data.bones)
    points = np.concatenate([heads, tails])
    return max(float(np.ptp(points, axis=0).max()), 1e-3) if len(points) else 1.0


def body_bones(armature: bpy.types.Object, height: float | None = None) -> list[str]:
    """Deform bones worth a capsule: Rigify's DEF bones on a generated Rigify rig, else every deform bone;
    facial, finger and very short bones are left out. height: rest_height(armature), when already known."""
    bones = armature.data.bones
    height = rest_height(armature) if height is None else height
    names = [b.name for b in bones if b.use_deform]
    if any(n.startswith("DEF-") for n in names):
        names = [n for n in names if n.startswith("DEF-")]
    return [n for n in names if not _DETAIL.search(n.removeprefix("DEF-"))
            and bones[n].length >= MIN_BONE_FRACTION * height]


def bone_radius(name: str, length: float, height: float) -> float:
    base = name.removeprefix("DEF-")
    for pattern, fraction in _BODY_PARTS:
        if pattern.search(base):
            return fraction * height
    return min(0.2 * length, 0.03 * height)


def capsule_template(segments: int = 12, cap_rings: int = 4):
    """Unit capsule rings: per ring (a, b, c) so that a ring of a capsule of length L and radius r sits at
    y = a·L + b·r with radius c·r; then quad faces between rings and triangle fans at the two poles.

    Returns (rings (R, 3), faces list) for R rings of `segments` vertices plus two pole vertices
    (indices R·segments and R·segments + 1)."""
    phi = np.linspace(0.0, np.pi / 2, cap_rings + 1)[1:]           # from the pole towards the equator
    head = np.stack([np.zeros_like(phi), -np.cos(phi), np.sin(phi)], axis=1)
    tail = np.stack([np.ones_like(phi), np.cos(phi), np.sin(phi)], axis=1)[::-1]
    rings = np.concatenate([head, tail])
    n_rings, s = len(rings), segments
    faces = []
    for k in range(n_rings - 1):
        for i in range(s):
            j = (i + 1) % s
            faces.append((k * s + i, k * s + j, (k + 1) * s + j, (k + 1) * s + i))
    bottom, top = n_rings * s, n_rings * s + 1
    faces += [(bottom, (i + 1) % s, i) for i in range(s)]
    last = (n_rings - 1) * s
    faces += [(top, last + i, last + (i + 1) % s) for i in range(s)]
    return rings, faces


def capsule_vertices(rings: np.ndarray, segments: int, lengths: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """(B, R·segments + 2, 3) capsule vertices in each bone's local space (bone along +Y from its head)."""
    theta = np.linspace(0.0, 2 * np.pi, segments, endpoint=False)
    L, r = lengths[:, None, None], radii[:, None, None]
    a, b, c = rings[None, :, 0, None], rings[None, :, 1, None], rings[None, :, 2, None]
    x = c * r * np.cos(theta)
    z = c * r * np.sin(theta)
    y = np.broadcast_to(a * L + b * r, x.shape)
    ring_verts = np.stack([x, y, z], axis=-1).reshape(len(lengths), -1, 3)
    poles = np.stack([np.zeros_like(lengths), -radii, np.zeros_like(lengths)], axis=-1)[:, None]
    poles_top = np.stack([np.zeros_like(lengths), lengths + radii, np.zeros_like(lengths)], axis=-1)[:, None]
    return np.concatenate([ring_verts, poles, poles_top], axis=1)


def _rest_points(bones) -> tuple[np.ndarray, np.ndarray]:
    n = len(bones)
    heads, tails = np.empty(n * 3, np.float32), np.empty(n * 3, np.float32)
    bones.foreach_get("head_local", heads)
    bones.foreach_get("tail_local", tails)
    return heads.reshape(n, 3).astype(np.float64), tails.reshape(n, 3).astype(np.float64)


def _rest_matrices(bones, names) -> np.ndarray:
    return np.array([np.array(bones[n].matrix_local, dtype=np.float64) for n in names]).reshape(-1, 4, 4)


def side_materials() -> list[bpy.types.Material]:
    mats = []
    for side, colour in SIDE_COLOURS.items():
        name = f"KR_body_{side}"
        mat = bpy.data.materials.get(name) or bpy.data.materials.new(name)
        mat.diffuse_color = colour
        mats.append(mat)
    return mats


def add_body_mesh(armature: bpy.types.Object, bones: list[str] | None = None, name: str | None = None,
                  segments: int = 12) -> bpy.types.Object:
    """Add a capsule body bound to `armature` (vertex groups + Armature modifier) and return the mesh object.

    bones: which bones get a capsule (default body_bones()); raises ValueError when none is usable.
    """
    if armature is None or armature.type != "ARMATURE":
        raise ValueError("a body mesh needs an armature object")
    arm_bones = armature.data.bones
    height = rest_height(armature)
    names = list(bones) if bones is not None else body_bones(armature, height)
    missing = [n for n in names if n not in arm_bones]
    if missing:
        raise ValueError(f"armature {armature.name!r} has no bone {', '.join(map(repr, missing))}")
    if not names:
        raise ValueError(f"armature {armature.name!r} has no deform bone to put a body on")
    lengths = np.array([arm_bones[n].length for n in names])
    radii = np.array([bone_radius(n, l, height) for n, l in zip(names, lengths)])
    rings, faces = capsule_template(segments)
    local = capsule_vertices(rings, segments, lengths, radii)          # (B, V, 3)
    rest = _rest_matrices(arm_bones, names)                             # bone -> armature space
    verts = np.einsum("bij,bvj->bvi", rest[:, :3, :3], local) + rest[:, None, :3, 3]
    per = local.shape[1]
    faces_all = [tuple(v + b * per for v in f) for b in range(len(names)) for f in faces]

    mesh = bpy.data.meshes.new(name or f"{armature.name}_body")
    mesh.from_pydata(verts.reshape(-1, 3).tolist(), [], faces_all)
    for mat in side_materials():
        mesh.materials.append(mat)
    mid_x = rest[:, 0, 3] + rest[:, 0, 1] * lengths / 2   # x of each bone's midpoint (bone axis is local Y)
    side = np.where(mid_x > 0.02 * height, SIDES.index("left"),
                    np.where(mid_x < -0.02 * height, SIDES.index("right"), SIDES.index("centre")))
    faces_per_bone = len(faces)
    mesh.polygons.foreach_set("material_index", np.repeat(side, faces_per_bone).astype(np.int32))
    mesh.polygons.foreach_set("use_smooth", np.ones(len(mesh.polygons), dtype=bool))
    mesh.update()

    body = bpy.data.objects.new(mesh.name, mesh)
    for coll in armature.users_collection:
        coll.objects.link(body)
    body.parent = armature
    body.matrix_parent_inverse.identity()  # vertices are in armature space: follow the armature's transform
    for b, bone in enumerate(names):
        body.vertex_groups.new(name=bone).add(range(b * per, (b + 1) * per), 1.0, "REPLACE")
    mod = body.modifiers.new("Armature", "ARMATURE")
    mod.object = armature
    mod.use_vertex_groups = True
    mod.use_bone_envelopes = False
    body["kinect_retarget_body"] = armature.name
    return body
