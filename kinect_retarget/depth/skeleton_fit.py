"""Fit the 20-joint Kinect v1 skeleton to one segmented person (numpy only).

Per frame: a torso patch (geodesic disc around where the forest sees the torso, else the last spine) gives
the torso frame, the line between the forest's shoulder parts or upper torso quarters (part_lines; else the
chest's surface normals, facing.py) its facing; geodesic extrema give head, hand and foot candidates;
level-set centroids (paper 003) near each extremity give hand/wrist and foot/ankle; elbows and knees come
from two-bone inverse kinematics with the calibrated bone lengths, choosing on the IK circle the point that
best agrees with the depth image (projective check), the level-set centroid and the previous frame. An
extremity at the image's edge or beside a nearer surface is where the view of the limb ends (limb_ends).
Arms are then fitted against the depth (arm_search): the elbow of a tracked hand, and the whole of an arm
whose hand is not a tracked extremity.
Legs without evidence keep their previous pose relative to the torso; both are reported inferred.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.skeletons import INFERRED, TRACKED
from . import body_model_fit as bm
from .arm_search import SIDES, J, TorsoFrame, fit_arms
from .facing import chest_facing
from .limb_fit import LimbScene, _nearest_cell, fit_limb
from .part_fit import USE_CONFIDENCE, shoulders_on_parts
from .part_lines import (LINE_AGREE_DEG, NORMALS_AGREE_DEG, checked_by_torso, line_facing, shoulder_line,
                         torso_line)
from .part_proposals import torso_seen
from .sides import assign_sides
from .surface_geodesic import SurfaceGraph, geodesic_extrema, level_set_centroid
from .two_bone import unit as _unit

HEAD_AXIS_WEIGHT = 0.65      # torso axis pulled this far toward the line from the torso patch to the head top
MAX_SIDE_LEAN_DEG = 20.0    # sideways component of a lean beyond which the "head" is not trusted to tilt
HEAD_PART_NEAR = 0.25       # m: a head extremity farther than this from a confident head part is a raised hand
# m up its axis the torso may move to a head top so confirmed (15-25 cm up it was as often hands held at
# the head, a basketball shot, as a torso left behind)
FAR_HEAD_SHIFT, MAX_HEAD_SHIFT = 0.25, 0.6
MAX_LEAN_DEG = 60.0         # a "head" farther than this from upright is taken for something else
AXIS_GRAVITY_WEIGHT = 0.75  # torso axis = this blend of gravity's up and the torso patch's long axis
SIDE_ON_WIDTH = 0.165       # visible chest width / height below which the torso is taken as seen side-on
HEAD_REGION = 0.12          # fraction of height along the surface from the head's extremum: head and neck
SHOULDERS_ON_PARTS = True   # the limbs fitted from the shoulders' confident body parts, when there are proposals
ARM_SEARCH = True           # arms without a hand extremity: search poses against the depth (arm_search)
BEHIND_FREE, BEHIND_COST = 0.06, 0.5   # m behind the surface a joint may sit for free; cost per metre beyond
SUPPORT_BEHIND = 0.08       # m behind the surface seen at its pixel an elbow/knee may sit and still be tracked
TURNED_DEG = 45.0           # facing estimate turned this far: shoulders and hips overlap in depth, inferred
SIDE_ON_DEG = 75.0          # chest facing this far from the sensor: side-on, the last facing is kept
TURN_JUMP_FROM_DEG = 15.0   # facing the sensor within this, a turn of ...
TURN_JUMP_DEG = 25.0        # ... more than this in one frame is not believed ...
TURN_CREEP_DEG = 3.0        # ... and the left-right direction turns toward it by this much a frame
LATERAL_SMOOTHING = 0.25    # weight of the last frame's left-right direction (0.5 before the shoulder line)


@dataclass
class FitResult:
    positions: np.ndarray
    states: np.ndarray
    lateral: np.ndarray
    extrema: list = field(default_factory=list)   # [(label, xyz)] for previews and tests
    torso_centre: np.ndarray | None = None
    projector: "Projector | None" = None          # for the confidence checks after the fit
    edge_on: bool = False                          # the chest's normal was unusable (seen side-on)
    turned: bool = False                           # facing more than TURNED_DEG away from the sensor
    axis: np.ndarray | None = None                 # the torso's up axis (with `lateral`, the body's frame)
    patch_centre: np.ndarray | None = None         # the torso patch's median before the head top pinned it


class Projector:
    """Projective agreement between 3D joint hypotheses and the cropped depth surface."""

    def __init__(self, grid, origin, xyz, mask):
        self.grid, self.r0, self.c0, self.xyz, self.mask = grid, origin[0], origin[1], xyz, mask

    def cells(self, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(row, col, on) of each (N, 3) point in the cropped grid: its cell (clipped into the crop) and
        whether that cell is inside the crop and on the person."""
        rc = np.round(self.grid.to_pixel(pts) - [self.r0, self.c0]).astype(np.int64)
        h, w = self.mask.shape
        ok = (rc[:, 0] >= 0) & (rc[:, 0] < h) & (rc[:, 1] >= 0) & (rc[:, 1] < w)
        r = np.clip(rc[:, 0], 0, h - 1)
        c = np.clip(rc[:, 1], 0, w - 1)
        return r, c, ok & self.mask[r, c]

    def depth_offset(self, pts: np.ndarray, inside) -> tuple[np.ndarray, np.ndarray]:
        """(dz, on): how far each point lies behind the surface seen at its pixel, less `inside` (the joint's
        depth below the skin), and whether that pixel is on the person."""
        r, c, on = self.cells(pts)
        return pts[:, 2] - (self.xyz[r, c, 2] + inside), on

    def cost(self, pts: np.ndarray, inside) -> np.ndarray:
        dz, on = self.depth_offset(pts, inside)
        # in front of the surface: impossible; well behind it: only if something nearer hides it (mild cost)
        behind = np.clip(BEHIND_COST * (dz - BEHIND_FREE), 0.0, 0.08)
        return np.where(on, np.where(dz < -0.04, -dz, behind), 0.25)

    def supported(self, p: np.ndarray, inside: float) -> bool:
        """On the person, and at the surface seen there (not in front of it, not hidden well behind it)."""
        dz, on = self.depth_offset(p[None], inside)
        return bool(on[0] and -0.04 <= dz[0] <= SUPPORT_BEHIND)


