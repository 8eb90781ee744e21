"""Rigs whose bone parents are driven by constraints (Rigify's MCH parents of its FK controls), evaluated in
numpy for every frame at once (issue 15). Relations are learned from Blender's evaluation once
(core/parent_fit.py); this module only applies them.

Every bone the mapped bones hang from, and every bone those follow, has one relation giving its
armature-space rotation R for every frame:

    plain      R_c = R_p · L_c                        L_c: rest rotation relative to the parent times the
                                                      bone's own (constant) pose rotation
    follow     R_c = slerp(R_p · L_c, R_t · K, w)     a constraint toward bone t (t = -1: the armature, R_t
                                                      = I) with a constant offset K, at influence w (w = 1:
                                                      follows t outright; Blender blends influence this way)
    evaluated  R_c = R_p · X_c(f)                     fallback: X_c read back from Blender's evaluation

A mapped bone's rotation before its own constraints is the solver's desired rotation D; its pose rotation is
then (R_p · rest_rel)ᵀ · D, exact whatever drives its parents.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .quat import conjugate, from_matrix, mul, normalize, to_matrix
from .target_rig import TargetRig

IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])


@dataclass(frozen=True)
class Follow:
    """R_c = slerp(R_c before the constraint, R_target · offset, weight); target -1 = armature space."""
    target: int
    offset: np.ndarray
    weight: float


def slerp_toward(a: np.ndarray, b: np.ndarray, w: float | np.ndarray) -> np.ndarray:
    """Blender's influence blend: a turned the shortest way toward b by the fraction w (broadcasts)."""
    rel = mul(conjugate(a), b)
    rel = rel * np.where(rel[..., :1] < 0, -1.0, 1.0)  # shortest way round, as interp_qt_qtqt
    return mul(a, power(rel, w))


def power(q: np.ndarray, w: float | np.ndarray) -> np.ndarray:
    """q^w for unit quaternions with q_w >= 0: the same axis, w times the angle."""
    half = np.arctan2(np.linalg.norm(q[..., 1:], axis=-1), q[..., 0])
    w = np.asarray(w, dtype=np.float64)  # broadcasts against q's leading axes
    scale = np.where(half > 1e-12, np.sin(w * half) / np.where(half > 1e-12, np.sin(half), 1.0), w)
    out = np.empty(scale.shape + (4,))
    out[..., 0] = np.cos(w * half)
    out[..., 1:] = q[..., 1:] * scale[..., None]
    return out


def local_rotations(rig: TargetRig, basis: np.ndarray) -> np.ndarray:
    """(B, 4): each bone's rest rotation relative to its parent (absolute for roots and bones that do not
    inherit rotation) times its pose rotation `basis` (B, 4)."""
    rot = rig.rest[:, :3, :3]
    rel = rot.copy()
    assert rig.inherit_rotation is not None   # TargetRig fills it in
    has = (rig.parents >= 0) & rig.inherit_rotation
    rel[has] = np.swapaxes(rot[rig.parents[has]], -1, -2) @ rot[has]
    return normalize(mul(from_matrix(rel), basis))  # rest matrices come as float32: exactly unit here


