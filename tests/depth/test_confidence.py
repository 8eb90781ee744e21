"""Honest tracking states: the checks that demote a fitted joint to INFERRED when the data does not back it."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from kinect_retarget.core.skeletons import INFERRED, KINECT_V1, TRACKED
from kinect_retarget.depth.confidence import (LIMB, LIMB_WARMUP_FRAMES, MAX_FRAMES_COUNTED, PREDICTION_SLACK,
                                           RECOVERY_FRAMES, WARMUP_FRAMES, ConfidenceCheck)
from kinect_retarget.sim.depth_scoring import score
from kinect_retarget.depth.skeleton_tracker import track_depth_frames

J = KINECT_V1.index
ALL_FOUND = [(n, None) for n in ("head", "HandLeft", "HandRight", "FootLeft", "FootRight")]


def _fit(extrema=ALL_FOUND):
    return SimpleNamespace(projector=None, edge_on=False, extrema=extrema)


def _steady(rng):
    pose = rng.normal(0.0, 0.3, (20, 3)) + [0.0, 0.0, 2.5]
    chk = ConfidenceCheck()
    tracked = np.full(20, TRACKED, np.uint8)
    for _ in range(max(WARMUP_FRAMES, LIMB_WARMUP_FRAMES + RECOVERY_FRAMES)):   # a person just found: settle first
        chk.assess(pose, tracked, _fit())
        chk.remember(pose)
    for _ in range(3):
        assert np.all(chk.assess(pose, tracked, _fit()) == TRACKED)
        chk.remember(pose)
    return chk, pose, tracked


def test_a_joint_that_breaks_the_motion_is_inferred_then_recovers(rng):
    chk, pose, tracked = _steady(rng)
    jumped = pose.copy()
    jumped[J("ElbowLeft")] += [0.4, 0.0, 0.0]       # an elbow 40 cm off in one frame: the fit is doubted
    st = chk.assess(jumped, tracked, _fit())
    flagged = {J("ElbowLeft"), J("WristLeft"), J("HandLeft")}   # and the chain beyond it
    assert {int(j) for j in np.nonzero(st != TRACKED)[0]} == flagged
    chk.remember(pose)
    for _ in range(RECOVERY_FRAMES):                  # one good frame is not yet evidence
        st = chk.assess(pose, tracked, _fit())
        chk.remember(pose)
        assert st[J("ElbowLeft")] == INFERRED
    assert np.all(chk.assess(pose, tracked, _fit()) == TRACKED)


def test_limbs_settle_before_they_are_claimed(rng):
    pose = rng.normal(0.0, 0.3, (20, 3)) + [0.0, 0.0, 2.5]
    chk, tracked = ConfidenceCheck(), np.full(20, TRACKED, np.uint8)
    assert 0 < LIMB_WARMUP_FRAMES <= WARMUP_FRAMES
    for _ in range(LIMB_WARMUP_FRAMES):
        st = chk.assess(pose, tracked, _fit())
        chk.remember(pose)
        assert np.all(st[LIMB] == INFERRED) and st[J("Head")] == TRACKED and st[J("HipCenter")] == TRACKED
    for _ in range(RECOVERY_FRAMES):
        chk.assess(pose, tracked, _fit())
        chk.remember(pose)
    assert np.all(chk.assess(pose, tracked, _fit()) == TRACKED)
    chk.reset()                                       # the person lost and found again: settle again
    assert np.all(chk.assess(pose, tracked, _fit())[LIMB] == INFERRED)


def test_checks_never_promote_a_joint(rng):
    chk, pose, tracked = _steady(rng)
    states = tracked.copy()
    states[[J("HandRight"), J("Head")]] = INFERRED
    st = chk.assess(pose, states, _fit())
    assert st[J("HandRight")] == INFERRED and st[J("Head")] == INFERRED
    assert st[J("WristRight")] == TRACKED       # a chain is demoted beyond a doubtful joint, not before it


def test_a_joint_on_its_own_evidence_does_not_hang_on_the_limb_above(rng):
    chk, pose, tracked = _steady(rng)
    jumped = pose.copy()
    jumped[J("KneeLeft")] += [0.4, 0.0, 0.0]        # a knee 40 cm off: the leg below it is doubted ...
    own = np.zeros(20, bool)
    own[J("FootLeft")] = True                        # ... but the foot stands on its own body-part proposal
    st = chk.assess(jumped, tracked, _fit(), own)
    assert st[J("KneeLeft")] == INFERRED and st[J("AnkleLeft")] == INFERRED and st[J("FootLeft")] == TRACKED


def test_little_evidence_flags_the_limbs_and_sides(rng):
    chk, pose, tracked = _steady(rng)
    st = chk.assess(pose, tracked, _fit([("HandLeft", None), ("FootRight", None)]))  # side-on: 2 of 5 seen
    assert st[J("ShoulderCenter")] == TRACKED
    for name in ("HipCenter", "HipLeft", "ShoulderRight", "ElbowLeft", "HandRight", "KneeLeft", "FootRight"):
        assert st[J(name)] == INFERRED, name


def test_rendered_hop_is_within_15cm_or_flagged_without_flagging_everything(rendered):
    seq, _ = rendered
    take = track_depth_frames(seq.mm, seq.times, gravity=seq.gravity)
    sc = score(take.positions, take.states, seq.joints, seq.present)
    assert sc.within_or_flagged >= 0.97, f"{sc.within_or_flagged:.3f}"
    assert sc.flagged < 0.6, f"{sc.flagged:.3f}"


def test_a_turn_unsteadies_the_facing_until_it_has_faced_the_sensor_again(rng):
    pose = rng.normal(0.0, 0.3, (20, 3)) + [0.0, 0.0, 2.5]
    chk, tracked = ConfidenceCheck(), np.full(20, TRACKED, np.uint8)
    facing = SimpleNamespace(projector=None, edge_on=False, turned=False, extrema=ALL_FOUND)
    turned = SimpleNamespace(projector=None, edge_on=False, turned=True, extrema=ALL_FOUND)
    for _ in range(WARMUP_FRAMES):
        assert not chk.facing_steady
        chk.assess(pose, tracked, facing)
    assert chk.settled and chk.facing_steady
    chk.assess(pose, tracked, turned)                 # turned away: a mirror image may be in the history
    assert chk.settled and not chk.facing_steady
    for _ in range(WARMUP_FRAMES - 1):
        chk.assess(pose, tracked, facing)
        assert not chk.facing_steady
    chk.assess(pose, tracked, facing)
    assert chk.facing_steady


def test_extremities_the_forest_saw_count_with_the_fits(rng):
    """Hands held against the body are no geodesic extremity: with the head and one foot found by the fit and
    a hand seen by the body-part forest, three extremities show and the limbs keep their states."""
    from kinect_retarget.depth.part_fit import TRACK_CONFIDENCE, ends_seen
    chk, pose, tracked = _steady(rng)
    conf = np.zeros(20)
    conf[J("HandRight")] = TRACK_CONFIDENCE
    conf[J("FootLeft")] = TRACK_CONFIDENCE / 2   # not confident: not seen
    ends = ends_seen(SimpleNamespace(confidence=conf))
    assert ends == {"HandRight"}
    st = chk.assess(pose, tracked, _fit([("head", None), ("FootRight", None)]), ends_seen=ends)
    assert np.all(st == TRACKED)
    chk.remember(pose)
    st = chk.assess(pose, tracked, _fit([("head", None), ("FootRight", None)]))   # without it: two of five
    assert st[J("ElbowLeft")] == INFERRED


def test_a_joint_seen_anew_needs_no_recovery_frame(rng):
    """After a flagged frame, an elbow both the fit and the forest see again is tracked at once; the rest of
    its chain, not seen anew, waits its recovery frame."""
    chk, pose, tracked = _steady(rng)
    jumped = pose.copy()
    jumped[J("ElbowLeft")] += [0.4, 0.0, 0.0]
    chk.assess(jumped, tracked, _fit())
    chk.remember(pose)
    fresh = np.zeros(20, bool)
    fresh[J("ElbowLeft")] = True
    st = chk.assess(pose, tracked, _fit(), fresh=fresh)
    assert st[J("ElbowLeft")] == TRACKED and st[J("HandLeft")] == INFERRED


def _moving(chk, pose, tracked, frames, velocity):
    """Poses at the given sensor frames of a body moving at `velocity` (m per 1/30 s) from `pose` at the first,
    each assessed then remembered with its timestamp; returns the states of the last."""
    for f in frames:
        moved = pose + velocity * (f - frames[0])
        st = chk.assess(moved, tracked, _fit(), timestamp=f / 30.0)
        chk.remember(moved, f / 30.0)
    return st


def test_a_steady_motion_seen_at_uneven_frame_steps_stays_tracked(rng):
    """A tracker slower than the sensor takes its newest frame: a body moving 5 cm a sensor frame (a hop's
    torso), seen 2 then 4 frames apart, moved 10 then 20 cm between the poses checked. Counted in sensor
    frames the motion is steady; counted per pose checked, the second step broke the torso's 10 cm slack."""
    chk, pose, tracked = _steady(rng)
    velocity = np.array([0.0, 0.05, 0.0])
    st = _moving(chk, pose, tracked, [100, 102, 106, 108, 112], velocity)
    assert np.all(st == TRACKED)
    plain = ConfidenceCheck()                        # the same poses without their times: doubted
    for _ in range(max(WARMUP_FRAMES, LIMB_WARMUP_FRAMES + RECOVERY_FRAMES) + 3):
        plain.assess(pose, tracked, _fit())
        plain.remember(pose)
    for f in (100, 102):
        plain.assess(pose + velocity * (f - 100), tracked, _fit())
        plain.remember(pose + velocity * (f - 100))
    assert plain.assess(pose + velocity * 6, tracked, _fit())[J("HipCenter")] == INFERRED


