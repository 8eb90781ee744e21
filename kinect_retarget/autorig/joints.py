"""Name the skeleton: the 20 Kinect v1 joints placed on the geodesic centre lines of the segments.

Limb joints are centroids of iso-geodesic rings around a limb (or the trunk), at fixed fractions of the
body's geodesic length; the fractions are human proportions, measured on MakeHuman's base mesh at rest and
checked on its posed versions (benchmarks/bench_autorig.py). The paper's hand-stepped shoulder/ankle
adjustment (§4.2) becomes automatic, and the trunk joints come from its geometry: the shoulder is moved onto
the upper arm's axis and the wrist onto the forearm's centre line; each hip is where its thigh's axis meets
the pelvis's left-right line; the hip centre is the centroid of the pelvis level set; the head is the head's
centroid and the spine a point of the trunk's chord, each moved onto the line the skull or the backbone
pivots on.
"""
from __future__ import annotations

import numpy as np

from ..core.skeletons import KINECT_V1
from .features import FeaturePoints
from .mesh import triangle_areas

# Ring positions as fractions of the body's geodesic length L (head top to feet, along the surface). The
# surface barely stretches when a body moves, so these hold from A-pose to T-pose to a split (the branch
# lengths of the tree metric do not: the junctions slide with the arms).
ARM = {"WristLeft": 0.105, "ElbowLeft": 0.215, "ShoulderLeft": 0.335}
FOREARM = (0.11, 0.18)  # arm levels that give the forearm's centre line: wrist (0.105) to elbow
UPPER_ARM = (0.25, 0.32)  # arm rings that give the upper arm's axis (shoulder adjustment, §4.2)
HAND_AT = (0.047, 0.5)   # the palm: half-way from the wrist to the ring across the finger roots
LEG = {"FootLeft": 0.075, "AnkleLeft": 0.125, "KneeLeft": 0.31}
PELVIS_AT = 0.44         # head field: the pelvis starts here (its cross-section; below it, its level set)
HIP_DROP = 0.01          # the pelvis's left-right line through the hips: this far below the hip centre
THIGH = (0.36, 0.46)     # leg rings that give the thigh's axis: knee (0.31) to just below the crotch
HIP_HALF_WIDTH = 0.056   # hips this far to each side of the hip centre, only if a thigh axis is parallel
                         # to the pelvis line (no crossing point)
TORSO = {"ShoulderCenter": 0.19, "HipCenter": 0.48}  # head field, inside the trunk (HipCenter: only
                                                     # when the trunk has nothing below PELVIS_AT)
SPINE_AT = 0.42          # Spine: this far from the hip centre to the shoulder centre
HEAD_CAP = 0.12          # the head: the surface this close to the crown (down to the chin)
HEAD_BACK = 0.25         # Head joint: this far from the back of the skull to the face (measured at rest)
SPINE_BACK = 0.25        # Spine: this far from the back to the belly (measured at rest: 0.26)


