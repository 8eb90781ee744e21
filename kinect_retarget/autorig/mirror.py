"""Left/right symmetry: a body that is its own mirror image gets a mirror-symmetric rig.

Why it is needed: distances along mesh edges over-estimate surface distances by an amount that depends on
the direction the edges run (metrication error). A body whose triangulation is not itself mirrored (quads
all split along the same diagonal, a decimated or re-meshed copy) has its left and right limbs measured
differently, so joints placed at geodesic fractions, and the trunk regions bounded by geodesic level sets,
come out asymmetric by up to 2 % of height on a perfectly mirror-symmetric surface.

The remedy: when the surface is its own mirror image (every sampled vertex, reflected across the fitted
plane, lies within MIRROR_TOLERANCE of height of the surface), the true joints are mirror-symmetric too, so
the detected joints are replaced by the nearest mirror-symmetric set (least squares): each left/right pair is
averaged with its partner's reflection and the centre joints are moved onto the plane. A posed body (one
arm raised, a step) fails the test and keeps its joints as found.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.skeletons import KINECT_V1
from .mesh import triangle_areas

MIRROR_TOLERANCE = 0.003  # of height (5 mm on 1.7 m): surface mismatch allowed for a body to count as mirrored
COVERAGE = 0.99           # fraction of the sampled vertices that must be within the tolerance
SAMPLES = 1000            # vertices reflected per check (evenly strided through the mesh)
SEARCH = 0.006            # of height: a reflected vertex's match is looked for this close (1 cm on 1.7 m)


@dataclass
class MirrorPlane:
    normal: np.ndarray   # unit, toward the character's left
    offset: float        # plane: x . normal = offset
    mismatch: float      # COVERAGE quantile of the reflected vertices' distance to the surface, / height
    symmetric: bool      # mismatch <= MIRROR_TOLERANCE

    def reflect(self, points: np.ndarray) -> np.ndarray:
        return points - 2.0 * np.outer(points @ self.normal - self.offset, self.normal)


def vertex_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    t = vertices[faces]
    fn = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])  # area-weighted
    n = np.stack([np.bincount(faces.ravel(), np.repeat(fn[:, k], 3), len(vertices)) for k in range(3)], axis=1)
    return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)


def surface_moments(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The surface's area centroid and principal axes (columns), from each triangle's exact second moment
    (independent of how the surface is cut into triangles)."""
    t = vertices[faces]
    area = triangle_areas(vertices, faces)
    total = max(area.sum(), 1e-30)
    mid = t.mean(axis=1)
    centroid = (area[:, None] * mid).sum(axis=0) / total
    d = t - centroid
    m = mid - centroid
    second = np.einsum("f,fi,fj->ij", area, m, m) * 9 + np.einsum("f,fki,fkj->ij", area, d, d)
    return centroid, np.linalg.eigh(second / (12 * total))[1]


