"""Geodesic distances on the mesh graph by Dijkstra (heap-based), single- or multi-source."""
from __future__ import annotations

import heapq

import numpy as np

from .graph import MeshGraph


def dijkstra(graph: MeshGraph, sources, return_nearest: bool = False):
    """Shortest edge-path length from the nearest of `sources` to every vertex (inf where unreachable).

    With return_nearest, also the position in `sources` of the source each vertex is closest to: the
    segmentation by nearest feature point comes out of one multi-source run.
    """
    sources = np.atleast_1d(np.asarray(sources, dtype=np.int64))
    # Python lists index much faster than numpy scalars inside the loop.
    indptr = graph.indptr.tolist()
    indices = graph.indices.tolist()
    weights = graph.weights.tolist()
    inf = float("inf")
    dist = [inf] * graph.n
    near = [-1] * graph.n
    heap = []
    for k, s in enumerate(sources.tolist()):
        if dist[s] > 0.0:
            dist[s], near[s] = 0.0, k
            heap.append((0.0, s))
    heapq.heapify(heap)
    pop, push = heapq.heappop, heapq.heappush
    done = [False] * graph.n
    while heap:
        d, u = pop(heap)
        if done[u]:
            continue
        done[u] = True
        nu = near[u]
        for i in range(indptr[u], indptr[u + 1]):
            v = indices[i]
            nd = d + weights[i]
            if nd < dist[v]:
                dist[v] = nd
                near[v] = nu
                push(heap, (nd, v))
    out = np.asarray(dist)
    return (out, np.asarray(near, dtype=np.int64)) if return_nearest else out
