"""Paper 004's output: a 16-joint H-Anim humanoid driven by joint Euler angles from inverse kinematics.

The figure (paper fig. 2: 16 joints, 15 segments, the pelvis the root) with H-Anim names; the joints H-Anim
has between them and a lower level of articulation leaves out are skipped, so each joint's parent is its
nearest H-Anim ancestor present. The pelvis is sacroiliac, the root bone (the armature object plays the
Humanoid and HumanoidRoot transform), so the hips and vl5 hang from it; the neck (skullbase) and both
shoulders hang from vt1 (the thoracic top where the paper's "clavicle" joint sits; the clavicle joints are
left out). The project's 'hanim' bone-mapping preset reads the same names, so our retargeting can drive the
same figure for comparison.

IK (§3.3, eq. 4-5): down the tree, each joint's rotation turns its rest bone (local +Y, toward its child)
onto the observed direction, in the frame its parent's rotation leaves it: R = Rz(α) Ry(β) Rx(γ), applied
X first (Blender's 'XYZ' Euler mode). One direction fixes two angles: the paper sets the pelvis's β (the
twist about the bone) to 0, and positions carry no twist for any other joint either, so every β is 0.
"""
from __future__ import annotations

import numpy as np

from ..core.skeletons import KINECT_V1

# (H-Anim joint, parent, Kinect joint it sits on, Kinect joint its bone points to)
HANIM_16 = (
    ("sacroiliac", None, "HipCenter", "Spine"),
    ("vl5", "sacroiliac", "Spine", "ShoulderCenter"),
    ("vt1", "vl5", "ShoulderCenter", "Head"),
    ("skullbase", "vt1", "Head", None),
    ("l_shoulder", "vt1", "ShoulderLeft", "ElbowLeft"),
    ("l_elbow", "l_shoulder", "ElbowLeft", "WristLeft"),
    ("l_wrist", "l_elbow", "WristLeft", "HandLeft"),
    ("r_shoulder", "vt1", "ShoulderRight", "ElbowRight"),
    ("r_elbow", "r_shoulder", "ElbowRight", "WristRight"),
    ("r_wrist", "r_elbow", "WristRight", "HandRight"),
    ("l_hip", "sacroiliac", "HipLeft", "KneeLeft"),
    ("l_knee", "l_hip", "KneeLeft", "AnkleLeft"),
    ("l_ankle", "l_knee", "AnkleLeft", "FootLeft"),
    ("r_hip", "sacroiliac", "HipRight", "KneeRight"),
    ("r_knee", "r_hip", "KneeRight", "AnkleRight"),
    ("r_ankle", "r_knee", "AnkleRight", "FootRight"),
)
NAMES = tuple(h[0] for h in HANIM_16)
PARENTS = np.array([-1 if h[1] is None else NAMES.index(h[1]) for h in HANIM_16])
AT = np.array([KINECT_V1.index(h[2]) for h in HANIM_16])
TO = np.array([-1 if h[3] is None else KINECT_V1.index(h[3]) for h in HANIM_16])
HEAD_LENGTH = 0.12  # skullbase's bone (no Kinect joint above the head's centre), metres

# H-Anim's default posture (standing, arms at the sides, facing +Z in H-Anim, -Y in Blender): each bone's
# rest direction in Blender axes (Z up, the figure's left +X).
_REST_DIR = {"sacroiliac": (0, 0, 1), "vl5": (0, 0, 1), "vt1": (0, 0, 1), "skullbase": (0, 0, 1),
             "l_shoulder": (0, 0, -1), "l_elbow": (0, 0, -1), "l_wrist": (0, 0, -1),
             "l_hip": (0, 0, -1), "l_knee": (0, 0, -1), "l_ankle": (0, -1, 0)}
# where each joint sits from its parent's joint at rest (Blender axes, metres, scaled by bone lengths)
_REST_OFFSET = {"l_shoulder": (0.18, 0, 0), "l_hip": (0.09, 0, -0.08)}


def _mirror(name: str) -> str:
    return "r_" + name[2:] if name.startswith("l_") else name


def bone_lengths(positions: np.ndarray) -> np.ndarray:
    """(16,) median length of each H-Anim bone over a take's frames (F, 20, 3), left and right averaged."""
    out = np.full(len(NAMES), HEAD_LENGTH)
    for k in range(len(NAMES)):
        if TO[k] >= 0:
            out[k] = np.nanmedian(np.linalg.norm(positions[:, TO[k]] - positions[:, AT[k]], axis=-1))
    for k, name in enumerate(NAMES):
        if name.startswith("l_"):
            r = NAMES.index(_mirror(name))
            out[k] = out[r] = 0.5 * (out[k] + out[r])
    return np.nan_to_num(out, nan=0.1)


