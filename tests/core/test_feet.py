"""Planted feet and the floor (issue 16): contacts found with hysteresis, pinned ankles that do not slide,
no ankle below the floor, knees kept in their bend plane, and nothing else changed."""
from __future__ import annotations

import copy

import numpy as np
import pytest

from kinect_retarget.core.foot_contacts import detect_contacts, intervals, pin_weights
from kinect_retarget.core.foot_lock import FootLock
from kinect_retarget.core.kinect_rig_layout import generated_mapping, generated_rig, median_segment_lengths
from kinect_retarget.core.pipeline import RetargetPipeline, RetargetSettings
from kinect_retarget.core.presets import PRESETS
from kinect_retarget.core.target_rig import evaluate_pose
from kinect_retarget.takes import load_take
from tests.conftest import SAMPLE_TAKES
from tests.rigs.humanoid_rigs import build, makehuman_rig
from tests.rigs.layouts import LAYOUTS
from tests.takes.steep_feet import steep_feet

UP = np.array([0.0, 0.0, 1.0])


def test_contacts_with_hysteresis_on_a_noisy_gait():
    """Steps of a synthetic foot (stance 0.5 s, swing 0.4 s) with 4 mm jitter: one contact per stance, none
    split by the jitter, none in the swing."""
    rng = np.random.default_rng(16)
    rate, stance, swing = 30.0, 15, 12
    path, truth = [], []
    x = 0.0
    for _ in range(5):
        path += [[x, 0, 0.08]] * stance
        truth += [True] * stance
        for k in range(swing):
            u = (k + 1) / (swing + 1)
            path.append([x + 0.6 * u, 0, 0.08 + 0.12 * np.sin(np.pi * u)])
            truth.append(False)
        x += 0.6
    pos = np.array(path) + rng.normal(0, 0.004, (len(path), 3))
    found = detect_contacts(pos, UP, 0.85, rate)
    assert len(intervals(found)) == 5
    assert (found & ~np.array(truth)).sum() <= 5 * 2       # at most two frames into each swing
    assert (np.array(truth) & ~found).sum() <= 5 * 4       # and a few at each stance's ends
    w, which = pin_weights(found, rate)
    assert w[found].min() == 1.0 and np.all((w >= 0) & (w <= 1)) and set(which[found]) == set(range(5))


def _bake(name, rig_kind):
    take = name if not isinstance(name, str) else load_take(SAMPLE_TAKES / f"{name}.krtake")
    if rig_kind == "generated":
        rig, mapping = generated_rig(take.skeleton, median_segment_lengths(take)), generated_mapping(take.skeleton)
    elif rig_kind == "makehuman":
        rig, mapping = makehuman_rig().target("MakeHuman"), PRESETS["makehuman"]
    else:
        rig, mapping = build(LAYOUTS["ue4-mannequin"], a_pose_deg=30).target("UE4"), PRESETS["ue4-mannequin"]
    pipe = RetargetPipeline(take.skeleton, rig, mapping, RetargetSettings())
    return take, rig, pipe, pipe.process_take(take)


def _plane(posed, thigh, shin, foot):
    """Unit bend-plane normals and unit hip->ankle directions of a leg, (F, 3) each."""
    hip, knee, ankle = (posed[:, b, :3, 3] for b in (thigh, shin, foot))
    n = np.cross(knee - hip, ankle - knee)
    axis = ankle - hip
    return n / np.linalg.norm(n, axis=-1, keepdims=True), axis / np.linalg.norm(axis, axis=-1, keepdims=True)


def _bent(posed, thigh, shin, foot, degrees=5.0):
    """(F,) the knee bends at least this much (a straighter leg has no well-defined plane)."""
    hip, knee, ankle = (posed[:, b, :3, 3] for b in (thigh, shin, foot))
    u, v = knee - hip, ankle - knee
    cos = np.sum(u * v, -1) / np.linalg.norm(u, axis=-1) / np.linalg.norm(v, axis=-1)
    return np.degrees(np.arccos(np.clip(cos, -1, 1))) >= degrees


def _turn(a, b):
    """(F, 3, 3) shortest rotations taking unit vectors a to b."""
    v, c = np.cross(a, b), np.sum(a * b, -1)
    k = np.zeros((len(a), 3, 3))
    k[:, 0, 1], k[:, 0, 2], k[:, 1, 0], k[:, 1, 2], k[:, 2, 0], k[:, 2, 1] = -v[:, 2], v[:, 1], v[:, 2], -v[:, 0], \
        -v[:, 1], v[:, 0]
    return np.eye(3) + k + (k @ k) / (1 + c)[:, None, None]


def _toes_below(rig, lock, posed, side):
    """Deepest tail of the foot or any bone below it under the rest pose's lowest point (m), from the pose."""
    foot = lock.legs[side][2].index
    below = [b for b in range(len(rig.bone_names)) if b == foot or foot in rig.ancestors(b)]
    sel = posed[:, below]
    tails = sel[..., :3, 3] + sel[..., :3, 1] * rig.lengths[below][None, :, None]
    floor = min(rig.heads[:, 2].min(), rig.tails[:, 2].min())
    return float(max(0.0, floor - tails[..., 2].min()))


