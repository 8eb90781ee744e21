"""Arms with no hand extremity, found by searching poses against the depth (depth/arm_search.py).

Real motion: CMU 131_02 at the moment the performer holds the right hand to the face while walking. The hand
touches the head, so it ends no geodesic branch; only the forearm standing out in front of the chest and the
elbow beside the body say where it is.
"""
from __future__ import annotations

import numpy as np
import pytest

from kinect_retarget.core.skeletons import KINECT_V1, TRACKED
from kinect_retarget.depth import arm_search, skeleton_fit
from kinect_retarget.depth.arm_search import DIRECTIONS, search_arm
from kinect_retarget.depth.skeleton_tracker import SkeletonTracker, TrackerSettings

HAND_R, ELBOW_R = KINECT_V1.index("HandRight"), KINECT_V1.index("ElbowRight")


@pytest.fixture(scope="module")
def hand_on_face(data_dir):
    from kinect_retarget.sim.synthetic_depth import Scenario, render_sequence
    return render_sequence(str(data_dir / "mocap_bvh" / "131_02.bvh"), str(data_dir / "meshes" / "makehuman"),
                           Scenario(seed=5), start=400, frames=3)


def _track(seq, settings=None):
    tracker = SkeletonTracker(gravity=seq.gravity, settings=settings)
    return [tracker.update(seq.mm[i], seq.times[i]) for i in range(len(seq.mm))]


def test_directions_cover_the_sphere():
    assert np.allclose(np.linalg.norm(DIRECTIONS, axis=1), 1.0)
    assert abs(DIRECTIONS.mean(axis=0)).max() < 0.02          # no side favoured
    cos = DIRECTIONS @ DIRECTIONS.T - 2 * np.eye(len(DIRECTIONS))
    assert np.degrees(np.arccos(cos.max(axis=1))).max() < 20   # no direction farther than 20 deg from another


def test_hand_on_the_face_is_found(hand_on_face, monkeypatch):
    gt = hand_on_face.joints
    out = _track(hand_on_face)
    hand = [np.linalg.norm(pos[HAND_R] - g[HAND_R]) for (pos, _), g in zip(out, gt)]
    elbow = [np.linalg.norm(pos[ELBOW_R] - g[ELBOW_R]) for (pos, _), g in zip(out, gt)]
    assert all(st[HAND_R] != TRACKED for _, st in out)             # honest: no extremity backs it
    # the first frame has no history (and a default body height); the next ones settle on the arm
    assert max(hand) < 0.25 and hand[-1] < 0.1 and max(elbow) < 0.12
    # without the search (and without the body parts, whose hand proposal also finds it) the same frames
    # leave the hand hanging at the hip
    monkeypatch.setattr(skeleton_fit, "ARM_SEARCH", False)
    pos, _ = _track(hand_on_face, TrackerSettings(part_forest=None))[-1]
    assert np.linalg.norm(pos[HAND_R] - gt[-1][HAND_R]) > 0.3


def test_search_alone_finds_the_arm(hand_on_face, monkeypatch):
    """With no previous pose to lean on, the depth alone places the raised arm."""
    calls = []
    real = arm_search.search_arm

    def spy(scorer, shoulder, l1, l2, lh, H, prev_elbow=None, prev_hand=None, max_step=None):
        calls.append((scorer, shoulder, l1, l2, lh, H))
        return real(scorer, shoulder, l1, l2, lh, H, prev_elbow, prev_hand, max_step)

    monkeypatch.setattr(arm_search, "search_arm", spy)
    _track(hand_on_face)
    scorer, shoulder, l1, l2, lh, H = calls[-1]     # the right arm (searched after the left) of the last frame
    g = hand_on_face.joints[-1]
    elbow, _, hand, _ = search_arm(scorer, shoulder, l1, l2, lh, H)
    assert np.linalg.norm(hand - g[HAND_R]) < 0.2 and np.linalg.norm(elbow - g[ELBOW_R]) < 0.12
    # and a pose across the chest (what the torso surface alone would allow) costs more than the found one
    u = np.array([-1.0, 0.0, 0.0])                  # from the right shoulder toward the body's centre
    from kinect_retarget.depth.arm_search import _chain_cost
    found_cost = _chain_cost(scorer, shoulder, _unit(elbow - shoulder)[None], _unit(hand - elbow)[None], l1, l2, lh, H)[0]
    across_cost = _chain_cost(scorer, shoulder, u[None], u[None], l1, l2, lh, H)[0]
    assert across_cost[0] > found_cost[0] + 1.0


def _unit(v):
    return v / np.linalg.norm(v)