def fit_person(grid, mask_full, up, calib, prev: np.ndarray | None, prev_states: np.ndarray | None,
               prev_lateral: np.ndarray | None, prev_centre: np.ndarray | None = None,
               predicted: np.ndarray | None = None, settled: bool = False,
               facing_steady: bool = False, proposals=None,
               frames_passed: int = 1) -> FitResult | None:
    """One frame's skeleton for the segmented person. `prev`/`prev_states`/`prev_lateral`: the last output;
    `predicted`: where the motion so far says the joints are now (continuity for left/right labels);
    `settled`: the person has been tracked past the first frames (their pose is no longer a first guess);
    `facing_steady`: and has faced the sensor for those frames (no turn's mirror image left in the history);
    `proposals`: the frame's body-part proposals (part_proposals.propose), whose confident shoulders the limbs
    are fitted from; `frames_passed`: the sensor's frames since the last output (a tracker slower than the
    sensor skips some)."""
    rows, cols = np.nonzero(mask_full)
    r0, r1, c0, c1 = rows.min(), rows.max() + 1, cols.min(), cols.max() + 1
    # the person's bounding box of the tracker's grid (no coarser: coarser cells merge arms with the body)
    xyz = grid.xyz[r0:r1, c0:c1]
    mask = mask_full[r0:r1, c0:c1]
    cell = float(np.median(xyz[mask][:, 2])) * grid.step / grid.camera.f   # metres per cell
    band = lambda w: max(w, 1.5 * cell)
    graph = SurfaceGraph(xyz, mask, max_jump=0.06)
    proj = Projector(grid, (r0, c0), xyz, mask)
    H = calib.height
    # the torso's disc grows from where the forest sees the torso now, else from where it was (after a deep
    # bend the last place is the trunk's lower half, from which the disc did not climb back up)
    seen = None if proposals is None else torso_seen(proposals)
    torso = _torso_frame(grid, mask_full, xyz, mask, graph, up, calib, prev_lateral,
                         prev_centre if seen is None else seen, shoulder_line(proposals),
                         torso_line(proposals))
    if torso is None:
        return None
    d0, loose, centre, axis, lat, facing, view, edge_on, narrow = torso
    inside = lambda name: view * bm.DEPTH_INSIDE[name]
    # --- extremities ---------------------------------------------------------------------------------
    extrema = geodesic_extrema(loose, d0, count=6, min_distance=0.15 * H, iterations=4)
    cand = []
    for r, c, dist in extrema:
        p = xyz[r, c]
        cand.append(((r, c), p, dist, (p - centre) @ axis, (p - centre) @ lat))
    head_part = confident_head_part(proposals)
    patch_centre = centre.copy()   # what the calibration measures (the pinned torso sits where the head says)
    head, shift, centre, axis, lat, facing = _pin_along_axis(xyz, mask, cand, centre, axis, lat, facing, up, calib,
                                                             head_part)

    def along(h_frac: float) -> np.ndarray:
        return centre + axis * (h_frac - calib.torso_patch_height) * H

    pos = np.zeros((20, 3))
    st = np.full(20, INFERRED, np.uint8)
    for name, hf in (("HipCenter", bm.HEIGHT_HIP_CENTER), ("Spine", bm.HEIGHT_SPINE),
                     ("ShoulderCenter", bm.HEIGHT_SHOULDER_CENTER)):
        pos[J[name]] = along(hf) + inside(name)
        st[J[name]] = TRACKED
    rest = [e for e in cand if e is not head]
    feet = sorted([e for e in rest if e[3] < -0.33 * H], key=lambda e: -e[2])[:2]
    hands = sorted([e for e in rest if e not in feet and e[3] > -0.35 * H and e[2] > 0.22 * H],
                   key=lambda e: -e[2])[:2]
    labels = []
    head_region = None
    if head is not None:
        dh = graph.distances(np.array([head[0]]), iterations=3)
        head_region = dh < HEAD_REGION * H
        hc = level_set_centroid(xyz, dh, 0.06 * H, band(0.04), head[1], 0.2)
        pos[J["Head"]] = (hc if hc is not None else head[1] - axis * 0.05 * H) + inside("Head")
        st[J["Head"]] = TRACKED
        labels.append(("head", head[1]))
    else:
        pos[J["Head"]] = pos[J["ShoulderCenter"]] + axis * (bm.HEIGHT_HEAD - bm.HEIGHT_SHOULDER_CENTER) * H
    sc, hc_ = pos[J["ShoulderCenter"]], pos[J["HipCenter"]]
    for s, sign in (("Left", 1.0), ("Right", -1.0)):
        pos[J[f"Shoulder{s}"]] = sc + lat * sign * bm.SHOULDER_HALF_WIDTH * H - axis * bm.SHOULDER_DROP * H
        pos[J[f"Hip{s}"]] = hc_ + lat * sign * bm.HIP_HALF_WIDTH * H
        st[J[f"Shoulder{s}"]] = st[J[f"Hip{s}"]] = TRACKED
    turned = bool(facing @ -view < np.cos(np.radians(TURNED_DEG)))
    # once a height is measured (before that the bones have a default body's lengths, and an arm of those
    # lengths hung from the shoulder's part misses its hand; the body model's shoulder is scaled alike), and
    # for a chest seen from the front (turned, the forest confuses the sides)
    if SHOULDERS_ON_PARTS and proposals is not None and calib.frames and not (turned or edge_on or narrow):
        shoulders_on_parts(pos, st, proposals, lat, axis, grid.in_view(pos))
    # --- limbs ---------------------------------------------------------------------------------------
    limb_specs = (("Shoulder", "Elbow", "Wrist", "Hand", bm.UPPER_ARM, bm.FOREARM, hands, 0.08, 0.08 + bm.HAND * H),
                  ("Hip", "Knee", "Ankle", "Foot", bm.THIGH, bm.SHIN, feet, 0.07, 0.15))
    legs_clipped = 0
    scene = LimbScene(grid, r0, c0, xyz, mask, graph, proj, d0, centre, axis, lat, facing, view, H, prev,
                      prev_states, pos, st, labels, cell)
    for root, mid, end, tip, r1, r2, found, d_tip, d_end in limb_specs:
        assign = assign_sides(found, prev if predicted is None else predicted, prev_states, tip)
        for s in SIDES:
            legs_clipped += fit_limb(scene, root, mid, end, tip, r1, r2, d_tip, d_end, s, assign.get(s))
    if ARM_SEARCH:
        fit_arms(pos, st, xyz, mask, proj, TorsoFrame(centre, axis, lat, facing, pos, H), H, prev, head_region,
                 settled, facing_steady, frames_passed)
    # without the head top or the shoulders the torso's place along its axis is a guess; seen more than
    # TURNED_DEG from the front, shoulders and hips overlap in depth: say so instead of claiming them
    if shift is None:
        st[[J["HipCenter"], J["Spine"], J["ShoulderCenter"]]] = INFERRED
    if legs_clipped == 2:   # both legs leave the image (the SDK's "clipped bottom"): nothing checks the hips
        st[[J["HipCenter"], J["HipLeft"], J["HipRight"]]] = INFERRED
    if turned:
        for name in ("ShoulderLeft", "ShoulderRight", "HipLeft", "HipRight"):
            st[J[name]] = INFERRED
    return FitResult(pos, st, lat, labels, centre, proj, edge_on or narrow, turned, axis, patch_centre)