def test_a_jump_is_still_doubted_at_a_slow_frame_rate_and_a_gap_is_not_a_licence(rng):
    chk, pose, tracked = _steady(rng)
    _moving(chk, pose, tracked, [200, 203], np.zeros(3))
    jumped = pose.copy()
    jumped[J("Spine")] += [0.0, 0.0, 0.45]           # 45 cm in 3 sensor frames: beyond 3 x 10 cm
    jumped[J("KneeLeft")] += [0.0, 0.3, 0.0]         # a limb's slack (25 cm) does not grow with the frames
    st = chk.assess(jumped, tracked, _fit(), timestamp=206 / 30.0)
    assert st[J("Spine")] == INFERRED and st[J("KneeLeft")] == INFERRED and st[J("ShoulderCenter")] == TRACKED
    chk, pose, tracked = _steady(rng)                # another performer, still
    _moving(chk, pose, tracked, [300, 301], np.zeros(3))
    jumped = pose.copy()
    jumped[J("Spine")] += [0.0, 0.0, 0.45]
    # a second without frames counts as MAX_FRAMES_COUNTED: 45 cm is still beyond its slack
    assert MAX_FRAMES_COUNTED * PREDICTION_SLACK[J("Spine")] < 0.45
    st = chk.assess(jumped, tracked, _fit(), timestamp=331 / 30.0)
    assert st[J("Spine")] == INFERRED and st[J("ShoulderCenter")] == TRACKED
