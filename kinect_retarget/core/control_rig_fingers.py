"""Finger chains of a control rig's hand found by structure (issue 16), for a rig whose finger bones no name
table knows (a renamed Rigify rig): the chains ending in the leaf bones under the deform bone that spans the
mapped hand control (the deform tree of control_rig_mapping.py), each bone then replaced by the
custom-shaped control spanning it. The thumb is the chain starting nearest the
wrist; index to pinky follow across the knuckles from the thumb's side. Pure numpy."""
from __future__ import annotations

import numpy as np

from .control_rig_mapping import COINCIDE, RigLinks, deform_parents, is_control_rig, near

FINGER_BONES = 3   # bones per finger chain (hand_pose bends the first and curls all three)


def _chains(tree: dict[int, int], hand: int) -> list[list[int]] | None:
    """Chains base to tip ending in the leaves under `hand`: up to FINGER_BONES bones each, stopping below a
    bone with more than one child (a palm bone carrying two fingers) or at the hand."""
    kids: dict[int, list[int]] = {}
    for b, p in tree.items():
        kids.setdefault(p, []).append(b)
    below, todo = [], list(kids.get(hand, ()))
    while todo:
        b = todo.pop()
        below.append(b)
        todo.extend(kids.get(b, ()))
    chains = []
    for tip in (b for b in below if b not in kids):
        chain = [tip]
        while len(chain) < FINGER_BONES and tree[chain[-1]] != hand and len(kids[tree[chain[-1]]]) == 1:
            chain.append(tree[chain[-1]])
        chains.append(chain[::-1])
    return chains if len(chains) == 5 and all(len(c) == FINGER_BONES for c in chains) else None


def finger_chains_by_structure(parents, heads, tails, links: RigLinks | None, hand: int) -> \
        dict[str, list[int]] | None:
    """{finger: control bone indices base to tip} of the control rig's hand control `hand`; None on other
    rigs, or when the hand has no five finger chains of three bones each with a control."""
    parents = np.asarray(parents, dtype=np.int64)
    heads, tails = np.asarray(heads, float), np.asarray(tails, float)
    tol = COINCIDE * float(np.linalg.norm(np.ptp(np.concatenate([heads, tails]), axis=0)))
    if links is None or not is_control_rig(parents, links):
        return None   # other rigs' fingers are found by name (hand_pose.FINGER_NAMES)
    tree = deform_parents(parents, heads, tails, links, tol)
    twin = [d for d in tree if near(heads[d], heads[hand], tol) and near(tails[d], tails[hand], tol)]
    if not twin:
        return None
    root = twin[0]
    chains = _chains(tree, root)
    if chains is None:
        return None
    wrist = heads[root]
    chains.sort(key=lambda c: float(np.linalg.norm(heads[c[0]] - wrist)))
    thumb, four = chains[0], chains[1:]
    bases = heads[[c[0] for c in four]]
    across = np.linalg.svd(bases - bases.mean(axis=0))[2][0]   # the line of the knuckles
    if across @ (bases.mean(axis=0) - heads[thumb[0]]) < 0:
        across = -across
    four.sort(key=lambda c: float(heads[c[0]] @ across))
    out = dict(zip(("thumb", "index", "middle", "ring", "pinky"), [thumb] + four))
    controls = np.flatnonzero(links.shaped & ~links.deform)
    spans = {}
    for chain in out.values():
        for d in chain:
            at = controls[near(heads[controls], heads[d], tol) & near(tails[controls], tails[d], tol)]
            if not len(at):
                return None
            spans[d] = int(at[0])
    return {finger: [spans[d] for d in chain] for finger, chain in out.items()}
