"""Feature points (paper §2.1, automated): the five extremities of a human surface, found as geodesic
farthest points and labelled head / hands / feet from the geometry alone, for any orientation and scale."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .mesh_geodesic import dijkstra
from .graph import MeshGraph
from .mesh import MeshError

MAX_ARM_LEG = 0.9  # humans measure 0.65-0.75 (arm and leg branch lengths, any pose we tried)
CANDIDATES = 8  # farthest points examined; a human needs five, the rest are fingers, hips, ...
LABELS = ("head", "hand_left", "hand_right", "foot_left", "foot_right")


@dataclass
class FeaturePoints:
    """Vertex index of each extremity in LABELS order, their geodesic distance fields (5, V), the body's
    up and front directions and its left (character's left) axis, all unit vectors in mesh coordinates."""

    vertices: np.ndarray
    distances: np.ndarray
    up: np.ndarray
    front: np.ndarray
    left: np.ndarray


def farthest_points(graph: MeshGraph, count: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Geodesic farthest-point sampling: the first point is the farthest from `seed`, each next one the
    farthest from those chosen. Returns indices (count,), their fields (count, V) and the radius at which
    each was chosen (count + 1,: the last is the radius the next point would have had)."""
    d0 = dijkstra(graph, [seed])
    if not np.isfinite(d0).all():
        raise MeshError("the body surface is not connected")
    pts, fields, radii = [int(np.argmax(d0))], [], [float(d0.max())]
    nearest = np.full(graph.n, np.inf)
    while True:
        d = dijkstra(graph, [pts[-1]])
        fields.append(d)
        nearest = np.minimum(nearest, d)
        radii.append(float(nearest.max()))
        if len(pts) == count:
            break
        pts.append(int(np.argmax(nearest)))
    return np.asarray(pts), np.asarray(fields), np.asarray(radii)


def branch_lengths(dist: np.ndarray) -> np.ndarray:
    """For each tip i, the geodesic length of its own branch before it meets the others: the smallest
    Gromov product (d_ij + d_ik - d_jk) / 2 over the other pairs (tree metric). Vectorised over (i, j, k)."""
    n = len(dist)
    g = (dist[:, :, None] + dist[:, None, :] - dist[None, :, :]) / 2      # g[i, j, k]
    i, j, k = np.meshgrid(np.arange(n), np.arange(n), np.arange(n), indexing="ij")
    g = np.where((i == j) | (i == k) | (j == k), np.inf, g)
    return g.reshape(n, -1).min(axis=1)


def leaf_candidates(dist: np.ndarray, tol: float = 0.05) -> np.ndarray:
    """Indices of the candidates that lie on no shortest path between two others (a point half-way up a
    leg does, a toe tip does not): only those can be extremities."""
    n = len(dist)
    keep = []
    for j in range(n):
        others = [i for i in range(n) if i != j]
        d = dist[np.ix_(others, others)]
        detour = dist[others, j][:, None] + dist[j, others][None, :] - d     # 0 when j is on the i-k path
        np.fill_diagonal(detour, np.inf)
        if detour.min() > tol * dist[j, others].min():
            keep.append(j)
    return np.asarray(keep, dtype=np.int64)


def _root_point(vertices: np.ndarray, field: np.ndarray, branch: float) -> np.ndarray:
    """Centroid of the iso-geodesic ring where a limb meets the body."""
    band = np.abs(field - branch) < 0.05 * branch
    return vertices[band].mean(axis=0) if band.any() else vertices[np.argmin(np.abs(field - branch))]


def _describe(what: str, tips: int) -> str:
    return f"{what}; found {tips} extremities where a human has five (head, two hands, two feet)"


def find_feature_points(vertices: np.ndarray, graph: MeshGraph) -> FeaturePoints:
    """The five extremities, labelled. Raises MeshError when the shape is not a standing humanoid."""
    seed = int(np.argmin(np.linalg.norm(vertices - vertices.mean(axis=0), axis=1)))
    cand, cand_fields, _ = farthest_points(graph, CANDIDATES, seed)
    leaves = leaf_candidates(cand_fields[:, cand])
    branch_all = branch_lengths(cand_fields[np.ix_(leaves, cand[leaves])]) if len(leaves) >= 3 else np.zeros(len(leaves))
    ranked = leaves[np.argsort(-branch_all)]
    long_b = np.sort(branch_all)[::-1]
    if len(leaves) < 5 or long_b[4] <= 0:
        raise MeshError(_describe("the shape has fewer than five limbs: not a human figure", int((long_b > 0.2 * long_b.max()).sum())))
    ratio = float(long_b[5] / long_b[4]) if len(long_b) > 5 else 0.0
    if ratio > 0.4:
        raise MeshError(_describe(f"the shape has more than five long branches (the sixth is {ratio:.0%} as long "
                                  f"as the fifth): not a human figure", int((long_b > 0.4 * long_b[4]).sum())))
    tips, fields = cand[ranked[:5]], cand_fields[ranked[:5]]
    pair = fields[:, tips]                     # (5, 5) geodesic distances between the tips
    branch = branch_lengths(pair)
    order = np.argsort(branch)
    # A human: one short branch (head and neck) and four long ones (limbs).
    if branch[order[0]] > 0.75 * branch[order[1]]:
        raise MeshError(_describe("no extremity is clearly shorter than the limbs, so there is no head", 5))
    head = order[0]
    others = [i for i in range(5) if i != head]
    by_head = sorted(others, key=lambda i: pair[head, i])
    hands, feet = by_head[:2], by_head[2:]     # feet are the two tips geodesically farthest from the head
    if pair[head, feet].min() < 1.05 * pair[head, hands].max():
        raise MeshError(_describe("the four limbs do not split into arms near the head and legs far from "
                                  "it: not a human figure", 5))
    arm_leg = branch[hands].max() / branch[feet].min()
    if arm_leg > MAX_ARM_LEG:
        raise MeshError(_describe(f"the four limbs are about as long as each other (arms/legs {arm_leg:.2f}; "
                                  f"a human's arms are clearly shorter): a four-legged animal or a piece of "
                                  f"furniture, not a human figure", 5))
    up = vertices[tips[head]] - vertices[tips[feet]].mean(axis=0)
    up /= np.linalg.norm(up)
    # Toes point forward: the foot tips lie ahead of the shins' centre line.
    shin = []
    for f in feet:
        band = (fields[f] > 0.15 * branch[f]) & (fields[f] < 0.35 * branch[f])
        shin.append(vertices[band].mean(axis=0) if band.any() else vertices[tips[f]])
    fwd = (vertices[tips[feet]] - np.asarray(shin)).mean(axis=0)
    fwd -= up * (fwd @ up)
    if np.linalg.norm(fwd) < 1e-9:
        raise MeshError("cannot tell the front of the figure from its feet")
    front = fwd / np.linalg.norm(fwd)
    left = np.cross(up, front)  # right-handed: up x front points to the character's left
    # Left and right are judged at the limbs' roots (shoulders, tops of the thighs), which stay side by
    # side whatever the pose: in a split or with crossed arms the tips themselves can swap sides.
    root = {i: _root_point(vertices, fields[i], branch[i]) for i in others}

    def split(pair_ids):
        a, b = pair_ids
        return (a, b) if (root[a] - root[b]) @ left >= 0 else (b, a)

    hl, hr = split(hands)
    fl, fr = split(feet)
    sel = [head, hl, hr, fl, fr]
    tips, fields = _refine_tips(graph, tips[sel], fields[sel])
    return FeaturePoints(tips, fields, up, front, left)


def _refine_tips(graph: MeshGraph, tips: np.ndarray, fields: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Move each tip to the vertex of its own segment farthest from the other four tips. Farthest-point
    sampling finds one point per extremity, but not always its end: with the arms out, the lower back can
    be sampled before the head, which then gets the chin instead of the crown."""
    segment = np.argmin(fields, axis=0)
    tips, fields = tips.copy(), fields.copy()
    for i in range(len(tips)):
        others = np.delete(np.arange(len(tips)), i)
        score = np.where(segment == i, fields[others].sum(axis=0), -np.inf)
        best = int(np.argmax(score))
        if best != tips[i]:
            tips[i] = best
            fields[i] = dijkstra(graph, [best])
    return tips, fields