def test_best_elbow_on_the_ik_circle_follows_the_depth(hand_on_face, monkeypatch):
    """Shoulder and wrist known (the ground truth's): of the elbows on their IK circle, the one the depth
    backs is the true one, although most of the circle lies on the body's surface too."""
    from kinect_retarget.depth.two_bone import two_bone_candidates
    scorers = []
    real = arm_search.ArmScorer.__init__

    def keep(self, *args, **kw):
        real(self, *args, **kw)
        scorers.append(self)

    monkeypatch.setattr(arm_search.ArmScorer, "__init__", keep)
    _track(hand_on_face)
    g = hand_on_face.joints[-1]
    s, e, w = (g[KINECT_V1.index(f"{n}Right")] for n in ("Shoulder", "Elbow", "Wrist"))
    cands, _ = two_bone_candidates(s, w, np.linalg.norm(e - s), np.linalg.norm(w - e), n=24)
    assert np.max(np.linalg.norm(cands - e, axis=1)) > 0.2        # a wrong choice would show
    elbow, _ = arm_search.best_elbow(scorers[-1], s, cands, w, 1.67)
    assert np.linalg.norm(elbow - e) < 0.06


def test_the_head_is_not_arm_evidence(hand_on_face, monkeypatch):
    """Cells around the head along the surface are the head's, not an arm's, unless in front of the face."""
    calls = []
    real = arm_search.arm_evidence

    def spy(xyz, mask, pos, frame, head_region=None):
        ev = real(xyz, mask, pos, frame, head_region)
        calls.append((xyz, mask, pos, ev, head_region))
        return ev

    monkeypatch.setattr(arm_search, "arm_evidence", spy)
    _track(hand_on_face)
    xyz, mask, pos, ev, head_region = calls[-1]
    assert head_region is not None and head_region.sum() > 10
    top = np.linalg.norm(xyz - pos[KINECT_V1.index("Head")], axis=-1) < 0.08
    assert not np.any(ev & top & mask & (xyz[..., 2] > pos[KINECT_V1.index("Head"), 2] - 0.12))
    g = hand_on_face.joints[-1]
    near_hand = mask & (np.linalg.norm(xyz - g[HAND_R], axis=-1) < 0.08)
    assert np.mean(ev[near_hand]) > 0.3     # the hand held to the face still counts for its arm


def test_well_explained_arms_of_a_performer_facing_the_sensor_are_tracked(data_dir, monkeypatch):
    """Walking toward the sensor with the hands hanging (no extremity): once the tracking is steady, the
    search's elbows and wrists that the surface shows are reported tracked, and they are right."""
    from kinect_retarget.sim.synthetic_depth import Scenario, render_sequence
    seq = render_sequence(str(data_dir / "mocap_bvh" / "131_02.bvh"), str(data_dir / "meshes" / "makehuman"),
                          Scenario(seed=5), start=0, frames=16)
    arm = [KINECT_V1.index(f"{j}{s}") for j in ("Elbow", "Wrist") for s in ("Left", "Right")]

    def tracked_arm_errors():
        return [float(np.linalg.norm(pos[j] - g[j])) for (pos, st), g in zip(_track(seq), seq.joints)
                for j in arm if st[j] == TRACKED]

    promoted = tracked_arm_errors()
    assert len(promoted) >= 8 and max(promoted) < 0.15
    monkeypatch.setattr(arm_search, "SEARCH_TRACKED_COST", -np.inf)   # the rule off: searched arms inferred
    assert len(tracked_arm_errors()) < len(promoted)


def test_hands_at_tracked_wrists_need_the_elbow_the_wrist_and_the_surface():
    J = {n: i for i, n in enumerate(KINECT_V1.joints)}

    class Surface:   # the hand is on the surface when its x is positive
        def supported(self, p, inside):
            return bool(p[0] > 0)

    pos = np.zeros((20, 3))
    pos[J["HandLeft"]], pos[J["HandRight"]] = [0.3, 0.0, 2.0], [-0.3, 0.0, 2.0]
    st = np.full(20, TRACKED, np.uint8)
    st[[J["HandLeft"], J["HandRight"]]] = 1
    assert np.flatnonzero(arm_search.hands_at_tracked_wrists(pos, st, Surface())).tolist() == [J["HandLeft"]]
    st[J["WristLeft"]] = 1
    assert not arm_search.hands_at_tracked_wrists(pos, st, Surface()).any()
    pos[J["HandRight"], 0] = 0.3   # now seen, but its elbow is only inferred
    st[J["ElbowRight"]] = 1
    assert not arm_search.hands_at_tracked_wrists(pos, st, Surface()).any()
    st[[J["WristLeft"], J["ElbowRight"]]] = TRACKED   # both qualify, but only the right hand is backed
    backed = np.zeros(20, bool)
    backed[J["HandRight"]] = True
    assert np.flatnonzero(arm_search.hands_at_tracked_wrists(pos, st, Surface(), backed)).tolist() == [J["HandRight"]]


