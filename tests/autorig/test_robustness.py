"""Imperfect meshes: holes, non-manifold fins, uneven triangles with T-junctions, the T-pose."""
import numpy as np

from kinect_retarget.autorig import autorig
from kinect_retarget.sim.autorig_scoring import (joint_errors, pose_body, reference_joints,
                                                rotations_from_makehuman_bvh)
from kinect_retarget.autorig.mesh import Mesh, subdivide
from kinect_retarget.core.skeletons import KINECT_V1
from kinect_retarget.takes.bvh import read_bvh_skeleton

LIMIT = 3.0  # % of height: the goal holds for meshes damaged on purpose too


def _check(mh, mesh, ref=None):
    rig = autorig(mesh)
    err = joint_errors(rig.joints, reference_joints(mh) if ref is None else ref, mh.height)
    assert err.max() < LIMIT, dict(zip(KINECT_V1.joints, err.round(2)))
    np.testing.assert_allclose(rig.weight.sum(axis=1), 1.0, atol=1e-9)
    return rig


def test_holes(mh, rng):
    v, f = mh.body.vertices, mh.body.faces
    centres = rng.choice(len(v), 8, replace=False)
    near = np.linalg.norm(v[:, None] - v[centres][None], axis=2).min(axis=1) < 0.3  # 3 cm holes, like open eye sockets or a missing patch of skin
    keep = ~near[f].any(axis=1)
    assert (~keep).sum() > 50
    _check(mh, Mesh(v, f[keep], "holed"))


def test_non_manifold_fins(mh, rng):
    v, f = mh.body.vertices, mh.body.faces
    pick = f[rng.choice(len(f), 300, replace=False)]
    tip = v[pick].mean(axis=1) + rng.normal(0, 0.05, (300, 3))  # a third face on an existing edge
    new_idx = len(v) + np.arange(300)
    fins = np.stack([pick[:, 0], pick[:, 1], new_idx], axis=1)
    _check(mh, Mesh(np.concatenate([v, tip]), np.concatenate([f, fins]), "fins"))


def test_uneven_triangles_and_t_junctions(mh):
    left = mh.body.vertices[mh.body.faces].mean(axis=1)[:, 0] > 0
    once = subdivide(mh.body, left)
    _check(mh, once)


def test_t_pose(mh, data_dir):
    rot = rotations_from_makehuman_bvh(mh, read_bvh_skeleton(data_dir / "meshes" / "makehuman" / "tpose.bvh"))
    _check(mh, pose_body(mh, rot), reference_joints(mh, rot))
