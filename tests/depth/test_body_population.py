"""The body-part forest's training population (sim/body_population.py): per-segment proportions, clothing and
hair as offset surfaces, and poses from real Kinect recordings; repository data only."""
from __future__ import annotations

from typing import cast

import numpy as np
import pytest

from kinect_retarget.assets import MAKEHUMAN_DIR
from kinect_retarget.depth.body_parts import BACKGROUND, PART
from kinect_retarget.sim.body_part_labels import vertex_parts
from kinect_retarget.sim.body_population import (
    GARMENTS,
    HAIR_MAX,
    PROPORTION_RANGES,
    SKIRT_FLARE,
    _outward,
    clothed_body,
    proportioned_body,
    random_proportions,
    take_points,
)
from kinect_retarget.sim.makehuman_body import load_body
from kinect_retarget.sim.mocap_pose import _rest_points, pose_from_points


@pytest.fixture(scope="module")
def body():
    return load_body(str(MAKEHUMAN_DIR))


def _length(p, a, b):
    return np.linalg.norm(p[a] - p[b])


def test_proportions_are_seeded_and_within_their_ranges(body):
    draws = [random_proportions(np.random.default_rng([7, k])) for k in range(200)]
    assert draws[3] == random_proportions(np.random.default_rng([7, 3]))
    for name, (lo, hi) in PROPORTION_RANGES.items():
        v = np.array([d[name] for d in draws])
        assert lo <= v.min() and v.max() <= hi and v.max() - v.min() > 0.6 * (hi - lo), name
    scales = draws[0]
    a, b = proportioned_body(body, scales, str(MAKEHUMAN_DIR)), proportioned_body(body, scales, str(MAKEHUMAN_DIR))
    assert np.array_equal(a.rest_vertices, b.rest_vertices)


def test_each_segment_is_scaled_and_the_mesh_stays_whole(body):
    scales = {"upperarm": 1.12, "forearm": 0.88, "hand": 1.15, "thigh": 0.9, "shin": 1.1, "torso": 1.12,
              "shoulders": 0.88, "hips": 1.15}
    new = proportioned_body(body, scales, str(MAKEHUMAN_DIR))
    r0, r1 = _rest_points(body), _rest_points(new)
    for seg, (a, b) in {"upperarm": ("shoulder", "elbow"), "forearm": ("elbow", "wrist"), "hand": ("wrist", "hand"),
                        "thigh": ("hip", "knee"), "shin": ("knee", "ankle")}.items():
        for s in ("L", "R"):
            ratio = _length(r1, f"{a}.{s}", f"{b}.{s}") / _length(r0, f"{a}.{s}", f"{b}.{s}")
            assert ratio == pytest.approx(scales[seg], abs=1e-6), (seg, s)
    assert _length(r1, "shoulder.L", "shoulder.R") / _length(r0, "shoulder.L", "shoulder.R") == pytest.approx(0.88)
    assert _length(r1, "hip.L", "hip.R") / _length(r0, "hip.L", "hip.R") == pytest.approx(1.15)
    assert (r1["neck"][1] - r1["hips"][1]) / (r0["neck"][1] - r0["hips"][1]) == pytest.approx(1.12, abs=0.01)
    # the skin follows: hand vertices move with the longer upper arm and shorter forearm, no edge tears
    labels = vertex_parts(body)
    hand = labels == PART["hand_left"]
    shift = np.linalg.norm(new.rest_vertices[hand].mean(0) - body.rest_vertices[hand].mean(0))
    expected = np.linalg.norm((r1["wrist.L"] - r1["shoulder.L"]) - (r0["wrist.L"] - r0["shoulder.L"]))
    assert shift > 0.5 * expected > 0.005
    q0, q1 = body.rest_vertices[body.quads], new.rest_vertices[new.quads]
    e0 = np.linalg.norm(q0 - np.roll(q0, 1, axis=1), axis=-1)
    e1 = np.linalg.norm(q1 - np.roll(q1, 1, axis=1), axis=-1)
    assert np.max(np.abs(e1 - e0)) < 0.01 and np.percentile(e1 / np.maximum(e0, 1e-6), 99) < 1.25