def _torso_frame(grid, mask_full, xyz, mask, graph, up, calib, prev_lateral, seed_at, line=None, quarters=None):
    """The torso: a geodesic disc around `seed_at` (or the person's middle) gives its centre and long
    axis; the right -> left `line` of the forest's shoulders or else the chest's normals its facing, unless
    the line of its upper torso `quarters` says they read too little of a turn (part_lines), kept through
    side-on views. None when the person has no torso.
    Returns (d0 geodesic distances from the seed, the graph that reached every part, centre, axis, lat,
    facing, view, edge_on, narrow)."""
    H = calib.height
    seed_p = seed_at if seed_at is not None else grid.xyz[mask_full].mean(axis=0)
    seed = _nearest_cell(xyz, mask, seed_p)
    if seed is None:
        return None
    d0 = graph.distances(np.array([seed]))
    cut_off = mask & ~np.isfinite(d0)
    if cut_off.sum() > 10:
        # parts joined to the body only across depth steps (a limb seen edge-on at the hip or shoulder):
        # reach them through a permissive graph so their extremities still count, with the steps' length
        loose = SurfaceGraph(xyz, mask, max_jump=0.25)
        d0 = loose.distances(np.array([seed]), init=d0)
    else:
        loose = graph
    patch = xyz[d0 < 0.1 * H]
    if len(patch) < 10:
        return None
    centre = np.median(patch, axis=0)  # the median ignores a hanging arm caught at the patch's edge
    _, _, vt = np.linalg.svd(patch - centre, full_matrices=False)
    axis = vt[0] if vt[0] @ up > 0 else -vt[0]
    # a torso patch's long axis tilts with a swinging arm or a turn; people stand close to upright
    axis = _unit((1 - AXIS_GRAVITY_WEIGHT) * axis + AXIS_GRAVITY_WEIGHT * up) if axis @ up > 0.5 else up
    view = _unit(centre)
    facing = vt[2] if vt[2] @ view < 0 else -vt[2]  # the chest's normal, toward the sensor
    facing = _unit(facing - (facing @ axis) * axis)
    edge_on = bool(facing @ -view < 0.3)
    toward = _unit(-view - (-view @ axis) * axis)
    # the facing read from the shoulders' parts where the forest sees both, else from the chest's normals
    # (checked by the forest's upper torso, which reads a turn surely, if not all of it)
    chest, agree = line_facing(line, axis, toward), LINE_AGREE_DEG
    if chest is None:
        chest = chest_facing(xyz, mask, centre - axis * calib.torso_patch_height * H, axis, H)
        agree = NORMALS_AGREE_DEG
    chest = checked_by_torso(chest, line_facing(quarters, axis, toward), axis, toward, agree)
    held = prev_lateral is not None and (chest is None or chest @ toward < np.cos(np.radians(SIDE_ON_DEG)))
    if held:  # side-on the chest's direction is ambiguous: keep the last one until the turn goes on
        lat = _unit(prev_lateral - (prev_lateral @ axis) * axis)
    else:
        # like the SDK, the performer is taken to face the sensor: a chest turned past side-on reads as
        # its mirror image (a back looks like a front)
        facing = chest if chest is not None else (toward if edge_on else facing)
        lat = _unit(np.cross(axis, facing))  # points to the performer's left
        if prev_lateral is not None:
            lat = next_lateral(lat, prev_lateral, axis, toward)
    facing = _unit(np.cross(lat, axis))
    # the torso plane's normal always faces the sensor, even side-on; the chest's visible width does not lie
    narrow = _visible_chest_width(xyz[mask], centre, axis, view, H) < SIDE_ON_WIDTH * H
    return d0, loose, centre, axis, lat, facing, view, edge_on, narrow


