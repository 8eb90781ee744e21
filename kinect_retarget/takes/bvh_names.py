"""Known BVH naming families: which joints stand for each Kinect v1 joint, per family.

The reader no longer maps by these tables (core/structure_mapping.py maps every skeleton by structure); they
name the family a file belongs to (`metadata["bvh_family"]`, informational) and let a CMU-named skeleton keep
CMU units (FAMILY_UNITS) when those give a plausible height.

Each Kinect joint lists alternatives, tried in order; an alternative is a tuple of BVH joint names whose
positions are averaged (e.g. the head centre is halfway between the head joint and its end site). End sites
are named `<parent>_end`. Names compare case-insensitively after dropping a namespace prefix ("mixamorig:", "DEF-").

Families are needed because the same name means different bones: "LeftShoulder" is the clavicle in CMU's
MotionBuilder release (01_01) but the upper arm in its 3ds Max release (131_xx).
"""
from __future__ import annotations

# Kinect v1 meaning of each joint, as mapped here:
#   HipCenter = pelvis centre; Spine = mid spine; ShoulderCenter = between the upper-arm heads;
#   Head = head centre; Shoulder = upper-arm head; Hand = finger base; Hip = upper-leg head;
#   Ankle = ankle; Foot = toe base.


def _sided(table: dict[str, list[tuple[str, ...]]], left: tuple[str, ...], right: tuple[str, ...]) -> dict:
    """Expand '{s}' placeholders in a one-sided table into the Left and Right Kinect joints."""
    out: dict[str, list[tuple[str, ...]]] = {}
    for joint, alternatives in table.items():
        if "{K}" not in joint:
            out[joint] = alternatives
            continue
        for kside, bside in (("Left", left), ("Right", right)):
            out[joint.replace("{K}", kside)] = [tuple(n.format(s=bside[0], side=bside[1], S=bside[2])
                                                      for n in alt) for alt in alternatives]
    return out


# {side}: Left/Right, {s}: L/R (CMU short prefix), {S}: l/r (CMU lower-case hand names)
_LEFT, _RIGHT = ("L", "Left", "l"), ("R", "Right", "r")

CMU_MOTIONBUILDER = _sided({  # cgspeed "MotionBuilder-friendly" CMU release, e.g. 01_01
    "HipCenter": [("Hips",)],
    "Spine": [("Spine", "Spine1")],
    "ShoulderCenter": [("LeftArm", "RightArm")],
    "Head": [("Head", "Head_end"), ("Head",)],
    "Shoulder{K}": [("{side}Arm",)],
    "Elbow{K}": [("{side}ForeArm",)],
    "Wrist{K}": [("{side}Hand",)],
    "Hand{K}": [("{s}Fingers",), ("{side}FingerBase",)],
    "Hip{K}": [("{side}UpLeg",)],
    "Knee{K}": [("{side}Leg",)],
    "Ankle{K}": [("{side}Foot",)],
    "Foot{K}": [("{side}ToeBase",)],
}, _LEFT, _RIGHT)

CMU_3DSMAX = _sided({  # cgspeed "3dsMax-friendly" CMU release, e.g. 131_01
    "HipCenter": [("Hips",)],
    "Spine": [("Chest", "Chest2")],
    "ShoulderCenter": [("LeftShoulder", "RightShoulder")],
    "Head": [("Head", "Head_end"), ("Head",)],
    "Shoulder{K}": [("{side}Shoulder",)],
    "Elbow{K}": [("{side}Elbow",)],
    "Wrist{K}": [("{side}Wrist",)],
    "Hand{K}": [("{s}Fingers",), ("{S}hand",)],
    "Hip{K}": [("{side}Hip",)],
    "Knee{K}": [("{side}Knee",)],
    "Ankle{K}": [("{side}Ankle",)],
    "Foot{K}": [("{side}Toe",)],
}, _LEFT, _RIGHT)

