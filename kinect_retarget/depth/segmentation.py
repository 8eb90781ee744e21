"""Person segmentation on a downsampled depth grid: floor plane, depth range, connected components.

Everything works on a strided grid (every `step`-th pixel), where a person 1.5-3.5 m away is still
50-130 cells tall. Pixels keep the camera's layout (column u -> Kinect -X, see core/conventions.py).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.conventions import depth_pixel_to_kinect, kinect_to_depth_pixel
from .depth_camera import DepthCamera

MIN_Z, MAX_Z = 0.5, 4.5


@dataclass
class DepthGrid:
    """A depth frame sampled every `step` pixels and back-projected to Kinect camera space."""
    z: np.ndarray        # (h, w) metres, 0 = no reading
    xyz: np.ndarray      # (h, w, 3) Kinect camera space
    valid: np.ndarray    # (h, w) bool
    step: int
    camera: DepthCamera

    @classmethod
    def from_mm(cls, depth_mm: np.ndarray, camera: DepthCamera, step: int = 4) -> "DepthGrid":
        z = depth_mm[step // 2::step, step // 2::step].astype(np.float64) * 0.001
        h, w = z.shape
        valid = (z > MIN_Z) & (z < MAX_Z)
        z = np.where(valid, z, 0.0)
        u = np.arange(w) * step + step // 2
        v = np.arange(h) * step + step // 2
        xyz = depth_pixel_to_kinect(u[None, :], v[:, None], z, camera.f, camera.cx, camera.cy)
        return cls(z, xyz, valid, step, camera)

    def to_pixel(self, points: np.ndarray) -> np.ndarray:
        """(..., 3) Kinect points -> (..., 2) float grid coordinates (row, col)."""
        c = self.camera
        p = np.concatenate([points[..., :2], np.maximum(points[..., 2:3], 1e-6)], axis=-1)   # never divide by 0
        u, v = np.moveaxis(kinect_to_depth_pixel(p, c.f, c.cx, c.cy), -1, 0)
        return np.stack([(v - self.step // 2) / self.step, (u - self.step // 2) / self.step], axis=-1)

    def in_view(self, points: np.ndarray) -> np.ndarray:
        """(...,) bool: the (..., 3) points project inside the grid (not at or past its last row or column)."""
        rc = self.to_pixel(points)
        return np.all((rc >= 0) & (rc < np.array(self.z.shape) - 1), axis=-1)


@dataclass
class FloorPlane:
    normal: np.ndarray   # unit, pointing up (against gravity)
    offset: float        # height of a point p above the floor = normal . p + offset

    def height(self, p: np.ndarray) -> np.ndarray:
        return p @ self.normal + self.offset


def fit_floor(grid: DepthGrid, gravity: np.ndarray | None, previous: FloorPlane | None = None) -> FloorPlane | None:
    """Floor from gravity (accelerometer) and a least-squares plane fit to the lowest dense height band.

    Returns None when no floor is visible (then no floor points are removed)."""
    up = -np.asarray(gravity if gravity is not None else (0.0, -1.0, 0.0), dtype=np.float64)
    up /= np.linalg.norm(up)
    pts = grid.xyz[grid.valid]
    if len(pts) < 200:
        return previous
    h = pts @ up
    hist, edges = np.histogram(h, bins=np.arange(h.min(), h.max() + 0.04, 0.03))
    dense = np.flatnonzero(hist >= max(60, 0.03 * len(pts)))
    if len(dense) == 0:
        return previous
    level = edges[dense[0]] + 0.015
    band = pts[np.abs(h - level) < 0.05]
    if len(band) < 60:
        return previous
    centre = band.mean(axis=0)
    _, _, vt = np.linalg.svd(band - centre, full_matrices=False)
    n = vt[2] if vt[2] @ up > 0 else -vt[2]
    spread = np.ptp(band - np.outer(band @ n, n), axis=0)
    residual = float(np.sqrt(np.mean(((band - centre) @ n) ** 2)))
    plane = FloorPlane(n, -float(n @ centre))
    below = float(np.mean(plane.height(pts) < -0.08))
    if (n @ up < np.cos(np.radians(10)) or residual > 0.03 or np.sort(spread)[-2] < 0.5
            or below > 0.03 or plane.offset < 0.2):
        # not a floor: legs cut by the image edge, a desk top with things below it, a surface above the
        # sensor. Better no floor (nothing removed) than a wrong one (the person removed).
        return previous if previous is not None and below <= 0.03 else None
    return plane


def connected_components(mask: np.ndarray, z: np.ndarray, max_jump: float) -> np.ndarray:
    """Label (h, w) int: 4-connected regions of `mask` with depth steps below max_jump; -1 outside.

    Label propagation with pointer jumping (a few vectorised passes instead of a per-pixel flood fill).
    """
    h, w = mask.shape
    idx = np.arange(h * w).reshape(h, w)
    a_list, b_list = [], []
    for da, db in ((mask[:, :-1] & mask[:, 1:] & (np.abs(z[:, :-1] - z[:, 1:]) < max_jump), (0, 1)),
                   (mask[:-1, :] & mask[1:, :] & (np.abs(z[:-1, :] - z[1:, :]) < max_jump), (1, 0))):
        a = idx[:h - db[0], :w - db[1]][da]
        b = idx[db[0]:, db[1]:][da]
        a_list.append(a)
        b_list.append(b)
    a = np.concatenate(a_list)
    b = np.concatenate(b_list)
    lab = idx.ravel().copy()
    for _ in range(64):
        la, lb = lab[a], lab[b]
        m = np.minimum(la, lb)
        changed = la != lb
        if not changed.any():
            break
        np.minimum.at(lab, la[changed], m[changed])
        np.minimum.at(lab, lb[changed], m[changed])
        while True:
            nxt = lab[lab]
            if np.array_equal(nxt, lab):
                break
            lab = nxt
    out = np.where(mask.ravel(), lab, -1).reshape(h, w)
    return out


@dataclass
class PersonMask:
    mask: np.ndarray      # (h, w) bool
    centroid: np.ndarray  # (3,)
    height: float         # vertical extent, metres
    pixels: int


def find_people(grid: DepthGrid, floor: FloorPlane | None, gravity: np.ndarray | None,
                max_jump: float = 0.2) -> list[PersonMask]:
    """Person-like connected components above the floor, largest first."""
    fg = grid.valid.copy()
    if floor is not None:
        fg &= floor.height(grid.xyz) > 0.04
    comps = connected_components(fg, grid.z, max_jump)
    labels, counts = np.unique(comps[comps >= 0], return_counts=True)
    up = -np.asarray(gravity if gravity is not None else (0.0, -1.0, 0.0), dtype=np.float64)
    up /= np.linalg.norm(up)
    people = []
    cell = grid.step / grid.camera.f
    for lab, n in zip(labels, counts):
        if n < 40:
            continue
        m = comps == lab
        pts = grid.xyz[m]
        area = np.sum((pts[:, 2] * cell) ** 2)  # metric area of the visible surface
        hts = pts @ up
        vert = float(np.ptp(hts))
        horiz = pts - np.outer(hts, up)
        width = float(np.max(np.ptp(horiz, axis=0)))
        if not (0.08 < area < 1.6 and 0.45 < vert < 2.4 and width < 1.6):
            continue
        sv = np.linalg.svd(pts[::4] - pts.mean(axis=0), compute_uv=False)
        if sv[2] < 0.06 * sv[0]:  # flat: a wall or door seen through a gap, not a body
            continue
        if floor is not None and np.min(floor.height(pts)) > 0.9:  # floating blob (lamp, shelf item)
            continue
        people.append(PersonMask(m, pts.mean(axis=0), vert, int(n)))
    people.sort(key=lambda p: -p.pixels)
    _attach_reaching_parts(grid, comps, labels, counts, people)
    return people


REACH_GAP = 0.45       # m: a piece this near a person's surface (3D) can be their arm ...
PIECE_SHARE = 0.3      # ... if it is at most this share of the person's cells ...
PIECE_MIN = 8          # ... and at least this many


def _attach_reaching_parts(grid: DepthGrid, comps: np.ndarray, labels, counts, people: list[PersonMask]) -> None:
    """Give each person the pieces of them that depth steps cut off: an arm pointing at the sensor is seen
    end-on, its forearm and hand a blob 30-50 cm in front of the chest with no gentle depth slope back to
    the body (real Kinect v1 depth, UTD-MHAD's squats and punches). A piece is someone's when it lies nearer
    the sensor than their body, within REACH_GAP of their surface and inside their silhouette's bounding box,
    and is small beside them. The person's centroid, height and size stay the body's own."""
    if not people:
        return
    own = [int(comps[p.mask][0]) for p in people]   # each person is one whole component
    # sizes first, then the pieces' cells in one pass (a cluttered room has a dozen components or more)
    small = (counts >= PIECE_MIN) & (counts <= PIECE_SHARE * max(p.pixels for p in people)) & ~np.isin(labels, own)
    if not small.any():
        return
    flat = comps.ravel()
    cells = np.flatnonzero(np.isin(flat, labels[small]))
    cells = cells[np.argsort(flat[cells], kind="stable")]
    ends = np.cumsum(counts[small])
    xyz = grid.xyz.reshape(-1, 3)
    w = comps.shape[1]
    boxes, bodies, depth = [], [], []
    for p in people:
        rows, cols = np.nonzero(p.mask)
        boxes.append((rows.min(), rows.max(), cols.min(), cols.max()))
        bodies.append(grid.xyz[p.mask][::3])
        depth.append(np.median(grid.z[p.mask]))
    for piece, n in zip(np.split(cells, ends[:-1]), counts[small]):
        rows, cols = np.divmod(piece, w)
        pts, near = xyz[piece], None
        for i, p in enumerate(people):
            r0, r1, c0, c1 = boxes[i]
            if (n > PIECE_SHARE * p.pixels or rows.max() < r0 or rows.min() > r1 or cols.max() < c0
                    or cols.min() > c1):
                continue
            near = np.median(pts[:, 2]) if near is None else near
            if near >= depth[i]:
                continue
            gap = np.min(np.linalg.norm(pts[::2, None, :] - bodies[i][None], axis=-1))
            if gap <= REACH_GAP:
                p.mask.flat[piece] = True
                break