def confident_head_part(proposals) -> np.ndarray | None:
    """The forest's head proposal where it is confident (the forest's surest part), else None."""
    if proposals is None:
        return None
    head = J["Head"]
    return proposals.positions[head] if proposals.confidence[head] >= USE_CONFIDENCE else None


def _pin_along_axis(xyz, mask, cand, centre, axis, lat, facing, up, calib, head_part=None):
    """Where the torso sits along its axis: the head top (which may also tilt a leaning trunk) and, better,
    the tops of the shoulders. A head top farther along the axis than the torso may move in a frame is
    refused, except FAR_HEAD_SHIFT-MAX_HEAD_SHIFT *up* the axis where the forest's confident head part
    (`head_part`) confirms it: the torso's disc, seeded at its last place where the forest does not see the
    torso, cannot climb back up on its own after a deep bend; and anywhere before the height is calibrated
    (the head top's place above the disc is then a guess). Returns (head candidate or None, shift or None,
    centre, axis, lat, facing)."""
    H = calib.height
    heady = [e for e in cand if (e[1] - centre) @ up > 0 and abs(e[4]) < 0.15 * H]
    head = max(heady, key=lambda e: e[1] @ up, default=None)
    # the head top pins the torso along its axis (the torso patch alone drifts along the body)
    if head is not None:
        # the geodesic extremum lies anywhere on the skull; the top is the highest point near it
        near = xyz[mask & (np.linalg.norm(xyz - head[1], axis=-1) < 0.15)]
        def anchor(ax):
            t = near[np.argmax(near @ ax)] if len(near) else head[1]
            return t, (t - ax * (1.0 - calib.torso_patch_height) * H - centre) @ ax

        top, shift = anchor(axis)
        lean = _unit(top - centre)
        # the trunk leans (a crouch, a bow): the line from the torso patch to the head top says how far. A bow
        # leans forward; a "head" off to the side or behind is more likely a hand, and tilts nothing
        forward = lean @ facing > 0 and abs(lean @ lat) < np.sin(np.radians(MAX_SIDE_LEAN_DEG))
        if HEAD_AXIS_WEIGHT > 0 and forward and lean @ up > np.cos(np.radians(MAX_LEAN_DEG)):
            leaned = _unit(HEAD_AXIS_WEIGHT * lean + (1 - HEAD_AXIS_WEIGHT) * axis)
            l_top, l_shift = anchor(leaned)
            if abs(l_shift) <= 0.15:
                axis, top, shift = leaned, l_top, l_shift
                lat = _unit(lat - (lat @ axis) * axis)
                facing = _unit(np.cross(lat, axis))
        confirmed = head_part is not None and np.linalg.norm(head[1] - head_part) < HEAD_PART_NEAR
        # uncalibrated, where the head top sits above the patch is a guess (a default height and proportion)
        believed = confirmed and (not calib.frames or FAR_HEAD_SHIFT < shift < MAX_HEAD_SHIFT)
        if abs(shift) > 0.15 and not believed:
            head, shift = None, None   # not the head (a shoulder or raised hand): the torso cannot move that far
    else:
        shift = None
    # the tops of the shoulders pin it better (the neck bends forward while walking; the shoulders stay)
    sc_a = (bm.HEIGHT_SHOULDER_CENTER - calib.torso_patch_height) * H
    top_a = _shoulder_top(xyz, mask, centre, axis, lat, H, sc_a + (shift or 0.0))
    if top_a is not None:
        s_shift = top_a + bm.SHOULDER_TOP_BELOW_CENTRE * H - sc_a
        if abs(s_shift) < 0.2 and (shift is None or abs(s_shift - shift) < 0.15):
            shift = s_shift
    if shift is not None:
        centre = centre + axis * shift
    return head, shift, centre, axis, lat, facing


