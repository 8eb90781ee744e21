"""One limb of the fitted skeleton (depth/skeleton_fit.py fits the torso and calls this per limb and side):
the end and tip from level-set centroids near the limb's extremity (or, with none, a hanging arm found in the
depth or the last frame's limb carried along), then the middle joint (elbow, knee) on the two-bone IK circle,
chosen against the depth, the level-set centroid, the previous frame and the body's sides."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.skeletons import INFERRED, NOT_TRACKED, TRACKED
from . import body_model_fit as bm
from .arm_search import J
from .limb_ends import at_image_border, occluded_end
from .surface_geodesic import SurfaceGraph, level_set_centroid
from .two_bone import two_bone_candidates
from .two_bone import unit as _unit

# weights of the elbow/knee choice on the IK circle (per metre): level-set centroid, previous frame
W_LEVEL_SET, W_PREVIOUS = 1.0, 0.3
TRUNCATED_EXTEND = 0.5      # a limb leaving the image continues this fraction of its remaining reach
W_MIDLINE = 1.0             # per metre a knee lies across the body's midline
REACH_SLACK = 0.10          # m an extremity may lie beyond the limb's calibrated reach and still be its end


@dataclass
class LimbScene:
    """What every limb of one frame shares: the person's crop of the depth grid, its surface graph, the torso
    frame, the previous output, and the joints and states being filled in."""
    grid: object
    r0: int
    c0: int
    xyz: np.ndarray
    mask: np.ndarray
    graph: SurfaceGraph
    proj: object                 # skeleton_fit.Projector
    d0: np.ndarray               # geodesic distance from the torso seed
    centre: np.ndarray
    axis: np.ndarray
    lat: np.ndarray
    facing: np.ndarray
    view: np.ndarray
    H: float
    prev: np.ndarray | None
    prev_states: np.ndarray | None
    pos: np.ndarray              # (20, 3), filled in
    st: np.ndarray               # (20,), filled in
    labels: list
    cell: float                  # metres per grid cell

    def band(self, w: float) -> float:
        return max(w, 1.5 * self.cell)

    def inside(self, name: str) -> np.ndarray:
        return self.view * bm.DEPTH_INSIDE[name]


def _nearest_cell(xyz: np.ndarray, mask: np.ndarray, p: np.ndarray) -> tuple[int, int] | None:
    if not mask.any():
        return None
    d = np.where(mask, np.linalg.norm(xyz[..., :2] - p[:2], axis=-1) + 0.3 * np.abs(xyz[..., 2] - p[2]), np.inf)
    k = int(np.argmin(d))
    return divmod(k, mask.shape[1])


def fit_limb(sc: LimbScene, root: str, mid: str, end: str, tip: str, r1: float, r2: float, d_tip: float,
             d_end: float, s: str, e) -> bool:
    """Fit one limb (`root` Shoulder or Hip, side `s`) from its extremity `e` (or None) into sc.pos/sc.st;
    True when it is a leg leaving the image."""
    leg_clipped = False
    a = sc.pos[J[f"{root}{s}"]]
    l1, l2 = r1 * sc.H, r2 * sc.H
    if (e is not None and sc.prev is not None and sc.prev_states is not None
            and sc.prev_states[J[f"{tip}{s}"]] == TRACKED and np.linalg.norm(e[1] - sc.prev[J[f"{tip}{s}"]]) > 0.45):
        e = None  # a hand or foot does not jump 45 cm in one frame: another body part's extremity
    if e is not None and root == "Shoulder" and \
            np.linalg.norm(e[1] - a) > 1.2 * (l1 + l2 + bm.HAND * sc.H):
        e = None  # out of the arm's reach: a knee or foot taken for a hand
    if e is not None and root == "Shoulder" and (1.0 if s == "Left" else -1.0) * e[4] < -0.1 * sc.H \
            and not (sc.prev is not None and np.linalg.norm(e[1] - sc.prev[J[f"{tip}{s}"]]) < 0.15):
        e = None  # out beyond the other shoulder and not followed there: the other side's part

    def without_extremity():
        """(end, tip, mid level-set) when no extremity stands for this limb: a hanging arm found in
        the depth, else the previous frame's limb carried along."""
        found_arm = _hanging_arm(sc.xyz, sc.mask, a, sc.axis, sc.lat, 1.0 if s == "Left" else -1.0, sc.centre, sc.H) \
            if root == "Shoulder" else None
        if found_arm is None:
            return _carry(sc.prev, s, end, tip, a, sc.axis, sc.pos, root)
        toward = _unit(a - found_arm)
        tip_p = found_arm + toward * 0.07 + sc.inside(tip)
        return tip_p + toward * bm.HAND * sc.H, tip_p, None

    if e is not None:
        de = sc.graph.distances(np.array([e[0]]), iterations=4)
        tip_p = level_set_centroid(sc.xyz, de, d_tip, sc.band(0.05), e[1], 0.2)
        end_p = level_set_centroid(sc.xyz, de, d_end, sc.band(0.05), e[1], 0.3)
        tip_p = (e[1] if tip_p is None else tip_p) + sc.inside(tip)
        end_p = (tip_p if end_p is None else end_p + sc.inside(end))
        mid_ls = level_set_centroid(sc.xyz, de, d_end + l2, sc.band(0.06), end_p, l2 + 0.1)
        sc.labels.append((f"{tip}{s}", e[1]))
        clipped = at_image_border(sc.grid, (sc.r0 + e[0][0], sc.c0 + e[0][1]))
        leg_clipped = clipped and root == "Hip"
        truncated = clipped or occluded_end(sc.xyz, sc.mask, e[0])
        if truncated:  # the limb leaves the image or goes behind the body: its extremity is where the
            # view ends, not where the limb does
            reach_left = max(0.0, l1 + l2 - np.linalg.norm(end_p - a))
            out = _unit(e[1] - a) * TRUNCATED_EXTEND * reach_left
            end_p, tip_p = end_p + out, tip_p + out
        # a true hand/foot lies a limb's length along the surface beyond its shoulder/hip; an
        # elbow sticking out (hand on the face) or a knee is nearer: keep the guess, flag it
        root_cell = _nearest_cell(sc.xyz, sc.mask, a)
        along_limb = e[2] - (sc.d0[root_cell] if root_cell is not None and np.isfinite(sc.d0[root_cell]) else 0.0)
        st_limb = TRACKED if along_limb > 0.7 * (l1 + l2) and not truncated else INFERRED
        if st_limb == INFERRED and root == "Shoulder":
            # not a hand (an elbow, a shoulder): look for the arm as if no extremity was found
            end_p, tip_p, mid_ls = without_extremity()
    else:
        end_p, tip_p, mid_ls = without_extremity()
        st_limb = INFERRED
    cands, end_p2 = two_bone_candidates(a, end_p, l1, l2)
    cost = sc.proj.cost(cands, bm.DEPTH_INSIDE[mid])
    if mid_ls is not None:
        cost = cost + W_LEVEL_SET * np.linalg.norm(cands - (mid_ls + sc.inside(mid)), axis=1)
    if sc.prev is not None and sc.prev_states is not None and sc.prev_states[J[f"{mid}{s}"]] != NOT_TRACKED:
        cost = cost + W_PREVIOUS * np.linalg.norm(cands - sc.prev[J[f"{mid}{s}"]], axis=1)
    else:  # no history: elbows bend backwards/outwards, knees forwards
        pref = -sc.view if root == "Hip" else (sc.view + sc.lat * (1 if s == "Left" else -1))
        cost = cost - 0.02 * ((cands - a) @ _unit(pref))
    if root == "Hip":  # knees only ever bend forwards: keep them off the back of the circle
        cost = cost + 0.3 * np.maximum(0.0, -((cands - (a + end_p2) / 2) @ sc.facing))
        # and stay on their own side of the body (a knee across the midline is the other leg's)
        cost = cost + W_MIDLINE * np.maximum(0.0, -(1.0 if s == "Left" else -1.0) * ((cands - sc.centre) @ sc.lat))
    m = cands[int(np.argmin(cost))]
    sc.pos[J[f"{mid}{s}"]] = m
    reach_shift = end_p2 - end_p  # keep the hand/foot attached when the end was pulled into reach
    sc.pos[J[f"{end}{s}"]] = end_p2
    sc.pos[J[f"{tip}{s}"]] = tip_p + reach_shift
    if np.linalg.norm(reach_shift) > REACH_SLACK:
        st_limb = INFERRED  # the extremity is out of this limb's reach: not its hand/foot, or a bad root
    mid_ok = st_limb == TRACKED and sc.proj.supported(m, bm.DEPTH_INSIDE[mid] - 0.02)
    sc.st[J[f"{mid}{s}"]] = TRACKED if mid_ok else INFERRED
    sc.st[J[f"{end}{s}"]] = sc.st[J[f"{tip}{s}"]] = st_limb
    return leg_clipped


