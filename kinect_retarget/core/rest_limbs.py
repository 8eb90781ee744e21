"""Joint choices of the structural mapper (structure_mapping.py), chiefly its armature mode: limb joints of
an armature from its rest pose alone.

A take shows which nodes bend; a rest pose does not, and armatures put twist bones inside their limb chains
(MakeHuman's upperarm02, Daz's lShldrTwist) where a BVH figure has none. Among the chain's nodes the limb's
three joints are the choice that (1) skips no node where the chain bends at rest (a twist node sits on a
straight line; a real elbow or knee rarely does) and (2) gives the upper and lower segments human proportions
(upper arm / forearm and thigh / shin about 1.1, and together most of the limb's length).
The helpers below the limb fits take the mapper itself (`m`: its kids, pos, short, size). Pure numpy.
"""
from __future__ import annotations

import itertools

import numpy as np

RATIO = 1.1          # upper arm / forearm, thigh / shin
BEND_COST = 0.01     # per degree of rest bend at a node the choice skips
ARM_COVERAGE = 0.75  # upper arm + forearm of the way from the clavicle's head to the wrist
LEG_COVERAGE = 0.95  # thigh + shin of the way from the hip bone's head to the ankle
FOOT_TURN = 30.0     # the chain turns at least this much (degrees) at the ankle, toward the toes


def bend_at(pos: np.ndarray, a: int, b: int, c: int) -> float:
    """Rest angle (degrees) at node b between a->b and b->c."""
    u, v = pos[b] - pos[a], pos[c] - pos[b]
    den = np.linalg.norm(u) * np.linalg.norm(v)
    return float(np.degrees(np.arccos(np.clip(u @ v / den, -1, 1)))) if den > 0 else 0.0


def _bends(pos: np.ndarray, k: list[int]) -> np.ndarray:
    out = np.zeros(len(k))
    for i in range(1, len(k) - 1):
        out[i] = bend_at(pos, k[i - 1], k[i], k[i + 1])
    return out


def _cost(pos, k, bends, upper: int, mid: int, lower: int, chain: float, coverage: float) -> float:
    a = np.linalg.norm(pos[k[mid]] - pos[k[upper]])
    b = np.linalg.norm(pos[k[lower]] - pos[k[mid]])
    if a <= 0 or b <= 0:
        return np.inf
    skipped = sum(bends[i] for i in range(upper + 1, lower) if i != mid)
    return abs(np.log(a / b / RATIO)) + abs(np.log((a + b) / chain / coverage)) + BEND_COST * skipped


def best_triple(pos: np.ndarray, k: list[int], lower: int, first: int = 1,
                coverage: float = ARM_COVERAGE) -> tuple[int, int]:
    """Indices (into k) of the upper and middle joints (shoulder and elbow, hip and knee) for the lower joint
    k[lower] (wrist, ankle), the upper one at k[first] or later. The two segments span about `coverage` of
    the chain from k[first] (a clavicle takes a quarter of the way from the chest to the wrist; two twist
    halves of a forearm have the right ratio but far too little length)."""
    bends = _bends(pos, k)
    pairs = [(u, m) for u, m in itertools.combinations(range(first, lower), 2)]
    if not pairs:
        return max(lower - 2, 0), lower - 1
    chain = float(np.linalg.norm(np.diff(pos[k[first:lower + 1]], axis=0), axis=1).sum())
    return min(pairs, key=lambda um: _cost(pos, k, bends, um[0], um[1], lower, chain, coverage))


def rest_leg(pos: np.ndarray, k: list[int]) -> tuple[int, int, int]:
    """(hip, knee, ankle) indices into k (k[0]: the pelvis node): the ankle is the first node past the leg's
    middle where the chain turns toward the toes (else the chain's last node); then the best triple."""
    bends = _bends(pos, k)
    total = np.linalg.norm(np.diff(pos[k], axis=0), axis=1).cumsum()
    ankle = next((i for i in range(3, len(k) - 1) if bends[i] >= FOOT_TURN and total[i - 1] > 0.5 * total[-1]),
                 len(k) - 1)
    hip, knee = best_triple(pos, k, ankle, coverage=LEG_COVERAGE)
    return hip, knee, ankle


def wrist_fan(m, k: list[int]) -> int | None:
    """The wrist: the first node (past the shoulder) where two or more chains leave. In an armature the
    nodes are bone heads, so bones leaving one point at the end of a long bone (Kinect v2's hand and thumb
    from the wrist) fork at the next node of the chain."""
    for i, j in enumerate(k[3:], start=3):
        if len(m.kids[j]) < 2:
            continue
        heads = m.pos[0, m.kids[j]]
        spread = np.ptp(heads, axis=0).max()
        if m.armature and i + 1 < len(k) and spread < 0.25 * np.linalg.norm(heads - m.pos[0, j], axis=1).min():
            return k[i + 1]
        return j
    return None


def fanout(m, j: int) -> int:
    """Children of j, counting those of zero-length children in their place."""
    return sum(fanout(m, c) if m._dist(j, c) < m.short * m.size else 1 for c in m.kids[j])


def big_branches(m, j: int, frac: float) -> list[int]:
    """Children of j reaching at least frac of the figure, by the length of their long bones or, failing that,
    in a straight line (a neck of two short bones under a head whose face bones hide its length reaches
    the top of the head all the same); in an armature, a zero-length child's own branches count in its place
    (Daz's legs hang from a pelvis bone that starts where the hip bone does)."""
    out = []
    for c in m.kids[j]:
        if m.armature and m.kids[c] and m.seg[c] < m.short * m.size:
            out += big_branches(m, c, frac)
        elif max(m.bulk[c] + m.long[c], m._extent(j, c)) >= frac * m.size:
            out.append(c)
    return out


def longest_leg(m, k: list[int]) -> tuple[int, int, int]:
    """(hip, knee, ankle) indices into k for a take's figure: thigh + shin are the longest pair of segments."""
    seg = [m._dist(k[i], k[i + 1]) for i in range(len(k) - 1)]
    hip = max(max(range(len(seg) - 1), key=lambda s: seg[s] + seg[s + 1]), 1)
    return hip, hip + 1, hip + 2


def head_base(m, head_chain: list[int]) -> int | None:
    """The head joint's node: in an armature, the first node where the face's bones fan out (through
    zero-length face roots); in a take's figure, the last node before the top with two or more children."""
    if m.armature:
        return next((j for j in head_chain[1:-1] if fanout(m, j) >= 2), None)
    return next((j for j in reversed(head_chain[1:-1]) if len(m.kids[j]) >= 2), None)