def next_lateral(reading: np.ndarray, prev_lateral: np.ndarray, axis: np.ndarray, toward: np.ndarray) -> np.ndarray:
    """This frame's left-right direction from the chest's reading and the last frame's (all across `axis`;
    `toward`: the sensor's direction). A performer facing the sensor cannot turn 25 degrees in a frame: such
    a jump is an arm across the chest or hands held before it (on real depth, 5 % of the frames facing the
    sensor read as turned past 45 degrees), so the direction only creeps toward it. A reading more than 45
    degrees from the last once turned is the mirror image flipping over: taken as it is."""
    last = _unit(prev_lateral - (prev_lateral @ axis) * axis)
    was = _angle_deg(np.cross(last, axis), toward)
    if was < TURN_JUMP_FROM_DEG and _angle_deg(np.cross(reading, axis), toward) - was > TURN_JUMP_DEG:
        return _turn_toward(last, reading, TURN_CREEP_DEG)
    if reading @ prev_lateral > np.cos(np.radians(45.0)):
        lat = LATERAL_SMOOTHING * prev_lateral + (1 - LATERAL_SMOOTHING) * reading
        return _unit(lat - (lat @ axis) * axis)
    return reading


def _angle_deg(a, b) -> float:
    return float(np.degrees(np.arccos(np.clip(_unit(a) @ _unit(b), -1.0, 1.0))))


