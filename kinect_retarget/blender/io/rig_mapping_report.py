"""`info --rig RIG.blend`: which bone of an armature drives which Kinect joint, and how it was found."""
from __future__ import annotations

from ...core.control_rig_mapping import map_armature
from ...core.presets import STRUCTURE, build_mapping
from .rig_reader import target_rig_from_object


def rig_mapping_summary(rig_path: str, armature: str | None = None, preset: str = "auto") -> dict:
    """{file, armature, bones, preset, mapping {bone: joint}, found {joint: 'bone (how)'}, notes}."""
    from ..headless import find_armature, open_blend

    open_blend(rig_path)
    obj = find_armature(armature)
    rig = target_rig_from_object(obj)
    used, mapping = build_mapping(preset, rig.bone_names, None, rig)
    out = {"file": rig_path, "armature": obj.name, "bones": len(rig.bone_names), "preset": used,
           "mapping": {b: j for b, j in mapping.items() if rig.has(b)}}
    if used == STRUCTURE:
        found = map_armature(rig.bone_names, rig.parents, rig.heads, rig.tails, rig.links)
        out["found"], out["notes"] = found.joints, found.notes
    return out
