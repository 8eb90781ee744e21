"""Learn a ParentModel (core/parent_model.py) from a few poses Blender evaluated (issue 15).

The probe poses the mapped bones at random and reads back every bone's armature-space rotation. Each bone
the mapped bones depend on is then explained, from the evaluated rotations of its parent and its
constraints' targets: plain parenting, or a blend toward one target (or the armature) with a constant
offset at a constant influence, fitted on the first poses and verified on the rest. A bone that no relation
explains to the tolerance is evaluated by Blender per frame (the fallback); the bake reports which.
"""
from __future__ import annotations

import numpy as np

from .parent_model import IDENTITY, Follow, ParentModel, dependency_order, local_rotations, power, slerp_toward
from .quat import angle_between, conjugate, mul, normalize
from .target_rig import TargetRig

TOLERANCE_DEG = 0.001     # Blender computes in float32: about 1e-4 degrees of noise on a long chain
GRID = np.linspace(0.002, 1.0, 500)
GOLDEN = (np.sqrt(5) - 1) / 2


def _hemisphere(q: np.ndarray) -> np.ndarray:
    return q * np.where(q[..., :1] < 0, -1.0, 1.0)


def _offsets(pre: np.ndarray, tgt: np.ndarray, ev: np.ndarray, w) -> np.ndarray:
    """The offset K each sample implies for influence w: ev = slerp(pre, tgt·K, w) solved for K."""
    g = _hemisphere(mul(conjugate(pre), ev))
    return mul(conjugate(tgt), mul(pre, power(g, 1.0 / np.asarray(w))))


def _errors(pre, tgt, ev, w, k) -> np.ndarray:
    """Worst angle (radians) between the relation's prediction and Blender's, per (w, k) pair."""
    goal = mul(tgt, np.asarray(k)[..., None, :])
    return angle_between(slerp_toward(pre, goal, np.asarray(w)[..., None]), ev).max(axis=-1)


def _fit_one(pre, tgt, ev, n_fit: int) -> tuple[float, np.ndarray, float]:
    """Influence, offset and worst error on all samples for one candidate target."""
    fp, ft, fe = pre[:n_fit], tgt[:n_fit], ev[:n_fit]
    g = mul(conjugate(fp[0]), fe[0])
    half = np.arctan2(np.linalg.norm(g[1:]), abs(g[0]))
    ws = GRID[half / GRID <= np.pi / 2]  # the full relation turns at most 180°
    if ws.size == 0:
        return 1.0, IDENTITY, np.inf
    ks = _offsets(fp[0], ft[0], fe[0], ws)
    err = _errors(fp, ft, fe, ws, ks)
    i = int(np.argmin(err))
    lo, hi = ws[max(i - 1, 0)], ws[min(i + 1, ws.size - 1)]

    def cost(w):
        return float(_errors(fp, ft, fe, np.array(w), _offsets(fp[0], ft[0], fe[0], w)))
    a, b = hi - GOLDEN * (hi - lo), lo + GOLDEN * (hi - lo)
    ca, cb = cost(a), cost(b)
    for _ in range(40):
        if ca < cb:
            hi, b, cb = b, a, ca
            a = hi - GOLDEN * (hi - lo)
            ca = cost(a)
        else:
            lo, a, ca = a, b, cb
            b = lo + GOLDEN * (hi - lo)
            cb = cost(b)
    w = float((lo + hi) / 2)
    k = _offsets(fp, ft, fe, w)  # one per fitted sample: average them (same hemisphere as the first)
    k = normalize(np.sum(k * np.where(k @ k[0] < 0, -1.0, 1.0)[:, None], axis=0))
    return w, k, float(_errors(pre, tgt, ev, np.array(w), k))


