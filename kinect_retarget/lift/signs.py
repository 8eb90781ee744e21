"""Depth-sign disambiguation: which way (toward or away from the camera) each bone points.

Every bone's depth offset is known up to its sign (paper 004 §3.2). Bones that move together share one sign
bit (the pelvis: left hip forward means right hip back), and the bits form small groups: the torso (pelvis,
spine, shoulder girdle, head) and each limb (3 bits). A group's state per frame is one of 2^bits sign
patterns; we choose the whole take's states by dynamic programming (Viterbi) with
* temporal continuity: joints do not jump in depth between frames (a flip only costs nothing where the bone
  lies in the image plane, which is where a real crossing happens);
* joint limits: knees do not bend forward, elbows not backward, a thigh swings only a little inward, a
  hanging upper arm does not point into the chest,
  hands continue the forearm, feet point forward, shoulders and hips do not twist apart by more than a
  spine can;
* priors: the trunk does not lean far backward, a walking body faces where it goes.
The torso is decided first, with each limb's best cost given each torso pattern folded into it, then each
limb given the torso.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.quat import normalize
from ..core.skeletons import KINECT_V1, Skeleton
from .geometry import JointLines
from .viterbi import viterbi


@dataclass(frozen=True)
class SignGroup:
    name: str
    anchor: str
    bits: tuple[tuple[tuple[str, int], ...], ...]  # per bit: (joint whose bone it signs, multiplier)

    @property
    def joints(self) -> tuple[str, ...]:
        return tuple(j for bit in self.bits for j, _ in bit)


TORSO = SignGroup("torso", "HipCenter", (
    (("Spine", 1), ("ShoulderCenter", 1)),
    (("Head", 1),),
    (("ShoulderLeft", 1), ("ShoulderRight", -1)),
    (("HipLeft", 1), ("HipRight", -1)),
))
LIMBS = tuple(
    SignGroup(f"{kind}{side}", anchor.format(side), tuple(((j.format(side), 1),) for j in joints))
    for side in ("Left", "Right")
    for kind, anchor, joints in (("arm", "Shoulder{}", ("Elbow{}", "Wrist{}", "Hand{}")),
                                 ("leg", "Hip{}", ("Knee{}", "Ankle{}", "Foot{}"))))


@dataclass(frozen=True)
class SignPriors:
    """Weights of the sign costs (dimensionless, comparable to one unit of temporal cost)."""

    max_speed_mps: float = 2.0       # joint depth speed that costs 1/2 per frame
    min_sigma_m: float = 0.015       # floor of that per-frame depth step (2D noise)
    jump_cost_cap: float = 4.0       # most a single joint's depth jump can cost in one frame
    knee_hyperextension: float = 40.0
    knee_tolerance: float = 0.0      # sine of the forward knee bend allowed before it costs
    elbow_hyperextension: float = 15.0
    elbow_tolerance: float = 0.05    # sine of the backward bend allowed before it costs
    hand_continues_forearm: float = 2.0
    foot_forward: float = 12.0
    thigh_adduction: float = 20.0
    foot_tolerance: float = 0.2      # how far forward (cosine) a foot should point before it is free
    wrist_behind_back: float = 4.0
    arm_into_chest: float = 10.0
    shoulder_hip_twist: float = 6.0
    trunk_lean_back: float = 6.0
    head_back: float = 2.0
    face_travel: float = 3.0


def _sign_table(nbits: int) -> np.ndarray:
    states = np.arange(2 ** nbits)
    return np.where((states[:, None] >> np.arange(nbits)) & 1, -1.0, 1.0)


def group_positions(group: SignGroup, lines: JointLines, anchor: np.ndarray, lengths: np.ndarray,
                    skeleton: Skeleton = KINECT_V1) -> np.ndarray:
    """(F, T, S, n, 3) positions of the group's joints for every sign pattern S, given T hypotheses of
    the anchor's position (F, T, 3)."""
    table = _sign_table(len(group.bits))
    names = group.joints
    f, t = anchor.shape[:2]
    out = np.zeros((f, t, table.shape[0], len(names), 3))
    base = anchor[:, :, None, :]   # one anchor for every sign pattern: its children broadcast over them
    for k, bit in enumerate(group.bits):
        for name, mult in bit:
            j = skeleton.index(name)
            parent = skeleton.joints[skeleton.parents[j]]
            p = out[:, :, :, names.index(parent)] if parent in names else base
            out[:, :, :, names.index(name)] = lines.end(j, p, lengths[j], mult * table[None, None, :, k])
    return out


