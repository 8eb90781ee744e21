import numpy as np

from kinect_retarget.autorig.mesh_geodesic import dijkstra
from kinect_retarget.autorig.graph import connected_components, mesh_graph
from tests.autorig.shapes import grid_mesh


def _floyd(graph):
    d = np.full((graph.n, graph.n), np.inf)
    np.fill_diagonal(d, 0)
    d[graph.edges[:, 0], graph.edges[:, 1]] = graph.lengths
    d[graph.edges[:, 1], graph.edges[:, 0]] = graph.lengths
    for k in range(graph.n):
        d = np.minimum(d, d[:, k:k + 1] + d[k:k + 1, :])
    return d


def test_dijkstra_matches_brute_force(rng):
    verts, faces = grid_mesh(9, rng)
    graph = mesh_graph(verts, faces)
    ref = _floyd(graph)
    for s in rng.choice(graph.n, 5, replace=False):
        np.testing.assert_allclose(dijkstra(graph, [s]), ref[s], rtol=1e-12)


def test_multi_source_gives_nearest_source(rng):
    verts, faces = grid_mesh(8, rng)
    graph = mesh_graph(verts, faces)
    ref = _floyd(graph)
    sources = np.array([0, 63, 27])
    dist, near = dijkstra(graph, sources, return_nearest=True)
    np.testing.assert_allclose(dist, ref[sources].min(axis=0), rtol=1e-12)
    # ties aside, each vertex is labelled with its nearest source
    best = ref[sources].min(axis=0)
    assert np.all(np.isclose(ref[sources[near], np.arange(graph.n)], best))


def test_unreachable_is_inf_and_components(rng):
    a, fa = grid_mesh(4, rng)
    verts = np.concatenate([a, a + 100])
    faces = np.concatenate([fa, fa + len(a)])
    graph = mesh_graph(verts, faces)
    d = dijkstra(graph, [0])
    assert np.isfinite(d[:16]).all() and np.isinf(d[16:]).all()
    comp = connected_components(graph.n, graph.edges)
    assert set(comp[:16]) != set(comp[16:]) and len(set(comp)) == 2
