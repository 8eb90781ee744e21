"""Paper 003 §2.2-§4.1: segmentation by nearest feature point, normalized geodesic levels, skeleton points
as centroids of connected vertex groups per (segment, level), joined into a tree; and a simple discrete
Reeb-graph baseline (levels of one geodesic function, no segmentation) for the paper's table 3.

Two readings of eq. 6: "segment" (the default) normalizes each feature point's geodesic field over its own
segment, so every limb is cut into K levels; "global", as printed, over all N vertices, so a short segment
(an arm) spans only the lower levels and gets fewer skeleton points (MakeHuman at K = 4: 26 points against
18). The default keeps every limb described at the same resolution, which the joints need (joints_paper.py).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .graph import MeshGraph, connected_components


@dataclass
class SkeletonPoints:
    points: np.ndarray       # (M, 3) centroids
    segment: np.ndarray      # (M,) feature-point segment of each group (-1 for the baseline)
    level: np.ndarray        # (M,) topological level 0..K-1
    vertex_group: np.ndarray  # (V,) group of each vertex
    tree: np.ndarray         # (M-1, 2) edges joining the points into one tree (no loops)
    size: np.ndarray | None = None   # (M,) vertices in each group
    value: np.ndarray | None = None  # (M,) mean geodesic distance g of each group's vertices

    def count_per_level(self, k: int) -> np.ndarray:
        return np.bincount(self.level, minlength=k)


NORMALIZATIONS = ("segment", "global")


def normalized_levels(segment: np.ndarray, g: np.ndarray, k: int,
                      normalization: str = "segment") -> tuple[np.ndarray, np.ndarray]:
    """Eq. (6): f = (g - min) / (max - min), per segment's domain or ("global", as printed) over all
    vertices; level = floor(K f), the top value folded into level K-1. Returns (f, level)."""
    if normalization not in NORMALIZATIONS:
        raise ValueError(f"normalization {normalization!r}: expected one of {NORMALIZATIONS}")
    if normalization == "global":
        segment = np.zeros_like(segment)
    n_seg = int(segment.max()) + 1
    lo = np.full(n_seg, np.inf)
    hi = np.full(n_seg, -np.inf)
    np.minimum.at(lo, segment, g)
    np.maximum.at(hi, segment, g)
    span = np.maximum(hi - lo, 1e-12)
    f = (g - lo[segment]) / span[segment]
    return f, np.minimum((f * k).astype(np.int64), k - 1)


def group_points(vertices: np.ndarray, graph: MeshGraph, label: np.ndarray, segment: np.ndarray,
                 level: np.ndarray, g: np.ndarray | None = None) -> SkeletonPoints:
    """§4.1 steps (1)-(7): vertices sharing a label and joined by edges inside it form one group; each
    group's centroid is a skeleton point (eqs. 7-9)."""
    e = graph.edges
    same = label[e[:, 0]] == label[e[:, 1]]
    group = connected_components(graph.n, e[same])
    m = int(group.max()) + 1
    counts = np.bincount(group, minlength=m).astype(np.float64)
    pts = np.stack([np.bincount(group, vertices[:, i], m) for i in range(3)], axis=1) / counts[:, None]
    first = np.zeros(m, dtype=np.int64)
    first[group[::-1]] = np.arange(graph.n)[::-1]  # any member gives the group's segment and level
    value = None if g is None else np.bincount(group, g, m) / counts
    return SkeletonPoints(pts, segment[first], level[first], group, spanning_tree(pts, group, e),
                          counts.astype(np.int64), value)


def spanning_tree(points: np.ndarray, group: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Join groups that touch on the mesh by the shortest links that make a tree (Kruskal): neighbouring
    levels and neighbouring segments connect, and no loop can form."""
    a, b = group[edges[:, 0]], group[edges[:, 1]]
    pairs = np.unique(np.sort(np.stack([a[a != b], b[a != b]], axis=1), axis=1), axis=0)
    if len(pairs) == 0:
        return np.zeros((0, 2), dtype=np.int64)
    length = np.linalg.norm(points[pairs[:, 0]] - points[pairs[:, 1]], axis=1)
    parent = list(range(len(points)))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    tree = []
    for i, j in pairs[np.argsort(length)].tolist():  # at most a few hundred groups: a plain loop is fine
        ri, rj = root(i), root(j)
        if ri != rj:
            parent[ri] = rj
            tree.append((i, j))
    return np.asarray(tree, dtype=np.int64).reshape(-1, 2)


def paper_skeleton(vertices: np.ndarray, graph: MeshGraph, distances: np.ndarray, k: int = 4,
                   normalization: str = "segment") -> SkeletonPoints:
    """The paper's skeleton points from the feature points' distance fields (F, V)."""
    segment = np.argmin(distances, axis=0)
    g = distances[segment, np.arange(distances.shape[1])]
    _, level = normalized_levels(segment, g, k, normalization)
    return group_points(vertices, graph, segment * k + level, segment, level, g)


def reeb_baseline(vertices: np.ndarray, graph: MeshGraph, field: np.ndarray, k: int = 4) -> SkeletonPoints:
    """Discrete Reeb graph of one geodesic function: K level bands of the globally normalized field, one
    skeleton point per connected piece of each band (no segmentation by feature points)."""
    zero = np.zeros(len(field), dtype=np.int64)
    _, level = normalized_levels(zero, field, k)
    sk = group_points(vertices, graph, level, zero, level)
    sk.segment[:] = -1
    return sk
