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