def _pose(rig, motion):
    idx = np.array([rig.index(b) for b in motion.bone_names])
    return evaluate_pose(rig, idx, motion.quats, rig.index(motion.root_bone), motion.root_location)


@pytest.mark.parametrize("name,rig_kind", [("kinect_v1_cmu_131_02_walk", "makehuman"),
                                           ("kinect_v1_cmu_131_03_hop", "ue4"),
                                           ("kinect_v1_cmu_01_01_jumps", "generated"),
                                           ("kinect_v2_ges05_demopoint", "makehuman")])
def test_locked_feet_stay_put_above_the_floor_and_nothing_else_moves(name, rig_kind):
    take, rig, pipe, before = _bake(name, rig_kind)
    after = copy.deepcopy(before)
    lock = FootLock(pipe.retargeter)
    report = lock.apply(after, "lock", take.rate)
    assert len(report.legs) == 2 and all(leg.contacts >= 1 for leg in report.legs)
    p0, p1 = _pose(rig, before), _pose(rig, after)
    shift = report.height_shift_cm / 100
    leg_bones = set()
    for leg in report.legs:
        thigh, shin, foot = lock.legs[leg.side]
        leg_bones |= {thigh.index, shin.index, foot.index}
        assert leg.slide_after_cm[1] <= 1.0 and leg.slide_after_cm[1] <= leg.slide_before_cm[1]
        assert leg.below_floor_after_cm < 1e-6
        ankle = p1[:, foot.index, :3, 3]
        for a, b in intervals(leg.contact):  # the ankle does not slide while planted
            d = ankle[a:b + 1, :2] - ankle[a:b + 1, :2].mean(axis=0)
            assert np.linalg.norm(d, axis=-1).max() < 0.02
        assert (ankle @ UP).min() >= rig.rest[foot.index, 2, 3] - 1e-6  # never below its rest height
        # the knee stays in the leg's bend plane: the plane turns with the hip-ankle line, never about it
        ch = leg.changed & _bent(p0, thigh.index, shin.index, foot.index) & _bent(p1, thigh.index, shin.index,
                                                                                   foot.index)
        n0, a0 = _plane(p0[ch], thigh.index, shin.index, foot.index)
        n1, a1 = _plane(p1[ch], thigh.index, shin.index, foot.index)
        carried = np.einsum("fij,fj->fi", _turn(a0, a1), n0)
        assert np.degrees(np.arccos(np.clip(np.sum(carried * n1, -1), -1, 1))).max(initial=0) < 1e-4
        below = [b for b in range(len(rig.bone_names)) if thigh.index in rig.ancestors(b) or b == thigh.index]
        leg_bones |= set(below)
        unchanged = ~leg.changed
        np.testing.assert_allclose(p1[unchanged][:, below, :3, :3], p0[unchanged][:, below, :3, :3], atol=1e-9)
        # the foot keeps its orientation in the armature where the leg was bent for it (and was not pitched up
        # to keep its toes on the floor)
        flat = ~leg.pitched if leg.pitched.size else slice(None)
        np.testing.assert_allclose(p1[flat, foot.index, :3, :3], p0[flat, foot.index, :3, :3], atol=1e-9)
        assert leg.toe_below_after_cm < 1e-6 and _toes_below(rig, lock, p1, leg.side) < 1e-8
    others = [b for b in range(len(rig.bone_names)) if b not in leg_bones]
    np.testing.assert_allclose(p1[:, others, :3, :3], p0[:, others, :3, :3], atol=1e-9)  # directions
    hips = rig.index(before.root_bone)  # the body moved up or down as one; the bones above the hips stay
    body = [b for b in others if b == hips or hips in rig.ancestors(b)]
    np.testing.assert_allclose(p1[:, body, :3, 3], p0[:, body, :3, 3] + shift * UP, atol=1e-9)
    still = [b for b in others if b not in body]
    np.testing.assert_allclose(p1[:, still, :3, 3], p0[:, still, :3, 3], atol=1e-9)


def test_floor_mode_only_lifts_and_off_changes_nothing():
    take, rig, pipe, before = _bake("kinect_v1_cmu_131_01_walk", "makehuman")
    off = copy.deepcopy(before)
    assert FootLock(pipe.retargeter).apply(off, "off", take.rate).summary() == "feet: off"
    np.testing.assert_array_equal(off.quats, before.quats)
    floor = copy.deepcopy(before)
    report = FootLock(pipe.retargeter).apply(floor, "floor", take.rate)
    assert max(leg.below_floor_before_cm for leg in report.legs) > 1.0   # MakeHuman's hips put its feet low
    assert all(leg.below_floor_after_cm < 1e-6 for leg in report.legs)
    with pytest.raises(ValueError, match="feet mode"):
        FootLock(pipe.retargeter).apply(floor, "glue", take.rate)


