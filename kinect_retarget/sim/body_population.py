"""A population of synthetic performers for the body-part forest's training data (tools/train_body_parts.py).

The MakeHuman body varied three ways, each keeping every skin vertex's part label:
- proportions: MakeHuman's skeleton and mesh scaled per segment (upper arm, forearm, hand, thigh, shin, torso
  length, shoulder and hip width), each driver's skin stretched along its bone about its joint, the joints
  chained so children stay attached, blended by skin weight;
- loose clothing and hair as offset surfaces: skin pushed out along its normals by a few cm per garment
  (top, sleeves, trousers, hair volume on the crown and back of the head), and sometimes a skirt or coat hem:
  a flared tube from the waist to about the knees, skinned and labelled from the body beneath it;
- poses of real Kinect recordings (any take the project reads: Kinect v2 CSV / Kinectron JSON, UI-PRMD) as
  the canonical mocap points sim/mocap_pose.pose_from_points poses the body from, as it does for CMU BVH.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..core.skeletons import V1_FROM_V2
from ..core.take import Take
from .makehuman_body import DRIVER_NAMES, DRIVERS, BodyModel, _driver_of_bone, read_makehuman
from .mocap_pose import _LIMB, _ORIGIN, _rest_points

# segment -> (low, high) length factor, uniform; the sources are adult spreads of a few per cent (sd ~4-5 %
# for limb segments), widened so the forest sees more than one body plan
PROPORTION_RANGES = {"upperarm": (0.88, 1.12), "forearm": (0.88, 1.12), "hand": (0.85, 1.15),
                     "thigh": (0.9, 1.1), "shin": (0.9, 1.1), "torso": (0.9, 1.12),
                     "shoulders": (0.88, 1.12), "hips": (0.88, 1.15)}
_LIMB_SEGMENT = {"upperarm": "upperarm", "lowerarm": "forearm", "hand": "hand", "upperleg": "thigh",
                 "lowerleg": "shin"}
# garment -> (drivers it covers, largest outward offset in metres)
GARMENTS = {"top": (("pelvis", "abdomen", "chest"), 0.045), "sleeves": (("upperarm", "lowerarm"), 0.025),
            "trousers": (("upperleg", "lowerleg"), 0.03)}
HAIR_MAX = 0.05           # metres of hair volume on the crown
SKIRT_CHANCE = 0.2        # share of performers with a skirt or coat hem
SKIRT_FLARE = (0.03, 0.2)  # extra radius at the hem, metres


def random_proportions(rng: np.random.Generator) -> dict[str, float]:
    return {k: float(rng.uniform(lo, hi)) for k, (lo, hi) in PROPORTION_RANGES.items()}


def _driver_transforms(body: BodyModel, scales: dict[str, float]):
    """Per driver (A (3, 3), rest origin, new origin): x -> o' + A (x - o), children's origins chained."""
    rest = _rest_points(body)
    out: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
    mid = 0.5 * (scales["hips"] + scales["shoulders"])
    for d in DRIVER_NAMES:   # parents come first
        o = rest[_ORIGIN[d]]
        a = np.eye(3)
        if d == "pelvis":
            a = np.diag([scales["hips"], 1.0, 1.0])
        elif d == "abdomen":
            a = np.diag([mid, scales["torso"], 1.0])
        elif d == "chest":
            a = np.diag([scales["shoulders"], scales["torso"], 1.0])
        elif d in _LIMB and d.split(".")[0] in _LIMB_SEGMENT:
            p, q = _LIMB[d]
            axis = (rest[q] - rest[p]) / np.linalg.norm(rest[q] - rest[p])
            a = np.eye(3) + (scales[_LIMB_SEGMENT[d.split(".")[0]]] - 1.0) * np.outer(axis, axis)
        parent = DRIVERS[d][0]
        if parent is None:
            new_o = o.copy()
        else:
            pa, po, pn = out[parent]
            new_o = pn + pa @ (o - po)
        out[d] = (a, o, new_o)
    return out


def proportioned_body(body: BodyModel, scales: dict[str, float], mesh_dir: str) -> BodyModel:
    """`body` with its segments scaled by `scales` (PROPORTION_RANGES keys): mesh blended by skin weight, the
    skeleton's bones moved with the driver that owns them (`mesh_dir`: the MakeHuman files it came from)."""
    tf = _driver_transforms(body, scales)
    v = body.rest_vertices
    moved = np.stack([n + (v - o) @ a.T for a, o, n in (tf[d] for d in DRIVER_NAMES)], axis=1)   # (V, D, 3)
    verts = np.einsum("vd,vdc->vc", body.weights, moved)
    owner = _driver_of_bone(read_makehuman(mesh_dir).skeleton["bones"])

    def move(bone, p):
        a, o, n = tf[owner.get(bone, "pelvis")]
        return n + a @ (p - o)
    bones = {b: (move(b, h), move(b, t)) for b, (h, t) in body.joints["bones"].items()}
    return replace(body, rest_vertices=verts, joints={**body.joints, "bones": bones})


