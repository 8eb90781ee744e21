"""The auto-rig on bodies other than MakeHuman's own (issue 13): other proportions, decimated, re-triangulated,
re-posed. Each surface is mirror-symmetric about x = 0; the rig must be too, within 0.5 % of height, although
geodesics measured on a triangulation that is not itself mirrored place the two sides differently."""
import numpy as np
import pytest

from kinect_retarget.autorig import autorig
from kinect_retarget.sim.body_variants import (decimated, one_sided_diagonals, random_diagonals,
                                                   reshape_points, reshaped)
from kinect_retarget.sim.autorig_scoring import (joint_errors, pose_body, reference_joints,
                                                rotations_from_makehuman_bvh, symmetry_error)
from kinect_retarget.autorig.mesh import Mesh
from kinect_retarget.autorig.mirror import MIRROR_TOLERANCE, fit_mirror_plane, symmetrize_joints
from kinect_retarget.core.skeletons import KINECT_V1
from kinect_retarget.takes.bvh import read_bvh_skeleton

LEFT = np.array([1.0, 0, 0])
BODIES = ("reshaped, one-sided diagonals", "decimated to 7k vertices", "random diagonals", "T-pose, one-sided diagonals")


@pytest.fixture(scope="module")
def bodies(mh, data_dir):
    y = mh.body.vertices[:, 1]
    rot = rotations_from_makehuman_bvh(mh, read_bvh_skeleton(data_dir / "meshes" / "makehuman" / "tpose.bvh"))
    ref = reference_joints(mh)
    return {  # name: (mesh, its reference joints)
        BODIES[0]: (one_sided_diagonals(reshaped(mh.body)), reshape_points(ref, (y.min(), y.max()))),
        BODIES[1]: (decimated(mh.body, 0.08), ref),
        BODIES[2]: (random_diagonals(mh.body, np.random.default_rng(13)), ref),
        BODIES[3]: (one_sided_diagonals(pose_body(mh, rot)), reference_joints(mh, rot)),
    }


@pytest.fixture(scope="module")
def rigs(bodies):
    return {name: autorig(mesh) for name, (mesh, _) in bodies.items()}


@pytest.mark.parametrize("name", BODIES)
def test_left_right_symmetric_within_half_a_percent(bodies, rigs, name):
    mesh, ref = bodies[name]
    rig = rigs[name]
    height = np.ptp(mesh.vertices[:, 1])
    # measured against the body's own mirror plane (x = 0, known by construction), not the fitted one
    assert symmetry_error(rig.joints, LEFT, np.zeros(3), height) < 0.5
    assert rig.report["mirror"]["symmetric"] and rig.report["mirror"]["surface_mismatch_pct"] < 0.05
    err = joint_errors(rig.joints, ref, height)
    assert err.max() < 3.0, dict(zip(KINECT_V1.joints, err.round(2)))


def _edge_keys(faces):
    e = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    return np.unique(e[:, 0] * 10**6 + e[:, 1])


def test_the_bodies_are_what_they_claim(mh, bodies):
    assert 6500 < len(bodies[BODIES[1]][0].vertices) < 7500
    for name in (BODIES[0], BODIES[2], BODIES[3]):  # the same quads, split along other diagonals
        new = np.setdiff1d(_edge_keys(bodies[name][0].faces), _edge_keys(mh.body.faces))
        assert len(new) > 3000, name


def test_the_asymmetry_came_from_the_triangulation(rigs):
    """Before symmetrising, the joints found on the one-sided triangulation were off by well over the goal
    (the issue's 1.6-2.0 %): the remedy is doing the work, not the test bodies being easy."""
    assert rigs[BODIES[0]].report["mirror"]["joint_asymmetry_found_pct"] > 1.5


def test_posed_body_is_left_as_found(mh, data_dir):
    """A body in an asymmetric pose is not its own mirror image: its joints follow the pose."""
    rot = rotations_from_makehuman_bvh(mh, read_bvh_skeleton(data_dir / "meshes" / "makehuman" / "benchmark.bvh"))
    rig = autorig(pose_body(mh, rot))
    assert not rig.report["mirror"]["symmetric"] and rig.report["mirror"]["surface_mismatch_pct"] > 0.5
    assert symmetry_error(rig.joints, LEFT, np.zeros(3), mh.height) > 10


def test_mirror_plane_of_a_moved_body_and_symmetrised_joints(mh, rng):
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    q *= np.sign(np.linalg.det(q))
    shift = rng.normal(size=3) * 5
    moved = Mesh(mh.body.vertices @ q.T + shift, mh.body.faces)
    # start 5 degrees off: the surface's own principal axes find the plane
    start = q @ np.array([1.0, 0.06, -0.06])
    plane = fit_mirror_plane(moved.vertices, moved.faces, start, mh.height)
    assert plane.symmetric and plane.mismatch < 1e-4
    assert abs(plane.normal @ (q @ LEFT)) > 1 - 1e-6 and abs(plane.offset - plane.normal @ shift) < 1e-3
    joints = reference_joints(mh) @ q.T + shift + rng.normal(0, 0.05, (20, 3))
    sym = symmetrize_joints(joints, plane)
    np.testing.assert_allclose(plane.reflect(sym[KINECT_V1.mirror]), sym, atol=1e-9)
    np.testing.assert_allclose(symmetrize_joints(sym, plane), sym, atol=1e-9)  # a projection
    # a surface pushed out of true by more than the tolerance is not mirrored
    bent = moved.vertices.copy()
    arm = mh.body.vertices[:, 0] > 3.0
    bent[arm] += (q @ np.array([0, 1.0, 0])) * 3 * MIRROR_TOLERANCE * mh.height
    assert not fit_mirror_plane(bent, moved.faces, start, mh.height).symmetric
