"""Pose the MakeHuman body from optical mocap joint positions by direction matching (numpy only).

Each driver (body_model.DRIVERS) gets a global rotation per frame: the pelvis and chest from two
directions (up and left-right), the limbs by the shortest swing that turns their rest direction, as
already rotated by the parent, onto the mocap direction (twist follows the parent). Joint positions chain
through the MakeHuman bone lengths, so the mesh keeps its proportions; the ground truth joints are the
MakeHuman skeleton's own joints, posed the same way.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.skeletons import KINECT_V1
from ..core.joint_frames import frame_from_y_hint
from ..core.quat import normalize
from .makehuman_body import DRIVER_NAMES, DRIVERS, BodyModel, linear_blend_skinning

# Canonical mocap points -> candidate BVH joint names (CMU "max" release first, then the MotionBuilder one).
_CMU_ALIASES = {
    "hips": ("Hips",), "chest": ("Chest", "Spine"), "neck": ("Neck1", "Neck"), "head": ("Head",),
    **{f"{k}.{s}": tuple(n.format(S=side) for n in names) for s, side in (("L", "Left"), ("R", "Right"))
       for k, names in (("hip", ("{S}Hip", "{S}UpLeg")), ("knee", ("{S}Knee", "{S}Leg")),
                        ("ankle", ("{S}Ankle", "{S}Foot")), ("toe", ("{S}Toe", "{S}ToeBase")),
                        ("elbow", ("{S}Elbow", "{S}ForeArm")), ("wrist", ("{S}Wrist", "{S}Hand")))},
}


def _mid(a, b):
    return 0.5 * (np.asarray(a) + np.asarray(b))


def cmu_points(names: list[str], positions: np.ndarray) -> dict[str, np.ndarray]:
    """Pick the canonical points out of CMU BVH joint positions (F, J, 3)."""
    mb = "LeftArm" in names  # MotionBuilder naming: LeftShoulder is the collar there
    out = {}
    for key, cands in _CMU_ALIASES.items():
        for c in cands:
            if c in names:
                out[key] = positions[:, names.index(c)]
                break
        else:
            raise ValueError(f"mocap has no joint for {key} (looked for {', '.join(cands)})")
    for s, side in (("L", "Left"), ("R", "Right")):
        out[f"shoulder.{s}"] = positions[:, names.index(f"{side}Arm" if mb else f"{side}Shoulder")]
        hand = f"{side[0]}Fingers"  # the knuckles: the hand joints themselves sit on the wrist
        out[f"hand.{s}"] = positions[:, names.index(hand)] if hand in names else out[f"wrist.{s}"]
    return out


# Driver -> (rest joint pair giving its direction, mocap pair for the same direction).
def _rest_points(body: BodyModel) -> dict[str, np.ndarray]:
    bj = body.joints["bones"]
    head = {b: h for b, (h, _) in bj.items()}
    tail = {b: t for b, (_, t) in bj.items()}
    p = {"hips": _mid(head["upperleg01.L"], head["upperleg01.R"]), "chest": head["spine02"],
         "neck": head["neck01"], "head": tail["head"], "head_mid": _mid(head["head"], tail["head"]),
         "spine": head["spine02"]}
    for s in ("L", "R"):
        p.update({f"hip.{s}": head[f"upperleg01.{s}"], f"knee.{s}": head[f"lowerleg01.{s}"],
                  f"ankle.{s}": head[f"foot.{s}"], f"toe.{s}": head[f"toe1-1.{s}"],
                  f"foot.{s}": tail[f"foot.{s}"],
                  f"shoulder.{s}": head[f"upperarm01.{s}"], f"elbow.{s}": head[f"lowerarm01.{s}"],
                  f"wrist.{s}": head[f"wrist.{s}"], f"hand.{s}": tail[f"metacarpal3.{s}"]})
    return p


_LIMB = {f"{d}.{s}": (f"{a}.{s}", f"{b}.{s}") for s in ("L", "R") for d, a, b in (
    ("upperarm", "shoulder", "elbow"), ("lowerarm", "elbow", "wrist"), ("hand", "wrist", "hand"),
    ("upperleg", "hip", "knee"), ("lowerleg", "knee", "ankle"), ("foot", "ankle", "toe"))}
_ORIGIN = {"pelvis": "hips", "abdomen": "hips", "chest": "chest", "head": "neck",
           **{d: a for d, (a, _) in _LIMB.items()}}
# Kinect v1 joint -> (rest point, driver that carries it)
_KINECT_POINTS = {
    "HipCenter": ("hips", "pelvis"), "Spine": ("spine", "abdomen"), "ShoulderCenter": ("neck", "chest"),
    "Head": ("head_mid", "head"),
    **{f"{k}{side}": (f"{p}.{s}", d if d in ("chest", "pelvis") else f"{d}.{s}") for s, side in (("L", "Left"), ("R", "Right")) for k, p, d in (
        ("Shoulder", "shoulder", "chest"), ("Elbow", "elbow", "upperarm"), ("Wrist", "wrist", "lowerarm"),
        ("Hand", "hand", "hand"), ("Hip", "hip", "pelvis"), ("Knee", "knee", "upperleg"),
        ("Ankle", "ankle", "lowerleg"), ("Foot", "foot", "foot"))},
}
_KINECT_POINTS = {k: _KINECT_POINTS[k] for k in KINECT_V1.joints}


def _swing(a, b):
    """Smallest rotations (..., 3, 3) turning unit vectors a onto b (Rodrigues)."""
    a, b = normalize(a), normalize(b)
    v = np.cross(a, b)
    c = np.sum(a * b, -1)
    k = np.zeros(v.shape + (3,))
    k[..., 0, 1], k[..., 0, 2], k[..., 1, 2] = -v[..., 2], v[..., 1], -v[..., 0]
    k = k - np.swapaxes(k, -1, -2)
    scale = (1.0 / np.maximum(1.0 + c, 1e-9))[..., None, None]
    return np.eye(3) + k + k @ k * scale


@dataclass
class PosedSequence:
    rotations: np.ndarray     # (F, D, 3, 3) driver rotations
    origins_rest: np.ndarray  # (D, 3)
    origins_posed: np.ndarray  # (F, D, 3)
    joints: np.ndarray        # (F, 20, 3) Kinect v1 ground truth, same space as the mesh

    def vertices(self, body: BodyModel, frames=None) -> np.ndarray:
        """(F, V, 3) linear-blend-skinned skin vertices."""
        sel = slice(None) if frames is None else frames
        return linear_blend_skinning(body.rest_vertices, body.weights, self.rotations[sel], self.origins_rest,
                                     self.origins_posed[sel])


def pose_from_points(body: BodyModel, cmu: dict[str, np.ndarray]) -> PosedSequence:
    """Direction-matching retarget of mocap points onto the MakeHuman skeleton."""
    rest = _rest_points(body)
    nf = cmu["hips"].shape[0]
    hips_c = _mid(cmu["hip.L"], cmu["hip.R"])
    leg = lambda p: (np.linalg.norm(p["hip.L"] - p["knee.L"], axis=-1) + np.linalg.norm(p["knee.L"] - p["ankle.L"], axis=-1))
    scale = float(leg(rest) / np.median(leg(cmu)))
    rot: dict[str, np.ndarray] = {}
    rest_pelvis = frame_from_y_hint(rest["chest"] - rest["hips"], rest["hip.L"] - rest["hip.R"])
    rot["pelvis"] = frame_from_y_hint(cmu["chest"] - hips_c, cmu["hip.L"] - cmu["hip.R"]) @ rest_pelvis.T
    rest_chest = frame_from_y_hint(rest["neck"] - rest["chest"], rest["shoulder.L"] - rest["shoulder.R"])
    rot["chest"] = frame_from_y_hint(cmu["neck"] - cmu["chest"], cmu["shoulder.L"] - cmu["shoulder.R"]) @ rest_chest.T
    lat = normalize(cmu["hip.L"] - cmu["hip.R"]) + normalize(cmu["shoulder.L"] - cmu["shoulder.R"])
    rest_abd = frame_from_y_hint(rest["neck"] - rest["hips"], (rest["hip.L"] - rest["hip.R"]) * 2)
    rot["abdomen"] = frame_from_y_hint(cmu["neck"] - hips_c, lat) @ rest_abd.T
    rot["head"] = _swing(np.einsum("fij,j->fi", rot["chest"], rest["head"] - rest["neck"]),
                         cmu["head"] - cmu["neck"]) @ rot["chest"]
    for d in DRIVER_NAMES:
        if d in _LIMB:
            a, b = _LIMB[d]
            parent = rot[DRIVERS[d][0]]
            rot[d] = _swing(np.einsum("fij,j->fi", parent, rest[b] - rest[a]), cmu[b] - cmu[a]) @ parent
    rotations = np.stack([rot[d] for d in DRIVER_NAMES], axis=1)
    origins_rest = np.stack([rest[_ORIGIN[d]] for d in DRIVER_NAMES])
    posed = np.zeros((nf, len(DRIVER_NAMES), 3))
    for i, d in enumerate(DRIVER_NAMES):  # parents come first in DRIVERS
        parent = DRIVERS[d][0]
        if parent is None:
            posed[:, i] = hips_c * scale
        else:
            p = DRIVER_NAMES.index(parent)
            posed[:, i] = posed[:, p] + np.einsum("fij,j->fi", rotations[:, p], origins_rest[i] - origins_rest[p])
    joints = np.zeros((nf, len(KINECT_V1), 3))
    for j, (pt, d) in enumerate(_KINECT_POINTS.values()):
        i = DRIVER_NAMES.index(d)
        joints[:, j] = posed[:, i] + np.einsum("fij,j->fi", rotations[:, i], rest[pt] - origins_rest[i])
    return PosedSequence(rotations, origins_rest, posed, joints)