def vertex_normals(vertices: np.ndarray, quads: np.ndarray) -> np.ndarray:
    """(V, 3) unit normals, the area-weighted mean of the adjoining quads' (diagonal cross products)."""
    c = vertices[quads]
    qn = np.cross(c[:, 2] - c[:, 0], c[:, 3] - c[:, 1])
    n = np.zeros_like(vertices)
    for k in range(4):
        np.add.at(n, quads[:, k], qn)
    return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)


def _outward(body: BodyModel) -> np.ndarray:
    """Normals oriented away from the body (MakeHuman's winding is not relied on): flipped where they point
    towards the owning driver's bone or axis."""
    n = vertex_normals(body.rest_vertices, body.quads)
    rest = _rest_points(body)
    v = body.rest_vertices
    main = np.asarray(DRIVER_NAMES)[np.argmax(body.weights, axis=1)]
    centre = np.tile(rest["hips"], (len(v), 1))
    centre[:, 1] = v[:, 1]   # torso: away from the vertical axis through the hips
    for d in DRIVER_NAMES:
        sel = main == d
        if d == "head":
            centre[sel] = rest["head_mid"]
        elif d in _LIMB:
            p, q = rest[_LIMB[d][0]], rest[_LIMB[d][1]]
            t = np.clip((v[sel] - p) @ (q - p) / ((q - p) @ (q - p)), 0, 1)
            centre[sel] = p + t[:, None] * (q - p)
    flip = np.sum(n * (v - centre), axis=1) < 0
    n[flip] *= -1
    return n


def clothed_body(body: BodyModel, labels: np.ndarray, rng: np.random.Generator,
                 skirt_chance: float = SKIRT_CHANCE) -> tuple[BodyModel, np.ndarray]:
    """Loose clothes and hair as offset surfaces on `body` (rest pose); (body, per-vertex labels). Offsets
    move vertices along their outward normals (labels unchanged); a skirt/coat hem adds a skinned tube whose
    vertices take the label and skin weights of the nearest body vertex."""
    v = body.rest_vertices
    n = _outward(body)
    offset = np.zeros(len(v))
    driver_kind = [d.split(".")[0] for d in DRIVER_NAMES]
    for drivers, most in GARMENTS.values():
        if rng.random() < 0.7:
            amount = rng.uniform(0.0, most)
            cover = np.array([k in drivers for k in driver_kind], float)
            offset += amount * (body.weights @ cover)
    if rng.random() < 0.6:   # hair: most on the crown and the back of the head, none on the face
        rest = _rest_points(body)
        head = body.weights[:, DRIVER_NAMES.index("head")]
        up = (v[:, 1] - rest["head_mid"][1]) / max(rest["head"][1] - rest["head_mid"][1], 1e-6)
        back = (rest["head_mid"][2] - v[:, 2]) / 0.1
        shape = np.clip(np.maximum(up + 0.3, back), 0.0, 1.0) * (v[:, 1] > rest["neck"][1] + 0.08)
        offset += rng.uniform(0.005, HAIR_MAX) * head * shape
    body = replace(body, rest_vertices=v + n * offset[:, None])
    if rng.random() < skirt_chance:
        body, labels = _with_skirt(body, labels, rng)
    return body, labels