def _turn_toward(a, b, max_deg):
    """Unit vector a turned toward unit vector b (both across the same axis) by at most max_deg."""
    ang = np.radians(_angle_deg(a, b))
    if ang < 1e-9:
        return b
    t = min(1.0, np.radians(max_deg) / ang)
    return _unit(np.sin((1 - t) * ang) * a + np.sin(t * ang) * b)


def _visible_chest_width(pts, centre, axis, view, H):
    """Width across the image of the person at chest height (near the torso, arms far out excluded)."""
    across = _unit(np.cross(axis, view))
    rel = pts - centre
    a, x = rel @ axis, rel @ across
    band = x[(a > 0.0) & (a < 0.12 * H) & (np.abs(x) < 0.35)]
    if len(band) < 10:
        return np.inf
    lo, hi = np.percentile(band, [5, 95])
    return float(hi - lo)


def _shoulder_top(xyz, mask, centre, axis, lat, H, expect):
    """Height along the torso axis (relative to `centre`) of the tops of the shoulders: the high points
    just beside the neck. The higher side, unless the sides disagree (a raised arm), then the lower."""
    pts = xyz[mask]
    rel = pts - centre
    a, l = rel @ axis, rel @ lat
    tops = []
    for sign in (1.0, -1.0):
        sel = (sign * l > 0.07 * H) & (sign * l < 0.11 * H) & (a > expect - 0.3) & (a < expect + 0.2)
        if sel.sum() >= 3:
            tops.append(float(np.percentile(a[sel], 90)))
    if not tops:
        return None
    return min(tops) if len(tops) == 2 and abs(tops[0] - tops[1]) > 0.08 else max(tops)
