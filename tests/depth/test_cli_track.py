"""`python -m kinect_retarget track`: capture .npz -> take; clear errors for bad input."""
from __future__ import annotations

import numpy as np
import pytest

from kinect_retarget.cli import main
from kinect_retarget.core.skeletons import NOT_TRACKED
from kinect_retarget.depth.output_smoothing import MAX_TRAIL, REST_MAX_MOVE
from kinect_retarget.depth.sdk_joints import to_sdk_joints
from kinect_retarget.depth.take_smoothing import smooth_recorded_joints
from kinect_retarget.takes import load_take


def test_track_capture_writes_a_take(rendered, tmp_path, capsys):
    seq, path = rendered
    out = tmp_path / "hop.krtake"
    assert main(["track", str(path), "--out", str(out)]) == 0
    take = load_take(out)
    assert take.frame_count == len(seq.mm) and take.skeleton.name == "kinect_v1"
    np.testing.assert_allclose(take.times, seq.times, atol=1e-6)
    assert np.all(take.states != NOT_TRACKED)
    assert np.mean(np.linalg.norm(take.positions - seq.joints, axis=-1)) < 0.1
    assert "skeleton in 100 %" in capsys.readouterr().out


def test_track_cleans_the_recorded_take_and_its_flags_skip_the_smoothing(rendered, tmp_path):
    seq, path = rendered
    takes = {}
    for name, flags in (("take", []), ("live", ["--live-smoothing"]), ("raw", ["--raw-joints"])):
        out = tmp_path / f"{name}.krtake"
        assert main(["track", str(path), "--out", str(out), *flags]) == 0
        takes[name] = load_take(out)
    take, live, raw = takes["take"], takes["live"], takes["raw"]
    np.testing.assert_array_equal(take.states, raw.states)
    np.testing.assert_array_equal(live.states, raw.states)
    trail = np.linalg.norm(live.positions - raw.positions, axis=-1)
    most = MAX_TRAIL + REST_MAX_MOVE + 1e-4   # the filter's bound and the rest line's (float32 takes)
    assert 0.0 < trail.max() <= most   # the live tracker's steadying: never far from the raw joints
    # by default the recorded take is also cleaned with its future frames (float32 takes: 1e-5 m)
    np.testing.assert_allclose(take.positions, smooth_recorded_joints(live.positions, live.states, live.times),
                               atol=1e-5)
    assert np.abs(take.positions - live.positions).max() > 1e-3


def test_track_raw_only_capture_with_device_ticks(rendered, tmp_path):
    seq, _ = rendered
    path = tmp_path / "raw.npz"
    ticks = (seq.times * 60_000_000).astype(np.int64) + (1 << 32) - 3_000_000   # the clock wraps mid-take
    np.savez(path, raw=seq.raw[:4], timestamp=ticks[:4] % (1 << 32))
    out = tmp_path / "raw.krtake"
    assert main(["track", str(path), "--out", str(out)]) == 0
    take = load_take(out)
    np.testing.assert_allclose(take.times, seq.times[:4] - seq.times[0], atol=1e-6)


@pytest.mark.parametrize("content, message", [
    ({"mm": np.zeros((2, 240, 320), np.uint16)}, "expected (frames, 480, 640)"),
    ({"depth": np.zeros((2, 480, 640), np.uint16)}, "expected an array named 'mm' or 'raw'"),
    ({"mm": np.zeros((2, 480, 640), np.uint16), "times": np.array([0.1, 0.1])}, "frame 1 is not later"),
    ({"mm": np.zeros((3, 480, 640), np.uint16), "times": np.array([0.0, 0.1])}, "3 depth frames but 2"),
])
def test_bad_captures_are_clear_errors(tmp_path, capsys, content, message):
    path = tmp_path / "bad.npz"
    np.savez(path, **content)
    assert main(["track", str(path), "--out", str(tmp_path / "x.krtake")]) == 2
    err = capsys.readouterr().err
    assert message in err and str(path) in err and "Traceback" not in err


