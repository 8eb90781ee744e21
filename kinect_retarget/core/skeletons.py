"""Joint sets of the Kinect SDKs: names, parents and the left/right pairing.

A skeleton here is the *source* side of retargeting: joints measured as positions. Parents follow the SDKs'
own bone lists (Kinect v2: the thumb hangs from the wrist, the hand tip from the hand).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

# Tracking states, as both SDKs report them.
NOT_TRACKED, INFERRED, TRACKED = 0, 1, 2


@dataclass(frozen=True)
class Skeleton:
    """A named joint set. `parents[j]` is the index of joint j's parent, -1 for the root."""

    name: str
    joints: tuple[str, ...]
    parents: tuple[int, ...]

    def __post_init__(self) -> None:
        if len(self.joints) != len(self.parents):
            raise ValueError(f"skeleton {self.name}: {len(self.joints)} joints but {len(self.parents)} parents")
        if self.parents.count(-1) != 1:
            raise ValueError(f"skeleton {self.name}: exactly one root joint expected")
        for j in range(len(self.parents)):  # every chain must reach the root: no cycles
            seen, k = 0, j
            while k != -1:
                k, seen = self.parents[k], seen + 1
                if seen > len(self.parents):
                    raise ValueError(f"skeleton {self.name}: parent cycle through {self.joints[j]}")

    def __len__(self) -> int:
        return len(self.joints)

    def index(self, joint: str) -> int:
        return self.joints.index(joint)

    @cached_property
    def parent_array(self) -> np.ndarray:
        return np.asarray(self.parents, dtype=np.int64)

    @cached_property
    def children(self) -> tuple[tuple[int, ...], ...]:
        kids: list[list[int]] = [[] for _ in self.joints]
        for j, p in enumerate(self.parents):
            if p >= 0:
                kids[p].append(j)
        return tuple(tuple(k) for k in kids)

    @cached_property
    def mirror(self) -> np.ndarray:
        """Index of each joint's left/right counterpart (itself for centre joints)."""
        out = np.arange(len(self.joints))
        for j, name in enumerate(self.joints):
            for a, b in (("Left", "Right"), ("Right", "Left")):
                if a in name and name.replace(a, b) in self.joints:
                    out[j] = self.joints.index(name.replace(a, b))
        return out

    @property
    def root(self) -> int:
        return self.parents.index(-1)


def _build(name: str, table: list[tuple[str, str | None]]) -> Skeleton:
    names = tuple(n for n, _ in table)
    parents = tuple(-1 if p is None else names.index(p) for _, p in table)
    return Skeleton(name, names, parents)


KINECT_V1 = _build("kinect_v1", [
    ("HipCenter", None), ("Spine", "HipCenter"), ("ShoulderCenter", "Spine"), ("Head", "ShoulderCenter"),
    ("ShoulderLeft", "ShoulderCenter"), ("ElbowLeft", "ShoulderLeft"), ("WristLeft", "ElbowLeft"),
    ("HandLeft", "WristLeft"),
    ("ShoulderRight", "ShoulderCenter"), ("ElbowRight", "ShoulderRight"), ("WristRight", "ElbowRight"),
    ("HandRight", "WristRight"),
    ("HipLeft", "HipCenter"), ("KneeLeft", "HipLeft"), ("AnkleLeft", "KneeLeft"), ("FootLeft", "AnkleLeft"),
    ("HipRight", "HipCenter"), ("KneeRight", "HipRight"), ("AnkleRight", "KneeRight"),
    ("FootRight", "AnkleRight"),
])

# Kinect v2 in SDK order (0..24); in the SDK's bone list SpineShoulder (20) sits between SpineMid and Neck.
_V2_ORDER = [
    ("SpineBase", None), ("SpineMid", "SpineBase"), ("Neck", "SpineShoulder"), ("Head", "Neck"),
    ("ShoulderLeft", "SpineShoulder"), ("ElbowLeft", "ShoulderLeft"), ("WristLeft", "ElbowLeft"),
    ("HandLeft", "WristLeft"),
    ("ShoulderRight", "SpineShoulder"), ("ElbowRight", "ShoulderRight"), ("WristRight", "ElbowRight"),
    ("HandRight", "WristRight"),
    ("HipLeft", "SpineBase"), ("KneeLeft", "HipLeft"), ("AnkleLeft", "KneeLeft"), ("FootLeft", "AnkleLeft"),
    ("HipRight", "SpineBase"), ("KneeRight", "HipRight"), ("AnkleRight", "KneeRight"),
    ("FootRight", "AnkleRight"),
    ("SpineShoulder", "SpineMid"), ("HandTipLeft", "HandLeft"), ("ThumbLeft", "WristLeft"),
    ("HandTipRight", "HandRight"), ("ThumbRight", "WristRight"),
]


# SDK indices are kept, so a parent may come after its child (SpineShoulder is 20): use topological_order().
KINECT_V2 = _build("kinect_v2", _V2_ORDER)

SKELETONS = {s.name: s for s in (KINECT_V1, KINECT_V2)}

# Kinect v2 joints that have a Kinect v1 counterpart (v1 name -> v2 name).
V1_FROM_V2 = {
    "HipCenter": "SpineBase", "Spine": "SpineMid", "ShoulderCenter": "SpineShoulder", "Head": "Head",
    **{f"{part}{side}": f"{part}{side}" for side in ("Left", "Right")
       for part in ("Shoulder", "Elbow", "Wrist", "Hand", "Hip", "Knee", "Ankle", "Foot")},
}


def topological_order(sk: Skeleton) -> np.ndarray:
    """Joint indices with every parent before its children."""
    order: list[int] = []
    stack = [sk.root]
    while stack:
        j = stack.pop()
        order.append(j)
        stack.extend(reversed(sk.children[j]))
    return np.asarray(order, dtype=np.int64)
