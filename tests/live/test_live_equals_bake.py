"""A live pose equals the baked pose for the same frame and settings (the real engine, no bpy)."""
import time
from dataclasses import replace

import numpy as np
import pytest

from kinect_retarget.core.kinect_rig_layout import generated_mapping, generated_rig, median_segment_lengths
from kinect_retarget.core.pipeline import RetargetPipeline, RetargetSettings
from kinect_retarget.live.session import LiveSession
from kinect_retarget.sources import TakePlayback
from kinect_retarget.takes import krtake

from kinect_retarget.core.quat import angle_between


@pytest.mark.parametrize("filter_name", ["none", "default"])
def test_live_pose_equals_baked_pose(wave_take, tmp_path, filter_name):
    # the take file keeps 5 decimals: play exactly representable positions so rounding does not blur the check
    wave_take.positions = np.round(wave_take.positions, 5)
    sk = wave_take.skeleton
    rig = generated_rig(sk, median_segment_lengths(wave_take))
    settings = RetargetSettings(filter=filter_name)
    live = RetargetPipeline(sk, rig, generated_mapping(sk), settings)
    applied = []
    s = LiveSession(TakePlayback(wave_take, speed=3.0), live, applied.append)
    s.start()
    s.start_recording(tmp_path / "rec.krtake")
    while s.pump():
        time.sleep(0.002)
    take = krtake.read(s.stop_recording())
    assert take.frame_count == wave_take.frame_count
    # bake the recording with the live root scale, one key per sample
    n = live.retargeter.scale_for(live.source_leg)
    bake = RetargetPipeline(sk, rig, generated_mapping(sk), replace(settings, root_scale=n, fps=100000.0))
    motion = bake.process_take(take)
    assert len(applied) >= 5  # how many are shown (not superseded) depends on machine load
    worst = 0.0
    for pose in applied:
        sample = int(np.argmin(np.abs(take.times - pose.time)))
        key = int(np.flatnonzero(motion.samples == sample)[0])
        err = np.degrees(angle_between(pose.quats, motion.quats[key])).max()
        worst = max(worst, err)
        assert err < 1e-6  # degrees; q and -q compare equal
        np.testing.assert_allclose(pose.root_location, motion.root_location[key], atol=1e-6)
    print(f"worst live-vs-baked angle {worst:.2e} deg over {len(applied)} poses")


def test_batch_equals_frame_by_frame(wave_take):
    """The pump filters every drained frame but solves only the newest: same pose as process_frame each."""
    sk = wave_take.skeleton
    rig = generated_rig(sk, median_segment_lengths(wave_take))
    one = RetargetPipeline(sk, rig, generated_mapping(sk), RetargetSettings())
    many = RetargetPipeline(sk, rig, generated_mapping(sk), RetargetSettings())
    states = wave_take.states.copy()
    states[7:9] = 0  # untracked frames inside a batch are skipped by both
    bounds = [0, 1, 5, 12, 13, 40, 90]
    for a, b in zip(bounds[:-1], bounds[1:]):
        last = None
        for i in range(a, b):
            last = one.process_frame(wave_take.positions[i], states[i], float(wave_take.times[i])) or last
        got = many.process_frames(wave_take.positions[a:b], states[a:b], wave_take.times[a:b])
        assert np.degrees(angle_between(got.quats, last.quats)).max() < 1e-9
        np.testing.assert_allclose(got.root_location, last.root_location, atol=1e-12)
        assert got.time == last.time
