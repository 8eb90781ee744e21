"""Geodesic stage on synthetic surfaces with known answers."""
from __future__ import annotations

import numpy as np

from kinect_retarget.depth.surface_geodesic import SurfaceGraph, geodesic_extrema, level_set_centroid


def _grid(h, w, spacing=0.02, z=2.0):
    v, u = np.mgrid[0:h, 0:w].astype(np.float64)
    return np.stack([u * spacing, -v * spacing, np.full((h, w), z)], axis=-1)


def test_flat_plane_distances_are_euclidean():
    xyz = _grid(40, 60)
    g = SurfaceGraph(xyz, np.ones((40, 60), bool))
    d = g.distances(np.array([[20, 30]]))
    true = np.linalg.norm(xyz - xyz[20, 30], axis=-1)
    assert d[20, 30] == 0
    along_axes = np.r_[d[20, :] - true[20, :], d[:, 30] - true[:, 30]]
    assert np.max(np.abs(along_axes)) < 1e-9          # straight rows/columns are exact
    rel = (d - true)[true > 0.1] / true[true > 0.1]
    assert rel.min() > -1e-9 and rel.max() < 0.09      # never shorter; 4+diagonal grid overestimates a little


def test_geodesic_goes_around_a_gap():
    xyz = _grid(30, 30)
    mask = np.ones((30, 30), bool)
    mask[0:25, 14:16] = False                            # a wall from the top down to row 24: a U shape
    d = SurfaceGraph(xyz, mask).distances(np.array([[0, 5]]))
    straight = np.linalg.norm(xyz[0, 25] - xyz[0, 5])
    # the shortest way runs diagonally down to the wall's end (row 25) and up again
    around = 2 * np.hypot(25 * 0.02, 9.5 * 0.02)
    assert d[0, 25] > 2.5 * straight and abs(d[0, 25] - around) < 0.12 * around  # 8-neighbour chamfer: <= 8 % long
    assert np.isinf(d[~mask]).all()


def test_depth_discontinuity_cuts_the_graph():
    xyz = _grid(20, 40)
    xyz[:, 20:, 2] -= 0.3                                # right half 30 cm nearer: an arm in front of the chest
    d = SurfaceGraph(xyz, np.ones((20, 40), bool), max_jump=0.06).distances(np.array([[10, 5]]))
    assert np.isfinite(d[:, :20]).all()
    assert np.isinf(d[:, 20:]).all()


def test_extrema_of_a_star_are_its_tips():
    # a cross: the four arm tips are the geodesic extrema from the centre (a body's head, hands, feet)
    mask = np.zeros((61, 61), bool)
    mask[27:34, :] = True
    mask[:, 27:34] = True
    xyz = _grid(61, 61)
    g = SurfaceGraph(xyz, mask)
    d0 = g.distances(np.array([[30, 30]]))
    ext = geodesic_extrema(g, d0, count=4, min_distance=0.3)
    tips = sorted((int(r > 40) - int(r < 20), int(c > 40) - int(c < 20)) for r, c, _ in ext)
    assert tips == [(-1, 0), (0, -1), (0, 1), (1, 0)]
    assert all(dist > 0.55 for _, _, dist in ext)


def test_level_set_centroid_is_on_the_medial_axis():
    mask = np.zeros((80, 21), bool)
    mask[:, 5:16] = True                                 # a vertical strip (a limb) centred on column 10
    xyz = _grid(80, 21)
    d = SurfaceGraph(xyz, mask).distances(np.array([[0, 10]]))
    c = level_set_centroid(xyz, d, 0.8, 0.05)
    assert abs(c[0] - 10 * 0.02) < 0.01 and abs(c[1] + 0.8) < 0.03


def _dijkstra(xyz, mask, source, max_jump):
    """Reference shortest paths on the same 8-neighbour graph, one cell at a time."""
    import heapq
    h, w = mask.shape
    d = np.full((h, w), np.inf)
    d[source] = 0.0
    heap = [(0.0, source)]
    while heap:
        dist, (r, c) = heapq.heappop(heap)
        if dist > d[r, c]:
            continue
        for dr in (-1, 0, 1):
            for dc in (-1, 0, 1):
                rr, cc = r + dr, c + dc
                if (dr or dc) and 0 <= rr < h and 0 <= cc < w and mask[rr, cc] \
                        and abs(xyz[rr, cc, 2] - xyz[r, c, 2]) < max_jump:
                    nd = dist + np.linalg.norm(xyz[rr, cc] - xyz[r, c])
                    if nd < d[rr, cc]:
                        d[rr, cc] = nd
                        heapq.heappush(heap, (nd, (rr, cc)))
    return d


def test_distances_match_dijkstra_on_a_ragged_surface():
    # holes, islands and depth steps: the chains pack only the person's cells, so gaps must still cut
    rng = np.random.default_rng(7)
    xyz = _grid(35, 22)
    xyz[..., 2] += np.cumsum(rng.normal(0.0, 0.012, (35, 22)), axis=1)
    xyz[10:20, 12:, 2] -= 0.2                             # a forearm in front of the chest
    mask = rng.random((35, 22)) > 0.15
    mask[:, 8] = False
    mask[5, 8] = True                                     # one bridge between the left strip and the rest
    graph = SurfaceGraph(xyz, mask, max_jump=0.06)
    for source in ((3, 2), (30, 15), (14, 16)):
        if not mask[source]:
            continue
        ref = _dijkstra(xyz, mask, source, 0.06)
        d = graph.distances(np.array([source]), iterations=60)
        assert np.array_equal(np.isfinite(d), np.isfinite(ref)), source
        fin = np.isfinite(ref)
        assert np.max(np.abs(d[fin] - ref[fin])) < 1e-9, source
