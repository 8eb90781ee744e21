"""Live correction for constrained parents (Rigify's MCH bones), checked against plain forward kinematics."""
import numpy as np

from kinect_retarget.core.quat import angle_between, from_matrix, to_matrix
from kinect_retarget.core.target_rig import TargetRig, evaluate_pose
from kinect_retarget.core.constrained_parent import ConstrainedParentCorrection


def chain_rig():
    """root -> mch (constrained, unmapped) -> upper -> lower: a Rigify-like FK chain."""
    rest = np.tile(np.eye(4), (4, 1, 1))
    rest[:, :3, 3] = [[0, 0, 0], [0, 0, 1], [0, 0, 1.2], [0, 0, 1.5]]
    rest[2, :3, :3] = to_matrix(np.array([np.cos(0.4), np.sin(0.4), 0, 0]))
    return TargetRig("chain", ("root", "mch", "upper", "lower"), [-1, 0, 1, 2], rest, np.full(4, 0.3))


def random_quats(rng, n):
    q = rng.normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def test_unconstrained_rig_is_left_alone(rng):
    rig = chain_rig()
    corr = ConstrainedParentCorrection(rig, ("root", "upper", "lower"), constrained_bones=())
    assert not corr.active


def test_constrained_parent_offset_is_compensated_exactly_when_it_follows_its_parent(rng):
    rig = chain_rig()
    mapped = ("root", "upper", "lower")
    corr = ConstrainedParentCorrection(rig, mapped, constrained_bones=("mch",))
    assert corr.active
    quats = random_quats(rng, 3)
    plain = evaluate_pose(rig, np.array([0, 2, 3]), quats[None])[0, :, :3, :3]
    desired = plain[[0, 2, 3]]   # what the solver meant: the rotations under plain parenting
    # Blender's constraint turns the MCH bone by a fixed offset relative to its parent
    offset = to_matrix(random_quats(rng, 1)[0])
    evaluated = {0: plain[0], 1: plain[1] @ offset}
    fixed = corr.correct(quats, evaluated, desired)
    # evaluate the corrected pose the way Blender would: the MCH bone keeps its constraint offset
    root = rig.rest[0, :3, :3] @ to_matrix(fixed[0])
    mch = root @ (rig.rest[0, :3, :3].T @ rig.rest[1, :3, :3]) @ offset
    upper = mch @ (rig.rest[1, :3, :3].T @ rig.rest[2, :3, :3]) @ to_matrix(fixed[1])
    lower = upper @ (rig.rest[2, :3, :3].T @ rig.rest[3, :3, :3]) @ to_matrix(fixed[2])
    got = from_matrix(np.stack([root, upper, lower]))
    assert np.degrees(angle_between(got, from_matrix(desired))).max() < 1e-8
    # without the correction the chain would be off by the offset
    assert np.degrees(angle_between(quats[1], fixed[1])) > 1.0


def test_desired_may_come_as_quaternions(rng):
    rig = chain_rig()
    corr = ConstrainedParentCorrection(rig, ("root", "upper", "lower"), constrained_bones=("mch",))
    quats = random_quats(rng, 3)
    desired = evaluate_pose(rig, np.array([0, 2, 3]), quats[None])[0, [0, 2, 3], :3, :3]
    evaluated = {0: desired[0], 1: desired[0] @ to_matrix(random_quats(rng, 1)[0])}
    a = corr.correct(quats, evaluated, desired)
    b = corr.correct(quats, evaluated, from_matrix(desired))
    assert np.degrees(angle_between(a, b)).max() < 1e-9
