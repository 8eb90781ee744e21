"""Bone-mapping presets as data: target bone -> source joint spec (see retarget.resolve_mapping).

Specs use Kinect v1 joint names; Kinect v2 takes resolve them through aliases (HipCenter = SpineBase, ...),
and v2-only joints (Neck, HandTip, Thumb) are simply skipped for v1 takes. The bone mapped to the root joint
carries root motion. Bones a preset does not name are left alone.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

from ..assets import ASSETS_DIR
from .skeletons import KINECT_V1, KINECT_V2


def _sides(table: dict[str, str], left: str, right: str) -> dict[str, str]:
    """Expand entries containing '{s}' (bone side tag) and '{S}' (joint side) for both sides."""
    out = {}
    for bone, joint in table.items():
        if "{s}" in bone:
            out[bone.replace("{s}", left)] = joint.replace("{S}", "Left")
            out[bone.replace("{s}", right)] = joint.replace("{S}", "Right")
        else:
            out[bone] = joint
    return out


PRESET_DIR = ASSETS_DIR / "presets"


def load_preset_files(folder: Path = PRESET_DIR) -> dict[str, dict[str, str]]:
    """Presets kept as data: each JSON file {"name", "source", "sides": [left tag, right tag], "bones":
    {bone: joint}}, '{s}' in a bone name standing for the side tag and '{S}' in a joint for Left/Right."""
    out = {}
    for path in sorted(folder.glob("*.json")):
        data = json.loads(path.read_text(encoding="utf-8"))
        left, right = data.get("sides", ("", ""))
        out[data["name"]] = _sides(data["bones"], left, right)
        PRESET_INFO[data["name"]] = {k: v for k, v in data.items() if k not in ("name", "bones", "sides")}
    return out


# per preset: "source" (where the names come from), "root_motion_bone" (the rig's floor-level root bone that
# carries root motion), "fingerprint" (bones only this preset's rigs have: breaks ties between name sets)
PRESET_INFO: dict[str, dict] = {"rigify": {"root_motion_bone": "root"}, "rigify-metarig": {}}


KINECT = {**{j: j for j in KINECT_V1.joints}, **{j: j for j in KINECT_V2.joints}}

RIGIFY = {  # generated Rigify rig: FK controls (the arm/leg chains are switched to FK when baking)
    "torso": "HipCenter", "chest": "ShoulderCenter", "neck": "Neck", "head": "Head",
    **_sides({"shoulder{s}": "Shoulder{S}", "upper_arm_fk{s}": "Elbow{S}", "forearm_fk{s}": "Wrist{S}",
              "hand_fk{s}": "Hand{S}", "thigh_fk{s}": "Knee{S}", "shin_fk{s}": "Ankle{S}",
              "foot_fk{s}": "Foot{S}"}, ".L", ".R"),
}
RIGIFY_FK_SWITCHES = tuple(f"{limb}_parent{s}" for limb in ("upper_arm", "thigh") for s in (".L", ".R"))

RIGIFY_METARIG = {
    "spine": "HipCenter", "spine.001": "Spine", "spine.003": "ShoulderCenter", "spine.004": "Neck",
    "spine.006": "Head",
    **_sides({"shoulder{s}": "Shoulder{S}", "upper_arm{s}": "Elbow{S}", "forearm{s}": "Wrist{S}",
              "hand{s}": "Hand{S}", "thigh{s}": "Knee{S}", "shin{s}": "Ankle{S}", "foot{s}": "Foot{S}"},
             ".L", ".R"),
}

MIXAMO = {
    "mixamorig:Hips": "HipCenter", "mixamorig:Spine": "Spine", "mixamorig:Spine2": "ShoulderCenter",
    "mixamorig:Neck": "Neck", "mixamorig:Head": "Head",
    **_sides({"mixamorig:{s}Shoulder": "Shoulder{S}", "mixamorig:{s}Arm": "Elbow{S}",
              "mixamorig:{s}ForeArm": "Wrist{S}", "mixamorig:{s}Hand": "Hand{S}",
              "mixamorig:{s}UpLeg": "Knee{S}", "mixamorig:{s}Leg": "Ankle{S}", "mixamorig:{s}Foot": "Foot{S}"},
             "Left", "Right"),
}

HANIM = {  # H-Anim humanoid: a bone is named after the joint at its head
    "sacroiliac": "HipCenter", "vl5": "Spine", "vt1": "ShoulderCenter", "vc4": "Neck", "skullbase": "Head",
    **_sides({"{s}sternoclavicular": "Shoulder{S}", "{s}shoulder": "Elbow{S}", "{s}elbow": "Wrist{S}",
              "{s}wrist": "Hand{S}", "{s}hip": "Knee{S}", "{s}knee": "Ankle{S}", "{s}ankle": "Foot{S}"},
             "l_", "r_"),
}

MAKEHUMAN = {  # MakeHuman default skeleton (default.mhskel); twist halves (…02) stay at rest
    "root": "HipCenter", "spine04": "Spine", "spine01": "ShoulderCenter", "neck01": "Neck", "head": "Head",
    **_sides({"clavicle{s}": "Shoulder{S}", "upperarm01{s}": "Elbow{S}", "lowerarm01{s}": "Wrist{S}",
              "wrist{s}": "Hand{S}", "pelvis{s}": "Hip{S}", "upperleg01{s}": "Knee{S}",
              "lowerleg01{s}": "Ankle{S}", "foot{s}": "Foot{S}"}, ".L", ".R"),
}

PRESETS = {"kinect": KINECT, "rigify": RIGIFY, "rigify-metarig": RIGIFY_METARIG, "mixamo": MIXAMO,
           "hanim": HANIM, "makehuman": MAKEHUMAN, **load_preset_files()}
STRUCTURE = "structure"  # no names: the armature's hierarchy and rest pose (core/armature_mapping.py)
PRESET_NAMES = ("auto",) + tuple(PRESETS) + (STRUCTURE,)


def detect_preset(bone_names) -> str:
    """The preset naming the most of these bones (ties: the order of PRESETS); raises when none fits."""
    names = set(bone_names)
    scores = {p: sum(b in names for b in table) + 0.5 * all(b in names for b in PRESET_INFO.get(p, {}).get(
        "fingerprint", ("",))) for p, table in PRESETS.items()}
    best = max(scores, key=lambda p: scores[p])
    if scores[best] < 6:
        raise ValueError("no bone-mapping preset fits this armature (found at most "
                         f"{int(scores[best])} known bone names); pick a preset or give a mapping file")
    return best


def load_mapping_file(path: str | os.PathLike) -> dict[str, str]:
    """A JSON object {target bone: source joint spec}; '' or null unmaps a bone."""
    try:
        with open(path, encoding="utf-8") as fh:
            data = json.load(fh)
    except (OSError, json.JSONDecodeError) as exc:
        raise ValueError(f"{os.fspath(path)}: cannot read bone mapping ({exc})") from None
    if isinstance(data, dict) and "mapping" in data:
        data = data["mapping"]
    if not isinstance(data, dict) or not all(isinstance(k, str) and (v is None or isinstance(v, str))
                                             for k, v in data.items()):
        raise ValueError(f"{os.fspath(path)}: bone mapping must be a JSON object of bone name -> joint name")
    return {k: (v or "") for k, v in data.items()}


KNOWN_JOINTS = frozenset(KINECT_V1.joints) | frozenset(KINECT_V2.joints)


def mapping_problems(bone_names, overrides: dict[str, str] | None) -> list[str]:
    """Sentences about user overrides that cannot take effect: a bone the armature lacks, a joint name that is
    no Kinect joint (a typo would otherwise leave the bone silently at rest)."""
    names, problems = set(bone_names), []
    for bone, spec in (overrides or {}).items():
        if bone not in names:
            problems.append(f"mapping names bone {bone!r}, which the armature does not have")
        for joint in (s.strip() for s in (spec or "").split(">") if s.strip()):
            if joint not in KNOWN_JOINTS:
                problems.append(f"mapping {bone!r} -> {joint!r}: no Kinect joint has that name")
    return problems


def structure_mapping(rig) -> dict[str, str]:
    """The mapping of a TargetRig found from its hierarchy and rest pose, and on a control rig (Rigify's) from
    its deform bones and constraints too (ValueError: not a humanoid)."""
    from .control_rig_mapping import map_armature
    return map_armature(rig.bone_names, rig.parents, rig.heads, rig.tails, getattr(rig, "links", None)).mapping


def build_mapping(preset: str, bone_names, overrides: dict[str, str] | None = None,
                  rig=None) -> tuple[str, dict]:
    """(preset actually used, mapping) for an armature's bones; overrides win, '' unmaps. With the rig
    (a TargetRig), 'structure' maps it by its structure, and so does 'auto' when no preset fits its names."""
    used = preset
    if preset == "auto":
        try:
            used = detect_preset(bone_names)
        except ValueError as exc:
            if rig is None:
                raise
            used, names_error = STRUCTURE, str(exc)
    if used == STRUCTURE:
        if rig is None:
            raise ValueError("the structure mapping needs the armature's rest pose")
        try:
            mapping = structure_mapping(rig)
        except ValueError as exc:
            raise ValueError(f"{names_error}; by structure: {exc}" if preset == "auto" else str(exc)) from None
    elif used not in PRESETS:
        raise ValueError(f"unknown preset {preset!r} (choose from {', '.join(PRESET_NAMES)})")
    else:
        mapping = dict(PRESETS[used])
    mapping.update(overrides or {})
    return used, {k: v for k, v in mapping.items() if v}
