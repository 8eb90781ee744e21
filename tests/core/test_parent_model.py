"""Constraint-driven parents learned from evaluated poses and solved in numpy (issue 15), on a small rig
whose 'Blender' is a known relation (float32-rounded like Blender's matrices)."""
import numpy as np
import pytest

from kinect_retarget.core.parent_fit import learn, relative_to_parent
from kinect_retarget.core.parent_model import Follow, ParentModel, dependency_order, local_rotations
from kinect_retarget.core.quat import angle_between, mul, normalize, to_matrix
from kinect_retarget.core.target_rig import TargetRig

NAMES = ("root", "chest", "mch", "upper", "lower")


def rig():
    """root -> chest; root -> mch (constrained: blends toward chest) -> upper -> lower."""
    rest = np.tile(np.eye(4), (5, 1, 1))
    rest[:, :3, 3] = [[0, 0, 0], [0, 0, 0.5], [0, 0, 1], [0.1, 0, 1.2], [0.3, 0, 1.5]]
    rest[3, :3, :3] = to_matrix(np.array([np.cos(0.4), np.sin(0.4), 0, 0]))
    rest[4, :3, :3] = to_matrix(normalize(np.array([0.9, 0.1, 0.3, -0.2])))
    return TargetRig("chain", NAMES, [-1, 0, 0, 2, 3], rest, np.full(5, 0.3))


def random_quats(rng, *shape):
    return normalize(rng.normal(size=shape + (4,)))


def blender(truth: ParentModel, basis, rng, noise=True):
    """'Evaluated' rotations (S, B, 4) of the true relations, rounded to float32 as Blender's are."""
    rot, _ = truth.run(len(basis), basis=basis)
    out = np.stack([rot[b] for b in range(len(NAMES))], axis=1)
    return normalize(out.astype(np.float32).astype(np.float64)) if noise else out


@pytest.fixture
def truth(rng):
    r = rig()
    mapped = (0, 1, 3, 4)
    follow = Follow(1, random_quats(rng), 0.35)
    local = local_rotations(r, np.tile([1.0, 0, 0, 0], (5, 1)))
    order = dependency_order(r, mapped, {2: [1]})
    return ParentModel(r, mapped, local, {2: follow}, (), tuple(order))


def test_dependency_order_puts_targets_first():
    r = rig()
    order = dependency_order(r, [4], {2: [1]})
    assert order.index(1) < order.index(2) < order.index(3) < order.index(4)
    loop = {2: [3]}  # a target below the bone itself would be a loop: dropped
    dependency_order(r, [4], loop)
    assert loop == {2: []}


def test_learns_the_blend_and_solves_desired_rotations_exactly(truth, rng):
    basis = random_quats(rng, 14, 4) * [1, 0.6, 0.6, 0.6]
    basis = normalize(basis)
    ev = blender(truth, basis, rng)
    model = learn(truth.rig, truth.mapped, np.tile([1.0, 0, 0, 0], (5, 1)), {2: [1]}, basis, ev, 4)
    assert model.fallback == () and set(model.follows) == {2}
    f = model.follows[2]
    assert f.target == 1 and f.weight == pytest.approx(0.35, abs=1e-5)
    assert np.degrees(angle_between(f.offset, truth.follows[2].offset)) < 1e-3
    assert model.error_deg < 1e-3
    # solving: the pose rotations that put the mapped bones where the solver wants them, all frames at once
    desired = random_quats(rng, 50, 4)
    quats = model.solve(desired)
    rot, _ = truth.run(50, basis=quats)  # the true relations: off only by what float32 noise left in the fit
    for k, b in enumerate(truth.mapped):
        assert np.degrees(angle_between(rot[b], desired[:, k])).max() < 1e-4


def test_a_parent_no_relation_explains_falls_back_to_evaluated_values(truth, rng):
    basis = normalize(random_quats(rng, 14, 4) * [1, 0.6, 0.6, 0.6])
    wild = random_quats(rng, 14)  # mch turns with something the probe does not see (time, an empty...)
    ev = blender(truth, basis, rng, noise=False)
    ev[:, 2] = wild
    ev[:, 3] = mul(mul(wild, truth.local[3]), basis[:, 2])
    ev[:, 4] = mul(mul(ev[:, 3], truth.local[4]), basis[:, 3])
    model = learn(truth.rig, truth.mapped, np.tile([1.0, 0, 0, 0], (5, 1)), {2: [1]}, basis, ev, 4)
    assert model.fallback == (2,) and model.fallback_names == ["mch"]
    assert model.error_deg < 1e-6   # the whole model, with the fallback bone's evaluated values
    desired = random_quats(rng, 1, 4)
    held = relative_to_parent(model.rig, model.fallback, ev[:1])
    quats = model.solve(desired, held)
    rot, _ = model.run(1, basis=quats, evaluated=held)
    assert np.degrees(angle_between(rot[4], desired[:, 3])).max() < 1e-9
