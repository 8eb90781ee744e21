"""The whole tracker on a short rendered sequence of real mocap, and on bad input."""
from __future__ import annotations

import numpy as np
import pytest

from kinect_retarget.core.skeletons import NOT_TRACKED, TRACKED
from kinect_retarget.sim.depth_scoring import score
from kinect_retarget.depth.sdk_joints import to_sdk_joints
from kinect_retarget.depth.skeleton_tracker import SkeletonTracker, track_depth_frames


def test_tracks_rendered_mocap_within_bound(rendered):
    seq, _ = rendered
    take = track_depth_frames(seq.mm, seq.times, gravity=seq.gravity)
    sc = score(take.positions, take.states, seq.joints, seq.present)
    assert sc.coverage == 1.0 and sc.nan_frames == 0
    assert sc.mean_error < 0.08, f"mean joint error {sc.mean_error:.3f} m"
    assert sc.per_joint[0] < 0.10 and sc.per_joint[3] < 0.10       # hip centre and head
    assert sc.swaps_over_3 == 0
    assert np.mean(take.states == TRACKED) > 0.5
    # calibration measured a plausible standing height for the 1.67 m MakeHuman body
    assert 1.45 < take.metadata["calibrated_height_m"] < 1.8


def test_same_frames_same_result(rendered):
    seq, _ = rendered
    a = track_depth_frames(seq.mm[:5], seq.times[:5], gravity=seq.gravity)
    b = track_depth_frames(seq.mm[:5], seq.times[:5], gravity=seq.gravity)
    assert np.array_equal(a.positions, b.positions) and np.array_equal(a.states, b.states)


@pytest.mark.parametrize("frame, why", [
    (np.zeros((480, 640), np.uint16), "no depth"),
    (np.full((480, 640), 2047, np.uint16), "no person"),      # raw 'no reading' mistaken for mm: a wall at 2 m
    (np.full((480, 640), 65535, np.uint16), "no depth"),
    (np.zeros((240, 320), np.uint16), "shape"),
    (np.zeros((480, 640, 3), np.uint16), "shape"),
    (np.full((480, 640), np.nan), "no depth"),
    (np.array(5), "shape"),
])
def test_bad_depth_gives_no_skeleton(frame, why):
    tr = SkeletonTracker()
    pos, st = tr.update(frame, 0.0)
    assert pos.shape == (20, 3) and st.shape == (20,)
    assert np.all(st == NOT_TRACKED) and np.all(np.isfinite(pos))
    assert why in tr.status


def test_bad_frame_in_the_middle_then_recovery(rendered):
    seq, _ = rendered
    tr = SkeletonTracker(gravity=seq.gravity)
    for i in range(4):
        tr.update(seq.mm[i], seq.times[i])
    pos, st = tr.update(np.zeros((10, 10), np.uint16), seq.times[4])
    assert np.all(st == NOT_TRACKED)
    pos, st = tr.update(seq.mm[5], seq.times[5])
    assert np.all(st != NOT_TRACKED)
    assert np.linalg.norm(pos[0] - to_sdk_joints(seq.joints[5])[0]) < 0.12


def test_feet_out_of_the_image_are_not_claimed(rendered, camera):
    """The performer's shins end at the image's bottom edge (the frames moved down so the feet leave the
    view, as when someone steps close): what the surface ends on there is not a foot, so the feet and ankles
    are reported inferred, and placed below the edge rather than on it; with both legs clipped the hips are
    inferred too (the SDK's "clipped bottom")."""
    seq, _ = rendered
    from kinect_retarget.core.skeletons import KINECT_V1
    foot, ankle = [KINECT_V1.index(f"Foot{s}") for s in ("Left", "Right")], \
        [KINECT_V1.index(f"Ankle{s}") for s in ("Left", "Right")]
    gt = seq.joints[0]
    knee_row = camera.cy - camera.f * gt[KINECT_V1.index("KneeLeft"), 1] / gt[KINECT_V1.index("KneeLeft"), 2]
    ankle_row = camera.cy - camera.f * gt[ankle[0], 1] / gt[ankle[0], 2]
    shift = int(480 - (knee_row + ankle_row) / 2)          # the image now ends mid-shin
    tracker = SkeletonTracker(gravity=seq.gravity)
    for i in range(len(seq.mm)):
        moved = np.zeros_like(seq.mm[i])
        moved[shift:] = seq.mm[i][:-shift]
        pos, st = tracker.update(moved, seq.times[i])
        assert np.all(st[foot + ankle] != TRACKED), f"frame {i}: a foot claimed at the image's edge"
        hips = [KINECT_V1.index(n) for n in ("HipCenter", "HipLeft", "HipRight")]
        assert np.all(st[hips] != TRACKED)                  # both legs clipped: nothing below checks the hips
        rows = camera.cy - camera.f * pos[foot, 1] / pos[foot, 2]
        assert np.all(rows > 480 - 8)                      # continued past the edge, not stopped on it


