"""`python -m kinect_retarget live`: the headless pump loop, its JSON line, recording and bake into a .blend."""
from __future__ import annotations

import json
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np

from kinect_retarget.sources.osc_codec import encode_message
from kinect_retarget.takes import krtake

REPO = Path(__file__).resolve().parents[2]
SAMPLE = REPO / "sample_takes" / "kinect_v2_ges01_wavehand.krtake"


def run_cli(*args, timeout=120):
    proc = subprocess.run([sys.executable, "-m", "kinect_retarget", "live", *args], cwd=REPO,
                          capture_output=True, text=True, timeout=timeout)
    return proc


def test_live_take_records_bakes_and_prints_one_json_line(tmp_path):
    rec, out = tmp_path / "rec.krtake", tmp_path / "out.blend"
    proc = run_cli("--source", f"take:{SAMPLE}", "--speed", "4", "--seconds", "5", "--record", str(rec),
                   "--out", str(out))
    assert proc.returncode == 0, proc.stderr[-2000:]
    lines = proc.stdout.strip().splitlines()
    assert len(lines) == 1, proc.stdout
    stats = json.loads(lines[0])
    take = krtake.read(SAMPLE)
    assert stats["received"] == take.frame_count == stats["recorded"]
    assert stats["applied"] + stats["dropped"] + stats["untracked"] == stats["received"]
    assert stats["latency_p50_ms"] is not None and stats["latency_p99_ms"] >= stats["latency_p50_ms"]
    assert krtake.read(rec).frame_count == take.frame_count
    assert out.is_file() and stats["action"].startswith("KinectRig_live_")


def test_live_bad_source_is_a_clear_error(tmp_path):
    proc = run_cli("--source", f"take:{tmp_path / 'missing.krtake'}", "--seconds", "1")
    assert proc.returncode == 2 and "does not exist" in proc.stderr and "Traceback" not in proc.stderr
    proc = run_cli("--source", "webcam", "--seconds", "1")
    assert proc.returncode == 2 and "unknown source" in proc.stderr


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _send_when_listening(port: int, frames: list[list[bytes]], stop: threading.Event) -> threading.Thread:
    """A thread that waits for the live command to hold `port` (Blender start-up), then sends each frame's
    packets, 30 frames a second."""
    def listening() -> bool:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
            try:
                probe.bind(("127.0.0.1", port))
            except OSError:
                return True  # the live command holds the port
        return False

    def sender():
        end = time.perf_counter() + 60
        while not listening() and not stop.is_set() and time.perf_counter() < end:
            time.sleep(0.2)
        time.sleep(0.2)
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            for packets in frames:
                if stop.is_set():
                    return
                for packet in packets:
                    s.sendto(packet, ("127.0.0.1", port))
                time.sleep(1 / 30)

    t = threading.Thread(target=sender)
    t.start()
    return t


def test_live_osc_receives_ni_mate_frames_and_skips_garbage(tmp_path):
    port = _free_port()
    take = krtake.read(SAMPLE)
    names = {"Head": "Head", "Neck": "Neck", "Torso": "SpineMid", "Left_Shoulder": "ShoulderLeft",
             "Left_Elbow": "ElbowLeft", "Left_Hand": "HandLeft", "Right_Shoulder": "ShoulderRight",
             "Right_Elbow": "ElbowRight", "Right_Hand": "HandRight", "Left_Hip": "HipLeft",
             "Left_Knee": "KneeLeft", "Left_Foot": "FootLeft", "Right_Hip": "HipRight",
             "Right_Knee": "KneeRight", "Right_Foot": "FootRight"}
    idx = {n: take.skeleton.index(j) for n, j in names.items()}
    frames = [([b"garbage!"] if i == 20 else [])  # skipped and counted, live goes on
              + [encode_message("/" + n, *map(float, take.positions[i, j])) for n, j in idx.items()]
              + [encode_message("/NI_mate_sync", "x")] for i in range(40)]
    stop = threading.Event()
    t = _send_when_listening(port, frames, stop)
    try:
        rec = tmp_path / "osc.krtake"
        proc = run_cli("--source", f"osc:{port}", "--seconds", "10", "--record", str(rec))
    finally:
        stop.set()
        t.join()
    assert proc.stdout.strip(), (proc.returncode, proc.stderr[-2000:])   # a run that printed nothing says why
    stats = json.loads(proc.stdout.strip().splitlines()[-1])
    assert proc.returncode == 0 and stats["error"] is None, proc.stderr[-2000:]
    assert stats["bad_packets"] == 1 and "bad OSC packet" in stats["warning"]
    assert stats["received"] == 40 and stats["applied"] > 0
    kept = krtake.read(rec)
    assert kept.frame_count == 40  # every frame, before and after the garbage
    np.testing.assert_allclose(kept.positions[0, idx["Left_Hand"]], take.positions[0, idx["Left_Hand"]], atol=1e-5)


