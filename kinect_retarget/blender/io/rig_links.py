"""Read what an armature says about its bones besides hierarchy and rest pose (use_deform, custom shapes,
constraints and the bones they read) into core.control_rig_mapping.RigLinks; nothing is changed."""
from __future__ import annotations

import bpy
import numpy as np

from ...core.control_rig_mapping import Constraint, RigLinks


def _targets(con, obj, index: dict[str, int]) -> tuple[int, ...]:
    """Bones of `obj` itself that a constraint reads (one subtarget, or an Armature constraint's list)."""
    pairs = [(t.target, t.subtarget) for t in con.targets] if con.type == "ARMATURE" else \
        [(getattr(con, "target", None), getattr(con, "subtarget", ""))]
    if con.type == "IK" and getattr(con, "pole_subtarget", ""):
        pairs.append((con.pole_target, con.pole_subtarget))
    return tuple(index[sub] for target, sub in pairs if target == obj and sub in index)


def rig_links_from_object(obj: bpy.types.Object) -> RigLinks:
    bones = obj.data.bones
    index = {b.name: i for i, b in enumerate(bones)}
    deform = np.array([b.use_deform for b in bones], dtype=bool)
    pose = obj.pose.bones
    shaped = np.array([pose[b.name].custom_shape is not None for b in bones], dtype=bool)
    constraints = tuple(
        tuple(Constraint(c.type, _targets(c, obj, index), float(c.influence), int(getattr(c, "chain_count", 0)))
              for c in pose[b.name].constraints if c.enabled and not c.mute)
        for b in bones)
    return RigLinks(deform, shaped, constraints)