def nearest_within(points: np.ndarray, targets: np.ndarray, radius: float) -> np.ndarray:
    """Index of the nearest target within `radius` of each point, -1 where there is none. Targets are
    bucketed in a grid of cells `radius` wide and each point is compared with the 27 cells around its own
    only (brute force over every vertex would cost more than the rest of the rig on a large mesh)."""
    lo = targets.min(axis=0) - radius
    cells = np.floor((targets - lo) / radius).astype(np.int64)
    dims = cells.max(axis=0) + 2
    key = (cells[:, 0] * dims[1] + cells[:, 1]) * dims[2] + cells[:, 2]
    order = np.argsort(key, kind="stable")
    sorted_key = key[order]
    around = np.stack(np.meshgrid(*[np.arange(-1, 2)] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    q = np.floor((points - lo) / radius).astype(np.int64)[:, None, :] + around[None]   # (P, 27, 3)
    inside = np.all((q >= 0) & (q < dims), axis=2)
    qkey = (q[..., 0] * dims[1] + q[..., 1]) * dims[2] + q[..., 2]
    start = np.searchsorted(sorted_key, qkey, "left")
    count = np.where(inside, np.searchsorted(sorted_key, qkey, "right") - start, 0).ravel()
    owner = np.repeat(np.repeat(np.arange(len(points)), around.shape[0]), count)
    first = np.repeat(start.ravel(), count)
    offset = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    cand = order[first + offset]
    d2 = ((targets[cand] - points[owner]) ** 2).sum(axis=1)
    out = np.full(len(points), -1, dtype=np.int64)
    if len(d2) == 0:
        return out
    starts = np.flatnonzero(np.r_[True, owner[1:] != owner[:-1]])   # `owner` is sorted by construction
    low = np.minimum.reduceat(d2, starts)
    hit = np.flatnonzero(d2 == np.repeat(low, np.diff(np.r_[starts, len(d2)])))
    hit = hit[np.r_[True, owner[hit][1:] != owner[hit][:-1]]]       # the first nearest of each point
    ok = d2[hit] <= radius * radius
    out[owner[hit][ok]] = cand[hit][ok]
    return out


def fit_mirror_plane(vertices: np.ndarray, faces: np.ndarray, left: np.ndarray, height: float,
                     iterations: int = 4) -> MirrorPlane:
    """The plane the body is most nearly mirrored across, refined from matched vertex pairs (ICP for a
    reflection). It starts from the surface's principal axis nearest to `left` (the feature points' left
    axis) through the surface centroid: the mirror plane of a symmetric surface holds its centroid and is
    normal to one of its principal axes, whatever the triangulation."""
    sample = vertices[:: max(1, len(vertices) // SAMPLES)]
    centroid, axes = surface_moments(vertices, faces)
    left = left / np.linalg.norm(left)
    n = axes[:, int(np.argmax(np.abs(axes.T @ left)))]
    n = n * np.sign(n @ left) if abs(n @ left) > np.cos(np.radians(15)) else left  # a degenerate axis: keep left
    c = float(centroid @ n)
    radius = SEARCH * height
    for k in range(iterations):
        # coarse to fine: the first rounds look farther for matches (fewer points, so it stays cheap), as
        # the starting axis can be a few degrees off at the fingertips
        wide = 2 ** max(0, iterations - 2 - k)
        pts = sample[:: wide * wide]
        j = nearest_within(pts - 2.0 * np.outer(pts @ n - c, n), vertices, wide * radius)
        pts, j = pts[j >= 0], j[j >= 0]
        diff = pts - vertices[j]                      # for a mirror pair: along the plane's normal
        far = np.abs(diff @ n) > 0.05 * height        # pairs across the body fix the direction well
        if far.sum() < 10:
            break
        d = diff[far] * np.sign(diff[far] @ n)[:, None]
        n = d.sum(axis=0) / np.linalg.norm(d.sum(axis=0))
        c = float(np.median(0.5 * (pts + vertices[j]) @ n))
    reflected = sample - 2.0 * np.outer(sample @ n - c, n)
    j = nearest_within(reflected, vertices, radius)
    # distance to the surface near the match, along the matched vertex's normal: a side triangulated
    # differently places its vertices elsewhere on the same surface, which is not asymmetry
    gap = np.where(j >= 0, np.abs(((reflected - vertices[j]) * vertex_normals(vertices, faces)[j]).sum(axis=1)),
                   radius)  # no surface within the search radius: at least that far off
    mismatch = float(np.quantile(gap, COVERAGE) / height)
    return MirrorPlane(n, c, mismatch, mismatch <= MIRROR_TOLERANCE)


def symmetrize_joints(joints: np.ndarray, plane: MirrorPlane) -> np.ndarray:
    """The mirror-symmetric joint set nearest to `joints` (KINECT_V1 order): the mean of the joints and
    their mirrored partners' reflections."""
    return 0.5 * (joints + plane.reflect(joints[KINECT_V1.mirror]))


def asymmetry(joints: np.ndarray, plane: MirrorPlane, height: float) -> float:
    """Largest distance between a joint and its partner's reflection, in % of height."""
    return float(np.linalg.norm(plane.reflect(joints[KINECT_V1.mirror]) - joints, axis=1).max() / height * 100)
