"""Training poses whose arms reach on and around the body (sim/reach_poses.py), on MakeHuman's rest skeleton."""
from __future__ import annotations

import numpy as np
import pytest

from kinect_retarget.assets import MAKEHUMAN_DIR
from kinect_retarget.sim.makehuman_body import load_body
from kinect_retarget.sim.mocap_pose import _rest_points
from kinect_retarget.sim.reach_poses import TARGETS, body_axes, gripping, reach_arm, reach_target, reaching

BONES = [("shoulder", "elbow"), ("elbow", "wrist"), ("wrist", "hand")]


@pytest.fixture(scope="module")
def rest():
    return _rest_points(load_body(str(MAKEHUMAN_DIR)))


def test_body_axes_follow_the_feet_and_shoulders(rest):
    lat, up, fwd = body_axes(rest)
    assert lat @ (rest["shoulder.L"] - rest["shoulder.R"]) > 0
    assert up[1] > 0.99
    toes = rest["toe.L"] - rest["ankle.L"]
    assert fwd @ toes > 0
    assert abs(lat @ up) < 1e-9 and abs(fwd @ up) < 1e-9


def test_reaching_keeps_bone_lengths_and_is_seeded(rest):
    for k in range(50):
        p = reaching(rest, np.random.default_rng([3, k]), chance=1.0)
        for s in ("L", "R"):
            for a, b in BONES:
                assert np.linalg.norm(p[f"{b}.{s}"] - p[f"{a}.{s}"]) == pytest.approx(
                    np.linalg.norm(rest[f"{b}.{s}"] - rest[f"{a}.{s}"]), rel=1e-9)
        for name in ("hips", "neck", "head", "hip.L", "knee.R"):   # only the arms move
            assert np.array_equal(p[name], rest[name])
    a = reaching(rest, np.random.default_rng([3, 4]))
    b = reaching(rest, np.random.default_rng([3, 4]))
    assert all(np.array_equal(a[n], b[n]) for n in a)


def test_a_hand_reaches_a_target_within_its_arm(rest):
    lat, up, fwd = body_axes(rest)
    target = rest["chest"] + 0.15 * fwd - 0.05 * lat   # before the chest, across from the left arm's side
    misses = []
    for k in range(30):
        p = reach_arm(rest, "L", target, np.random.default_rng([5, k]))
        misses.append(np.linalg.norm(p["hand.L"] - target))
        elbow = p["elbow.L"] - rest["shoulder.L"]
        assert elbow @ up < 0.1   # the elbow swivels to a natural side: not up over the shoulder
    hand = np.linalg.norm(rest["hand.L"] - rest["wrist.L"])   # the hand turns about the wrist, at random
    assert max(misses) < 1.2 * hand and np.median(misses) < 0.7 * hand


def test_targets_lie_on_and_around_the_body(rest):
    lat, up, fwd = body_axes(rest)
    hips, torso = rest["hips"], np.linalg.norm(rest["neck"] - rest["hips"])
    rng = np.random.default_rng(11)
    pts = np.array([reach_target(rest, "L", rng) - hips for _ in range(400)])
    assert np.all(pts @ fwd > -0.2 * torso)   # none behind the back
    assert np.all(pts @ up > -0.4 * torso) and np.all(pts @ up < 3.0 * torso)
    across = np.mean(pts @ lat < 0)   # the left hand over the right half of the body (crossed arms)
    assert 0.1 < across < 0.6
    assert len(TARGETS) == 7


def test_gripping_puts_both_hands_together_before_the_body(rest):
    lat, up, fwd = body_axes(rest)
    hand = np.linalg.norm(rest["hand.L"] - rest["wrist.L"])
    apart, crossed = [], 0
    for k in range(60):
        p = gripping(rest, np.random.default_rng([7, k]))
        for s in ("L", "R"):
            for a, b in BONES:
                assert np.linalg.norm(p[f"{b}.{s}"] - p[f"{a}.{s}"]) == pytest.approx(
                    np.linalg.norm(rest[f"{b}.{s}"] - rest[f"{a}.{s}"]), rel=1e-9)
            assert (p[f"hand.{s}"] - rest["chest"]) @ fwd > -0.1   # before the body (overhead: about over it)
        assert all(np.array_equal(p[n], rest[n]) for n in ("hips", "neck", "head", "hip.L", "knee.R"))
        apart.append(np.linalg.norm(p["hand.L"] - p["hand.R"]))
        crossed += (p["hand.L"] - rest["chest"]) @ lat < 0   # the left hand over the right half of the body
    assert np.median(apart) < 1.5 * hand and max(apart) < 3.0 * hand   # one thing held in both hands
    assert 10 < crossed < 50   # at the right shoulder (a bat), the left arm crosses the chest; at the left, not
    a, b = gripping(rest, np.random.default_rng(4)), gripping(rest, np.random.default_rng(4))
    assert all(np.array_equal(a[n], b[n]) for n in a)
