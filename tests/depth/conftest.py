"""A short rendered sequence of real mocap (CMU 131_03, hop), rendered once per test session."""
from __future__ import annotations

import numpy as np
import pytest


@pytest.fixture(scope="session")
def rendered(data_dir, tmp_path_factory):
    from kinect_retarget.sim.synthetic_depth import Scenario, render_sequence
    seq = render_sequence(str(data_dir / "mocap_bvh" / "131_03.bvh"), str(data_dir / "meshes" / "makehuman"),
                          Scenario(seed=7), start=40, frames=12)
    path = tmp_path_factory.mktemp("depth") / "hop.npz"
    seq.save_npz(str(path))
    return seq, path


@pytest.fixture
def camera():
    from kinect_retarget.depth.depth_camera import DepthCamera
    return DepthCamera()


def plane_depth(camera, z0: float = 2.0, tilt_y: float = 0.0) -> np.ndarray:
    """(480, 640) metres of a fronto-parallel plane (optionally slanted along image rows)."""
    v, u = np.mgrid[0:camera.height, 0:camera.width].astype(np.float64)
    return z0 + tilt_y * (v - camera.cy) / camera.height