def fit_follow(pre: np.ndarray, ev: np.ndarray, candidates: dict[int, np.ndarray],
               n_fit: int) -> tuple[Follow | None, float]:
    """pre (S, 4): the bone's rotation before its constraints; ev (S, 4): Blender's; candidates: target
    bone -> its evaluated rotations (S, 4) (-1: the armature). Returns the best relation (None: plain
    parenting explains it) and its worst error on all samples, degrees."""
    best, best_err = None, float(angle_between(pre, ev).max())
    for target, tgt in candidates.items():
        if best_err < np.radians(TOLERANCE_DEG) / 10:
            break
        w, k, err = _fit_one(pre, tgt, ev, n_fit)
        if err < best_err:
            best, best_err = Follow(target, k, w), err
    return best, float(np.degrees(best_err))


def learn(rig: TargetRig, mapped, user_basis: np.ndarray, constrained: dict[int, list[int]],
          sample_basis: np.ndarray, evaluated: np.ndarray, n_fit: int,
          tolerance_deg: float = TOLERANCE_DEG) -> ParentModel:
    """rig and mapped (rig indices of the solver's bones); user_basis (B, 4): every bone's pose rotation as
    the user left it; constrained: bone -> its constraints' target bones (bones with constraints or
    drivers); sample_basis (S, M, 4): the mapped bones' pose rotations of each probe pose; evaluated
    (S, B, 4): Blender's armature-space rotation of every bone for each. Samples [:n_fit] fit, all verify."""
    mapped = tuple(int(b) for b in mapped)
    targets = {b: list(t) for b, t in constrained.items()}
    order = dependency_order(rig, mapped, targets)
    basis = np.array(user_basis, dtype=np.float64)
    basis[list(mapped)] = IDENTITY
    local = local_rotations(rig, basis)
    slot = {b: k for k, b in enumerate(mapped)}
    follows, fallback, errors = {}, [], {}
    done = []  # bones placed so far: a target must be evaluated before the bone that follows it
    for b in order:
        p = int(rig.parents[b])
        own = mul(local[b], sample_basis[:, slot[b]]) if b in slot else np.broadcast_to(local[b], (len(evaluated), 4))
        pre = own if p < 0 or not rig.inherit_rotation[b] else mul(evaluated[:, p], own)
        ev = evaluated[:, b]
        if b in targets:
            cands = {t: evaluated[:, t] for t in targets[b]}
            cands[-1] = np.broadcast_to(IDENTITY, ev.shape)
            follow, err = fit_follow(pre, ev, cands, n_fit)
            if err > tolerance_deg:  # what it names does not explain it: try every mapped bone above it
                more = {t: evaluated[:, t] for t in done if t in slot and t not in cands}
                if more:
                    follow, err = min((follow, err), fit_follow(pre, ev, more, n_fit), key=lambda r: r[1])
        else:
            follow, err = None, float(np.degrees(angle_between(pre, ev).max()))
        errors[b] = err
        done.append(b)
        if err > tolerance_deg:
            fallback.append(b)
        elif follow is not None:
            follows[b] = follow
    model = ParentModel(rig, mapped, local, follows, tuple(fallback), tuple(order), notes={"errors": errors})
    model.error_deg = check(model, sample_basis, evaluated)
    return model


def relative_to_parent(rig: TargetRig, bones, evaluated: np.ndarray) -> dict:
    """bone -> (S, 4) rotation relative to its parent (absolute without one), from evaluated (S, B, 4)."""
    out = {}
    for b in bones:
        p = int(rig.parents[b])
        out[b] = evaluated[:, b] if p < 0 or not rig.inherit_rotation[b] else \
            mul(conjugate(evaluated[:, p]), evaluated[:, b])
    return out


def check(model: ParentModel, sample_basis: np.ndarray, evaluated: np.ndarray) -> float:
    """Worst angle, degrees, between the whole model run forward from the mapped bones' pose rotations and
    Blender's rotations, over every bone that matters (fallback bones take Blender's values; plain bones
    in between were each checked by learn)."""
    rel = relative_to_parent(model.rig, model.fallback, evaluated)
    rotations, _ = model.run(len(sample_basis), basis=sample_basis, evaluated=rel)
    worst = max(float(angle_between(rotations[b], evaluated[:, b]).max()) for b in rotations)
    return float(np.degrees(worst))