def _with_skirt(body: BodyModel, labels: np.ndarray, rng: np.random.Generator, n_theta: int = 48,
                n_rows: int = 8) -> tuple[BodyModel, np.ndarray]:
    """A flared tube from the waist down to about the knees around the hips and thighs."""
    rest = _rest_points(body)
    v = body.rest_vertices
    top = rest["hips"][1] + rng.uniform(0.0, 0.12)
    knee = 0.5 * (rest["knee.L"][1] + rest["knee.R"][1])
    bottom = knee + rng.uniform(-0.15, 0.2)
    flare = rng.uniform(*SKIRT_FLARE)
    lower = np.isin(np.argmax(body.weights, axis=1),
                    [DRIVER_NAMES.index(d) for d in ("pelvis", "abdomen", "upperleg.L", "upperleg.R")])
    centre = rest["hips"]
    theta = np.linspace(0, 2 * np.pi, n_theta, endpoint=False)
    ring = []
    for i, y in enumerate(np.linspace(top, bottom, n_rows)):
        sl = lower & (np.abs(v[:, 1] - y) < 0.03)
        d = v[sl][:, [0, 2]] - centre[[0, 2]]
        ang = np.arctan2(d[:, 1], d[:, 0])
        r = np.hypot(d[:, 0], d[:, 1])
        # widest body point within each direction's 30-degree sector, plus a loose fit and the flare
        diff = np.abs((ang[None] - theta[:, None] + np.pi) % (2 * np.pi) - np.pi)
        radius = np.where(diff < np.radians(15), r[None], 0.0).max(axis=1) if len(r) else np.full(n_theta, 0.15)
        radius = np.maximum(radius, 0.08) + 0.01 + flare * i / (n_rows - 1)
        ring.append(np.stack([centre[0] + radius * np.cos(theta), np.full(n_theta, y),
                              centre[2] + radius * np.sin(theta)], axis=1))
    pts = np.concatenate(ring)
    cand = np.flatnonzero(lower)
    near = cand[np.argmin(((pts[:, None] - v[cand][None]) ** 2).sum(-1), axis=1)]
    k = len(v)
    r_i, t_i = np.meshgrid(np.arange(n_rows - 1), np.arange(n_theta), indexing="ij")
    a = k + r_i * n_theta + t_i
    b = k + r_i * n_theta + (t_i + 1) % n_theta
    quads = np.stack([a, b, b + n_theta, a + n_theta], axis=-1).reshape(-1, 4)
    return (replace(body, rest_vertices=np.concatenate([v, pts]), quads=np.concatenate([body.quads, quads]),
                    weights=np.concatenate([body.weights, body.weights[near]])),
            np.concatenate([labels, labels[near]]))


# canonical mocap point -> Kinect v1 joint name (v2 takes through core.skeletons.V1_FROM_V2)
_TAKE_POINTS = {"hips": "HipCenter", "chest": "Spine", "neck": "ShoulderCenter", "head": "Head",
                **{f"{p}.{s}": f"{j}{side}" for s, side in (("L", "Left"), ("R", "Right")) for p, j in (
                    ("hip", "Hip"), ("knee", "Knee"), ("ankle", "Ankle"), ("toe", "Foot"), ("shoulder", "Shoulder"),
                    ("elbow", "Elbow"), ("wrist", "Wrist"), ("hand", "Hand"))}}


def take_points(take: Take, every: int = 1) -> list[dict[str, np.ndarray]]:
    """Canonical mocap points (each (3,), Y up) of every `every`-th frame of a Kinect take whose joints are
    all known; a missing hand (UI-PRMD has none) continues the forearm by a third of its length."""
    sk = take.skeleton
    index = {n: sk.index(V1_FROM_V2[n] if sk.name == "kinect_v2" else n) for n in _TAKE_POINTS.values()}
    out = []
    for f in range(0, len(take.positions), every):
        p = {k: take.positions[f, index[j]] for k, j in _TAKE_POINTS.items()}
        for s in ("L", "R"):
            if not np.all(np.isfinite(p[f"hand.{s}"])):
                p[f"hand.{s}"] = p[f"wrist.{s}"] + (p[f"wrist.{s}"] - p[f"elbow.{s}"]) / 3.0
        if all(np.all(np.isfinite(x)) for x in p.values()):
            out.append(p)
    return out