def _hanging_arm(xyz, mask, shoulder, axis, lat, sign, centre, H):
    """Hand of an arm hanging beside the body (touching it, so no geodesic extremity): the point on that
    side, outside the torso's width and within reach, farthest below the shoulder."""
    pts = xyz[mask]
    rel = pts - centre
    side = (rel @ lat) * sign
    below = (shoulder - pts) @ axis
    reach = np.linalg.norm(pts - shoulder, axis=1)
    ok = (side > 0.1 * H) & (below > 0.1 * H) & (reach < (bm.UPPER_ARM + bm.FOREARM + bm.HAND) * H + 0.05)
    if ok.sum() < 5:
        return None
    far = np.argsort(-below[ok])[:5]   # a few lowest points: the finger tips
    tip = pts[ok][far].mean(axis=0)
    return tip


def _carry(prev, s, end, tip, root_pos, axis, pos, root):
    """A limb with no extremity found: its previous pose moved with the torso, or hanging straight."""
    if prev is not None:
        delta = root_pos - prev[J[f"{root}{s}"]]
        return prev[J[f"{end}{s}"]] + delta, prev[J[f"{tip}{s}"]] + delta, None
    if root == "Shoulder":
        e = root_pos - axis * 0.26
        return e, e - axis * 0.08, None
    e = root_pos - axis * 0.46
    return e, e - axis * 0.04 + _unit(-root_pos) * 0.08, None
