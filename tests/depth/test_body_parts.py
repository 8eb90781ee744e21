"""The shipped body-part forest on a rendered frame, and the per-pixel labels it was trained on."""
from __future__ import annotations

import numpy as np
import pytest

from kinect_retarget.core.skeletons import KINECT_V1
from kinect_retarget.depth.body_parts import BACKGROUND, PART, PARTS
from kinect_retarget.depth.part_forest import MODEL_PATH, load_forest
from kinect_retarget.depth.part_proposals import propose
from kinect_retarget.depth.skeleton_tracker import SkeletonTracker, TrackerSettings


def test_shipped_forest_classifies_a_rendered_frame(rendered):
    forest = load_forest(MODEL_PATH)
    assert forest is not None, f"{MODEL_PATH} is missing or unreadable"
    assert forest.leaf_probs.shape[1] == len(PARTS) and len(forest.roots) >= 1
    seq, _ = rendered
    tracker = SkeletonTracker(gravity=seq.gravity, settings=TrackerSettings(part_forest=None))
    for f in range(4):
        tracker.update(seq.mm[f], seq.times[f])
    props = propose(forest, tracker.last_grid, tracker.last_mask)
    assert np.allclose(props.probs.sum(axis=1), 1.0, atol=0.05)
    gt = seq.joints[3]
    rows, cols = props.cells
    pts = tracker.last_grid.xyz[rows, cols]
    label = np.argmax(props.probs, axis=1)
    near_head = np.linalg.norm(pts - gt[KINECT_V1.index("Head")], axis=1) < 0.12   # the head joint is its centre
    assert near_head.sum() > 10 and np.mean(label[near_head] == PART["head"]) > 0.6
    for joint, bound in (("Head", 0.10), ("FootLeft", 0.15), ("FootRight", 0.15)):
        j = KINECT_V1.index(joint)
        assert props.confidence[j] > 0, joint
        assert np.linalg.norm(props.positions[j] - gt[j]) < bound, joint


def test_unreadable_forest_leaves_the_tracker_without_parts(tmp_path):
    bad = tmp_path / "forest.npz"
    bad.write_bytes(b"not a forest")
    assert load_forest(str(bad)) is None
    assert SkeletonTracker(settings=TrackerSettings(part_forest=str(bad))).forest is None


def test_part_labels_from_skin_weights(data_dir):
    from kinect_retarget.depth.depth_camera import DepthCamera
    from kinect_retarget.sim.body_part_labels import render_parts, surface_labels, vertex_parts
    from kinect_retarget.sim.depth_render import quad_sampler, surface_points
    from kinect_retarget.sim.makehuman_body import load_body
    body = load_body(str(data_dir / "meshes" / "makehuman"))
    labels = vertex_parts(body)
    counts = np.bincount(labels, minlength=len(PARTS))
    assert np.all(counts > 0)   # every part has skin
    for name in PARTS:
        if name.endswith("_left") and not name.startswith("torso"):   # symmetric limbs (the midline is one side)
            assert counts[PART[name]] == counts[PART[name[:-5] + "_right"]], name
    # the performer's left (MakeHuman +X) is labelled left
    assert np.all(body.rest_vertices[labels == PART["hand_left"], 0] > 0)
    cam = DepthCamera()
    groups = quad_sampler(body.rest_vertices, body.quads, 2.5, cam)
    v = body.rest_vertices * [-1, 1, -1] + [0, 0, 2.5]   # turned to face the sensor, 2.5 m away
    depth, image = render_parts(surface_points(v, body.quads, groups), surface_labels(labels, body.quads, groups), cam)
    seen = image != BACKGROUND
    assert np.array_equal(seen, np.isfinite(depth))
    cols = np.nonzero(image == PART["hand_left"])[1]
    assert len(cols) > 20 and np.all(cols > cam.cx)   # facing the sensor, the left hand is on the image's right


