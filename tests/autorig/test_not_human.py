import numpy as np
import pytest

from kinect_retarget.autorig import Mesh, MeshError, autorig
from tests.autorig.shapes import spiky_sphere


@pytest.mark.parametrize("n_spikes, message", [(6, "more than five long branches"), (4, "not a human")])
def test_star_shapes_are_not_human(n_spikes, message):
    dirs = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)[:n_spikes]
    verts, faces = spiky_sphere(dirs)
    with pytest.raises(MeshError, match=message):
        autorig(Mesh(verts, faces, "star"))


def test_plain_sphere_is_not_human():
    verts, faces = spiky_sphere(np.zeros((0, 3)) + [[1, 0, 0]], spike=0.0)
    with pytest.raises(MeshError, match="not a human|no head|limbs"):
        autorig(Mesh(verts, faces, "ball"))


def test_no_faces():
    with pytest.raises(MeshError, match="no faces"):
        Mesh(np.zeros((3, 3)), np.zeros((0, 3)), "dots")


def test_tailless_quadruped_is_not_human():
    """Four equal legs and a short head: five branches like a human, but the 'arms' are as long as the legs."""
    legs = [[1, -1, 0.6], [1, -1, -0.6], [-1, -1, 0.6], [-1, -1, -0.6]]
    dirs = np.array(legs + [[1.2, 0.8, 0]], float)
    verts, faces = spiky_sphere(dirs, subdivisions=60, spike=[4, 4, 4, 4, 1.2])
    with pytest.raises(MeshError, match="four-legged"):
        autorig(Mesh(verts * [1.6, 1, 1], faces, "dog"))
