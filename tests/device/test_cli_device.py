"""The device commands through the real dispatcher (`python -m kinect_retarget`): 2 = bad input, 1 = device."""
import json
import subprocess
import sys

import numpy as np
import pytest

from kinect_retarget.cli import main
from kinect_retarget.device.protocol import TICKS_PER_FRAME

FAKENECT = "depth_real/fakenect_openiss/fakenect-record"


def test_devices_simulated(capsys):
    assert main(["devices", "--simulate", "--json"]) == 0
    info = json.loads(capsys.readouterr().out.strip())
    assert info["model"] == "Xbox 360 Kinect (1414)" and info["camera_available"]


def test_udev_rule(capsys):
    assert main(["devices", "--udev-rule"]) == 0
    out = capsys.readouterr().out
    assert "51-kinect.rules" in out and "udevadm" in out


def _emulator_on_a_virtual_clock(monkeypatch, faults=None):
    """Make --simulate build an emulated Kinect whose time only it moves: what arrives is load-independent."""
    from kinect_retarget.sim.emulated_kinect import EmulatedKinect
    from kinect_retarget.sim.emulated_stream import VirtualClock
    from kinect_retarget.sources import simulated_kinect

    class VirtualTimeKinect(EmulatedKinect):
        def __init__(self, images, **kwargs):
            super().__init__(images, clock=VirtualClock(), faults=faults, **kwargs)

    monkeypatch.setattr(simulated_kinect, "EmulatedKinect", VirtualTimeKinect)


def test_capture_simulated_with_dump_then_replay(tmp_path, data_dir, capsys, monkeypatch):
    _emulator_on_a_virtual_clock(monkeypatch)
    out, dump = tmp_path / "depth.npz", tmp_path / "packets.dump"
    assert main(["capture", "--simulate", "--simulate-from", str(data_dir / FAKENECT), "--seconds", "0.5",
                 "--out", str(out), "--dump", str(dump)]) == 0
    live = np.load(out)
    assert live["raw"].shape[1:] == (480, 640) and live["raw"].shape[0] == 15    # 0.5 s of device time
    steps = np.diff(live["timestamp"]) & 0xFFFFFFFF
    assert (steps == TICKS_PER_FRAME).all() and (live["lost_packets"] == 0).all()
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
    assert main(["capture", "--replay", str(dump), "--out", str(replayed), "--calibration", str(dump)]) == 2
    assert "no usable calibration" in capsys.readouterr().err


def test_motor_commands_simulated(capsys):
    assert main(["tilt", "--angle", "35", "--simulate"]) == 0
    assert "clamped" in capsys.readouterr().out
    assert main(["led", "red", "--simulate"]) == 0
    assert main(["accel", "--simulate"]) == 0
    assert "accelerometer" in capsys.readouterr().out


def test_bad_input_exits_2_with_a_message_not_a_traceback(tmp_path, capsys):
    assert main(["capture", "--replay", str(tmp_path / "nope.dump"), "--out", str(tmp_path / "x.npz")]) == 2
    assert "no such dump file" in capsys.readouterr().err
    bad = tmp_path / "bad.dump"
    bad.write_bytes(b"\xff\xff\xff\xff garbage")
    assert main(["capture", "--replay", str(bad), "--out", str(tmp_path / "y.npz")]) == 2
    assert "bad.dump" in capsys.readouterr().err
    assert main(["capture", "--simulate", "--simulate-from", str(tmp_path), "--out", str(tmp_path / "e.npz")]) == 2
    assert "no fakenect depth frames" in capsys.readouterr().err
    assert main(["tilt", "--angle", "nan", "--simulate"]) == 2
    assert "error:" in capsys.readouterr().err
    for args, reason in ((["--seconds", "0"], "--seconds must be positive"),
                         (["--wait", "-1"], "--wait must not be negative"),
                         (["--calibration", str(bad)], "--calibration only applies to --replay"),
                         (["--simulate-from", str(tmp_path)], "--simulate-from only applies to --simulate")):
        assert main(["capture", "--out", str(tmp_path / "z.npz"), *args]) == 2
        assert reason in capsys.readouterr().err
    assert not list(tmp_path.glob("*.npz"))


def test_truncated_dump_keeps_its_frames_and_exits_2(tmp_path, data_dir, capsys):
    from kinect_retarget.device.dump import DumpWriter
    from kinect_retarget.sim.emulated_stream import packets_for_frames
    from kinect_retarget.sim.depth_sequences import load_fakenect_dir
    dump = tmp_path / "cut.dump"
    with DumpWriter(dump) as writer:
        writer.write_packets(packets_for_frames(load_fakenect_dir(data_dir / FAKENECT, limit=3), 3))
    dump.write_bytes(dump.read_bytes()[:-100])          # the last record loses its tail
    out = tmp_path / "cut.npz"
    assert main(["capture", "--replay", str(dump), "--out", str(out)]) == 2
    assert "truncated" in capsys.readouterr().err
    assert np.load(out)["raw"].shape[0] == 2              # the two whole frames before the damage


@pytest.mark.parametrize("command, code, expected", [
    (["devices", "--simulate", "--json"], 0, "Xbox 360 Kinect"),
    (["accel", "--simulate"], 0, "accelerometer"),
    (["capture", "--replay", "{tmp}/nope.dump", "--out", "{tmp}/x.npz"], 2, "no such dump file"),
    (["capture", "--simulate", "--serial", "NOPE", "--wait", "0.2", "--out", "{tmp}/y.npz"], 1,
     "no depth frame was captured"),
])
def test_python_dash_m_kinect_retarget(tmp_path, command, code, expected):
    """The real entry point: output, exit code, and no traceback."""
    argv = [a.format(tmp=tmp_path) for a in command]
    done = subprocess.run([sys.executable, "-m", "kinect_retarget", *argv], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == code, done.stderr
    assert expected in (done.stdout if code == 0 else done.stderr) and "Traceback" not in done.stderr
    assert not list(tmp_path.glob("*.npz"))


def test_capture_gives_up_when_no_kinect_streams(tmp_path, capsys, monkeypatch):
    from kinect_retarget.cli import device_commands as cli_device
    from kinect_retarget.sim.depth_sequences import synthetic_depth_frames
    from kinect_retarget.sim.emulated_kinect import EmulatedKinect

    def unplugged_kinect(args):
        emu = EmulatedKinect(synthetic_depth_frames(2))
        emu.unplug()
        return emu

    monkeypatch.setattr(cli_device, "_backend", unplugged_kinect)
    out = tmp_path / "none.npz"
    assert main(["capture", "--simulate", "--seconds", "1", "--wait", "0.3", "--out", str(out)]) == 1
    assert "no Kinect found" in capsys.readouterr().err and not out.exists()


def test_capture_keeps_its_frames_when_the_kinect_goes_and_stays_away(tmp_path, monkeypatch, capsys):
    from kinect_retarget.sim.emulated_stream import Faults
    _emulator_on_a_virtual_clock(monkeypatch, Faults(unplug_at=0.21))     # after frames 0-5, for good
    out = tmp_path / "cut.npz"
    assert main(["capture", "--simulate", "--seconds", "2", "--wait", "0.3", "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert "no frame for 0.3 s" in err and "0.20 of 2 s captured and saved" in err
    kept = np.load(out)
    assert kept["raw"].shape[0] == 6 and (np.diff(kept["timestamp"]) & 0xFFFFFFFF == TICKS_PER_FRAME).all()
