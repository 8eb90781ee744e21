"""The source skeleton's overlay geometry (pure numpy): bones as parent->joint lines, joints coloured by
tracking state, untracked joints left out, and placed beside the character (first root and lowest foot at
the origin) on a real Kinect v2 take."""
from __future__ import annotations

import numpy as np
import pytest

from kinect_retarget.core.conventions import kinect_to_blender
from kinect_retarget.core.skeleton_overlay import COLORS, OverlayPlacement, skeleton_overlay
from kinect_retarget.core.skeletons import INFERRED, KINECT_V1, KINECT_V2, NOT_TRACKED, TRACKED
from kinect_retarget.takes import kinect_v2_csv


@pytest.fixture(scope="module")
def take(data_dir):
    return kinect_v2_csv.read(data_dir / "kinect_v2" / "Ges04_comehere.csv")


def test_every_bone_is_a_line_from_parent_to_joint(take):
    sk = KINECT_V2
    i = int(np.flatnonzero(np.all(take.states == TRACKED, axis=1))[0])
    g = skeleton_overlay(sk, take.positions[i], take.states[i])
    p = kinect_to_blender(take.positions[i])
    assert g.lines.shape == (2 * (len(sk) - 1), 3) and g.points.shape == (len(sk), 3)
    assert g.lines.dtype == np.float32 and g.line_colors.shape == (2 * (len(sk) - 1), 4)
    want = [(p[sk.parents[j]], p[j]) for j in range(len(sk)) if sk.parents[j] >= 0]  # in joint order
    np.testing.assert_allclose(g.lines.reshape(-1, 2, 3), np.array(want), atol=1e-6)
    np.testing.assert_allclose(g.point_colors, np.tile(COLORS[TRACKED], (len(sk), 1)))


def test_states_colour_joints_and_untracked_joints_are_left_out(take):
    sk = KINECT_V1
    pos = np.random.default_rng(3).normal(size=(len(sk), 3))
    states = np.full(len(sk), TRACKED, dtype=np.uint8)
    elbow, wrist, knee = sk.index("ElbowLeft"), sk.index("WristLeft"), sk.index("KneeRight")
    states[elbow] = INFERRED
    states[knee] = NOT_TRACKED
    pos[knee] = np.nan  # untracked: what takes hold there
    g = skeleton_overlay(sk, pos, states)
    assert len(g.points) == len(sk) - 1 and np.all(np.isfinite(g.lines))
    # the knee's two bones (hip->knee, knee->ankle) are gone
    assert len(g.lines) == 2 * (len(sk) - 1 - 2)
    p = kinect_to_blender(pos).astype(np.float32)
    colour_of = {tuple(pt): tuple(c) for pt, c in zip(g.points, g.point_colors)}
    assert colour_of[tuple(p[elbow])] == pytest.approx(COLORS[INFERRED])
    assert colour_of[tuple(p[wrist])] == pytest.approx(COLORS[TRACKED])
    ends = g.lines.reshape(-1, 2, 3)
    colours = g.line_colors.reshape(-1, 2, 4)[:, 0]
    for (a, b), c in zip(ends, colours):  # a bone touching the inferred elbow is amber, the others green
        touches = np.allclose(a, p[elbow]) or np.allclose(b, p[elbow])
        assert tuple(c) == pytest.approx(COLORS[INFERRED] if touches else COLORS[TRACKED])
    nothing = skeleton_overlay(sk, pos, np.zeros(len(sk), dtype=np.uint8))
    assert nothing.empty and len(nothing.lines) == 0


def test_placement_puts_the_performer_beside_the_character(take):
    sk = KINECT_V2
    placement = OverlayPlacement.for_take(sk, take.positions, take.states)
    origin = np.array([2.0, -1.0, 0.5])
    feet = [sk.index(n) for n in ("FootLeft", "FootRight", "AnkleLeft", "AnkleRight")]
    lowest, first = [], None
    for i in range(0, take.frame_count, 7):
        g = skeleton_overlay(sk, take.positions[i], take.states[i], origin, placement)
        p = kinect_to_blender(take.positions[i]) - [*placement.reference_xy, placement.floor] + origin
        np.testing.assert_allclose(g.points, p[take.states[i] != NOT_TRACKED], atol=1e-5)
        lowest.append(p[feet, 2][take.states[i, feet] != NOT_TRACKED].min())
        if first is None:
            first = p[sk.root]
    # the first root stands on the origin horizontally; no foot goes below the origin's height
    np.testing.assert_allclose(first[:2], origin[:2], atol=0.05)  # the first sampled frame is frame 0
    assert min(lowest) >= origin[2] - 1e-9 and min(lowest) < origin[2] + 0.05


def test_live_placement_learns_from_the_frames(take):
    sk = KINECT_V2
    placement = OverlayPlacement()
    i0, i1 = 0, 60
    g0 = skeleton_overlay(sk, take.positions[i0], take.states[i0], (0, 0, 0), placement)
    root0 = g0.points[list(np.flatnonzero(take.states[i0] != NOT_TRACKED)).index(sk.root)]
    np.testing.assert_allclose(root0[:2], 0, atol=1e-6)  # the first root is the reference
    moved = take.positions[i1].copy()
    moved[:, 0] += 0.5   # the performer stepped 0.5 m along Kinect X: Blender -X
    moved[:, 1] -= 0.2   # and everything is 0.2 m lower: the floor follows it down
    g1 = skeleton_overlay(sk, moved, take.states[i1], (0, 0, 0), placement)
    root1 = g1.points[list(np.flatnonzero(take.states[i1] != NOT_TRACKED)).index(sk.root)]
    p = kinect_to_blender(take.positions)
    np.testing.assert_allclose(root1[0], p[i1, sk.root, 0] - p[i0, sk.root, 0] - 0.5, atol=1e-5)
    assert placement.floor < kinect_to_blender(take.positions[i0])[:, 2].min()