def test_not_an_npz_and_missing_file(tmp_path, capsys):
    junk = tmp_path / "junk.npz"
    junk.write_bytes(b"this is not numpy")
    assert main(["track", str(junk), "--out", str(tmp_path / "x.krtake")]) == 2
    assert "not a readable depth capture" in capsys.readouterr().err
    assert main(["track", str(tmp_path / "nope.npz"), "--out", str(tmp_path / "x.krtake")]) == 2
    assert "no such file" in capsys.readouterr().err



def test_empty_cut_off_and_single_array_captures_are_clear_errors(tmp_path, capsys):
    whole = tmp_path / "whole.npz"
    np.savez(whole, mm=np.zeros((2, 480, 640), np.uint16))
    empty, cut, single = tmp_path / "empty.npz", tmp_path / "cut.npz", tmp_path / "single.npz"
    empty.write_bytes(b"")
    cut.write_bytes(whole.read_bytes()[:1000])  # a copy interrupted early: no zip directory at the end
    with open(single, "wb") as f:
        np.save(f, np.zeros(3))
    for path, message in ((empty, "not a readable depth capture"), (cut, "not a readable depth capture"),
                          (single, "one unnamed array")):
        assert main(["track", str(path), "--out", str(tmp_path / "x.krtake")]) == 2
        err = capsys.readouterr().err
        assert message in err and str(path) in err

def test_all_zero_capture_gives_an_untracked_take(tmp_path):
    path = tmp_path / "empty.npz"
    np.savez(path, mm=np.zeros((3, 480, 640), np.uint16))
    out = tmp_path / "empty.krtake"
    assert main(["track", str(path), "--out", str(out)]) == 0
    assert np.all(load_take(out).states == NOT_TRACKED)


def test_track_replays_a_usb_packet_dump(rendered, tmp_path):
    from kinect_retarget.device.dump import DumpWriter
    from kinect_retarget.sim.emulated_stream import packets_for_frames
    seq, _ = rendered
    dump = tmp_path / "capture.dump"
    with DumpWriter(dump) as w:
        w.write_packets(packets_for_frames(list(seq.raw[:4]), 4))
    out = tmp_path / "replay.krtake"
    assert main(["track", "--replay", str(dump), "--out", str(out)]) == 0
    take = load_take(out)
    assert take.frame_count == 4
    np.testing.assert_allclose(np.diff(take.times), 1 / 30, atol=1e-3)
    assert np.all(take.states != NOT_TRACKED)
    hip_centre = to_sdk_joints(seq.joints[:4])[:, 0]   # the SDK's HipCenter, as the tracker reports it
    assert np.linalg.norm(take.positions[:, 0] - hip_centre, axis=-1).max() < 0.1
    # a truncated dump still gives the frames completed before the damage, with a warning
    data = dump.read_bytes()
    (tmp_path / "cut.dump").write_bytes(data[: len(data) * 3 // 4 + 7])
    assert main(["track", "--replay", str(tmp_path / "cut.dump"), "--out", str(out)]) == 0
    assert load_take(out).frame_count == 3


def test_replayed_frame_with_a_lost_packet_does_not_pass_filler_for_depth(rendered, tmp_path):
    """The pixels of a packet lost on the wire are "no reading" for the tracker, as `capture --replay` and
    the live stream decode them (device/decode.py), not whatever filler the reassembly left there."""
    from kinect_retarget.cli.track_commands import load_replay
    from kinect_retarget.device.dump import DumpWriter
    from kinect_retarget.sim.emulated_stream import DEPTH_PACKETS_PER_FRAME, packets_for_frames
    seq, _ = rendered
    packets = packets_for_frames(list(seq.raw[:3]), 3)
    lost = DEPTH_PACKETS_PER_FRAME + DEPTH_PACKETS_PER_FRAME // 2   # mid-image (the person) of frame 1
    dump = tmp_path / "lossy.dump"
    with DumpWriter(dump) as w:
        w.write_packets(packets[:lost] + packets[lost + 1:])
    mm, _, _ = load_replay(str(dump))
    from kinect_retarget.device.dump import replay_dump
    frames, _, _ = replay_dump(dump)
    holey = [i for i, f in enumerate(frames) if f.holes]
    assert holey, "the lost packet left no hole"
    for i in holey:
        for start, end in frames[i].holes:
            first, last = (8 * start) // 11, (8 * end - 1) // 11
            assert np.all(mm[i].reshape(-1)[first:last + 1] == 0)
