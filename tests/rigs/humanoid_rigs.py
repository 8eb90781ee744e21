"""Humanoid armatures as arrays (names, parents, heads, tails; Blender axes, metres, facing -Y), built from
a short layout per rig family: bone-name lists placed on one body's landmarks. Variants: twist bones beside or
inside the limbs, fingers, face bones, an A-pose, and every name replaced by a seeded random string."""
from __future__ import annotations

import json
from dataclasses import dataclass, replace

import numpy as np

from kinect_retarget.assets import MAKEHUMAN_DIR
from kinect_retarget.core.target_rig import TargetRig


@dataclass
class Rig:
    names: list
    parents: np.ndarray
    heads: np.ndarray
    tails: np.ndarray

    def target(self, name="Rig") -> TargetRig:
        """A TargetRig with each bone's Y axis along head -> tail (roll from a fixed up hint)."""
        rest = np.tile(np.eye(4), (len(self.names), 1, 1))
        for i, (h, t) in enumerate(zip(self.heads, self.tails)):
            y = (t - h) / np.linalg.norm(t - h)
            hint = np.array([0.0, -1.0, 0.0]) if abs(y[1]) < 0.9 else np.array([0.0, 0.0, 1.0])
            x = np.cross(y, hint)
            x /= np.linalg.norm(x)
            rest[i, :3, :3] = np.stack([x, y, np.cross(x, y)], axis=1)
            rest[i, :3, 3] = h
        return TargetRig(name, tuple(self.names), self.parents, rest, np.linalg.norm(self.tails - self.heads, axis=1))


def from_target(rig: TargetRig) -> Rig:
    return Rig(list(rig.bone_names), rig.parents.copy(), rig.heads.copy(), rig.tails.copy())


def renamed(rig: Rig, seed: int) -> tuple[Rig, dict]:
    """Every bone renamed to a random string; returns the rig and {new name: old name}."""
    rng = np.random.default_rng(seed)
    letters = np.array(list("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"))
    new = ["".join(rng.choice(letters, 10)) for _ in rig.names]
    return replace(rig, names=new), dict(zip(new, rig.names))


# landmarks of one body in a T-pose (left side; the right mirrors X)
HIPS, NECK_BASE, SKULL, TOP = (0, 0, 1.0), (0, 0, 1.47), (0, 0, 1.6), (0, 0, 1.78)
CLAV, SHOULDER, ELBOW, WRIST, KNUCKLE = (0.02, 0.0, 1.44), (0.18, 0.02, 1.44), (0.46, 0.03, 1.44), \
    (0.71, 0.0, 1.44), (0.80, 0.0, 1.44)
HIP, KNEE, ANKLE, BALL, TOE = (0.1, 0, 0.94), (0.1, -0.02, 0.52), (0.1, 0.02, 0.09), (0.1, -0.11, 0.02), \
    (0.1, -0.18, 0.02)


class _Builder:
    def __init__(self):
        self.names, self.parents, self.heads, self.tails = [], [], [], []

    def bone(self, name, parent, head, tail) -> str:
        self.names.append(name)
        self.parents.append(parent)
        self.heads.append(np.asarray(head, float))
        self.tails.append(np.asarray(tail, float))
        return name

    def chain(self, names, parent, a, b) -> str:
        """Bones `names` splitting a -> b evenly, each the child of the one before; returns the last."""
        a, b = np.asarray(a, float), np.asarray(b, float)
        for i, n in enumerate(names):
            parent = self.bone(n, parent, a + (b - a) * i / len(names), a + (b - a) * (i + 1) / len(names))
        return parent

    def leaves(self, names, parent, a, b) -> None:
        """Twist bones beside a limb bone: short leaves along a -> b."""
        a, b = np.asarray(a, float), np.asarray(b, float)
        for i, n in enumerate(names):
            f = (i + 0.5) / (len(names) + 0.5)
            self.bone(n, parent, a + (b - a) * f, a + (b - a) * (f + 0.15))

    def rig(self) -> Rig:
        index = {n: i for i, n in enumerate(self.names)}
        return Rig(list(self.names), np.array([index[p] if p else -1 for p in self.parents]),
                   np.array(self.heads), np.array(self.tails))


def _side(p, x_sign):
    return np.array([p[0] * x_sign, p[1], p[2]])