def rest_pose(lengths: np.ndarray, positions: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(heads, tails) (16, 3) of the default posture in Blender axes, the pelvis at the origin; shoulder
    and hip spacing from the take (positions in Blender axes) when given."""
    heads, tails = np.zeros((len(NAMES), 3)), np.zeros((len(NAMES), 3))
    for k, name in enumerate(NAMES):
        base = name if not name.startswith("r_") else "l_" + name[2:]
        sign = np.array([-1.0, 1, 1]) if name.startswith("r_") else np.ones(3)
        direction = np.asarray(_REST_DIR[base], float) * sign
        p = PARENTS[k]
        if p >= 0:  # shoulders and hips sit beside their parent's joint, the rest at its bone's end
            heads[k] = heads[p] + sign * _offset(base, positions) if base in _REST_OFFSET else tails[p]
        tails[k] = heads[k] + direction * lengths[k]
    return heads, tails


def _offset(base: str, positions) -> np.ndarray:
    off = np.asarray(_REST_OFFSET[base], float)
    if positions is None:
        return off
    a, b = (("ShoulderLeft", "ShoulderRight") if base == "l_shoulder" else ("HipLeft", "HipRight"))
    half = 0.5 * np.nanmedian(np.linalg.norm(positions[:, KINECT_V1.index(a)] - positions[:, KINECT_V1.index(b)],
                                             axis=-1))
    return off * (half / off[0]) if np.isfinite(half) and half > 0 else off


def rest_frames(heads: np.ndarray, tails: np.ndarray) -> np.ndarray:
    """(16, 3, 3) world rest orientation of each bone: Y along the bone, X toward the figure's left where
    the bone allows (Blender's edit-bone convention for roll 0 is not needed: these are the frames the
    Euler angles are measured in, and the armature is built with them)."""
    out = np.zeros((len(NAMES), 3, 3))
    for k in range(len(NAMES)):
        y = tails[k] - heads[k]
        y /= np.linalg.norm(y)
        ref = np.array([1.0, 0, 0]) if abs(y[0]) < 0.9 else np.array([0, 0, 1.0])
        x = ref - y * (ref @ y)
        x /= np.linalg.norm(x)
        out[k] = np.stack([x, y, np.cross(x, y)], axis=1)
    return out


def euler_from_direction(u: np.ndarray) -> np.ndarray:
    """(..., 3) Euler angles (γ about X, β = 0 about Y, α about Z) with Rz(α) Rx(γ) (0, 1, 0) = u (unit)."""
    gamma = np.arcsin(np.clip(u[..., 2], -1.0, 1.0))
    alpha = np.arctan2(-u[..., 0], u[..., 1])
    return np.stack([gamma, np.zeros_like(gamma), alpha], axis=-1)


def euler_matrix(e: np.ndarray) -> np.ndarray:
    """Rz(α) Ry(β) Rx(γ) for (..., 3) angles (γ, β, α): Blender's 'XYZ' Euler mode."""
    g, b, a = e[..., 0], e[..., 1], e[..., 2]
    cg, sg, cb, sb, ca, sa = np.cos(g), np.sin(g), np.cos(b), np.sin(b), np.cos(a), np.sin(a)
    one, zero = np.ones_like(g), np.zeros_like(g)
    rx = np.stack([one, zero, zero, zero, cg, -sg, zero, sg, cg], -1).reshape(e.shape[:-1] + (3, 3))
    ry = np.stack([cb, zero, sb, zero, one, zero, -sb, zero, cb], -1).reshape(e.shape[:-1] + (3, 3))
    rz = np.stack([ca, -sa, zero, sa, ca, zero, zero, zero, one], -1).reshape(e.shape[:-1] + (3, 3))
    return rz @ ry @ rx


def solve_euler(positions: np.ndarray, rest: np.ndarray) -> np.ndarray:
    """(F, 16, 3) Euler angles (radians) per frame from Kinect joint positions (F, 20, 3) in Blender axes,
    rest: (16, 3, 3) rest_frames. Eq. 4: each joint's world frame is its parent's posed frame times the
    rest offset between them times its own rotation; the rotation turns the rest bone onto the observed
    one. Frames or joints without a position keep the rest pose (angles 0)."""
    f = positions.shape[0]
    world = np.zeros((f, len(NAMES), 3, 3))
    out = np.zeros((f, len(NAMES), 3))
    for k in range(len(NAMES)):  # parents come first in HANIM_16
        p = PARENTS[k]
        base = np.broadcast_to(rest[k], (f, 3, 3)) if p < 0 else world[:, p] @ (rest[p].T @ rest[k])
        if TO[k] >= 0:
            d = positions[:, TO[k]] - positions[:, AT[k]]
            n = np.linalg.norm(d, axis=-1, keepdims=True)
            ok = np.isfinite(d).all(axis=-1) & (n[:, 0] > 1e-9)
            u = np.einsum("fji,fj->fi", base, np.where(ok[:, None], d / np.where(n > 1e-9, n, 1.0), 0.0))
            out[:, k] = np.where(ok[:, None], euler_from_direction(u), 0.0)
        world[:, k] = base @ euler_matrix(out[:, k])
    return out