@pytest.mark.parametrize("nearer", [1.0, 0.12])
def test_forest_classifies_as_a_node_by_node_walk_with_probe_features(rendered, nearer):
    # the fast path reads node records and probes from a grid in a background margin; the reference follows
    # each cell down each tree. nearer 0.12 puts the performer 0.3 m away, beyond the margin's cap
    from kinect_retarget.depth.part_forest import MAX_MARGIN, probe_features
    forest = load_forest(MODEL_PATH)
    seq, _ = rendered
    tracker = SkeletonTracker(gravity=seq.gravity, settings=TrackerSettings(part_forest=None))
    tracker.update(seq.mm[0], seq.times[0])
    grid, mask = tracker.last_grid, tracker.last_mask
    zb = np.where(mask, grid.z * nearer, 10.0)
    if nearer < 1:
        assert forest.reach * grid.camera.f / grid.step / zb[mask].min() > MAX_MARGIN
    zb[:, :3] = 0.8                                       # near probes at the image's edge too
    rows, cols = np.nonzero(mask)
    pick = np.random.default_rng(3).choice(len(rows), 60, replace=False)
    rows, cols = np.r_[rows[pick], 0, grid.z.shape[0] - 1], np.r_[cols[pick], 1, grid.z.shape[1] - 2]
    cells_per_m = grid.camera.f / grid.step
    probs = forest.classify(zb, rows, cols, cells_per_m)
    for i in range(len(rows)):
        expect = np.zeros(len(PARTS))
        for node in forest.roots:
            while forest.left[node] != node:
                f = probe_features(zb, rows[i:i + 1], cols[i:i + 1], forest.offsets[forest.feature[node]][None],
                                   cells_per_m)[0]
                node = forest.left[node] if f <= forest.threshold[node] else forest.right[node]
            expect += forest.leaf_probs[node] / 255.0
        assert np.allclose(probs[i], expect / len(forest.roots), atol=1e-6), i


def test_probe_features_read_background_off_the_grid():
    # written out with explicit bounds, as the features are defined
    from kinect_retarget.depth.part_forest import BACKGROUND_DEPTH, probe_features
    rng = np.random.default_rng(11)
    zb = np.where(rng.random((30, 40)) > 0.3, rng.uniform(1.5, 3.0, (30, 40)), BACKGROUND_DEPTH)
    rows, cols = np.nonzero(zb < BACKGROUND_DEPTH)
    offsets = rng.uniform(-0.8, 0.8, (25, 2, 2))          # many probes land off the 30 x 40 grid
    got = probe_features(zb, rows, cols, offsets[None], 140.0)
    for i in range(0, len(rows), 7):
        for k in range(len(offsets)):
            vals = []
            for probe in offsets[k]:
                r = rows[i] + int(np.rint(probe[1] * 140.0 / zb[rows[i], cols[i]]))
                c = cols[i] + int(np.rint(probe[0] * 140.0 / zb[rows[i], cols[i]]))
                vals.append(zb[r, c] if 0 <= r < 30 and 0 <= c < 40 else BACKGROUND_DEPTH)
            assert got[i, k] == vals[0] - vals[1]


def test_a_cell_without_depth_leaves_the_other_cells_as_they_were(rendered):
    # no tracked cell should lack depth, but one that does (0 or NaN) must not stop the frame's classification
    forest = load_forest(MODEL_PATH)
    seq, _ = rendered
    tracker = SkeletonTracker(gravity=seq.gravity, settings=TrackerSettings(part_forest=None))
    tracker.update(seq.mm[0], seq.times[0])
    grid, mask = tracker.last_grid, tracker.last_mask
    zb = np.where(mask, grid.z, 10.0)
    rows, cols = np.nonzero(mask)
    cells_per_m = grid.camera.f / grid.step
    clean = forest.classify(zb, rows, cols, cells_per_m)
    for bad in (0.0, np.nan):
        broken = zb.copy()
        broken[rows[0], cols[0]] = bad
        with np.errstate(all="ignore"):
            probs = forest.classify(broken, rows, cols, cells_per_m)
        assert probs.shape == clean.shape and np.allclose(probs[0].sum(), 1.0, atol=0.05)
        # only cells whose probes could read that cell may differ
        far = np.hypot(rows - rows[0], cols - cols[0]) > forest.reach * cells_per_m / zb[mask].min() + 1
        assert far.sum() > 10 and np.array_equal(probs[far], clean[far])
