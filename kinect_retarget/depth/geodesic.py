"""Geodesic distances over the person's depth surface (a grid graph cut at depth discontinuities).

Each cell links to its 4 neighbours with the 3D distance between them, or not at all when the depth
jumps (an arm in front of the chest stays separate from it). Distances are relaxed with whole-row and
whole-column passes: along a 1D chain, d[i] = S[i] + min_{j<=i}(d[j] - S[j]) with S the running edge
length, which `np.minimum.accumulate` does for every row at once. A few alternating passes (plus diagonal
steps) converge to the shortest paths; no Python loop visits a cell.
"""
from __future__ import annotations

import numpy as np

CUT = 1e4  # an edge at a depth discontinuity costs this much: unreachable in practice
INF = np.inf


class SurfaceGraph:
    def __init__(self, xyz: np.ndarray, mask: np.ndarray, max_jump: float = 0.06):
        self.xyz = xyz
        self.mask = mask
        z = xyz[..., 2]
        # edge lengths to the right (h, w-1) and down (h-1, w); CUT where not connected
        dr = np.linalg.norm(xyz[:, 1:] - xyz[:, :-1], axis=-1)
        dd = np.linalg.norm(xyz[1:] - xyz[:-1], axis=-1)
        okr = mask[:, 1:] & mask[:, :-1] & (np.abs(z[:, 1:] - z[:, :-1]) < max_jump)
        okd = mask[1:] & mask[:-1] & (np.abs(z[1:] - z[:-1]) < max_jump)
        self.right = np.where(okr, dr, CUT)
        self.down = np.where(okd, dd, CUT)
        dg1 = np.linalg.norm(xyz[1:, 1:] - xyz[:-1, :-1], axis=-1)
        dg2 = np.linalg.norm(xyz[1:, :-1] - xyz[:-1, 1:], axis=-1)
        self.diag1 = np.where(mask[1:, 1:] & mask[:-1, :-1] & (np.abs(z[1:, 1:] - z[:-1, :-1]) < max_jump), dg1, CUT)
        self.diag2 = np.where(mask[1:, :-1] & mask[:-1, 1:] & (np.abs(z[1:, :-1] - z[:-1, 1:]) < max_jump), dg2, CUT)
        # cumulative edge lengths along rows and columns, for the prefix-min passes
        h, w = mask.shape
        self._srow = np.concatenate([np.zeros((h, 1)), np.cumsum(self.right, axis=1)], axis=1)
        self._scol = np.concatenate([np.zeros((1, w)), np.cumsum(self.down, axis=0)], axis=0)

    def distances(self, sources: np.ndarray, init: np.ndarray | None = None, iterations: int = 12) -> np.ndarray:
        """Geodesic distance (h, w) from the source cells (bool mask or (k, 2) row/col); inf off-surface."""
        d = np.full(self.mask.shape, INF) if init is None else init.copy()
        src = np.asarray(sources)
        if src.dtype == bool:
            d[src & self.mask] = 0.0
        elif src.size:
            d[src[:, 0], src[:, 1]] = 0.0
        d = np.where(np.isfinite(d), d, 1e9)
        sr, sc = self._srow, self._scol
        for _ in range(iterations):
            prev = d
            d = np.minimum(d, sr + np.minimum.accumulate(d - sr, axis=1))                       # left -> right
            d = np.minimum(d, -sr + np.minimum.accumulate((d + sr)[:, ::-1], axis=1)[:, ::-1])  # right -> left
            d = np.minimum(d, sc + np.minimum.accumulate(d - sc, axis=0))                       # top -> bottom
            d = np.minimum(d, -sc + np.minimum.accumulate((d + sc)[::-1], axis=0)[::-1])        # bottom -> top
            d[1:, 1:] = np.minimum(d[1:, 1:], d[:-1, :-1] + self.diag1)
            d[:-1, :-1] = np.minimum(d[:-1, :-1], d[1:, 1:] + self.diag1)
            d[1:, :-1] = np.minimum(d[1:, :-1], d[:-1, 1:] + self.diag2)
            d[:-1, 1:] = np.minimum(d[:-1, 1:], d[1:, :-1] + self.diag2)
            if np.array_equal(d, prev):
                break
        return np.where((d < CUT * 0.5) & self.mask, d, INF)


def geodesic_extrema(graph: SurfaceGraph, d0: np.ndarray, count: int = 6, min_distance: float = 0.3,
                     iterations: int = 8) -> list[tuple[int, int, float]]:
    """Plagemann-style interest points: repeatedly take the farthest cell, then add it as a source.

    Returns [(row, col, geodesic distance from the torso)] for extrema at least `min_distance` away."""
    out = []
    d = d0.copy()
    for _ in range(count):
        finite = np.where(np.isfinite(d), d, -1.0)
        k = int(np.argmax(finite))
        if finite.flat[k] < min_distance * 0.5:
            break
        r, c = divmod(k, d.shape[1])
        if d0[r, c] >= min_distance:
            out.append((r, c, float(d0[r, c])))
        d = graph.distances(np.array([[r, c]]), init=d, iterations=iterations)
    return out


def level_set_centroid(xyz: np.ndarray, dist: np.ndarray, level: float, width: float,
                       near: np.ndarray | None = None, radius: float = 0.25) -> np.ndarray | None:
    """Centroid of the surface points whose geodesic distance is within level +- width/2 (paper 003's
    skeleton point); only points within `radius` of `near` when given (one connected group)."""
    sel = np.abs(dist - level) <= width * 0.5
    pts = xyz[sel]
    if near is not None and len(pts):
        pts = pts[np.linalg.norm(pts - near, axis=1) < radius]
    if len(pts) < 3:
        return None
    return pts.mean(axis=0)