def test_live_osc_with_two_users_drives_a_rig_each(tmp_path, data_dir):
    """NI mate numbering its users (`/Joint_1`, `/Joint_2`): `live --body 0 --body 1` drives a generated rig
    per user from the command line, records each user to its own file and bakes each onto its rig."""
    from tests.takes.two_performers import performers
    port = _free_port()
    first, second = performers(data_dir)
    joints = first.skeleton.joints
    frames = [[encode_message(f"/{name}_{user}", *map(float, take.positions[i, j]))
               for user, take in ((1, first), (2, second)) for j, name in enumerate(joints)]
              + [encode_message("/NI_mate_sync", "x")] for i in range(30)]
    stop = threading.Event()
    t = _send_when_listening(port, frames, stop)
    try:
        rec, out = tmp_path / "duo.krtake", tmp_path / "duo.blend"
        proc = run_cli("--source", f"osc:{port}", "--seconds", "10", "--body", "0", "--body", "1",
                       "--filter", "none", "--record", str(rec), "--out", str(out))
    finally:
        stop.set()
        t.join()
    assert proc.returncode == 0, proc.stderr[-2000:]
    result = json.loads(proc.stdout.strip().splitlines()[-1])
    assert [(p["armature"], p["body"]) for p in result["performers"]] == [("KinectRig_body0", 0),
                                                                          ("KinectRig_body1", 1)]
    assert all(p["action"] and p["applied"] > 0 and p["error"] is None for p in result["performers"])
    for path, take in ((rec, first), (tmp_path / "duo_body1.krtake", second)):  # each user on its own
        kept = krtake.read(path)
        assert kept.frame_count == 30
        np.testing.assert_allclose(kept.positions[-1], take.positions[29], atol=2e-5)
    assert out.is_file()


def test_live_unknown_preset_or_filter_is_a_usage_error_not_a_traceback():
    for flag in ("--preset", "--filter"):
        proc = run_cli("--source", f"take:{SAMPLE}", "--seconds", "1", flag, "bogus")
        assert proc.returncode == 2, proc.stderr[-2000:]
        assert "invalid choice: 'bogus'" in proc.stderr and "Traceback" not in proc.stderr


def test_live_record_to_an_unwritable_path_is_one_error_line(tmp_path):
    blocker = tmp_path / "a_file"
    blocker.write_text("not a folder")
    proc = run_cli("--source", f"take:{SAMPLE}", "--seconds", "1", "--record", str(blocker / "rec.krtake"))
    assert proc.returncode == 2, proc.stderr[-2000:]
    assert "Traceback" not in proc.stderr and proc.stdout == ""
    errors = [l for l in proc.stderr.splitlines() if l.startswith("error:")]
    assert len(errors) == 1 and "cannot write the recording" in errors[0] and str(blocker) in errors[0]


def test_live_generated_rig_runs_at_the_source_rate_one_key_per_frame(tmp_path):
    import bpy

    rec, out = tmp_path / "rec.krtake", tmp_path / "out.blend"
    proc = run_cli("--source", f"take:{SAMPLE}", "--seconds", "30", "--record", str(rec), "--out", str(out))
    assert proc.returncode == 0, proc.stderr[-2000:]
    stats = json.loads(proc.stdout)
    bpy.ops.wm.open_mainfile(filepath=str(out), load_ui=False)
    scene = bpy.context.scene
    fps = scene.render.fps / scene.render.fps_base
    assert fps == krtake.read(SAMPLE).rate == 30.0  # not Blender's factory 24
    action = bpy.data.actions[stats["action"]]
    curve = action.layers[0].strips[0].channelbag(action.slots[0]).fcurves.find(
        'pose.bones["SpineMid"].rotation_quaternion', index=0)
    times = krtake.read(rec).times
    expected = len(np.unique(np.round((times - times[0]) * fps)))
    assert len(curve.keyframe_points) == expected >= 0.95 * len(times)  # at 24 fps it would be ~0.8
    bpy.ops.wm.read_factory_settings(use_empty=True)


def test_live_usb_without_a_working_device_fails_with_the_reason():
    """No libusb (fails at once) or no Kinect (nothing received before --seconds): exit 1 with the reason."""
    proc = run_cli("--source", "usb", "--seconds", "2")
    assert proc.returncode == 1, (proc.stdout, proc.stderr[-2000:])
    stats = json.loads(proc.stdout)
    assert stats["received"] == 0 and stats["error"].startswith("USB Kinect")
    errors = [l for l in proc.stderr.splitlines() if l.startswith("error:")]
    assert len(errors) == 1 and stats["error"] in errors[0] and "Traceback" not in proc.stderr


def test_live_unreadable_rig_or_unwritable_out_is_one_error_line(tmp_path):
    not_blend = tmp_path / "rig.blend"
    not_blend.write_text("this is not a .blend file")
    for args, expect in ((("--rig", str(not_blend)), "not a readable .blend file"),
                         (("--out", "/proc/out.blend"), "cannot save")):
        proc = run_cli("--source", f"take:{SAMPLE}", "--seconds", "0.3", *args)
        assert proc.returncode == 2, proc.stderr[-2000:]
        errors = [l for l in proc.stderr.splitlines() if l.startswith("error:")]
        assert len(errors) == 1 and expect in errors[0] and "Traceback" not in proc.stderr, proc.stderr[-2000:]
