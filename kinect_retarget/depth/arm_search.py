"""Arms fitted against the depth image (analysis by synthesis): the whole arm when its hand is no tracked
extremity (hanging against the body, a hand on the face, folded over the chest), and the elbow of a tracked
hand on its IK circle.

A candidate is the chain shoulder -> elbow -> wrist -> hand with the calibrated bone lengths. Points along
its bones are projected into the person's depth grid, and each scores
- agreement: the observed surface should lie at the bone's front (its depth minus its radius), or in front
  of it (occluded: a small cost); a surface seen well behind it means the arm would have hidden it (free
  space violated: full cost), and so does a point off the person's silhouette;
- explanation: the person's cells that neither the torso, the head nor the legs account for ("arm
  evidence") reward a bone that covers them at the right depth, so an arm is not laid over the chest where
  any pose agrees with the surface.
Upper-arm directions on a sphere are scored first, the best few extended by forearm directions, and the
best chain is refined in a finer cone. Pure numpy; a few thousand point lookups per arm.
"""
from __future__ import annotations

import numpy as np

from ..core.skeletons import INFERRED, KINECT_V1, TRACKED
from . import body_model_fit as bm
from .two_bone import two_bone_candidates

J = {n: i for i, n in enumerate(KINECT_V1.joints)}
SIDES = ("Left", "Right")


def _sphere(n: int) -> np.ndarray:
    """n nearly uniform unit directions (Fibonacci lattice)."""
    i = np.arange(n) + 0.5
    phi = np.arccos(1 - 2 * i / n)
    theta = np.pi * (1 + 5 ** 0.5) * i
    return np.stack([np.cos(theta) * np.sin(phi), np.sin(theta) * np.sin(phi), np.cos(phi)], axis=1)


DIRECTIONS = _sphere(160)          # about 16 degrees apart
REFINE = _sphere(24) * 0.14        # offsets of a refinement cone, about 8 degrees
UPPER_KEEP = 6                     # upper-arm directions carried into the forearm search
FOLD_LIMIT = -0.85                 # cos of the tightest elbow fold allowed between upper arm and forearm
# sample points along each bone (fraction of its length) and the bone's radius (fraction of height)
UPPER_T, UPPER_R = np.array([0.4, 0.6, 0.8, 1.0]), 0.026
FORE_T, FORE_R = np.array([0.2, 0.4, 0.6, 0.8, 1.0]), 0.02
HAND_T, HAND_R = np.array([0.5, 1.0]), 0.015
FREE_SPACE = 0.08      # m: a surface seen this far behind a bone's front is where the bone cannot be
OCCLUDED = 0.06        # m: a surface this far in front of it hides it
OCCLUSION_COST = 0.35  # hidden is possible but explains nothing
COVER_TOL = 0.08       # m: depth agreement for a covered evidence cell
W_COVER = 0.8          # reward per sample on arm evidence, against a cost of 1 for a free-space violation
ON_BODY_COST = 0.2     # a bone on the torso's own surface: an arm lying there would stand out in front of it
W_PREVIOUS = 0.5       # per metre from the previous frame's elbow and hand
MAX_HAND_STEP, W_JUMP = 0.25, 2.0   # m a searched hand moves a sensor frame for free; cost per metre beyond
INSIDE_COST = 2.0      # an elbow or hand inside the torso
TORSO_HALF_WIDTH = 0.1   # fraction of height: the trunk's half width seen from the front
IN_FRONT = 0.06        # m in front of the chest's surface: an arm, not the chest
TORSO_BAND = 0.04      # fraction of height: bands of the trunk whose surface depth is taken apart
# the trunk's surface: bands nearer than the line through all bands are set back to it (see torso())
SURFACE_LINE = True
HEAD_HALF_WIDTH = 0.065  # fraction of height: head and neck, above the shoulder line
LEG_RADIUS = 0.09      # m around the fitted leg bones
ARM_UNSEEN_COST = 0.1      # per-sample search cost above which no arm was seen (hidden: keep the carried pose)
# a searched arm this well explained (per-sample cost) while the chest faces the sensor within this many
# degrees has its seen elbow and wrist reported tracked (chosen on the benchmark's first halves: none of
# the 153 such elbows and 134 wrists there was farther than 12.2 cm from the truth)
SEARCH_TRACKED_COST, SEARCH_TRACKED_TURN_DEG = -0.4, 30.0
ARM_RADIUS = 0.08      # m around an arm already placed: its cells are not the other arm's evidence


