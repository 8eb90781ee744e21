"""Read a Blender armature into a numpy TargetRig (rest matrices only; the rig is never modified)."""
from __future__ import annotations

import bpy
import numpy as np
from bpy.utils import escape_identifier

from ...core.presets import RIGIFY_FK_SWITCHES
from ...core.target_rig import TargetRig
from .rig_links import rig_links_from_object

GENERATED_TAG = "kinect_retarget_generated"


def target_rig_from_object(obj: bpy.types.Object) -> TargetRig:
    if obj is None or obj.type != "ARMATURE":
        kind = "nothing" if obj is None else f"a {obj.type.lower()} object ({obj.name!r})"
        raise ValueError(f"an armature is needed, got {kind}")
    bones = obj.data.bones
    n = len(bones)
    if n == 0:
        raise ValueError(f"armature {obj.name!r} has no bones")
    rest = np.empty(n * 16, dtype=np.float32)
    bones.foreach_get("matrix_local", rest)
    # foreach_get flattens each 4x4 column by column
    rest = rest.reshape(n, 4, 4).transpose(0, 2, 1).astype(np.float64)
    lengths = np.empty(n, dtype=np.float32)
    bones.foreach_get("length", lengths)
    names = [b.name for b in bones]
    index = {name: i for i, name in enumerate(names)}
    parents = np.array([index[b.parent.name] if b.parent else -1 for b in bones])
    inherit = np.array([b.use_inherit_rotation for b in bones], dtype=bool)
    world = np.array(obj.matrix_world, dtype=np.float64)
    return TargetRig(obj.name, tuple(names), parents, rest, lengths.astype(np.float64), world, inherit,
                     generated=bool(obj.get(GENERATED_TAG, False)), links=rig_links_from_object(obj))


def fk_switch_bones(obj: bpy.types.Object) -> list[str]:
    """The Rigify FK/IK switch bones this rig has: RIGIFY_FK_SWITCHES with an 'IK_FK' property, or, when the
    bones have other names, every pose bone whose 'IK_FK' property a driver of a constraint's influence reads."""
    pose_bones = obj.pose.bones
    named = [name for name in RIGIFY_FK_SWITCHES if name in pose_bones and "IK_FK" in pose_bones[name]]
    ad = obj.animation_data
    if named or ad is None:
        return named
    read = {t.data_path for d in ad.drivers if ".constraints[" in d.data_path and d.data_path.endswith(".influence")
            for v in d.driver.variables for t in v.targets if t.id == obj}
    return [pb.name for pb in pose_bones if "IK_FK" in pb and f'pose.bones["{escape_identifier(pb.name)}"]["IK_FK"]'
            in read]


def constrained_bones(obj: bpy.types.Object) -> set[str]:
    """Bones whose pose Blender computes from more than their parent: constraints or drivers."""
    names = {pb.name for pb in obj.pose.bones if len(pb.constraints)}
    ad = obj.animation_data
    if ad is not None:
        names.update(d.data_path.split('"')[1] for d in ad.drivers if d.data_path.startswith('pose.bones["'))
    return names


def has_constrained_ancestry(obj: bpy.types.Object, bone_names) -> bool:
    """True when an ancestor of a mapped bone has constraints or drivers: the mapped bone's posed parent
    matrix then depends on more than rest matrices and must be read back from Blender's evaluation. (A mapped
    bone's own constraints act after its keyed rotation, as the rig's author intended.)"""
    constrained = constrained_bones(obj)
    for name in bone_names:
        pb = obj.pose.bones.get(name)
        pb = pb.parent if pb is not None else None
        while pb is not None:
            if pb.name in constrained:
                return True
            pb = pb.parent
    return False
