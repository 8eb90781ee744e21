"""Bone-name lists of the rigs people bring (the presets' families), laid out for tests/rigs/humanoid_rigs.build.
Names from each family's published skeleton; only the bones a humanoid body has (no IK or control bones)."""


def _fingers(fmt, names=("thumb", "index", "middle", "ring", "pinky"), joints=("01", "02", "03")):
    return {f: [fmt.format(f=f, n=n) for n in joints] for f in names}


LAYOUTS = {
    "ue4-mannequin": {
        "sides": ["_l", "_r"], "root": "root", "spine": ["pelvis", "spine_01", "spine_02", "spine_03"],
        "neck": ["neck_01"], "head": "head", "clavicle": "clavicle{s}", "upper": ["upperarm{s}"],
        "upper_twist": ["upperarm_twist_01{s}"], "fore": ["lowerarm{s}"], "fore_twist": ["lowerarm_twist_01{s}"],
        "hand": "hand{s}", "fingers": _fingers("{f}_{n}{{s}}"), "thigh": ["thigh{s}"],
        "thigh_twist": ["thigh_twist_01{s}"], "shin": ["calf{s}"], "shin_twist": ["calf_twist_01{s}"],
        "foot": "foot{s}", "toe": "ball{s}"},
    "ue5-mannequin": {
        "sides": ["_l", "_r"], "root": "root",
        "spine": ["pelvis", "spine_01", "spine_02", "spine_03", "spine_04", "spine_05"],
        "neck": ["neck_01", "neck_02"], "head": "head", "clavicle": "clavicle{s}", "upper": ["upperarm{s}"],
        "upper_twist": ["upperarm_twist_01{s}", "upperarm_twist_02{s}"], "fore": ["lowerarm{s}"],
        "fore_twist": ["lowerarm_twist_01{s}", "lowerarm_twist_02{s}"], "hand": "hand{s}",
        "fingers": _fingers("{f}_{n}{{s}}", joints=("metacarpal", "01", "02", "03")),
        "thigh": ["thigh{s}"], "thigh_twist": ["thigh_twist_01{s}", "thigh_twist_02{s}"], "shin": ["calf{s}"],
        "shin_twist": ["calf_twist_01{s}", "calf_twist_02{s}"], "foot": "foot{s}", "toe": "ball{s}"},
    "vroid": {
        "sides": ["L", "R"], "root": "Root",
        "spine": ["J_Bip_C_Hips", "J_Bip_C_Spine", "J_Bip_C_Chest", "J_Bip_C_UpperChest"],
        "neck": ["J_Bip_C_Neck"], "head": "J_Bip_C_Head", "clavicle": "J_Bip_{s}_Shoulder",
        "upper": ["J_Bip_{s}_UpperArm"], "upper_twist": [], "fore": ["J_Bip_{s}_LowerArm"], "fore_twist": [],
        "hand": "J_Bip_{s}_Hand",
        "fingers": _fingers("J_Bip_{{s}}_{f}{n}", ("Thumb", "Index", "Middle", "Ring", "Little"), ("1", "2", "3")),
        "thigh": ["J_Bip_{s}_UpperLeg"], "thigh_twist": [], "shin": ["J_Bip_{s}_LowerLeg"], "shin_twist": [],
        "foot": "J_Bip_{s}_Foot", "toe": "J_Bip_{s}_ToeBase"},
    "auto-rig-pro": {
        "sides": [".l", ".r"], "root": None, "spine": ["root.x", "spine_01.x", "spine_02.x", "spine_03.x"],
        "neck": ["neck.x"], "head": "head.x", "clavicle": "shoulder{s}", "upper": ["arm_stretch{s}"],
        "upper_twist": ["arm_twist{s}"], "fore": ["forearm_stretch{s}"], "fore_twist": ["forearm_twist{s}"],
        "hand": "hand{s}", "fingers": _fingers("{f}{n}{{s}}", joints=("1", "2", "3")),
        "thigh": ["thigh_stretch{s}"], "thigh_twist": ["thigh_twist{s}"], "shin": ["leg_stretch{s}"],
        "shin_twist": ["leg_twist{s}"], "foot": "foot{s}", "toe": "toes_01{s}"},
    "daz-genesis8": {  # bend and twist halves inside the limb chains; the legs hang from a pelvis under the hip
        "sides": ["l", "r"], "root": None, "spine": ["hip", "abdomenLower", "abdomenUpper", "chestLower", "chestUpper"],
        "legs_parent": "pelvis", "neck": ["neckLower", "neckUpper"], "head": "head", "clavicle": "{s}Collar",
        "upper": ["{s}ShldrBend", "{s}ShldrTwist"], "upper_twist": [], "fore": ["{s}ForearmBend", "{s}ForearmTwist"],
        "fore_twist": [], "hand": "{s}Hand",
        "fingers": _fingers("{{s}}{f}{n}", ("Thumb", "Index", "Mid", "Ring", "Pinky"), ("1", "2", "3")),
        "thigh": ["{s}ThighBend", "{s}ThighTwist"], "thigh_twist": [], "shin": ["{s}Shin"], "shin_twist": [],
        "foot": "{s}Foot", "toe": "{s}Toe"},
    "daz-genesis9": {
        "sides": ["l_", "r_"], "root": None, "spine": ["hip", "spine1", "spine2", "spine3", "spine4"],
        "legs_parent": "pelvis", "neck": ["neck1", "neck2"], "head": "head", "clavicle": "{s}shoulder",
        "upper": ["{s}upperarm"], "upper_twist": ["{s}upperarmtwist1", "{s}upperarmtwist2"], "fore": ["{s}forearm"],
        "fore_twist": ["{s}forearmtwist1", "{s}forearmtwist2"], "hand": "{s}hand",
        "fingers": _fingers("{{s}}{f}{n}", ("thumb", "index", "mid", "ring", "pinky"), ("1", "2", "3")),
        "thigh": ["{s}thigh"], "thigh_twist": ["{s}thightwist1", "{s}thightwist2"], "shin": ["{s}shin"],
        "shin_twist": [], "foot": "{s}foot", "toe": "{s}toes"},
    "character-creator": {
        "sides": ["L", "R"], "root": "CC_Base_BoneRoot",
        "spine": ["CC_Base_Hip", "CC_Base_Waist", "CC_Base_Spine01", "CC_Base_Spine02"], "legs_parent": "CC_Base_Pelvis",
        "neck": ["CC_Base_NeckTwist01", "CC_Base_NeckTwist02"], "head": "CC_Base_Head",
        "clavicle": "CC_Base_{s}_Clavicle", "upper": ["CC_Base_{s}_Upperarm"],
        "upper_twist": ["CC_Base_{s}_UpperarmTwist01", "CC_Base_{s}_UpperarmTwist02"], "fore": ["CC_Base_{s}_Forearm"],
        "fore_twist": ["CC_Base_{s}_ForearmTwist01", "CC_Base_{s}_ForearmTwist02"], "hand": "CC_Base_{s}_Hand",
        "fingers": _fingers("CC_Base_{{s}}_{f}{n}", ("Thumb", "Index", "Mid", "Ring", "Pinky"), ("1", "2", "3")),
        "thigh": ["CC_Base_{s}_Thigh"], "thigh_twist": ["CC_Base_{s}_ThighTwist01", "CC_Base_{s}_ThighTwist02"],
        "shin": ["CC_Base_{s}_Calf"], "shin_twist": ["CC_Base_{s}_CalfTwist01", "CC_Base_{s}_CalfTwist02"],
        "foot": "CC_Base_{s}_Foot", "toe": "CC_Base_{s}_ToeBase"},
}
