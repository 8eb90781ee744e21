"""Per-pixel body-part labels for rendered depth (training data and tests of the part classifier).

Each skin vertex gets a part (body_parts.PARTS) from the MakeHuman mesh's own skin weights: the driver
that moves it most (makehuman_body.DRIVERS), split along that driver's bone in the rest pose (the shoulder, elbow
and wrist parts are the ends of the arm's bones), the torso into quarters by height and side. Rendered
surface samples take the label of their nearest quad corner, and the z-buffer keeps the nearest sample's.
"""
from __future__ import annotations

import numpy as np

from ..depth.body_parts import BACKGROUND, PART
from ..depth.depth_camera import DepthCamera
from .depth_render import splat
from .makehuman_body import DRIVER_NAMES, BodyModel
from .mocap_pose import _rest_points

# limb driver -> (bone start, bone end, [(fraction along the bone up to which, part)])
_LIMB_SPLITS = {
    "upperarm": ("shoulder", "elbow", ((0.2, "shoulder"), (0.75, "upperarm"), (9, "elbow"))),
    "lowerarm": ("elbow", "wrist", ((0.2, "elbow"), (0.8, "forearm"), (9, "wrist"))),
    "hand": ("wrist", "hand", ((0.15, "wrist"), (9, "hand"))),
    "upperleg": ("hip", "knee", ((0.2, "hip"), (0.82, "thigh"), (9, "knee"))),
    "lowerleg": ("knee", "ankle", ((0.15, "knee"), (0.85, "shin"), (9, "ankle"))),
    "foot": ("ankle", "toe", ((9, "foot"),)),
}


def vertex_parts(body: BodyModel) -> np.ndarray:
    """(V,) part index of every skin vertex."""
    rest = _rest_points(body)
    v = body.rest_vertices
    driver = np.asarray(DRIVER_NAMES)[np.argmax(body.weights, axis=1)]
    out = np.full(len(v), PART["torso_lower_left"], np.uint8)
    left = v[:, 0] > 0   # MakeHuman: the character's left at +X
    for i in range(len(v)):
        name = driver[i]
        if name == "head":
            neck_top = rest["neck"][1] + 0.35 * (rest["head_mid"][1] - rest["neck"][1])
            out[i] = PART["neck" if v[i, 1] < neck_top else "head"]
        elif name in ("chest", "abdomen", "pelvis"):
            out[i] = PART[f"torso_{'upper' if name == 'chest' else 'lower'}_{'left' if left[i] else 'right'}"]
        else:
            limb, s = name.split(".")
            a, b, splits = _LIMB_SPLITS[limb]
            pa, pb = rest[f"{a}.{s}"], rest[f"{b}.{s}"]
            t = float((v[i] - pa) @ (pb - pa) / max((pb - pa) @ (pb - pa), 1e-9))
            part = next(p for upto, p in splits if t < upto)
            out[i] = PART[f"{part}_{'left' if s == 'L' else 'right'}"]
    return out


def surface_labels(labels: np.ndarray, quads: np.ndarray, groups) -> np.ndarray:
    """Per surface sample (in render.surface_points' order) the part of its quad's nearest corner."""
    return np.concatenate([labels[quads[idx]][:, np.argmax(w, axis=1)].reshape(-1) for idx, w in groups])


def render_parts(points: np.ndarray, point_labels: np.ndarray, cam: DepthCamera):
    """(depth metres (H, W), inf = empty; labels (H, W) uint8, BACKGROUND where empty) of surface samples."""
    depth, lab = splat(points, cam, point_labels)
    return depth, np.where(lab < 0, BACKGROUND, lab).astype(np.uint8)
