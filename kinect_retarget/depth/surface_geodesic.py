"""Geodesic distances over the person's depth surface (a grid graph cut at depth discontinuities).

Each cell links to its 8 neighbours with the 3D distance between them, or not at all when the depth
jumps (an arm in front of the chest stays separate from it). Distances are relaxed with whole-line
passes: along a 1D chain, d[i] = S[i] + min_{j<=i}(d[j] - S[j]) with S the running edge length, which
`np.minimum.accumulate` does for every row, column or diagonal at once. A few alternating passes converge
to the shortest paths; no Python loop visits a cell. The accumulate is numpy's slowest step (a scalar loop,
about 4 ns a cell), so each direction's lines are packed into one chain of the person's cells only.
"""
from __future__ import annotations

import numpy as np

CUT = 10.0  # m: an edge at a depth discontinuity costs this much, beyond any path on a person (and small
            # enough that the running sums over a whole chain keep sub-nanometre precision)
UNREACHED = 1e9   # a cell no path has reached yet
INF = np.inf


def _lines(h: int, w: int, dr: int, dc: int) -> np.ndarray:
    """Flat cell indices (n_lines, length) of the grid's straight lines in direction (dr, dc); -1 pads."""
    idx = np.arange(h * w).reshape(h, w)
    if (dr, dc) == (0, 1):
        return idx
    if (dr, dc) == (1, 0):
        return idx.T.copy()
    # diagonals: skew so that each diagonal becomes a row
    flip = idx if dc == 1 else idx[:, ::-1]
    out = np.full((h + w - 1, min(h, w)), -1, dtype=np.int64)
    r, c = np.mgrid[0:h, 0:w]
    k = c - r + (h - 1)
    pos = np.minimum(r, c)
    out[k.ravel(), pos.ravel()] = flip.ravel()
    return out


def _relax(v: np.ndarray, cum: np.ndarray) -> None:
    """One pass each way along the chain `v`, in place: v = min(v, S + running min of (v - S))."""
    np.minimum(v, cum + np.minimum.accumulate(v - cum), out=v)
    np.minimum(v, np.minimum.accumulate((v + cum)[::-1])[::-1] - cum, out=v)


class SurfaceGraph:
    """The person's surface as a graph on the depth grid: 8-neighbour edges with 3D lengths, cut at depth
    discontinuities. Each of the 4 line directions (rows, columns, two diagonals) is stored as one chain: the
    person's cells line after line, with the running edge length, where a cut edge (and the step from one
    line's end to the next line) costs CUT. One relaxation pass along a direction is then a single
    accumulate over the person's cells only, not over the bounding box."""

    def __init__(self, xyz: np.ndarray, mask: np.ndarray, max_jump: float = 0.06):
        self.xyz = xyz
        self.mask = mask
        h, w = mask.shape
        flat_xyz = xyz.reshape(-1, 3)
        flat_mask = mask.ravel()
        self._dirs = []
        for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
            lines = _lines(h, w, dr, dc)
            if lines.shape[1] < 2:
                continue
            a, b = lines[:, :-1], lines[:, 1:]
            real = (a >= 0) & (b >= 0)
            a0, b0 = np.where(real, a, 0), np.where(real, b, 0)
            length = np.linalg.norm(flat_xyz[a0] - flat_xyz[b0], axis=-1)
            ok = real & flat_mask[a0] & flat_mask[b0] & (np.abs(flat_xyz[a0, 2] - flat_xyz[b0, 2]) < max_jump)
            step = np.full(lines.shape, CUT)
            step[:, 1:] = np.where(ok, length, CUT)   # the edge from each cell's predecessor in its line
            on = (lines >= 0) & flat_mask[np.maximum(lines, 0)]
            self._dirs.append((lines[on], np.cumsum(step[on])))

    def distances(self, sources: np.ndarray, init: np.ndarray | None = None, iterations: int = 12) -> np.ndarray:
        """Geodesic distance (h, w) from the source cells (bool mask or (k, 2) row/col); inf off-surface."""
        d = np.full(self.mask.shape, INF) if init is None else init.copy()
        src = np.asarray(sources)
        if src.dtype == bool:
            d[src & self.mask] = 0.0
        elif src.size:
            d[src[:, 0], src[:, 1]] = 0.0
        flat = np.where(np.isfinite(d), d, UNREACHED).ravel()
        for _ in range(iterations):
            before = flat.copy()
            for cells, cum in self._dirs:
                v = flat[cells]
                _relax(v, cum)
                flat[cells] = v
            if np.array_equal(flat, before):
                break
        d = flat.reshape(self.mask.shape)
        return np.where((d < CUT * 0.5) & self.mask, d, INF)


def geodesic_extrema(graph: SurfaceGraph, d0: np.ndarray, count: int = 6, min_distance: float = 0.3,
                     iterations: int = 8) -> list[tuple[int, int, float]]:
    """Plagemann-style interest points: repeatedly take the farthest cell, then add it as a source.

    Returns [(row, col, geodesic distance from the torso)] for extrema at least `min_distance` away."""
    out = []
    d = d0.copy()
    for i in range(count):
        finite = np.where(np.isfinite(d), d, -1.0)
        k = int(np.argmax(finite))
        if finite.flat[k] < min_distance * 0.5:
            break
        r, c = divmod(k, d.shape[1])
        if d0[r, c] >= min_distance:
            out.append((r, c, float(d0[r, c])))
        if i < count - 1:   # the last extremum's distances would never be read
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