MAKEHUMAN = _sided({  # MakeHuman default skeleton (tpose.bvh, benchmark.bvh); sides are ".L"/".R"
    "HipCenter": [("spine05",)],
    "Spine": [("spine02",)],
    "ShoulderCenter": [("upperarm01.L", "upperarm01.R")],
    "Head": [("head", "head", "temporalis01.L", "temporalis01.R"), ("head",)],
    "Shoulder{K}": [("upperarm01.{s}",)],
    "Elbow{K}": [("lowerarm01.{s}",)],
    "Wrist{K}": [("wrist.{s}",)],
    "Hand{K}": [("finger3-1.{s}",), ("wrist.{s}_end",)],
    "Hip{K}": [("upperleg01.{s}",)],
    "Knee{K}": [("lowerleg01.{s}",)],
    "Ankle{K}": [("foot.{s}",)],
    "Foot{K}": [("toe3-1.{s}",), ("toe1-1.{s}",)],
}, _LEFT, _RIGHT)

MIXAMO = _sided({  # Mixamo and other "Hips/Spine/LeftUpLeg" rigs (namespace prefix dropped)
    "HipCenter": [("Hips",)],
    "Spine": [("Spine1",), ("Spine",)],
    "ShoulderCenter": [("LeftArm", "RightArm")],
    "Head": [("Head", "HeadTop_End"), ("Head", "Head_end"), ("Head",)],
    "Shoulder{K}": [("{side}Arm",)],
    "Elbow{K}": [("{side}ForeArm",)],
    "Wrist{K}": [("{side}Hand",)],
    "Hand{K}": [("{side}HandMiddle1",), ("{side}HandIndex1",), ("{side}Hand_end",), ("{side}Hand",)],
    "Hip{K}": [("{side}UpLeg",)],
    "Knee{K}": [("{side}Leg",)],
    "Ankle{K}": [("{side}Foot",)],
    "Foot{K}": [("{side}ToeBase",), ("{side}Foot_end",)],
}, _LEFT, _RIGHT)

BIPED = _sided({  # 3ds Max Character Studio Biped ("Bip01 L UpperArm"; "Bip001" is matched as "Bip01")
    "HipCenter": [("Bip01 Pelvis",), ("Bip01",)],
    "Spine": [("Bip01 Spine1",), ("Bip01 Spine",)],
    "ShoulderCenter": [("Bip01 L UpperArm", "Bip01 R UpperArm")],
    "Head": [("Bip01 Head", "Bip01 HeadNub"), ("Bip01 Head", "Bip01 Head_end"), ("Bip01 Head",)],
    "Shoulder{K}": [("Bip01 {s} UpperArm",)],
    "Elbow{K}": [("Bip01 {s} Forearm",)],
    "Wrist{K}": [("Bip01 {s} Hand",)],
    "Hand{K}": [("Bip01 {s} Finger2",), ("Bip01 {s} Finger1",), ("Bip01 {s} Finger0",), ("Bip01 {s} Hand_end",)],
    "Hip{K}": [("Bip01 {s} Thigh",)],
    "Knee{K}": [("Bip01 {s} Calf",)],
    "Ankle{K}": [("Bip01 {s} Foot",)],
    "Foot{K}": [("Bip01 {s} Toe0",), ("Bip01 {s} Foot_end",)],
}, _LEFT, _RIGHT)

DAZ = _sided({  # DAZ Studio / Poser figures ("lShldr", Genesis 3+ "lShldrBend")
    "HipCenter": [("hip",)],
    "Spine": [("abdomen", "chest"), ("abdomenUpper",), ("abdomen",)],
    "ShoulderCenter": [("lShldr", "rShldr"), ("lShldrBend", "rShldrBend")],
    "Head": [("head", "head_end"), ("head",)],
    "Shoulder{K}": [("{S}Shldr",), ("{S}ShldrBend",)],
    "Elbow{K}": [("{S}ForeArm",), ("{S}ForearmBend",)],
    "Wrist{K}": [("{S}Hand",)],
    "Hand{K}": [("{S}Mid1",), ("{S}Hand_end",)],
    "Hip{K}": [("{S}Thigh",), ("{S}ThighBend",)],
    "Knee{K}": [("{S}Shin",)],
    "Ankle{K}": [("{S}Foot",)],
    "Foot{K}": [("{S}Toe",), ("{S}Metatarsals",), ("{S}Foot_end",)],
}, _LEFT, _RIGHT)