@dataclass
class ParentModel:
    """What the bake and live need to pose mapped bones exactly on a constrained rig.

    mapped: rig indices of the solver's bone_names; local (B, 4) see local_rotations (the mapped bones'
    entries hold only their rest-relative part); follows: bone -> Follow; fallback: bones whose relation did
    not verify (evaluated per frame); order: every bone needed, each after its parent and its target."""

    rig: TargetRig
    mapped: tuple[int, ...]
    local: np.ndarray
    follows: dict[int, Follow]
    fallback: tuple[int, ...]
    order: tuple[int, ...]
    error_deg: float = 0.0           # worst disagreement with Blender on the probe's poses
    notes: dict = field(default_factory=dict)          # what learning found (per-bone errors)
    _plan_cache: dict = field(default_factory=dict, repr=False)

    @property
    def fallback_names(self) -> list[str]:
        return [self.rig.bone_names[b] for b in self.fallback]

    @property
    def learned_names(self) -> list[str]:
        return [self.rig.bone_names[b] for b in self.follows]

    def _plan(self) -> list[tuple[int, int, np.ndarray | None]]:
        """The bones whose rotation matters (mapped, constrained, followed), each as (bone, anchor, C):
        its parent's rotation is R_anchor · C (anchor -1: C alone; C None: identity), as 3x3 matrices. Plain
        bones in between fold into C, so a frame costs a few matrix products per bone that matters."""
        cache = self._plan_cache
        if not cache:
            key = set(self.mapped) | set(self.follows) | set(self.fallback) | \
                {f.target for f in self.follows.values() if f.target >= 0}
            local = to_matrix(normalize(self.local))
            carry, plan = {}, []
            for b in self.order:
                p = int(self.rig.parents[b])
                if p < 0 or not self.rig.inherit_rotation[b]:
                    anchor, c = -1, None
                elif p in key:
                    anchor, c = p, None
                else:
                    anchor, c = carry[p]
                if b in key:
                    plan.append((b, anchor, c))
                else:
                    carry[b] = (anchor, local[b] if c is None else c @ local[b])
            cache.update(plan=plan, local=local,
                         offset={b: to_matrix(normalize(f.offset)) for b, f in self.follows.items()})
        return cache["plan"]

    def run(self, nframes: int, desired: np.ndarray | None = None, basis: np.ndarray | None = None,
            evaluated: dict | None = None, rotations: bool = True) -> tuple[dict, np.ndarray]:
        """Armature-space rotations (F, 4) of the bones that matter (mapped, constrained, followed; with
        `rotations`) and the mapped bones' pose quaternions (F, M, 4). Give either `desired` (F, M, 4)
        armature-space rotations of the mapped bones (the bake and live) or their pose rotations `basis`
        (F, M, 4) (checking against Blender). evaluated: fallback bone -> (F, 4) rotation relative to its
        parent, from Blender."""
        plan = self._plan()
        local, offset = self._plan_cache["local"], self._plan_cache["offset"]
        slot = {b: k for k, b in enumerate(self.mapped)}
        mapped_q = desired if desired is not None else basis
        assert mapped_q is not None, "give desired or basis"
        given = to_matrix(mapped_q)        # (F, M, 3, 3)
        pose = np.empty_like(given)
        out: dict[int, np.ndarray] = {}
        for b, anchor, c in plan:
            base = c if anchor < 0 else out[anchor] if c is None else out[anchor] @ c
            k = slot.get(b)
            if k is not None and desired is not None:
                frame = local[b] if base is None else base @ local[b]
                pose[:, k] = np.swapaxes(frame, -1, -2) @ given[:, k]
                r = given[:, k]           # what the pose rotation was solved for
                if evaluated is not None and b in evaluated:  # its own constraints turn it further
                    r = to_matrix(evaluated[b]) if base is None else base @ to_matrix(evaluated[b])
            else:
                if k is not None:
                    pose[:, k] = given[:, k]
                    own = local[b] @ given[:, k]
                elif evaluated is not None and b in evaluated:   # a fallback bone, as Blender has it
                    own = to_matrix(evaluated[b])
                else:
                    own = local[b]
                r = own if base is None else base @ own
            follow = self.follows.get(b)
            if follow is not None:
                goal = offset[b] if follow.target < 0 else out[follow.target] @ offset[b]
                rel = from_matrix(np.swapaxes(r, -1, -2) @ goal)  # w >= 0: the shortest way round
                r = r @ to_matrix(power(rel, follow.weight))
            out[b] = np.broadcast_to(r, (nframes, 3, 3))
        quats = from_matrix(pose)
        return ({b: from_matrix(m) for b, m in out.items()} if rotations else {}), quats

    def solve(self, desired: np.ndarray, evaluated: dict | None = None) -> np.ndarray:
        """desired (F, M, 4) armature-space rotations of the mapped bones -> pose quaternions (F, M, 4)."""
        desired = np.asarray(desired, dtype=np.float64)
        return self.run(desired.shape[0], desired=desired, evaluated=evaluated, rotations=False)[1]


def dependency_order(rig: TargetRig, roots, targets: dict[int, list[int]]) -> list[int]:
    """`roots` and everything they depend on (ancestors; for constrained bones their targets too), each
    bone after its parent and its targets. A target that would close a loop is dropped from `targets`."""
    order, state = [], {}

    def visit(b: int) -> bool:
        if state.get(b) == 2:
            return True
        if state.get(b) == 1:
            return False  # a loop
        state[b] = 1
        p = int(rig.parents[b])
        if p >= 0:
            visit(p)
        for t in list(targets.get(b, ())):
            if not visit(t):
                targets[b].remove(t)
        state[b] = 2
        order.append(b)
        return True

    for b in roots:
        visit(int(b))
    return order