@pytest.mark.parametrize("rig_kind", ["generated", "ue4", "makehuman"])
@pytest.mark.parametrize("mode", ["lock", "floor"])
def test_feet_pointing_down_keep_their_toes_on_the_floor(rig_kind, mode):
    """Feet turned 40 degrees further down than the performer's dip the foot tip (and a toe bone's tip) under
    the floor in the plain bake; the pass pitches each foot up about its ankle just enough, eased in and out,
    and turns nothing else."""
    take = steep_feet(load_take(SAMPLE_TAKES / "kinect_v1_cmu_131_02_walk.krtake"))
    _, rig, pipe, before = _bake(take, rig_kind)
    after = copy.deepcopy(before)
    lock = FootLock(pipe.retargeter)
    report = lock.apply(after, mode, take.rate)
    p0, p1 = _pose(rig, before), _pose(rig, after)
    for leg in report.legs:
        thigh, shin, foot = lock.legs[leg.side]
        assert leg.toe_below_before_cm > 2.0 and _toes_below(rig, lock, p0, leg.side) > 0.02  # the test can fail
        assert leg.toe_below_after_cm < 1e-6 and _toes_below(rig, lock, p1, leg.side) < 1e-8
        assert leg.below_floor_after_cm < 1e-6
        assert 0 < leg.toe_frames < len(after.frames) and leg.changed[leg.pitched].all()
        # eased: a pitched stretch starts and ends small, never at full angle
        pitch = _angle(p0[:, foot.index, :3, :3], p1[:, foot.index, :3, :3]) * leg.pitched
        start = np.flatnonzero(leg.pitched[1:] & ~leg.pitched[:-1]) + 1
        end = np.flatnonzero(leg.pitched[:-1] & ~leg.pitched[1:])
        assert pitch[start].max(initial=0) < 0.4 * pitch.max() and pitch[end].max(initial=0) < 0.4 * pitch.max()
        # the pitch turns the foot about its ankle: where the leg itself was not bent, the ankle stays put
        # (up to the body's one vertical shift)
        legs_bent = np.abs(p1[:, [thigh.index, shin.index], :3, :3] - p0[:, [thigh.index, shin.index], :3, :3]
                           ).max(axis=(1, 2, 3)) > 1e-9
        only = leg.pitched & ~legs_bent
        assert only.any()
        np.testing.assert_allclose(p1[only, foot.index, :3, 3],
                                   p0[only, foot.index, :3, 3] + report.height_shift_cm / 100 * UP, atol=1e-9)
    untouched = ~np.any([leg.changed for leg in report.legs], axis=0)
    np.testing.assert_allclose(p1[untouched][..., :3, :3], p0[untouched][..., :3, :3], atol=1e-9)


def _angle(r0, r1):
    """(F,) degrees between two stacks of rotation matrices."""
    rel = np.swapaxes(r0, -1, -2) @ r1
    return np.degrees(np.arccos(np.clip((np.trace(rel, axis1=-2, axis2=-1) - 1) / 2, -1, 1)))


def test_needed_pitch_is_the_smallest_turn_up_that_clears_the_floor(rng):
    """The closed form against a brute-force search over turns: at the returned turn every tip is on or above
    the floor, and no smaller turn up (on a 0.02-degree grid) is; feet already clear get 0. The room an ease
    may use never sinks a tip."""
    from kinect_retarget.core.quat import to_matrix
    from kinect_retarget.core.toe_floor import axis_angle_quats, needed_pitch, pitch_room
    n, k = 200, 3
    ankle = rng.normal(0, 0.05, (n, 3)) + [0, 0, 0.1]
    tip = ankle[:, None] + rng.normal(0, 0.12, (n, k, 3))
    axis = rng.normal(0, 1, (n, 3)) * [1, 1, 0]
    axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
    need = needed_pitch(ankle, tip, axis, UP, 0.0)

    def lowest(t):
        r = to_matrix(axis_angle_quats(axis, t))
        return (ankle[:, None] + np.einsum("fij,fkj->fki", r, tip - ankle[:, None]))[..., 2].min(axis=1)

    grid = np.radians(np.arange(0, 360, 0.02))
    first = np.full(n, np.inf)
    for t in grid[::-1]:
        ok = lowest(np.full(n, t)) >= 0
        first[ok] = t
    reachable = np.isfinite(first)                               # some turn up clears every tip
    clear = tip[..., 2].min(axis=1) >= 0
    assert np.all(need[clear] == 0) and (reachable & ~clear).sum() > 25
    assert np.all(lowest(need)[reachable] >= -1e-9)
    np.testing.assert_allclose(need[reachable], first[reachable], atol=np.radians(0.021))
    room = pitch_room(ankle, tip, axis, UP, 0.0, need)
    for frac in (0.25, 0.5, 1.0):
        t = need + frac * (np.minimum(room, need + np.pi) - need)
        assert np.all(lowest(t)[reachable] >= -1e-9)
