"""`devices --diagnose`: what a user pastes into a bug report, from the emulated Kinect's point of view."""
import re

from kinect_retarget.cli import main
from kinect_retarget.device.diagnosis import diagnose
from kinect_retarget.sim.emulated_kinect import EmulatedKinect
from kinect_retarget.sim.emulated_stream import Faults, VirtualClock


def test_report_for_a_1473_on_a_windows_like_host(real_depth):
    emu = EmulatedKinect(real_depth[:2], model="1473", topology="no-ports", clock=VirtualClock(),
                         faults=Faults(reply_padding=True, write_ack_bytes=4))
    text = diagnose(emu)
    assert "045e:02ae" in text and "Kinect camera, bcdDevice 0x0110" in text and "045e:02ad" in text
    assert "Xbox 360 Kinect (1473)  serial A00366A08793039A" in text
    assert "audio device: 02ad on bus 1" in text and "(only one on the bus)" in text
    assert "audios.bin" in text                                     # why the motor is not available
    assert "LED keep-alive to the audio chip: sent, answered" in text
    assert "calibration from the device: const_shift 200" in text and "full 0x200-byte buffers" in text
    assert "write register 0x06 = 0 (depth off): answered 00000000 instead of 0000 (accepted)" in text
    frames = int(re.search(r"depth stream for up to 3 s: (\d+) frames", text).group(1))
    assert frames >= 30 and "0 reconnects" in text
    assert emu.reenumerations == 0


def test_report_says_what_failed(real_depth):
    emu = EmulatedKinect(real_depth[:1], faults=Faults(submit_io_error=True))
    text = diagnose(emu, stream_seconds=2.0)
    assert "depth stream for up to 2 s: 0 frames" in text and "state error" in text
    assert "LIBUSB_ERROR_IO" in text and "bandwidth" in text
    denied = diagnose(EmulatedKinect(real_depth[:1], faults=Faults(access_denied=True)))
    assert "camera: not usable:" in denied and "depth stream" not in denied
    unpowered = diagnose(EmulatedKinect(real_depth[:1], faults=Faults(no_power=True)))
    assert "045e:02b0" in unpowered and "no Kinect v1 camera" in unpowered and "12 V" in unpowered


def test_devices_diagnose_command(capsys):
    assert main(["devices", "--diagnose", "--simulate"]) == 0
    out = capsys.readouterr().out
    assert "bus 1:" in out and "Xbox 360 Kinect (1414)" in out and "depth stream for up to 3 s" in out