def test_hanging_hands_below_tracked_wrists_are_tracked(data_dir, monkeypatch):
    """The same walk: hands that hang off tracked wrists are reported tracked, and they are right. Tracked
    without body parts: with them, such a hand also needs evidence of its own (part_fit.hands_backed), which
    the forest's hand parts, found up the forearm of a hanging hand, do not give here."""
    from kinect_retarget.depth import skeleton_tracker
    from kinect_retarget.depth.skeleton_tracker import TrackerSettings
    from kinect_retarget.sim.synthetic_depth import Scenario, render_sequence
    seq = render_sequence(str(data_dir / "mocap_bvh" / "131_02.bvh"), str(data_dir / "meshes" / "makehuman"),
                          Scenario(seed=5), start=0, frames=16)
    hands = [KINECT_V1.index("HandLeft"), KINECT_V1.index("HandRight")]

    def tracked_hand_errors():
        return [float(np.linalg.norm(pos[j] - g[j]))
                for (pos, st), g in zip(_track(seq, TrackerSettings(part_forest=None)), seq.joints)
                for j in hands if st[j] == TRACKED]

    with_rule = tracked_hand_errors()
    monkeypatch.setattr(skeleton_tracker, "HANDS_AT_TRACKED_WRISTS", False)
    without = tracked_hand_errors()
    assert len(with_rule) >= len(without) + 8 and max(with_rule) < 0.10


def _leaning_trunk_with_folded_forearms():
    """Cells of a trunk 1.7 m tall seen from the front, leaning back 10 cm from hips to shoulders, with forearms
    folded across its chest: 8 cm before the surface and as wide as the trunk, so they fill their bands."""
    H = 1.7
    frame = arm_search.TorsoFrame(np.zeros(3), np.array([0.0, 1.0, 0.0]), np.array([1.0, 0.0, 0.0]),
                                  np.array([0.0, 0.0, 1.0]), np.zeros((20, 3)), H)
    frame.hip_a, frame.shoulder_a = -0.25, 0.25
    a, l = np.meshgrid(np.linspace(-0.26, 0.26, 53), np.linspace(-0.15, 0.15, 31), indexing="ij")
    f = -0.2 * a   # the lean: the surface nearer the sensor at the hips
    forearms = np.isin(np.floor((a + 0.25) / (arm_search.TORSO_BAND * H)), (4, 5))   # two whole bands
    f = f + np.where(forearms, 0.08, 0.0)
    pts = np.stack([l, a, f], axis=-1)
    return frame, pts, forearms


def test_forearms_folded_over_the_chest_are_not_taken_for_it(monkeypatch):
    frame, pts, forearms = _leaning_trunk_with_folded_forearms()
    mask = np.ones(forearms.shape, bool)
    torso = frame.torso(pts, mask)
    assert not torso[forearms].any()            # arm evidence, for the search to explain
    assert torso[~forearms].mean() > 0.95       # the leaning chest itself is still the trunk
    # with each band's own median as the surface, the forearms filling their bands were the chest
    monkeypatch.setattr(arm_search, "SURFACE_LINE", False)
    assert frame.torso(pts, mask)[forearms].all()


def test_band_surfaces_are_set_back_to_their_line_never_forward():
    bands = np.arange(8)
    level = 0.3 - 0.01 * bands                  # a lean
    level[3:5] += 0.07                          # two bands of forearms
    level[6] -= 0.03                            # a hollow stays where it is
    out = arm_search._no_nearer_than_line(bands, level)
    assert np.allclose(out[3:5], 0.3 - 0.01 * bands[3:5])
    assert np.allclose(np.delete(out, [3, 4]), np.delete(level, [3, 4]))
    assert np.array_equal(arm_search._no_nearer_than_line(bands[:3], level[:3]), level[:3])


def test_a_searched_hand_may_move_farther_when_more_sensor_frames_passed(hand_on_face, monkeypatch):
    """A tracker slower than the sensor sees every second or third frame: the searched hand's free step
    (MAX_HAND_STEP a sensor frame) counts the frames that passed, as the tracker's motion check does."""
    steps, real = [], arm_search.search_arm

    def spy(scorer, shoulder, l1, l2, lh, H, prev_elbow=None, prev_hand=None, max_step=None):
        steps.append(max_step)
        return real(scorer, shoulder, l1, l2, lh, H, prev_elbow, prev_hand, max_step)

    monkeypatch.setattr(arm_search, "search_arm", spy)
    calls, real_fit = [], skeleton_fit.fit_arms

    def fit_spy(*args, **kw):
        calls.append(args)
        return real_fit(*args, **kw)

    monkeypatch.setattr(skeleton_fit, "fit_arms", fit_spy)
    tracker = SkeletonTracker(gravity=hand_on_face.gravity)
    t0 = float(hand_on_face.times[0])
    for i, frames in enumerate((0, 3, 5)):          # the sensor's frames 0, 3 and 5
        tracker.update(hand_on_face.mm[i], t0 + frames / 30.0)
    assert [c[11] for c in calls] == [1, 3, 2]
    pos, st, *rest = calls[-1][:9]
    for passed in (1, 3):                            # once settled, the last frame's arms searched again
        steps.clear()
        real_fit(pos.copy(), st.copy(), *rest, settled=True, facing_steady=False, frames_passed=passed)
        assert steps and all(s == pytest.approx(passed * arm_search.MAX_HAND_STEP) for s in steps)
