import json

import numpy as np

from kinect_retarget.cli_device import main

FAKENECT = "depth_real/fakenect_openiss/fakenect-record"


def test_devices_simulated(capsys):
    assert main(["devices", "--simulate", "--json"]) == 0
    info = json.loads(capsys.readouterr().out.strip())
    assert info["model"] == "Xbox 360 Kinect (1414)" and info["camera_available"]


def test_udev_rule(capsys):
    assert main(["devices", "--udev-rule"]) == 0
    out = capsys.readouterr().out
    assert "51-kinect.rules" in out and "udevadm" in out


def test_capture_simulated_with_dump_then_replay(tmp_path, shared_data, capsys):
    out, dump = tmp_path / "depth.npz", tmp_path / "packets.dump"
    assert main(["capture", "--simulate", "--simulate-from", str(shared_data / FAKENECT), "--seconds", "0.5",
                 "--out", str(out), "--dump", str(dump)]) == 0
    live = np.load(out)
    assert live["raw"].shape[1:] == (480, 640) and live["raw"].shape[0] >= 10
    assert live["mm"].shape == live["raw"].shape and live["timestamp"].shape == (live["raw"].shape[0],)
    assert json.loads(str(live["calibration"]))["source"] == "device"
    replayed = tmp_path / "replayed.npz"
    assert main(["capture", "--replay", str(dump), "--out", str(replayed), "--calibration", str(out)]) == 0
    again = np.load(replayed)
    assert json.loads(str(again["calibration"])) == json.loads(str(live["calibration"]))
    # the dump holds every packet, so offline decoding gives the same frames (and maybe one more at the end)
    n = live["raw"].shape[0]
    np.testing.assert_array_equal(again["raw"][:n], live["raw"])
    np.testing.assert_array_equal(again["timestamp"][:n], live["timestamp"])
    np.testing.assert_array_equal(again["mm"][:n], live["mm"])
    assert main(["capture", "--replay", str(dump), "--out", str(replayed), "--calibration", str(dump)]) == 1
    assert "no usable calibration" in capsys.readouterr().err


def test_motor_commands_simulated(capsys):
    assert main(["tilt", "--angle", "35", "--simulate"]) == 0
    assert "clamped" in capsys.readouterr().out
    assert main(["led", "red", "--simulate"]) == 0
    assert main(["accel", "--simulate"]) == 0
    assert "accelerometer" in capsys.readouterr().out


def test_errors_are_messages_not_tracebacks(tmp_path, capsys):
    assert main(["capture", "--replay", str(tmp_path / "nope.dump"), "--out", str(tmp_path / "x.npz")]) == 1
    assert "no such dump file" in capsys.readouterr().err
    bad = tmp_path / "bad.dump"
    bad.write_bytes(b"\xff\xff\xff\xff garbage")
    assert main(["capture", "--replay", str(bad), "--out", str(tmp_path / "y.npz")]) == 1
    assert "bad.dump" in capsys.readouterr().err


def test_capture_gives_up_when_no_kinect_streams(tmp_path, capsys, monkeypatch):
    from kinect_retarget import cli_device
    from kinect_retarget.device.depth_images import synthetic_depth_frames
    from kinect_retarget.device.emulated import EmulatedKinect

    def unplugged_kinect(args):
        emu = EmulatedKinect(synthetic_depth_frames(2))
        emu.unplug()
        return emu

    monkeypatch.setattr(cli_device, "_backend", unplugged_kinect)
    out = tmp_path / "none.npz"
    assert main(["capture", "--simulate", "--seconds", "1", "--wait", "0.3", "--out", str(out)]) == 1
    assert "no Kinect found" in capsys.readouterr().err and not out.exists()