def _segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    ab = b - a
    t = np.clip(((p - a) @ ab) / max(ab @ ab, 1e-12), 0.0, 1.0)
    return np.linalg.norm(p - (a + t[..., None] * ab), axis=-1)


class TorsoFrame:
    """The fitted torso's place: centre on the chest's surface, unit axis (up), lat (performer's left),
    facing (toward the sensor), and the heights along the axis of the hips and shoulders."""

    def __init__(self, centre, axis, lat, facing, pos, H):
        self.centre, self.axis, self.lat, self.facing, self.H = centre, axis, lat, facing, H
        self.hip_a = (pos[J["HipCenter"]] - centre) @ axis
        self.shoulder_a = (pos[J["ShoulderCenter"]] - centre) @ axis

    def facing_sensor(self, within_deg: float) -> bool:
        """The chest faces the sensor within this many degrees (about the torso's axis)."""
        toward = -self.centre - (-self.centre @ self.axis) * self.axis
        return bool(self.facing @ toward > np.cos(np.radians(within_deg)) * np.linalg.norm(toward))

    def coords(self, pts):
        rel = pts - self.centre
        return rel @ self.axis, rel @ self.lat, rel @ self.facing

    def torso(self, pts, mask, half_width=TORSO_HALF_WIDTH, front=IN_FRONT):
        """Cells of the trunk: within its width between hips and shoulders, and not standing out in front of
        its surface. The surface's depth is the median of each height band, so a forward lean or a bent
        back does not make the upper chest look like an arm in front of it; but no band is nearer than the
        line through the bands' medians: forearms folded over the chest fill their bands, whose medians
        then lie on the forearms, and the arms went unexplained (on real depth, crossed arms 14.7 -> 11.8
        degrees against the Kinect SDK, docs/depth_tracking.md)."""
        a, l, f = self.coords(pts)
        box = mask & (a > self.hip_a - 0.03 * self.H) & (a < self.shoulder_a + 0.03 * self.H) \
            & (np.abs(l) < half_width * self.H)
        band = np.floor((a - self.hip_a) / (TORSO_BAND * self.H)).astype(np.int64)
        bands, which = np.unique(band[box], return_inverse=True)
        in_box = f[box]
        level = np.array([np.median(in_box[which == k]) for k in range(len(bands))])
        if SURFACE_LINE:
            level = _no_nearer_than_line(bands, level)
        surface = np.zeros_like(f)
        surface[box] = level[which]
        return box & (f < surface + front)

    def inside(self, pts):
        """Points well inside the trunk (behind its front surface, within its width)."""
        a, l, f = self.coords(pts)
        return (a > self.hip_a) & (a < self.shoulder_a) & (np.abs(l) < 0.08 * self.H) & (f < -0.03) & (f > -0.25)


def _no_nearer_than_line(bands: np.ndarray, level: np.ndarray) -> np.ndarray:
    """Band surface depths (`level`, larger = nearer the sensor) no nearer than the robust line through them
    (Theil-Sen over the band indices, so a lean or a bent back still tilts it). Fewer than 4 bands: as given."""
    if len(bands) < 4:
        return level
    i, j = np.triu_indices(len(bands), 1)
    slope = np.median((level[j] - level[i]) / (bands[j] - bands[i]))
    line = np.median(level - slope * bands) + slope * bands
    return np.minimum(level, line)


def arm_evidence(xyz: np.ndarray, mask: np.ndarray, pos: np.ndarray, frame: TorsoFrame,
                 head_region: np.ndarray | None = None) -> np.ndarray:
    """Cells of the person that the torso, head and fitted legs leave unexplained. The head is a box above
    the shoulders, plus `head_region` (the cells near the head along the surface) when the head was found."""
    ev = mask & ~frame.torso(xyz, mask)
    a, l, f = frame.coords(xyz)
    face = (pos[J["Head"]] - frame.centre) @ frame.facing + 0.10   # the head joint sits 10 cm behind the face
    head = (a > frame.shoulder_a - 0.03 * frame.H) & (np.abs(l) < HEAD_HALF_WIDTH * frame.H)
    if head_region is not None:
        head |= head_region
    ev &= ~(head & (f < face + IN_FRONT))   # a hand held in front of the face still counts
    for s in SIDES:
        for top, bottom in (("Hip", "Knee"), ("Knee", "Ankle"), ("Ankle", "Foot")):
            ev &= _segment_distance(xyz, pos[J[f"{top}{s}"]], pos[J[f"{bottom}{s}"]]) > LEG_RADIUS
    return ev