def test_gravity_of_any_scale_gives_the_same_skeleton(rendered):
    """An accelerometer reads about 9.8 m/s^2, the synthetic frames carry a unit vector: the tracker keeps
    only the direction. Without a floor in view (rows below the hips blanked) it leans on gravity alone."""
    seq, _ = rendered
    frames = seq.mm[:4].copy()
    frames[:, 300:] = 0
    unit, scaled = SkeletonTracker(gravity=seq.gravity), SkeletonTracker(gravity=9.81 * np.asarray(seq.gravity))
    for i, frame in enumerate(frames):
        a, b = unit.update(frame, seq.times[i]), scaled.update(frame, seq.times[i])
        assert unit.floor is None
        np.testing.assert_allclose(a[0], b[0], atol=1e-9)
        np.testing.assert_array_equal(a[1], b[1])


def test_pre_segmented_frames_without_floor_or_gravity(rendered):
    """Frames with only the person's pixels (floor and background removed, as some recorded datasets
    store them) and no accelerometer: the tracker takes gravity as level, finds no floor, and still measures
    the performer's height above their own lowest point."""
    seq, _ = rendered
    from kinect_retarget.core.conventions import depth_pixel_to_kinect
    cam = SkeletonTracker().camera
    v, u = np.mgrid[0:480, 0:640]
    mm = seq.mm.copy()
    for f in mm:
        xyz = depth_pixel_to_kinect(u, v, f * 0.001, cam.f, cam.cx, cam.cy)
        level_height = xyz @ -seq.gravity                # metres above the sensor, along gravity
        f[(level_height < -0.88) | (xyz[..., 2] > 4.4)] = 0   # floor (sensor 0.9 m above it) and back wall
    tracker = SkeletonTracker()
    pos = np.stack([tracker.update(f, t)[0] for f, t in zip(mm, seq.times)])
    assert tracker.floor is None and tracker.calibration.frames > 0
    assert 1.5 < tracker.calibration.height < 1.8, tracker.calibration.height
    err = np.linalg.norm(pos - to_sdk_joints(seq.joints), axis=-1)
    assert err.mean() < 0.08, err.mean()


def test_a_head_extremity_away_from_the_head_part_is_not_measured(rendered, monkeypatch):
    """Hands held over the head (a basketball shot) give the fit's head extremity to the hands: where the
    forest's confident head part lies elsewhere, the frame is not a standing-height measurement."""
    from dataclasses import replace

    from kinect_retarget.core.conventions import depth_pixel_to_kinect
    from kinect_retarget.core.skeletons import KINECT_V1
    from kinect_retarget.depth import skeleton_tracker
    seq, _ = rendered
    cam = SkeletonTracker().camera
    v, u = np.mgrid[0:480, 0:640]
    mm = seq.mm.copy()
    for f in mm:   # pre-segmented (no floor): the height comes from the tracker's own measurements
        xyz = depth_pixel_to_kinect(u, v, f * 0.001, cam.f, cam.cx, cam.cy)
        f[((xyz @ -seq.gravity) < -0.88) | (xyz[..., 2] > 4.4)] = 0

    def heights(shift):
        real = skeleton_tracker.propose

        def moved_head(*args):
            props = real(*args)
            pos, conf = props.positions.copy(), props.confidence.copy()
            pos[KINECT_V1.index("Head")] += shift
            conf[KINECT_V1.index("Head")] = 1.0   # as sure as a head gets
            return replace(props, positions=pos, confidence=conf)

        monkeypatch.setattr(skeleton_tracker, "propose", moved_head)
        tracker = SkeletonTracker()
        for f, t in zip(mm, seq.times):
            tracker.update(f, t)
        return tracker.calibration.frames

    assert heights([0.0, 0.0, 0.0]) > 0
    assert heights([0.0, -0.4, 0.0]) == 0   # the head part 40 cm below the extremity: not measured


def test_calibration_measures_the_torso_patch_where_it_grew_not_where_the_head_pinned_it(rendered, monkeypatch):
    """The calibration's torso-patch height says where the pin expects the head top; measured on the pinned
    torso it would follow the pin's own moves (on real depth, a torso seeded where the forest sees it lost
    subject 4's head that way). A pin moved 10 cm up leaves the measured patch height as it was."""
    from kinect_retarget.core.conventions import depth_pixel_to_kinect
    from kinect_retarget.depth import skeleton_fit
    seq, _ = rendered
    cam = SkeletonTracker().camera
    v, u = np.mgrid[0:480, 0:640]
    mm = seq.mm.copy()
    for f in mm:   # pre-segmented (no floor, as the real benchmark's frames)
        xyz = depth_pixel_to_kinect(u, v, f * 0.001, cam.f, cam.cx, cam.cy)
        f[((xyz @ -seq.gravity) < -0.88) | (xyz[..., 2] > 4.4)] = 0

    def patch_height():
        tracker = SkeletonTracker()
        for f, t in zip(mm, seq.times):
            tracker.update(f, t)
        assert tracker.calibration.frames > 0
        return tracker.calibration.torso_patch_height

    grown = patch_height()
    real = skeleton_fit._pin_along_axis

    def pinned_higher(*args, **kwargs):
        head, shift, centre, axis, lat, facing = real(*args, **kwargs)
        return head, shift, centre + 0.1 * axis, axis, lat, facing

    assert 0.5 < grown < 0.75, grown
    monkeypatch.setattr(skeleton_fit, "_pin_along_axis", pinned_higher)
    assert abs(patch_height() - grown) < 0.01
