"""The chest's facing from its normals, on real motion rendered turned away from the sensor."""
from __future__ import annotations

import numpy as np
import pytest

from kinect_retarget.core.skeletons import KINECT_V1
from kinect_retarget.depth.depth_camera import DepthCamera
from kinect_retarget.depth.facing import CHEST_BAND, CHEST_RADIUS, chest_facing, surface_normals
from kinect_retarget.depth.segmentation import DepthGrid

J = KINECT_V1.index
UP = np.array([0.0, 1.0, 0.0])   # the renders' gravity is straight down (no tilt)


@pytest.fixture(scope="module")
def turned(data_dir):
    from kinect_retarget.sim.synthetic_depth import Scenario, render_sequence
    return render_sequence(str(data_dir / "mocap_bvh" / "131_02.bvh"), str(data_dir / "meshes" / "makehuman"),
                           Scenario(turn_deg=60.0, seed=8), start=0, frames=2)


def _yaw(direction, towards):
    """Signed degrees of a horizontal direction from the one toward the sensor."""
    a, b = direction * [1, 0, 1], towards * [1, 0, 1]
    return float(np.degrees(np.arctan2(np.cross(b, a)[1], a @ b)))


def _truth(gt):
    lat = (gt[J("HipLeft")] - gt[J("HipRight")]) + (gt[J("ShoulderLeft")] - gt[J("ShoulderRight")])
    return _yaw(np.cross(lat, UP), -gt[J("HipCenter")])


def _estimate(seq, i):
    """chest_facing on the person's cells, its torso axis and height from the ground truth."""
    grid = DepthGrid.from_mm(seq.mm[i], DepthCamera(), 4)
    gt = seq.joints[i]
    floor = gt[J("HipCenter")].copy()
    floor[1] = np.min(gt[:, 1]) - 0.05                   # the feet's joints sit above the soles
    height = gt[J("Head")][1] + 0.1 - floor[1]
    person = grid.valid & (np.linalg.norm((grid.xyz - gt[J("Spine")])[..., [0, 2]], axis=-1) < 0.6)
    facing = chest_facing(grid.xyz, person, floor, UP, height)
    return facing, grid, person, floor, height


def test_turned_chest_reads_its_turn(turned):
    """60 degrees away: the mode of the normals finds the chest's front; the plane through the same cells
    (what the tracker used before) is pulled toward the sensor by the visible side."""
    for i in range(len(turned.mm)):
        facing, grid, person, floor, height = _estimate(turned, i)
        truth = _truth(turned.joints[i])
        assert abs(truth) > 45
        assert facing is not None and abs(facing @ UP) < 1e-9
        assert abs(_yaw(facing, -turned.joints[i][J("HipCenter")]) - truth) < 8.0
        rel = grid.xyz - floor
        chest = person & (rel[..., 1] > CHEST_BAND[0] * height) & (rel[..., 1] < CHEST_BAND[1] * height) \
            & (np.linalg.norm(rel[..., [0, 2]], axis=-1) < CHEST_RADIUS)
        pts = grid.xyz[chest]
        normal = np.linalg.svd(pts - pts.mean(axis=0), full_matrices=False)[2][2]
        normal = normal if normal @ pts.mean(axis=0) < 0 else -normal
        plane = _yaw(normal, -turned.joints[i][J("HipCenter")])
        assert abs(plane - truth) > 20.0


def test_frontal_chest(rendered):
    seq, _ = rendered
    for i in (0, 6, 11):
        facing, *_ = _estimate(seq, i)
        assert abs(_yaw(facing, -seq.joints[i][J("HipCenter")]) - _truth(seq.joints[i])) < 12.0


def test_too_little_chest_is_no_answer(rendered):
    seq, _ = rendered
    grid = DepthGrid.from_mm(seq.mm[0], DepthCamera(), 4)
    assert chest_facing(grid.xyz, np.zeros(grid.valid.shape, bool), np.zeros(3), UP, 1.7) is None


def test_normals_point_at_the_sensor_and_skip_depth_edges(camera):
    from tests.depth.conftest import plane_depth
    mm = (plane_depth(camera, 2.0, tilt_y=0.5) * 1000).astype(np.uint16)
    mm[:, 320:] = 3000     # a step of a metre: no normal across it
    grid = DepthGrid.from_mm(mm, camera, 4)
    n, ok = surface_normals(grid.xyz, grid.valid)
    assert np.all(n[ok][:, 2] < 0)                        # toward the sensor (at the origin, looking along +Z)
    assert not ok[:, 79].any() and not ok[:, 80].any()    # the cells either side of the step
    assert ok[10:-10, 10:70].all()