def near_arm(xyz: np.ndarray, pos: np.ndarray, side: str, radius: float = ARM_RADIUS) -> np.ndarray:
    """Cells within `radius` of one arm's bones (shoulder to hand)."""
    near = np.zeros(xyz.shape[:-1], bool)
    for top, bottom in (("Shoulder", "Elbow"), ("Elbow", "Wrist"), ("Wrist", "Hand")):
        near |= _segment_distance(xyz, pos[J[f"{top}{side}"]], pos[J[f"{bottom}{side}"]]) < radius
    return near


class ArmScorer:
    """Per-sample cost of arm bones against one frame's cropped depth grid."""

    def __init__(self, projector, evidence: np.ndarray, frame: TorsoFrame):
        self.p, self.evidence, self.frame = projector, evidence, frame

    def samples(self, pts: np.ndarray, radius: float):
        """(cost, covered) per sample point: the agreement cost, and the evidence cell it covers (-1: none)."""
        p = self.p
        shape = pts.shape[:-1]
        flat = pts.reshape(-1, 3)
        r, c, on = p.cells(flat)
        w = p.mask.shape[1]
        dz = p.xyz[r, c, 2] - (flat[:, 2] - radius)   # > 0: the surface is seen behind the bone's front
        cover = on & self.evidence[r, c] & (np.abs(dz) <= COVER_TOL)
        cost = np.where(~on | (dz > FREE_SPACE), 1.0,
                        np.where(dz < -OCCLUDED, OCCLUSION_COST, np.where(cover, 0.0, ON_BODY_COST)))
        return cost.reshape(shape), np.where(cover, r * w + c, -1).reshape(shape)

    def score(self, bones) -> np.ndarray:
        """Cost of chains given as [(points (..., n, 3), radius)]: agreement summed over the samples, minus a
        reward per distinct evidence cell covered (two bones over one cell explain it once)."""
        costs, cells = zip(*(self.samples(pts, radius) for pts, radius in bones))
        cells = np.sort(np.concatenate(cells, axis=-1), axis=-1)
        distinct = (cells[..., :1] >= 0).astype(np.int64)[..., 0] + np.sum((np.diff(cells, axis=-1) != 0)
                                                                          & (cells[..., 1:] >= 0), axis=-1)
        return sum(c.sum(-1) for c in costs) - W_COVER * distinct


def _chain_cost(scorer, shoulder, u, v, l1, l2, lh, H):
    """Cost of chains (broadcast over u, v): bone samples, plus elbow/hand inside the trunk."""
    elbow = shoulder + l1 * u
    wrist = elbow + l2 * v
    cost = scorer.score([(shoulder[None] + (l1 * u)[..., None, :] * UPPER_T[:, None], UPPER_R * H),
                         (elbow[..., None, :] + (l2 * v)[..., None, :] * FORE_T[:, None], FORE_R * H),
                         (wrist[..., None, :] + (lh * v)[..., None, :] * HAND_T[:, None], HAND_R * H)])
    cost = cost + INSIDE_COST * (scorer.frame.inside(elbow) | scorer.frame.inside(wrist + lh * v))
    return cost, elbow, wrist, wrist + lh * v


