"""The naming scheme for Movie Clip tracks (docs/lifting.md): which joint each 2D track follows.

A track name is matched after lower-casing and dropping separators (space, _, -, .): a side (left/right,
l/r as a prefix or suffix) plus a body part. Kinect names (ElbowLeft), OpenPose names (LElbow), COCO names
(left_elbow), H-Anim names (l_elbow, humanoid_root, skullbase) and plain words (left elbow, L.Elbow) all work.
"""
from __future__ import annotations

import re

# Body part words -> Kinect v1 joint stem (sided) or full name (central).
_SIDED = {
    "shoulder": "Shoulder", "elbow": "Elbow", "wrist": "Wrist", "hand": "Hand", "hip": "Hip", "knee": "Knee",
    "ankle": "Ankle", "foot": "Foot", "toe": "Foot", "toes": "Foot", "bigtoe": "Foot", "ball": "Foot",
    "upperarm": "Elbow", "forearm": "Wrist", "thigh": "Knee", "shin": "Ankle", "midtarsal": "Foot",
    "metatarsal": "Foot", "radiocarpal": "Wrist",
}
_CENTRAL = {
    "hipcenter": "HipCenter", "hipcentre": "HipCenter", "midhip": "HipCenter", "pelvis": "HipCenter",
    "hips": "HipCenter", "root": "HipCenter", "humanoidroot": "HipCenter", "sacroiliac": "HipCenter",
    "spine": "Spine", "spinemid": "Spine", "vl5": "Spine", "vl1": "Spine", "vt10": "Spine", "chest": "Spine",
    "shouldercenter": "ShoulderCenter", "shouldercentre": "ShoulderCenter", "neck": "ShoulderCenter",
    "spineshoulder": "ShoulderCenter", "vc7": "ShoulderCenter", "vt1": "ShoulderCenter",
    "head": "Head", "skullbase": "Head", "skull": "Head", "nose": "Head", "face": "Head",
}
_SIDES = (("left", "Left"), ("right", "Right"), ("l", "Left"), ("r", "Right"))


def joint_for_track(name: str) -> str | None:
    """The Kinect v1 joint a track name denotes, or None when the name follows no known scheme."""
    key = re.sub(r"[\s_\-.:]+", "", name).lower()
    key = re.sub(r"\d+$", "", key) if key not in _CENTRAL else key  # "knee.001" duplicates
    if key in _CENTRAL:
        return _CENTRAL[key]
    for word, side in _SIDES:
        for part in (key[len(word):] if key.startswith(word) else None,
                     key[:-len(word)] if key.endswith(word) else None):
            if part and part in _SIDED:
                return _SIDED[part] + side
    return None


def match_tracks(names: list[str]) -> tuple[dict[str, str], list[str]]:
    """Map track names to joints. Returns ({track name: joint}, problems). Unknown names and a second track
    for the same joint are reported, never guessed."""
    mapping: dict[str, str] = {}
    unknown, problems = [], []
    taken: dict[str, str] = {}
    for n in names:
        j = joint_for_track(n)
        if j is None:
            unknown.append(n)
        elif j in taken:
            problems.append(f"tracks '{taken[j]}' and '{n}' both name joint {j}; using '{taken[j]}'")
        else:
            taken[j] = n
            mapping[n] = j
    if unknown:
        problems.append(f"{len(unknown)} track name(s) follow no joint naming and were ignored: "
                        f"{', '.join(repr(u) for u in unknown[:8])}{' ...' if len(unknown) > 8 else ''} "
                        f"(name tracks like 'ElbowLeft', 'l_elbow', 'LElbow' or 'left elbow'; see docs/lifting.md)")
    return mapping, problems