def vertex_areas(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """A third of the area of each triangle around each vertex: centroids weighted by it do not drift
    toward the finely meshed side of a ring (faces, hands and seams are often denser)."""
    area = triangle_areas(vertices, faces)
    return np.bincount(faces.ravel(), np.repeat(area / 3, 3), len(vertices))


def ring_centroid(vertices: np.ndarray, field: np.ndarray, g: float, width: float,
                  mask: np.ndarray | None, area: np.ndarray) -> np.ndarray:
    """Area-weighted centroid of the vertices whose geodesic value is within `width` of g (the band is
    widened until it holds vertices)."""
    for w in (width, 2 * width, 4 * width, 8 * width):
        band = np.abs(field - g) < w
        if mask is not None:
            band &= mask
        if band.any():
            return np.average(vertices[band], axis=0, weights=area[band] + 1e-30)
    near = np.argmin(np.abs(field - g) + (0 if mask is None else np.where(mask, 0, np.inf)))
    return vertices[near].copy()


def _axis(points: np.ndarray) -> np.ndarray:
    """Unit direction of the line best fitting the points."""
    return np.linalg.svd(points - points.mean(axis=0))[2][0]


def _cross_section_axis(vertices, field, g, width, mask, normal, area) -> np.ndarray:
    """Unit long axis of the ring at g, in the plane normal to `normal` (area-weighted principal axis)."""
    for w in (width, 2 * width, 4 * width):
        band = (np.abs(field - g) < w) & mask
        if band.sum() >= 3:
            break
    wt = area[band] + 1e-30
    p = vertices[band] - np.average(vertices[band], axis=0, weights=wt)
    p -= np.outer(p @ normal, normal)
    return np.linalg.eigh((p * wt[:, None]).T @ p)[1][:, -1]


def _level_line_at(vertices: np.ndarray, field: np.ndarray, lo: float, hi: float, at: float,
                   area: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    """The point at geodesic level `at` of a straight limb's centre line, fitted between levels lo and hi:
    the area-weighted linear regression of the vertex positions on their geodesic value, i.e. the line
    through all the ring centroids at once (sampling a few rings instead makes the line jitter)."""
    band = (field > lo) & (field < hi)
    if band.sum() < 4:
        return fallback
    w = area[band] + 1e-30
    mean_g = np.average(field[band], weights=w)
    g = field[band] - mean_g
    centre = np.average(vertices[band], axis=0, weights=w)
    slope = ((vertices[band] - centre) * (w * g)[:, None]).sum(axis=0) / max((w * g * g).sum(), 1e-30)
    return centre + slope * (at - mean_g)


def _from_back(vertices: np.ndarray, mask: np.ndarray, point: np.ndarray, axis: np.ndarray,
               front: np.ndarray, half_thickness: float, fraction: float) -> np.ndarray:
    """`point` moved along the front direction (made square to `axis`) to `fraction` of the body's depth
    from the back, the depth measured on the slice of the masked vertices through `point` across `axis`."""
    axis = axis / max(np.linalg.norm(axis), 1e-12)
    front = front - axis * (front @ axis)
    front /= max(np.linalg.norm(front), 1e-12)
    slab = mask & (np.abs((vertices - point) @ axis) < half_thickness)
    if not slab.any():
        return point
    depth = vertices[slab] @ front
    return point + front * (depth.min() + fraction * (depth.max() - depth.min()) - point @ front)


def _closest_on_line(p: np.ndarray, d: np.ndarray, q: np.ndarray, e: np.ndarray,
                     fallback: np.ndarray) -> np.ndarray:
    """The point of the line p + s d nearest to the line q + t e (`fallback` when they are parallel)."""
    w = p - q
    b = d @ e
    den = (d @ d) * (e @ e) - b * b
    if den < 1e-9 * (d @ d) * (e @ e):
        return fallback
    return p + d * ((b * (e @ w) - (e @ e) * (d @ w)) / den)


def body_length(fp: FeaturePoints) -> float:
    """Geodesic head-top-to-feet length L, the pose-independent size every fraction refers to."""
    return float(fp.distances[0, fp.vertices[3:5]].mean())


def kinect_joints(vertices: np.ndarray, faces: np.ndarray, fp: FeaturePoints, segment: np.ndarray,
                  height: float) -> np.ndarray:
    """(20, 3) joint positions in KINECT_V1 order, in mesh coordinates."""
    area = vertex_areas(vertices, faces)

    def ring(field, g, mask=None):
        return ring_centroid(vertices, field, g, width, mask, area)

    out = np.zeros((len(KINECT_V1), 3))
    idx = KINECT_V1.index
    size = body_length(fp)
    width = 0.006 * height
    head_f = fp.distances[0]
    in_trunk = segment == 0  # the head's domain holds the neck and the whole trunk

    for side, s_hand, s_foot in (("Left", 1, 3), ("Right", 2, 4)):
        f = fp.distances[s_hand]
        for name, t in ARM.items():
            out[idx(name.replace("Left", side))] = ring(f, t * size)
        # §4.2, automatically: the ring at the shoulder wraps the armpit and the deltoid, so its centroid
        # sits low and inward; the joint is put back on the upper arm's axis at the same distance.
        shoulder, elbow = out[idx("Shoulder" + side)], out[idx("Elbow" + side)]
        axis = _axis(np.array([ring(f, t * size) for t in np.linspace(*UPPER_ARM, 5)]))
        axis *= np.sign(axis @ (shoulder - elbow)) or 1.0
        out[idx("Shoulder" + side)] = elbow + axis * np.linalg.norm(shoulder - elbow)
        # The wrist: where the forearm's straight centre line reaches the wrist's level. The ring at the
        # wrist itself slants into the palm when the hand bends, and its centroid can leave the wrist.
        out[idx("Wrist" + side)] = _level_line_at(vertices, f, FOREARM[0] * size, FOREARM[1] * size,
                                                  ARM["WristLeft"] * size, area, out[idx("Wrist" + side)])
        wrist = out[idx("Wrist" + side)]
        palm = ring(f, HAND_AT[0] * size)
        out[idx("Hand" + side)] = wrist + HAND_AT[1] * (palm - wrist)
        f = fp.distances[s_foot]
        for name, t in LEG.items():
            out[idx(name.replace("Left", side))] = ring(f, t * size)
    for name, t in TORSO.items():
        out[idx(name)] = ring(head_f, t * size, in_trunk)

    neck = out[idx("ShoulderCenter")]
    # Head: the centroid of the head (the surface within HEAD_CAP of the crown, down to the chin), which no
    # single vertex moves; then, front to back, onto the head's pivot line a quarter of the skull's depth
    # from the back (the face and nose make the rest), measured across the head's own axis (neck to head)
    # so that a bowed or tilted head is measured along its own depth, not the body's.
    cap = head_f < HEAD_CAP * size
    head = np.average(vertices[cap], axis=0, weights=area[cap] + 1e-30)
    head = _from_back(vertices, head_f < TORSO["ShoulderCenter"] * size, head, head - neck, fp.front,
                      0.02 * height, HEAD_BACK)
    out[idx("Head")] = head
    # The pelvis: the area centroid of the trunk below PELVIS_AT, down to where the legs begin (the
    # paper's level-set centroid rather than one ring, which a raised or split leg drags forward).
    pelvis = in_trunk & (head_f > PELVIS_AT * size)
    hip_centre = (np.average(vertices[pelvis], axis=0, weights=area[pelvis] + 1e-30) if pelvis.any()
                  else out[idx("HipCenter")])
    trunk = neck - hip_centre
    trunk /= max(np.linalg.norm(trunk), 1e-12)
    lateral = _cross_section_axis(vertices, head_f, PELVIS_AT * size, 6 * width, in_trunk, trunk, area)
    lateral *= np.sign(lateral @ fp.left) or 1.0
    below = hip_centre - HIP_DROP * size * trunk
    # Hips (§4.2, automatically): each hip joint lies on its thigh's axis, the line fitted to the centroids
    # of the upper leg's cross-sections, where that axis passes closest to the pelvis's left-right line
    # (just below the hip centre, along the long axis of the trunk's cross-section above the crotch). The
    # thigh gives the joint's spacing and front-back place, the pelvis its height; a spread, flexed or
    # crossed leg carries its axis with it.
    for side, s_foot, sign in (("Left", 3, 1.0), ("Right", 4, -1.0)):
        f = fp.distances[s_foot]
        rings = np.array([ring(f, t * size) for t in np.linspace(*THIGH, 8)])
        out[idx("Hip" + side)] = _closest_on_line(rings.mean(axis=0), _axis(rings), below, lateral,
                                                  below + sign * HIP_HALF_WIDTH * size * lateral)
    # The hip centre is midway between the hips across the pelvis: the trunk's ring there leans toward a
    # raised or spread leg.
    mid = 0.5 * (out[idx("HipLeft")] + out[idx("HipRight")])
    out[idx("HipCenter")] = hip_centre + lateral * ((mid - hip_centre) @ lateral)
    # Spine: at its height on the trunk's chord, then moved front to back to where the backbone runs, a
    # quarter of the trunk's depth from the back (the chord of an arched or bowed back leaves the body).
    spine = out[idx("HipCenter")] + SPINE_AT * (neck - out[idx("HipCenter")])
    out[idx("Spine")] = _from_back(vertices, in_trunk, spine, neck - out[idx("HipCenter")], fp.front,
                                   0.02 * height, SPINE_BACK)
    return out