def search_arm(scorer: ArmScorer, shoulder, l1, l2, lh, H, prev_elbow=None, prev_hand=None, max_step=None):
    """Best arm chain -> (elbow, wrist, hand, cost per sample). `max_step`: metres the hand may move from
    `prev_hand` before each further metre costs W_JUMP (None: no limit)."""
    n_samples = len(UPPER_T) + len(FORE_T) + len(HAND_T)

    def chains(u, v):
        """Cost of every chain (u, v broadcast), with the previous pose's pull and the fold limit."""
        cost, elbow, wrist, hand = _chain_cost(scorer, shoulder, u, v, l1, l2, lh, H)
        if prev_elbow is not None and prev_hand is not None:
            step = np.linalg.norm(hand - prev_hand, axis=-1)
            cost = cost + W_PREVIOUS * n_samples * (np.linalg.norm(elbow - prev_elbow, axis=-1) + step)
            if max_step is not None:
                cost = cost + W_JUMP * n_samples * np.maximum(0.0, step - max_step)
        return cost + np.where(np.sum(u * v, -1) < FOLD_LIMIT, 10.0, 0.0), elbow, wrist, hand

    up = scorer.score([(shoulder + (l1 * DIRECTIONS)[:, None, :] * UPPER_T[:, None], UPPER_R * H)])
    up = up + INSIDE_COST * scorer.frame.inside(shoulder + l1 * DIRECTIONS)
    if prev_elbow is not None:
        up = up + W_PREVIOUS * n_samples * np.linalg.norm(shoulder + l1 * DIRECTIONS - prev_elbow, axis=-1)
    u = DIRECTIONS[np.argsort(up)[:UPPER_KEEP]]                       # (K, 3)
    v = np.broadcast_to(DIRECTIONS, (len(u),) + DIRECTIONS.shape)      # (K, N, 3)
    cost, *_ = chains(np.broadcast_to(u[:, None, :], v.shape), v)
    k, n = np.unravel_index(int(np.argmin(cost)), cost.shape)
    # refine: every pair of small offsets of both directions
    ru = u[k] + np.vstack([np.zeros(3), REFINE])
    rv = DIRECTIONS[n] + np.vstack([np.zeros(3), REFINE])
    ru /= np.linalg.norm(ru, axis=1, keepdims=True)
    rv /= np.linalg.norm(rv, axis=1, keepdims=True)
    cost, elbow, wrist, hand = chains(*np.broadcast_arrays(ru[:, None, :], rv[None, :, :]))
    i, j = np.unravel_index(int(np.argmin(cost)), cost.shape)
    return elbow[i, j], wrist[i, j], hand[i, j], float(cost[i, j]) / n_samples


def best_elbow(scorer: ArmScorer, shoulder, candidates: np.ndarray, wrist, H, prev_elbow=None):
    """Of the elbows that join a known shoulder and wrist (two-bone IK circle), the one whose bones best
    explain the depth -> (elbow, cost)."""
    t_up, t_fore = UPPER_T[:, None], FORE_T[:, None]
    cost = scorer.score([(shoulder + (candidates - shoulder)[:, None, :] * t_up, UPPER_R * H),
                         (candidates[:, None, :] + (wrist - candidates)[:, None, :] * t_fore, FORE_R * H)])
    cost = cost + INSIDE_COST * scorer.frame.inside(candidates)
    if prev_elbow is not None:
        cost = cost + W_PREVIOUS * (len(UPPER_T) + len(FORE_T)) * np.linalg.norm(candidates - prev_elbow, axis=1)
    i = int(np.argmin(cost))
    return candidates[i], float(cost[i])