def build(layout: dict, a_pose_deg: float = 0.0, fingers: bool = True, face: bool = False) -> Rig:
    """layout: {"sides": [l, r], "root": name|None, "spine": [pelvis, ..., chest], "legs_parent": name|None,
    "neck": [...], "head": name, "clavicle", "upper": [...], "upper_twist": [...], "fore": [...],
    "fore_twist": [...], "hand", "fingers": {finger: [bones]}, "thigh": [...], "thigh_twist": [...],
    "shin": [...], "shin_twist": [...], "foot", "toe"} ('{s}' in limb names: the side tag)."""
    b = _Builder()
    parent = b.bone(layout["root"], None, (0, 0, 0), (0, 0.1, 0)) if layout.get("root") else None
    spine = layout["spine"]
    chest = b.chain(spine, parent, HIPS, NECK_BASE)
    pelvis = spine[0]
    if layout.get("legs_parent"):  # Daz: a pelvis bone under the hip carries the legs
        pelvis = b.bone(layout["legs_parent"], spine[0], HIPS, (0, 0, 0.9))
    neck = b.chain(layout["neck"], chest, NECK_BASE, SKULL)
    head = b.bone(layout["head"], neck, SKULL, TOP)
    if face:
        for n, (h, t) in {"face_eye.L": ((0.03, -0.08, 1.68), (0.03, -0.1, 1.68)),
                          "face_eye.R": ((-0.03, -0.08, 1.68), (-0.03, -0.1, 1.68)),
                          "face_jaw": ((0, -0.02, 1.62), (0, -0.09, 1.57))}.items():
            b.bone(n, head, h, t)
        b.chain(["face_jaw.001", "face_chin"], "face_jaw", (0, -0.09, 1.57), (0, -0.11, 1.55))
    a = np.radians(a_pose_deg)
    for tag, x in zip(layout["sides"], (1, -1)):
        def arm(p):  # lower the arm about the forward axis around the shoulder
            p, s = _side(p, x), _side(SHOULDER, x)
            d = p - s
            rot = np.array([[np.cos(a), 0, -np.sin(a) * x], [0, 1, 0], [np.sin(a) * x, 0, np.cos(a)]])
            return s + rot @ d if a_pose_deg else p

        def nm(key):
            v = layout[key]
            return [n.format(s=tag) for n in v] if isinstance(v, list) else v.format(s=tag)
        clav = b.bone(nm("clavicle"), chest, _side(CLAV, x), arm(SHOULDER))
        upper = b.chain(nm("upper"), clav, arm(SHOULDER), arm(ELBOW))
        b.leaves(nm("upper_twist"), nm("upper")[0], arm(SHOULDER), arm(ELBOW))
        fore = b.chain(nm("fore"), upper, arm(ELBOW), arm(WRIST))
        b.leaves(nm("fore_twist"), nm("fore")[0], arm(ELBOW), arm(WRIST))
        hand = b.bone(nm("hand"), fore, arm(WRIST), arm(KNUCKLE))
        if fingers:
            for k, (finger, bones) in enumerate(layout["fingers"].items()):
                dy = (k - 1.5) * 0.022
                base = np.array([0.02 if finger == "thumb" else 0.0, dy - (0.03 if finger == "thumb" else 0), 0])
                start = arm(np.array(WRIST) + base + (0, 0, 0)) if finger == "thumb" else arm(np.array(KNUCKLE) + base)
                b.chain([n.format(s=tag) for n in bones], hand, start, start + arm(np.array(WRIST) + (0.09, 0, 0)) - arm(WRIST))
        thigh = b.chain(nm("thigh"), pelvis, _side(HIP, x), _side(KNEE, x))
        b.leaves(nm("thigh_twist"), nm("thigh")[0], _side(HIP, x), _side(KNEE, x))
        shin = b.chain(nm("shin"), thigh, _side(KNEE, x), _side(ANKLE, x))
        b.leaves(nm("shin_twist"), nm("shin")[0], _side(KNEE, x), _side(ANKLE, x))
        foot = b.bone(nm("foot"), shin, _side(ANKLE, x), _side(BALL, x))
        b.bone(nm("toe"), foot, _side(BALL, x), _side(TOE, x))
    return b.rig()


def makehuman_rig() -> Rig:
    """MakeHuman's default skeleton (163 bones, A-pose, twist halves inside the limbs, fingers, face)."""
    skel = json.loads((MAKEHUMAN_DIR / "default.mhskel").read_text())
    verts = np.array([[float(x) for x in line.split()[1:4]] for line in open(MAKEHUMAN_DIR / "base.obj")
                      if line.startswith("v ")])
    joints = {n: verts[i].mean(axis=0) for n, i in skel["joints"].items()}

    def blender(p):  # decimetres, Y-up -> metres, Z-up, facing -Y
        return np.array((0.1 * p[0], -0.1 * p[2], 0.1 * p[1]))
    names = list(skel["bones"])
    bones = skel["bones"]
    return Rig(names, np.array([names.index(bones[n]["parent"]) if bones[n]["parent"] else -1 for n in names]),
               np.array([blender(joints[bones[n]["head"]]) for n in names]),
               np.array([blender(joints[bones[n]["tail"]]) for n in names]))