RIGIFY = _sided({  # Blender's human metarig / Rigify deform bones ("upper_arm.L"; "DEF-" dropped)
    "HipCenter": [("spine",), ("pelvis",), ("hips",)],
    "Spine": [("spine.002",), ("spine.001",)],
    "ShoulderCenter": [("upper_arm.L", "upper_arm.R")],
    "Head": [("spine.006", "spine.006_end"), ("head", "head_end"), ("spine.006",), ("head",)],
    "Shoulder{K}": [("upper_arm.{s}",)],
    "Elbow{K}": [("forearm.{s}",)],
    "Wrist{K}": [("hand.{s}",)],
    "Hand{K}": [("f_middle.01.{s}",), ("hand.{s}_end",)],
    "Hip{K}": [("thigh.{s}",)],
    "Knee{K}": [("shin.{s}",)],
    "Ankle{K}": [("foot.{s}",)],
    "Foot{K}": [("toe.{s}",), ("foot.{s}_end",)],
}, _LEFT, _RIGHT)

# Tried in order; the first family that resolves every Kinect v1 joint wins.
FAMILIES: dict[str, dict[str, list[tuple[str, ...]]]] = {
    "cmu_3dsmax": CMU_3DSMAX,
    "cmu_motionbuilder": CMU_MOTIONBUILDER,
    "makehuman": MAKEHUMAN,
    "mixamo": MIXAMO,
    "biped": BIPED,
    "daz": DAZ,
    "rigify": RIGIFY,
}

# Metres per file unit for families whose unit is known (CMU: 1 unit = 1/0.45 inch; MakeHuman: decimetres).
FAMILY_UNITS = {"cmu_3dsmax": 0.0254 / 0.45, "cmu_motionbuilder": 0.0254 / 0.45, "makehuman": 0.1}


def canonical(name: str) -> str:
    """Compare names case-insensitively, without a namespace ('mixamorig:') or Rigify layer ('DEF-')
    prefix, with 3ds Max's 'Bip001' read as 'Bip01'."""
    name = name.rsplit(":", 1)[-1].strip().lower()
    for prefix in ("def-", "org-"):
        if name.startswith(prefix):
            name = name[len(prefix):]
    if name.startswith("bip001"):
        name = "bip01" + name[6:]
    return name


def _common_prefix(names: list[str] | tuple[str, ...]) -> str:
    """A prefix every joint name shares and that ends at a separator ('Character1_', 'rig.', 'mixamorig_')."""
    import os.path
    prefix = os.path.commonprefix([n for n in names if not n.endswith("_end")])
    cut = max(prefix.rfind(c) for c in "_.: |-")
    return prefix[:cut + 1] if cut >= 0 else ""


def resolve(bvh_names: list[str] | tuple[str, ...], kinect_joints: tuple[str, ...]
            ) -> tuple[str, dict[str, tuple[int, ...]]] | tuple[None, dict[str, list[str]]]:
    """Map each Kinect joint to BVH joint indices (averaged).

    Returns (family, {kinect joint: indices}) on success, or (None, {family: [unresolved kinect joints]}).
    Names are tried as they are, then without a prefix that all of them share ('Character1_Hips').
    """
    prefix = _common_prefix(bvh_names)
    attempts = [bvh_names] + ([[n[len(prefix):] for n in bvh_names]] if prefix else [])
    missing: dict[str, list[str]] = {}
    for names in attempts:
        index = {}
        for i, n in enumerate(names):
            index.setdefault(canonical(n), i)
        for family, table in FAMILIES.items():
            mapping: dict[str, tuple[int, ...]] = {}
            for joint in kinect_joints:
                for alt in table.get(joint, []):
                    if all(canonical(n) in index for n in alt):
                        mapping[joint] = tuple(index[canonical(n)] for n in alt)
                        break
            unresolved = [j for j in kinect_joints if j not in mapping]
            if not unresolved:
                return family, mapping
            if names is bvh_names:
                missing[family] = unresolved
    return None, missing