def fit_arms(pos, st, xyz, mask, proj, frame: TorsoFrame, H, prev=None, head_region=None,
             settled: bool = False, facing_steady: bool = False, frames_passed: int = 1) -> None:
    """The arms of one fitted frame, in place (`pos`, `st`: the fit's 20 joints and states). A tracked hand
    keeps its wrist and gets the elbow its IK circle's depth backs; an arm whose hand is not a tracked
    extremity gets the pose that best explains the depth, reported inferred. Each arm explains its own
    cells: a tracked arm's are withheld, and when two searched arms claim the same cells the weaker looks
    again without them (a hidden far arm must not borrow the near arm's). Once the tracking has `settled`,
    a searched hand does not jump more than MAX_HAND_STEP a sensor frame for free (a wrong early guess must
    still be free to move; `frames_passed`: the sensor's frames since the last pose). On real depth tracked at
    uneven steps of 2-4 frames, as a slow machine sees it, subjects 3-4's hands and wrists went 9.6 -> 8.7 cm
    with the step per sensor frame instead of per frame tracked. A searched arm explained well enough, of a
    performer who has been facing the sensor (`facing_steady`) and still is, reports its seen elbow and wrist
    tracked."""
    todo = [s for s in SIDES if st[J[f"Hand{s}"]] != TRACKED]
    evidence = arm_evidence(xyz, mask, pos, frame, head_region)
    lengths = (bm.UPPER_ARM * H, bm.FOREARM * H, bm.HAND * H)
    for s in SIDES:   # a tracked hand fixes the wrist; the elbow's place on its circle is the depth's call
        if s in todo:
            continue
        shoulder, wrist = pos[J[f"Shoulder{s}"]], pos[J[f"Wrist{s}"]]
        cands, _ = two_bone_candidates(shoulder, wrist, lengths[0], lengths[1], n=24)
        if len(cands) > 1:
            pos[J[f"Elbow{s}"]], _ = best_elbow(ArmScorer(proj, evidence, frame), shoulder, cands, wrist, H,
                                                None if prev is None else prev[J[f"Elbow{s}"]])
    if not todo:
        return
    for s in SIDES:
        if s not in todo:
            evidence &= ~near_arm(xyz, pos, s)

    def search(s, ev):
        pe, ph = (None, None) if prev is None else (prev[J[f"Elbow{s}"]], prev[J[f"Hand{s}"]])
        return search_arm(ArmScorer(proj, ev, frame), pos[J[f"Shoulder{s}"]], *lengths, H, pe, ph,
                          MAX_HAND_STEP * frames_passed if settled else None)

    found = {s: search(s, evidence) for s in todo}
    if len(todo) == 2:
        first, second = sorted(todo, key=lambda s: found[s][3])
        trial = pos.copy()
        for s in todo:
            trial[J[f"Elbow{s}"]], trial[J[f"Wrist{s}"]], trial[J[f"Hand{s}"]] = found[s][:3]
        taken = evidence & near_arm(xyz, trial, first)
        if np.any(taken & near_arm(xyz, trial, second)):  # both claim the same cells: the weaker looks again
            found[second] = search(second, evidence & ~taken)
    for s in todo:
        e, w, h, cost = found[s]
        if cost > ARM_UNSEEN_COST:
            continue  # nothing in view explains this arm (hidden behind the body): keep the carried guess
        pos[J[f"Elbow{s}"]], pos[J[f"Wrist{s}"]], pos[J[f"Hand{s}"]] = e, w, h
        st[[J[f"Elbow{s}"], J[f"Wrist{s}"], J[f"Hand{s}"]]] = INFERRED
        # a well-explained arm of a settled performer facing the sensor: its elbow (and wrist), where the
        # surface is seen at their pixels, are as good as the tracked ones (the hand's tip is not)
        if facing_steady and frame.facing_sensor(SEARCH_TRACKED_TURN_DEG) and cost < SEARCH_TRACKED_COST \
                and proj.supported(e, bm.DEPTH_INSIDE["Elbow"] - 0.02):
            st[J[f"Elbow{s}"]] = TRACKED
            if proj.supported(w, bm.DEPTH_INSIDE["Wrist"] - 0.02):
                st[J[f"Wrist{s}"]] = TRACKED


def hands_at_tracked_wrists(pos: np.ndarray, st: np.ndarray, proj,
                            backed: np.ndarray | None = None) -> np.ndarray:
    """(20,) bool: hands to report tracked because their elbow and wrist are, and the surface is seen where
    the hand is (as the SDK reports a hand that hangs off a tracked wrist); only `backed` hands where given
    ((20,) bool: evidence of their own, part_fit.hands_backed). On real depth (all 216 UTD-MHAD sequences)
    the hands this reports tracked lay 5.5 cm from the SDK's (subjects 1-2, trial 1: 7.1), about as
    near as the tracked wrists."""
    out = np.zeros(20, bool)
    for s in SIDES:
        h = J[f"Hand{s}"]
        if backed is not None and not backed[h]:
            continue
        if st[h] != TRACKED and st[J[f"Elbow{s}"]] == TRACKED and st[J[f"Wrist{s}"]] == TRACKED:
            out[h] = proj.supported(pos[h], bm.DEPTH_INSIDE["Hand"] - 0.02)
    return out
