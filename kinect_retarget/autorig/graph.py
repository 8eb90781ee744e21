"""The mesh as a graph: unique edges with their lengths, CSR adjacency, connected components."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class MeshGraph:
    """Undirected edge graph. indptr/indices/weights: CSR adjacency (both directions), weights = lengths."""

    n: int
    edges: np.ndarray      # (E, 2) unique, i < j
    lengths: np.ndarray    # (E,)
    indptr: np.ndarray     # (n + 1,)
    indices: np.ndarray    # (2E,)
    weights: np.ndarray    # (2E,)


def mesh_graph(vertices: np.ndarray, faces: np.ndarray) -> MeshGraph:
    """Edges of the triangles, deduplicated; works on non-manifold and holed meshes alike."""
    n = len(vertices)
    e = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    e = np.sort(e, axis=1)
    e = e[e[:, 0] != e[:, 1]]  # degenerate triangles repeat a vertex
    e = np.unique(e, axis=0)
    lengths = np.linalg.norm(vertices[e[:, 0]] - vertices[e[:, 1]], axis=1)
    src = np.concatenate([e[:, 0], e[:, 1]])
    dst = np.concatenate([e[:, 1], e[:, 0]])
    w = np.concatenate([lengths, lengths])
    order = np.argsort(src, kind="stable")
    indptr = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(np.bincount(src, minlength=n), out=indptr[1:])
    return MeshGraph(n, e, lengths, indptr, dst[order], w[order])


def connected_components(n: int, edges: np.ndarray) -> np.ndarray:
    """(n,) component label per vertex, labels 0.. by decreasing size. Vectorised union-find by pointer
    jumping: each pass hooks every edge's larger root onto its smaller one, then compresses paths."""
    parent = np.arange(n)
    if len(edges):
        a, b = edges[:, 0], edges[:, 1]
        while True:
            ra, rb = parent[a], parent[b]
            lo, hi = np.minimum(ra, rb), np.maximum(ra, rb)
            diff = lo != hi
            if not diff.any():
                break
            np.minimum.at(parent, hi[diff], lo[diff])
            while True:  # path compression until every vertex points at a root
                nxt = parent[parent]
                if np.array_equal(nxt, parent):
                    break
                parent = nxt
    _, label, counts = np.unique(parent, return_inverse=True, return_counts=True)
    rank = np.empty_like(counts)
    rank[np.argsort(-counts, kind="stable")] = np.arange(len(counts))
    return rank[label]