def test_clothing_and_hair_are_outward_offsets_that_keep_the_labels(body):
    labels = vertex_parts(body)
    a = clothed_body(body, labels, np.random.default_rng(11), skirt_chance=1.0)
    b = clothed_body(body, labels, np.random.default_rng(11), skirt_chance=1.0)
    assert np.array_equal(a[0].rest_vertices, b[0].rest_vertices) and np.array_equal(a[1], b[1])
    clothed, new_labels = a
    n = len(body.rest_vertices)
    assert np.array_equal(new_labels[:n], labels)   # the body's own vertices keep their parts
    move = clothed.rest_vertices[:n] - body.rest_vertices
    dist = np.linalg.norm(move, axis=1)
    most = sum(m for _, m in GARMENTS.values()) + HAIR_MAX
    assert dist.max() <= most + 1e-9 and dist.max() > 0.005
    moved = dist > 1e-6
    assert np.all(np.sum(move[moved] * _outward(body)[moved], axis=1) > 0.99 * dist[moved])   # along the normal
    # the skirt: a skinned tube around hips and thighs, labelled from the body beneath it
    extra = new_labels[n:]
    assert len(extra) > 100 and len(clothed.quads) > len(body.quads)
    lower = {PART[p] for p in ("torso_lower_left", "torso_lower_right", "hip_left", "hip_right", "thigh_left",
                               "thigh_right", "knee_left", "knee_right")}
    assert set(np.unique(extra)) <= lower and len(np.unique(extra)) >= 4
    assert np.allclose(clothed.weights.sum(axis=1), 1.0)
    tube = clothed.rest_vertices[n:]
    hips = _rest_points(body)["hips"]
    radius = np.hypot(tube[:, 0] - hips[0], tube[:, 2] - hips[2])
    assert radius.min() > 0.08 and radius.max() < 0.5 + SKIRT_FLARE[1]
    # with nothing to wear the body is unchanged
    bare, bare_labels = clothed_body(body, labels, cast(np.random.Generator, _NoClothes()), skirt_chance=0.0)
    assert np.array_equal(bare.rest_vertices, body.rest_vertices) and np.array_equal(bare_labels, labels)


class _NoClothes:
    """A generator whose every chance fails."""
    def random(self):
        return 1.0

    def uniform(self, lo, hi, size=None):
        return lo


def test_clothed_body_renders_with_labels_of_the_body_beneath(body):
    from kinect_retarget.depth.depth_camera import DepthCamera
    from kinect_retarget.sim.body_part_labels import render_parts, surface_labels
    from kinect_retarget.sim.depth_render import quad_sampler, surface_points
    labels = vertex_parts(body)
    cam = DepthCamera()
    seen = []
    for b, lab in ((body, labels), clothed_body(body, labels, np.random.default_rng(11), skirt_chance=1.0)):
        groups = quad_sampler(b.rest_vertices, b.quads, 2.5, cam)
        v = b.rest_vertices * [-1, 1, -1] + [0, 0, 2.5]
        _, image = render_parts(surface_points(v, b.quads, groups), surface_labels(lab, b.quads, groups), cam)
        seen.append(image != BACKGROUND)
    assert seen[1].sum() > 1.1 * seen[0].sum()   # the clothes and the skirt widen the silhouette


@pytest.mark.parametrize("path", ["kinect_v2/Ges01_wavehand.csv",
                                  "kinect_v2_vicon_uiprmd/Kinect/m07_s01_e01_positions.txt"])
def test_kinect_recordings_pose_the_body(data_dir, body, path):
    from kinect_retarget.takes import load_take
    take = load_take(data_dir / path)
    points = take_points(take, every=5)
    assert len(points) >= len(take.positions) // 5 - 1
    pose = {k: np.stack([p[k] for p in points]) for k in points[0]}
    posed = pose_from_points(body, pose)
    assert np.all(np.isfinite(posed.joints))
    from kinect_retarget.core.skeletons import KINECT_V1
    j = KINECT_V1.index
    for a, b, pa, pb in (("ElbowLeft", "WristLeft", "elbow.L", "wrist.L"), ("ShoulderRight", "ElbowRight",
                                                                                "shoulder.R", "elbow.R")):
        got = posed.joints[:, j(b)] - posed.joints[:, j(a)]
        want = pose[pb] - pose[pa]
        cos = np.sum(got * want, axis=1) / np.linalg.norm(got, axis=1) / np.linalg.norm(want, axis=1)
        assert np.degrees(np.arccos(np.clip(cos, -1, 1))).max() < 3.0, (a, b)
