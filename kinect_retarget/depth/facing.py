"""Which way the performer faces, from the surface normals of the chest (numpy only).

A plane fitted to the visible torso (its mean normal) turns much less than the performer: the camera only
ever sees normals within 90 degrees of itself, so a torso turned 60 degrees shows its front (normals at 60)
and its side (normals near -30), and the mean lands near 20. The chest is flatter than the torso's sides,
so its front's normals are the densest direction on the surface: the mode of the normals' directions,
each cell weighted by the surface area it stands for (1 / cos of the viewing angle, undoing foreshortening),
is the chest's facing. On the rendered hop's turns (45-63 degrees) the tracker's facing is within 6 degrees
of the truth, where the mean normal read 12-35.
"""
from __future__ import annotations

import numpy as np

from .two_bone import unit

CHEST_BAND = (0.658, 0.815)   # fraction of height above the floor: spine to just below the shoulder line
CHEST_RADIUS = 0.25           # m from the torso axis: the trunk, not an arm hanging beside it
MAX_STEP = 0.15               # m between a cell's neighbours: more is a depth edge, not surface
KERNEL_DEG = 8.0              # smoothing of the histogram of directions
REFINE_DEG = 10.0             # window of the mean-shift refinement around the histogram's peak
MIN_CELLS = 30                # fewer chest cells (held far off, mostly hidden): no answer
_BINS = np.arange(-90.0, 90.5, 2.0)


def surface_normals(xyz: np.ndarray, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(h, w, 3) unit normals toward the camera from each cell's four neighbours, and where they are valid
    (the cell and its neighbours on the surface, no depth edge between them)."""
    dx = np.zeros_like(xyz)
    dy = np.zeros_like(xyz)
    dx[:, 1:-1] = xyz[:, 2:] - xyz[:, :-2]
    dy[1:-1] = xyz[2:] - xyz[:-2]
    ok = np.zeros(mask.shape, bool)
    ok[1:-1, 1:-1] = (mask[1:-1, 1:-1] & mask[1:-1, 2:] & mask[1:-1, :-2] & mask[2:, 1:-1] & mask[:-2, 1:-1])
    ok &= (np.linalg.norm(dx, axis=-1) < MAX_STEP) & (np.linalg.norm(dy, axis=-1) < MAX_STEP)
    n = np.cross(dx, dy)
    length = np.linalg.norm(n, axis=-1)
    ok &= length > 0
    n = n / np.maximum(length, 1e-12)[..., None]
    n = np.where((np.sum(n * xyz, axis=-1) > 0)[..., None], -n, n)   # toward the camera (at the origin)
    return n, ok


def chest_facing(xyz: np.ndarray, mask: np.ndarray, floor_point: np.ndarray, axis: np.ndarray,
                 height: float) -> np.ndarray | None:
    """Unit facing direction (perpendicular to `axis`) of the chest, or None when too little of it is seen.

    `floor_point`: where the torso axis meets the floor; `height`: the performer's standing height."""
    rel = xyz - floor_point
    along = rel @ axis
    across = np.linalg.norm(rel - along[..., None] * axis, axis=-1)
    sel = mask & (along > CHEST_BAND[0] * height) & (along < CHEST_BAND[1] * height) & (across < CHEST_RADIUS)
    if sel.sum() < MIN_CELLS:
        return None
    rows, cols = np.nonzero(sel)   # normals only around the chest (a sixth of the person's cells)
    box = (slice(max(rows.min() - 1, 0), rows.max() + 2), slice(max(cols.min() - 1, 0), cols.max() + 2))
    n, ok = surface_normals(xyz[box], mask[box])
    sel = sel[box] & ok
    if sel.sum() < MIN_CELLS:
        return None
    normals, points = n[sel], xyz[box][sel]
    toward = unit(-np.mean(points, axis=0))
    e1 = unit(toward - (toward @ axis) * axis)          # toward the camera, across the axis
    e2 = np.cross(axis, e1)
    h1, h2 = normals @ e1, normals @ e2
    level = np.hypot(h1, h2) > 0.5                      # normals far from the axis (not tops of shoulders)
    if level.sum() < MIN_CELLS:
        return None
    angle = np.degrees(np.arctan2(h2[level], h1[level]))
    view = -points[level] / np.linalg.norm(points[level], axis=1, keepdims=True)
    weight = 1.0 / np.clip(np.sum(normals[level] * view, axis=1), 0.25, 1.0)   # area behind each cell
    density = np.exp(-0.5 * ((_BINS[:, None] - angle[None, :]) / KERNEL_DEG) ** 2) @ weight
    peak = _BINS[int(np.argmax(density))]
    for _ in range(5):
        w = weight * np.exp(-0.5 * ((angle - peak) / REFINE_DEG) ** 2)
        peak = float(np.sum(w * angle) / np.sum(w))
    a = np.radians(peak)
    return np.cos(a) * e1 + np.sin(a) * e2