def _unit(v: np.ndarray) -> np.ndarray:
    return normalize(v, 1e-9)


def _hinge(a: np.ndarray, b: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """Signed sine of the bend from a to b about `axis` (all unit-normalised here)."""
    return np.sum(np.cross(_unit(a), _unit(b)) * _unit(axis), axis=-1)


def _temporal(rel_z: np.ndarray, times: np.ndarray, pri: SignPriors, breaks: np.ndarray) -> np.ndarray:
    """(F-1, S, S) cost of depth jumps of the group's joints between consecutive frames."""
    dt = np.diff(times)
    sigma = np.maximum(pri.max_speed_mps * dt, pri.min_sigma_m)
    jump = rel_z[1:, None, :, :] - rel_z[:-1, :, None, :]
    # Capped per joint: a bone whose length or scale is slightly off never reaches zero depth where it
    # crosses the image plane, and a true crossing must stay affordable.
    cost = np.sum(np.minimum(jump ** 2 / (2 * sigma[:, None, None, None] ** 2), pri.jump_cost_cap), axis=-1)
    cost[breaks[1:] | breaks[:-1]] = 0.0
    return cost


def _torso_frame(tp: np.ndarray):
    """Performer's left (F, S, 3) and horizontal forward (F, S, 3) from torso positions (F, S, 7, 3)."""
    names = TORSO.joints
    left = tp[:, :, names.index("HipLeft")] - tp[:, :, names.index("HipRight")]
    left = _unit(left + 0.5 * (tp[:, :, names.index("ShoulderLeft")] - tp[:, :, names.index("ShoulderRight")]))
    fwd = np.cross(left, np.array([0.0, 1.0, 0.0]))  # left x up = forward (conventions: -Z faces camera)
    return left, _unit(fwd)


def _torso_unary(tp: np.ndarray, left: np.ndarray, fwd: np.ndarray, travel: np.ndarray,
                 pri: SignPriors) -> np.ndarray:
    n = TORSO.joints
    g = lambda name: tp[:, :, n.index(name)]  # noqa: E731
    hip_l = _unit(g("HipLeft") - g("HipRight"))
    sh_l = _unit(g("ShoulderLeft") - g("ShoulderRight"))
    up = _unit(g("ShoulderCenter"))
    head = _unit(g("Head") - g("ShoulderCenter"))
    cost = pri.shoulder_hip_twist * np.maximum(0.0, 0.8 - np.sum(hip_l * sh_l, axis=-1)) ** 2 * 4
    cost += pri.trunk_lean_back * np.maximum(0.0, -np.sum(up * fwd, axis=-1) - 0.1) ** 2 * 10
    cost += pri.head_back * np.maximum(0.0, -np.sum(head * fwd, axis=-1) - 0.2) ** 2 * 10
    cost -= pri.face_travel * np.sum(fwd * travel[:, None, :], axis=-1)
    return cost


def _limb_unary(group: SignGroup, lp: np.ndarray, left: np.ndarray, fwd: np.ndarray,
                pri: SignPriors) -> np.ndarray:
    """(F, St, Sl) cost of each limb pattern given each torso pattern's body frame."""
    a, b, c = (lp[..., i, :] for i in range(3))  # joint positions rel. anchor: (F, St, Sl, 3)
    upper, lower, tip = a, b - a, c - b
    left, fwd = left[:, :, None], fwd[:, :, None]
    if group.name.startswith("leg"):
        flex = _hinge(upper, lower, left)  # knee flexion bends the shin back: positive about the left axis
        cost = pri.knee_hyperextension * np.maximum(0.0, -flex - pri.knee_tolerance) ** 2 * 10
        cost += pri.foot_forward * np.maximum(0.0, pri.foot_tolerance - np.sum(_unit(tip) * fwd, axis=-1)) ** 2
        # a thigh can swing far outward but only a little inward: the other leg is in the way
        outward = np.sum(_unit(upper) * (left if group.name.endswith("Left") else -left), axis=-1)
        cost = cost + pri.thigh_adduction * np.maximum(0.0, -outward - 0.3) ** 2 * 10
    else:
        flex = _hinge(upper, lower, left)  # elbow flexion brings the forearm forward: negative about left
        cost = pri.elbow_hyperextension * np.maximum(0.0, flex - pri.elbow_tolerance) ** 2 * 10
        cost += pri.hand_continues_forearm * np.maximum(0.0, -np.sum(_unit(tip) * _unit(lower), axis=-1)) ** 2
        cost += pri.wrist_behind_back * np.maximum(0.0, -np.sum(b * fwd, axis=-1) - 0.3) ** 2 * 10
        # a hanging upper arm cannot point into the chest
        inward = np.sum(_unit(upper) * (-left if group.name.endswith("Left") else left), axis=-1)
        down = -_unit(upper)[..., 1]
        cost = cost + pri.arm_into_chest * np.maximum(0.0, inward - 0.3) ** 2 * np.maximum(down, 0.0) * 10
    return cost


def choose_signs(lines: JointLines, lengths: np.ndarray, root: np.ndarray, times: np.ndarray,
                 valid: np.ndarray, travel: np.ndarray | None = None, priors: SignPriors = SignPriors(),
                 method: str = "viterbi", skeleton: Skeleton = KINECT_V1) -> np.ndarray:
    """Side of every bone (+1: the joint is the farther of its two possible places along its line), (F, J)
    indexed by child joint.

    lines: each joint's image ray or orthographic line; root (F, 3) the pelvis position; valid (F,) frames
    with a body; travel (F, 3) horizontal direction the body moves, weighted by speed (0 when still).
    method: "viterbi" (whole take), "greedy" (frame by frame, causal: usable live), "camera" (every bone
    toward the camera: no disambiguation, the baseline).
    """
    f = root.shape[0]
    signs = np.ones((f, len(skeleton)))
    if method == "camera":
        return -signs
    if method not in ("viterbi", "greedy"):
        raise ValueError(f"unknown sign method {method!r} (viterbi, greedy, camera)")
    breaks = ~np.asarray(valid, dtype=bool)
    travel = np.zeros((f, 3)) if travel is None else travel
    root = np.nan_to_num(root)
    tp = group_positions(TORSO, lines, root[:, None], lengths, skeleton)[:, 0]  # (F, St, 7, 3)
    left, fwd = _torso_frame(tp)
    limb_pos, limb_un = [], []
    for g in LIMBS:
        anchor = tp[:, :, TORSO.joints.index(g.anchor)]                        # (F, St, 3)
        lp = group_positions(g, lines, anchor, lengths, skeleton)               # (F, St, Sl, 3, 3)
        limb_pos.append(lp - anchor[:, :, None, None, :])
        limb_un.append(_limb_unary(g, limb_pos[-1], left, fwd, priors))        # (F, St, Sl)
    unary = _torso_unary(tp - root[:, None, None, :], left, fwd, travel, priors)
    unary = unary + sum(u.min(axis=2) for u in limb_un)  # each limb's best cost under each torso pattern
    unary[breaks] = 0.0
    rel_z = tp[..., 2] - root[:, None, None, 2]
    torso_state = _solve(unary, _temporal(rel_z, times, priors, breaks), method)
    _write(signs, TORSO, torso_state, skeleton)
    rows = np.arange(f)
    for g, lp, lu in zip(LIMBS, limb_pos, limb_un):
        u = lu[rows, torso_state]
        u[breaks] = 0.0
        z = lp[rows, torso_state][..., 2]
        _write(signs, g, _solve(u, _temporal(z, times, priors, breaks), method), skeleton)
    return signs


def _solve(unary: np.ndarray, pairwise: np.ndarray, method: str) -> np.ndarray:
    if method == "viterbi":
        return viterbi(unary, pairwise)
    out = np.empty(unary.shape[0], dtype=np.int64)
    out[0] = int(np.argmin(unary[0]))
    for t in range(1, unary.shape[0]):  # causal: each frame given the previous choice only
        out[t] = int(np.argmin(unary[t] + pairwise[t - 1, out[t - 1]]))
    return out


def _write(signs: np.ndarray, group: SignGroup, states: np.ndarray, skeleton: Skeleton) -> None:
    table = _sign_table(len(group.bits))[states]
    for k, bit in enumerate(group.bits):
        for name, mult in bit:
            signs[:, skeleton.index(name)] = mult * table[:, k]
