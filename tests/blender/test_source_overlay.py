"""The source skeleton in the 3D View: its draw handler comes and goes with the add-on, the sidebar's toggle
shows or hides it, and what it would draw is the take's frame at the scene's frame (no live) or each
performer's newest frame (live), beside each character at the sidebar's offset. (Headless Blender has no
GPU drawing; the draw itself is not run here.)"""
from __future__ import annotations

import time

import bpy
import numpy as np
import pytest

import kinect_retarget
from kinect_retarget.blender.io.kinect_rig import build_kinect_rig
from kinect_retarget.blender.live import live_runtime as live
from kinect_retarget.blender.ui import source_overlay
from kinect_retarget.core.kinect_rig_layout import median_segment_lengths
from kinect_retarget.core.skeleton_overlay import OverlayPlacement, skeleton_overlay
from kinect_retarget.core.skeletons import KINECT_V2, NOT_TRACKED
from kinect_retarget.takes import load_take
from tests.takes.two_performers import write_two_person_ntu


def test_the_draw_handler_comes_and_goes_with_the_add_on():
    assert not source_overlay.handler_registered()
    for _ in range(2):  # again after unregistering: nothing left over, nothing doubled
        kinect_retarget.register()
        try:
            assert source_overlay.handler_registered()
            handle = source_overlay._handle
            source_overlay.register_extra()  # idempotent
            assert source_overlay._handle is handle
        finally:
            kinect_retarget.unregister()
        assert not source_overlay.handler_registered()
    source_overlay._draw()  # without a scene setting or a GPU it draws nothing and raises nothing


@pytest.fixture
def scene(data_dir, tmp_path):
    kinect_retarget.register()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    path = write_two_person_ntu(data_dir, tmp_path / "S001C001P001R001A050.skeleton")
    takes = load_take(path), load_take(path, body=1)
    sc = bpy.context.scene
    rigs = [build_kinect_rig(sc, KINECT_V2, median_segment_lengths(t), n) for t, n in zip(takes, ("Alice", "Bob"))]
    rigs[1].location = (3.0, 0.0, 0.0)
    bpy.context.view_layer.update()  # the overlay reads each rig's world matrix
    s = sc.kinect_retarget
    s.initialised = True
    s.source, s.take_path, s.armature, s.speed, s.loop = "TAKE", str(path), rigs[0], 4.0, False
    sc.render.fps, sc.render.fps_base, sc.frame_start = 30, 1.0, 1
    yield sc, rigs, takes, path
    live.stop_live(bake=False)
    kinect_retarget.unregister()
    bpy.ops.wm.read_factory_settings(use_empty=True)


def test_a_loaded_take_is_drawn_at_the_scene_frame_beside_each_rig(scene):
    sc, (alice, bob), (a, b), path = scene
    s = sc.kinect_retarget
    assert source_overlay.overlay_geometries(bpy.context) == []  # toggle off
    s.show_source = True
    s.source_offset = (1.0, 0.5, 0.0)
    sc.frame_set(11)  # 10 frames after the start at 30 fps: take sample 10
    geoms = source_overlay.overlay_geometries(bpy.context)
    assert len(geoms) == 1
    want = skeleton_overlay(KINECT_V2, a.positions[10], a.states[10], (1.0, 0.5, 0.0),
                            OverlayPlacement.for_take(KINECT_V2, a.positions, a.states))
    np.testing.assert_allclose(geoms[0].lines, want.lines)
    np.testing.assert_allclose(geoms[0].point_colors, want.point_colors)
    # the other performer, body 1, beside its own rig
    item = s.performers.add()
    item.armature, item.body = bob, 1
    geoms = source_overlay.overlay_geometries(bpy.context)
    assert len(geoms) == 2
    want_b = skeleton_overlay(KINECT_V2, b.positions[10], b.states[10], (4.0, 0.5, 0.0),
                              OverlayPlacement.for_take(KINECT_V2, b.positions, b.states))
    np.testing.assert_allclose(geoms[1].points, want_b.points)
    # the frame moves the skeleton; moving the rig moves its skeleton with it
    sc.frame_set(41)
    later = source_overlay.overlay_geometries(bpy.context)[0]
    assert np.abs(later.points - geoms[0].points).max() > 0.01
    alice.location = (0.0, 2.0, 0.0)
    bpy.context.view_layer.update()
    moved = source_overlay.overlay_geometries(bpy.context)[0]
    np.testing.assert_allclose(moved.points - later.points, np.tile([0.0, 2.0, 0.0], (len(later.points), 1)),
                               atol=1e-5)
    s.show_source = False
    assert source_overlay.overlay_geometries(bpy.context) == []


def test_a_bad_take_draws_nothing_and_says_why(scene, tmp_path):
    sc, *_ = scene
    s = sc.kinect_retarget
    s.show_source = True
    bad = tmp_path / "bad.csv"
    bad.write_text("not a take\n")
    s.take_path = str(bad)
    assert source_overlay.overlay_geometries(bpy.context) == []
    assert "unknown take format" in source_overlay.loaded_take(str(bad), 0)


def test_live_draws_each_performers_newest_frame(scene):
    sc, (alice, bob), (a, b), path = scene
    s = sc.kinect_retarget
    s.show_source = True
    item = s.performers.add()
    item.armature, item.body = bob, 1
    c = live.start_live(bpy.context, use_timer=False)
    end = time.perf_counter() + 30
    while time.perf_counter() < end and not (c.session.last_frame and c.followers[0].session.last_frame):
        live.pump_live()
        time.sleep(0.002)
    geoms = source_overlay.overlay_geometries(bpy.context)
    assert len(geoms) == 2
    for g, ctrl, obj in zip(geoms, (c, c.followers[0]), (alice, bob)):
        f = ctrl.session.last_frame
        assert len(g.points) == int(np.count_nonzero(f.states != NOT_TRACKED))
        # beside its own rig: the lowest foot seen so far stands at the rig's origin + offset
        assert g.points[:, 2].min() >= obj.location.z - 1e-5
        assert abs(np.mean(g.points[:, 0]) - (obj.location.x + 1.0)) < 0.6
    live.stop_live(bake=False)
