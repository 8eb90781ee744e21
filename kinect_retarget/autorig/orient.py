"""Stand a rigged mesh the Blender way: Z up, facing -Y, feet on the floor, sized in metres. Axis-aligned
turns only (the nearest of the 24), so a model built square to its axes stays square."""
from __future__ import annotations

from itertools import permutations, product

import numpy as np

HUMAN_HEIGHT_M = (0.5, 2.6)  # a standing figure, child to tall adult; anything else keeps its scale


def axis_rotations() -> np.ndarray:
    """The 24 proper rotations that permute and flip the axes."""
    out = []
    for perm in permutations(range(3)):
        for signs in product((1, -1), repeat=3):
            r = np.zeros((3, 3))
            r[range(3), perm] = signs
            if np.linalg.det(r) > 0:
                out.append(r)
    return np.array(out)


def upright_rotation(up: np.ndarray, front: np.ndarray) -> np.ndarray:
    """Axis-aligned rotation taking the body's up toward +Z and its front toward -Y."""
    target = np.array([[0, 0, 1.0], [0, -1.0, 0]])
    source = np.array([up, front])
    rots = axis_rotations()
    score = np.einsum("rij,kj,ki->r", rots, source, target)
    return rots[int(np.argmax(score))]


def metres_per_unit(height: float) -> float:
    """The power of ten (or inch) that makes `height` a human height in metres; 1 when none does."""
    for s in (1.0, 0.1, 0.01, 0.001, 0.0254):
        if HUMAN_HEIGHT_M[0] <= height * s <= HUMAN_HEIGHT_M[1]:
            return s
    return 1.0


def upright_transform(vertices: np.ndarray, up: np.ndarray, front: np.ndarray, height: float,
                      centre: np.ndarray) -> np.ndarray:
    """4x4 matrix: turn upright, scale to metres, put the lowest point on z = 0 and `centre` over the origin."""
    r = upright_rotation(up, front) * metres_per_unit(height)
    moved = vertices @ r.T
    c = centre @ r.T
    m = np.eye(4)
    m[:3, :3] = r
    m[:3, 3] = [-c[0], -c[1], -moved[:, 2].min()]
    return m
