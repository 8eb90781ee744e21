"""Find the Kinect v1 joints in any humanoid skeleton from its structure, not its names.

One mapper for every skeleton: a BVH hierarchy (takes/bvh_figure.py) and an armature (armature_mapping.py).

API
---
``map_structure(names, parents, rest, frames=None, end_site=None, armature=False) -> StructureMapping``

* ``names``: (N,) node names; used only as a tiebreak (left/right when the figure cannot tell, twist bones in
  a single-frame skeleton) and for Kinect-named skeletons, which map one to one.
* ``parents``: (N,) parent index of each node, -1 for a root. Any order (a parent may follow its child).
* ``rest``: (N, 3) node positions in one pose (the rest pose); any units, any up axis.
* ``frames``: optional (F, N, 3) node positions over a take. With them, up, facing and left/right come from
  the motion (the floor under the feet and the head above them, core/floor_plane.py; toes and knees pointing
  forward) and twist nodes are found as the nodes that never bend; without them the rest pose is the only
  frame.
* ``end_site``: optional (N,) bool, True for nodes that only mark where a chain ends (BVH End Site).
* ``armature``: True for an armature's rest pose (core/armature_mapping.py; its choices: core/rest_limbs.py).

A node is a point: for BVH a joint or end site; for a Blender armature pass every bone's head as a node
(parent = the parent bone's head node) plus one node for the tail of each bone without children
(end_site=True), so ``RoleMatch.node`` is the bone whose head sits at the joint, or a leaf bone's tail.

The result maps each Kinect v1 joint (``ROLES``: HipCenter, Spine, ShoulderCenter, Head, Shoulder/Elbow/Wrist/
Hand Left/Right, Hip/Knee/Ankle/Foot Left/Right) to a ``RoleMatch``: ``node`` (the node located at that joint,
or None when no node is: a spine without a middle joint, a hand or foot the skeleton lacks), ``average``
(nodes whose mean position stands for the joint, e.g. the head centre halfway between the head joint and
the top of the head; empty when nothing does and the caller must extrapolate), and ``how`` (a short note:
"end site after the wrist", "Kinect name", ...). Twist, roll, finger, toe, face and helper nodes get no role.
``StructureError`` (a ValueError) says why a skeleton is not a humanoid.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from .floor_plane import estimate_up
from .rest_limbs import best_triple, big_branches, head_base, longest_leg, rest_leg, wrist_fan
from .skeletons import KINECT_V1
from .structure_names import branch_side, kinect_names

ROLES = KINECT_V1.joints
SHORT = 0.03        # a segment shorter than this fraction of the figure's size is a zero-length helper
SHORT_REST = 0.004  # ... for an armature (its short bones are real: MakeHuman's upperarm01)
BIG_BRANCH = 0.15   # a pelvis branch (spine, leg) reaches at least this fraction of the figure's size
NECK_BRANCH = 0.08  # a chest branch (arm, neck) reaches at least this much
FINGER = 0.015      # a finger base at least this far from the wrist stands for the hand (not a carpal node)
ARM_BRANCH = 0.2    # and the two arms at least this much (breasts and other helpers are shorter)
STILL_DEG = 0.5     # a node whose chain never bends more than this over the take is a twist node
TWIST_NAME = re.compile(r"twist|roll|upperarm0?2|lowerarm0?2|upperleg0?2|lowerleg0?2|helper|adjust|share",
                        re.IGNORECASE)


class StructureError(ValueError):
    """The skeleton has no humanoid structure (message says what is missing)."""


@dataclass(frozen=True)
class RoleMatch:
    node: int | None
    average: tuple[int, ...]
    how: str


@dataclass
class StructureMapping:
    roles: dict[str, RoleMatch]
    up_axis: int                 # 0, 1, 2: the lab axis nearest to up
    up_sign: float
    up_vector: np.ndarray        # (3,) unit: up (the floor's normal when the capture volume is tilted)
    forward: np.ndarray          # (3,) unit, horizontal: where the figure faces (median over the take)
    top: int                     # the node at the top of the head
    feet: tuple[int, ...]        # nodes of both legs from the ankle down (the lowest points of a standing figure)
    notes: list[str] = field(default_factory=list)

    @property
    def up(self) -> np.ndarray:
        return self.up_vector

    def indices(self) -> dict[str, tuple[int, ...]]:
        """{role: nodes to average} (empty tuple: none, the caller extrapolates)."""
        return {r: m.average for r, m in self.roles.items()}

    def describe(self, names) -> dict[str, str]:
        """{role: 'node name (how it was found)'} for reports."""
        out = {}
        for role, m in self.roles.items():
            where = " + ".join(names[i] for i in m.average) if m.average else "-"
            out[role] = f"{where} ({m.how})"
        return out


def map_structure(names, parents, rest, frames=None, end_site=None, armature=False) -> StructureMapping:
    names = [str(n) for n in names]
    parents = np.asarray(parents, dtype=np.int64)
    rest = np.asarray(rest, dtype=np.float64)
    n = len(names)
    if parents.shape != (n,) or rest.shape != (n, 3):
        raise StructureError(f"skeleton arrays disagree: {n} names, parents {parents.shape}, rest {rest.shape}")
    pos = rest[None] if frames is None else np.asarray(frames, dtype=np.float64)
    if pos.ndim != 3 or pos.shape[1:] != (n, 3) or not np.all(np.isfinite(pos)):
        raise StructureError("frames must be finite (F, N, 3) positions of the skeleton's nodes")
    ends = np.zeros(n, dtype=bool) if end_site is None else np.asarray(end_site, dtype=bool)
    return _Mapper(names, parents, pos, ends, armature and frames is None).run()


class _Mapper:
    def __init__(self, names, parents, pos, ends, armature=False):
        self.names, self.parents, self.pos, self.ends = names, parents, pos, ends
        self.armature, self.short = armature, (SHORT_REST if armature else SHORT)
        n = len(names)
        self.kids: list[list[int]] = [[] for _ in range(n)]
        for j, p in enumerate(parents):
            if p >= n or p < -1 or p == j:
                raise StructureError(f"node {names[j]!r} has an invalid parent index {p}")
            if p >= 0:
                self.kids[p].append(j)
        self.order = self._parents_first()
        seg = np.linalg.norm(pos - pos[:, np.maximum(parents, 0)], axis=-1)
        self.seg = np.where(parents >= 0, np.median(seg, axis=0), 0.0)  # length of the segment into each node
        self.size = float(np.median(np.linalg.norm(np.ptp(pos, axis=1), axis=-1)))
        if not self.size > 0:
            raise StructureError("all nodes sit at one point: no figure to map")
        self.reach = np.zeros(n)  # longest path from a node down to a leaf of its subtree
        # ... counting only bones longer than SHORT: a chain of many small face or finger nodes counts little
        self.long = np.where(self.seg >= SHORT * self.size, self.seg, 0.0)
        self.bulk = np.zeros(n)
        for j in self.order[::-1]:
            if self.kids[j]:
                self.reach[j] = max(self.reach[c] + self.seg[c] for c in self.kids[j])
                self.bulk[j] = max(self.bulk[c] + self.long[c] for c in self.kids[j])
        self.notes: list[str] = []
        self._extents: dict[tuple[int, int], float] = {}

    def _parents_first(self) -> list[int]:
        roots = [j for j, p in enumerate(self.parents) if p < 0]
        order, stack = [], list(roots)
        while stack:
            j = stack.pop()
            order.append(j)
            stack.extend(self.kids[j])
        if len(order) != len(self.parents):
            raise StructureError("the hierarchy has a parent cycle")
        return order

    # ------------------------------------------------------------------------------------------ structure

    def _extent(self, j: int, c: int) -> float:
        """How far from j the subtree of its child c reaches (straight line: a winding chain of face or
        finger nodes reaches less far than an arm)."""
        key = (j, c)
        if key not in self._extents:
            sub, stack = [], [c]
            while stack:
                sub.append(stack.pop())
                stack.extend(self.kids[sub[-1]])
            d = np.linalg.norm(self.pos[:, sub] - self.pos[:, j, None], axis=-1)
            self._extents[key] = float(np.median(d, axis=0).max())
        return self._extents[key]

    def _pair(self, j: int, branches: list[int]) -> tuple[int, int]:
        """The left-right pair among j's branches: the longest two whose long bones add up to about the same
        length (a neck with a head may reach further than one arm, but it has no twin)."""
        size = {b: self.bulk[b] + self.long[b] for b in branches}
        pairs = [(a, b) for i, a in enumerate(branches) for b in branches[i + 1:]
                 if max(size[a], size[b]) <= 1.25 * min(size[a], size[b])]
        if not pairs:
            first, second = sorted(branches, key=lambda b: -size[b])[:2]
            return first, second
        return max(pairs, key=lambda p: min(size[p[0]], size[p[1]]))

    def _branches(self, j: int, frac: float) -> list[int]:
        return big_branches(self, j, frac)

    def _descend_to_fork(self, j: int, frac: float, forks: int, long: float = 0.0) -> int | None:
        """Follow single big branches down from j to the first node with `forks` or more big branches, two of
        them reaching at least `long` (a chest: two arms and a neck)."""
        while True:
            big = self._branches(j, frac)
            if len(big) >= forks and (not long or len(self._branches(j, long)) >= 2):
                return j
            if not self.kids[j]:
                return None
            j = max(self.kids[j], key=lambda c: self.reach[c] + self.seg[c])

    def _chain(self, start: int, stop_at: int) -> list[int]:
        """Nodes from `start` down to the leaf at the end of its longest path; `stop_at` is prepended."""
        chain = [stop_at, start]
        while self.kids[chain[-1]]:
            chain.append(max(self.kids[chain[-1]], key=lambda c: self.reach[c] + self.seg[c]))
        return chain

    def _path_up(self, node: int, ancestor: int) -> list[int]:
        path = [node]
        while path[-1] != ancestor:
            path.append(int(self.parents[path[-1]]))
        return path[::-1]

    def _dist(self, a: int, b: int) -> float:
        return float(np.median(np.linalg.norm(self.pos[:, a] - self.pos[:, b], axis=-1)))

    def _bend(self, a: int, b: int, c: int, over=np.min) -> float:
        """Largest angle (degrees) at b between a->b and b->c over the take (`over=np.median`: typical)."""
        u = self.pos[:, b] - self.pos[:, a]
        v = self.pos[:, c] - self.pos[:, b]
        den = np.linalg.norm(u, axis=-1) * np.linalg.norm(v, axis=-1)
        cos = np.einsum("fi,fi->f", u, v) / np.where(den > 0, den, 1.0)
        return float(np.degrees(np.arccos(np.clip(over(cos), -1.0, 1.0))))

    def _joints(self, chain: list[int]) -> list[int]:
        """The chain without zero-length helpers and twist nodes (the chain's first and last node stay)."""
        kept = [chain[0]]
        for i, j in enumerate(chain[1:], start=1):
            last = i == len(chain) - 1
            if self._dist(kept[-1], j) < self.short * self.size:
                if last and len(kept) > 1:
                    continue  # a zero-length end: the chain really ends at the node before
                if not last:
                    continue
            elif i < len(chain) - 2 and len(kept) > 1:  # (a joint before a leaf may sit still: a wrist)
                still = self.pos.shape[0] > 1 and self._bend(kept[-1], j, chain[i + 1]) < STILL_DEG
                if TWIST_NAME.search(self.names[j]) or still:
                    continue
            kept.append(j)
        return kept

    # -------------------------------------------------------------------------------------------- limbs

    def _leg(self, pelvis: int, branch: int) -> dict:
        chain = self._chain(branch, pelvis)
        k = self._joints(chain)
        if len(k) < 4:
            raise StructureError(f"the leg from {self.names[branch]!r} has fewer than three joints")
        hip, knee, ankle = rest_leg(self.pos[0], k) if self.armature else longest_leg(self, k)
        leg = {"Hip": k[hip], "Knee": k[knee], "Ankle": k[ankle], "Foot": k[ankle + 1] if ankle + 1 < len(k) else None}
        leg["feet"] = tuple(j for j in chain[chain.index(leg["Ankle"]):])
        return leg

    def _arm(self, chest: int, branch: int) -> dict:
        chain = self._chain(branch, chest)
        k = self._joints(chain)
        if len(k) < 4:
            raise StructureError(f"the arm from {self.names[branch]!r} has fewer than three joints")
        arm = self._arm_joints(chain, k)
        if self.armature:  # twist nodes inside the chain: proportions choose the shoulder and elbow
            arm["Shoulder"], arm["Elbow"] = (k[i] for i in best_triple(self.pos[0], k, k.index(arm["Wrist"])))
        return arm

    def _arm_joints(self, chain: list[int], k: list[int]) -> dict:
        fan = wrist_fan(self, k)
        if fan is not None:
            w = k.index(fan)
            return {"Shoulder": k[w - 2], "Elbow": k[w - 1], "Wrist": fan,
                    "Hand": self._hand_child(k[w - 1], fan), "hand_how": "base of the longest finger"}
        if k[-1] != chain[-1]:  # the chain's end collapsed onto the last joint: no hand length at all
            return {"Shoulder": k[-3], "Elbow": k[-2], "Wrist": k[-1], "Hand": None,
                    "hand_how": "no hand node: extrapolated along the forearm"}
        s = [self._dist(k[i], k[i + 1]) for i in range(len(k) - 1)]
        # is the last segment a hand (upper arm, forearm, hand) or a forearm (clavicle, upper arm, forearm)?
        hand_fit = abs(np.log(s[-3] / s[-2] / 1.2)) + abs(np.log(s[-1] / s[-2] / 0.45)) if len(s) >= 3 else 0.0
        wrist_fit = abs(np.log(s[-2] / s[-1] / 1.2)) + (abs(np.log(s[-3] / s[-1] / 0.55)) if len(s) >= 3 else 1.0)
        what = "end site" if self.ends[k[-1]] else "last node"
        if len(k) >= 5 and wrist_fit < hand_fit:
            return {"Shoulder": k[-3], "Elbow": k[-2], "Wrist": k[-1], "Hand": None,
                    "hand_how": f"no hand ({what} at the wrist): extrapolated along the forearm"}
        return {"Shoulder": k[-4], "Elbow": k[-3], "Wrist": k[-2], "Hand": k[-1],
                "hand_how": f"{what} after the wrist"}

    def _hand_child(self, elbow: int, wrist: int) -> int:
        """Base of the longest finger (the middle one; ties go to the one reaching furthest along the forearm),
        past zero-length nodes."""
        fore = self.pos[:, wrist] - self.pos[:, elbow]
        fore /= np.maximum(np.linalg.norm(fore, axis=-1, keepdims=True), 1e-12)

        def along(c: int) -> float:
            tip = self._chain(c, wrist)[-1]
            reach = float(np.median(np.einsum("fi,fi->f", self.pos[:, tip] - self.pos[:, wrist], fore)))
            return self.seg[c] + self.reach[c] + 0.1 * reach

        chain = self._chain(max(self.kids[wrist], key=along), wrist)
        return next((j for j in chain[1:] if self._dist(wrist, j) >= FINGER * self.size), chain[-1])

    # --------------------------------------------------------------------------------------------- run

    def run(self) -> StructureMapping:
        roots = [j for j in self.order if self.parents[j] < 0]
        root = max(roots, key=lambda r: self.reach[r])
        pelvis = self._descend_to_fork(root, BIG_BRANCH, 3)
        if pelvis is None:
            raise StructureError("no node where a spine and two legs meet (no pelvis with three large branches)")
        big = self._branches(pelvis, BIG_BRANCH)
        chests = {b: c for b in big if (c := self._descend_to_fork(b, NECK_BRANCH, 3, ARM_BRANCH)) is not None}
        spines = list(chests)   # the branches with a chest, in `big`'s order
        if not spines:
            raise StructureError(f"no chest above {self.names[pelvis]!r}: no node where two arms and a neck meet")
        spine = max(spines, key=lambda b: self._extent(pelvis, b))
        chest = chests[spine]
        legs = [b for b in big if b != spine]
        if len(legs) < 2:
            raise StructureError(f"{self.names[pelvis]!r} has one leg branch; a humanoid needs two")
        legs = list(self._pair(pelvis, legs))
        branches = self._branches(chest, NECK_BRANCH)
        arm_a, arm_b = self._pair(chest, branches)
        neck = max((b for b in branches if b not in (arm_a, arm_b)), key=lambda b: self._extent(chest, b))
        leg_a, leg_b = (self._leg(pelvis, b) for b in legs)
        arm_a, arm_b = self._arm(chest, arm_a), self._arm(chest, arm_b)
        head = [neck]
        for j in head:  # the neck branch's nodes; the top of the head is the one furthest from the chest
            head.extend(self.kids[j])
        top = max(head, key=lambda j: self._dist(chest, j))
        head_chain = self._joints(self._path_up(top, chest))
        est = estimate_up(self.pos, top, (leg_a["feet"], leg_b["feet"]))  # core/floor_plane.py
        up = est.up
        self.notes.append(f"up: {est.how}")
        forward, a_is_left = self._facing(up, leg_a, leg_b, legs)
        if not a_is_left:
            leg_a, leg_b = leg_b, leg_a
        left = np.cross(up, forward)
        side = [float(np.median((self.pos[:, arm["Shoulder"]] - self.pos[:, chest]) @ left)) for arm in (arm_a, arm_b)]
        if side[0] < side[1]:
            arm_a, arm_b = arm_b, arm_a
        roles = self._roles(pelvis, chest, spine, head_chain, top, arm_a, arm_b, leg_a, leg_b)
        roles = kinect_names(self.names, self.ends, roles, self.notes)
        return StructureMapping(roles, est.axis, est.sign, up, forward, top, leg_a["feet"] + leg_b["feet"],
                                self.notes)

    def _facing(self, up: np.ndarray, leg_a: dict, leg_b: dict, legs: list[int]) -> tuple[np.ndarray, bool]:
        """Forward (horizontal unit) and whether leg A is the left one: from the toes, else the knees, else names."""
        def flat(v):
            return v - (v @ up)[..., None] * up

        lateral = flat(self.pos[:, leg_a["Hip"]] - self.pos[:, leg_b["Hip"]])
        f0 = np.cross(lateral, up)  # forward if A is the left leg
        f0 /= np.maximum(np.linalg.norm(f0, axis=-1, keepdims=True), 1e-12)
        def vote(vectors) -> float:  # length-weighted mean cosine with f0; 0 when the vectors vanish
            total = sum(float(np.linalg.norm(v, axis=-1).sum()) for v in vectors)
            if total < SHORT * self.size * 0.3 * sum(len(v) for v in vectors):
                return 0.0
            return sum(float(np.einsum("fi,fi->", v, f0)) for v in vectors) / total

        # a foot in line with the shin (an end site under the ankle) says nothing about facing
        toes = [flat(self.pos[:, leg["Foot"]] - self.pos[:, leg["Ankle"]]) for leg in (leg_a, leg_b)
                if leg["Foot"] is not None and self._bend(leg["Knee"], leg["Ankle"], leg["Foot"], np.median) > 45]
        score, how = (vote(toes) if toes else 0.0), "toes"
        if abs(score) < 0.3:
            knees = [flat(self.pos[:, leg["Knee"]] - (self.pos[:, leg["Hip"]] + self.pos[:, leg["Ankle"]]) / 2)
                     for leg in (leg_a, leg_b)]
            score, how = vote(knees), "knees"
        if abs(score) < 0.15:
            la = (branch_side(self.names, self.kids, self.reach, legs[0])
                  - branch_side(self.names, self.kids, self.reach, legs[1]))
            score, how = (float(np.sign(la)) if la else 1.0), ("joint names" if la else "default (no evidence)")
            self.notes.append(f"left and right decided by {how}: the figure's toes and knees do not tell")
        forward = np.median(f0, axis=0) * np.sign(score)
        forward = flat(forward)
        forward /= max(np.linalg.norm(forward), 1e-12)
        self.notes.append(f"facing from the {how}")
        return forward, score > 0

    def _roles(self, pelvis, chest, spine, head_chain, top, arm_l, arm_r, leg_l, leg_r) -> dict[str, RoleMatch]:
        nm = self.names
        roles = {"HipCenter": RoleMatch(pelvis, (pelvis,), "root of the spine and both legs")}
        inner = self._joints(self._path_up(chest, pelvis))[1:-1]
        if inner:  # the upper spine: its highest joint below the chest, averaged with the chest
            roles["Spine"] = RoleMatch(inner[-1], (inner[-1], chest), f"between the spine joint below the chest "
                                       f"and {nm[chest]}")
        else:
            roles["Spine"] = RoleMatch(None, (pelvis, chest), f"no spine joint: halfway from pelvis to {nm[chest]}")
        roles["ShoulderCenter"] = RoleMatch(chest, (arm_l["Shoulder"], arm_r["Shoulder"]),
                                            f"between the upper-arm heads; the arms leave the spine at {nm[chest]}")
        base = head_base(self, head_chain)
        if base is None:
            base = head_chain[-2] if len(head_chain) >= 3 else top
        roles["Head"] = RoleMatch(base, (base, top) if base != top else (top,),
                                  "between the head joint and the top of the head" if base != top
                                  else "top of the neck")
        for side, arm, leg in (("Left", arm_l, leg_l), ("Right", arm_r, leg_r)):
            for part in ("Shoulder", "Elbow", "Wrist"):
                roles[part + side] = RoleMatch(arm[part], (arm[part],), f"{part.lower()} of the {side.lower()} arm")
            h = arm["Hand"]
            roles["Hand" + side] = RoleMatch(h, (h,) if h is not None else (), arm["hand_how"])
            for part in ("Hip", "Knee", "Ankle"):
                roles[part + side] = RoleMatch(leg[part], (leg[part],), f"{part.lower()} of the {side.lower()} leg")
            f = leg["Foot"]
            how = "no foot node: extrapolated forward from the ankle" if f is None else (
                "end site after the ankle" if self.ends[f] else "toe joint after the ankle")
            roles["Foot" + side] = RoleMatch(f, (f,) if f is not None else (), how)
        return {r: roles[r] for r in ROLES}
