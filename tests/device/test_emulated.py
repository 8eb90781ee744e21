"""The emulated Kinect seen through plain pyusb, and the driver's camera code running against it."""
import struct

import pytest
import usb.core
import usb.util

from kinect_retarget.device import protocol as P
from kinect_retarget.device.kinect_camera import KinectCamera
from kinect_retarget.sim.emulated_kinect import EmulatedKinect
from kinect_retarget.sim.emulated_stream import Faults
from kinect_retarget.device.errors import DeviceGone, ProtocolError


@pytest.fixture
def emu(real_depth):
    return EmulatedKinect(real_depth[:2])


def _camera(backend):
    return usb.core.find(idVendor=P.VENDOR_MICROSOFT, idProduct=P.PID_CAMERA, backend=backend)


def test_descriptors_through_pyusb(emu):
    cam = _camera(emu)
    assert (cam.bcdDevice, cam.manufacturer, cam.product, cam.serial_number) == (
        267, "Microsoft", "Xbox NUI Camera", "A00366A08793039A")
    intf = cam.get_active_configuration()[(0, 0)]
    eps = {ep.bEndpointAddress: ep for ep in intf}
    assert set(eps) == {0x81, 0x82}
    assert usb.util.endpoint_type(eps[0x82].bmAttributes) == usb.util.ENDPOINT_TYPE_ISO
    # 960 bytes with one extra transaction per microframe = 1920-byte iso packets
    assert eps[0x82].wMaxPacketSize & 0x7FF == 960 and (eps[0x82].wMaxPacketSize >> 11) & 3 == 1
    motor = usb.core.find(idVendor=P.VENDOR_MICROSOFT, idProduct=P.PID_MOTOR, backend=emu)
    assert motor.product == "Xbox NUI Motor"


def test_kinect_for_windows_has_a_streaming_alt_setting(real_depth):
    emu = EmulatedKinect(real_depth[:1], model="k4w")
    cam = usb.core.find(idVendor=P.VENDOR_MICROSOFT, idProduct=P.PID_CAMERA_K4W, backend=emu)
    alts = [i.bAlternateSetting for i in cam.get_active_configuration()]
    assert alts == [0, 1]
    with KinectCamera(cam) as camera:
        assert camera.model == "Kinect for Windows"
        assert emu.registers == {}                  # nothing written yet, but alt 1 selected and calibration read


def test_command_protocol_and_registers(emu):
    with KinectCamera(_camera(emu)) as camera:
        assert camera.calibration.source == "device" and camera.calibration.const_shift == 200
        camera.write_register(0x12, 3)
        assert camera.read_register(0x12) == 3
        camera.start_depth()
        assert emu.depth_stream is not None and emu.registers[P.REG_DEPTH_STREAM] == 2
        camera.stop_depth()
        assert emu.depth_stream is None


def test_stream_does_not_start_without_the_format_registers(emu):
    with KinectCamera(_camera(emu)) as camera:
        camera.write_register(P.REG_DEPTH_STREAM, 2)
        assert emu.depth_stream is None


def _gm(opcode, tag, payload, magic=b"GM", words=None):
    return struct.pack("<2sHHH", magic, len(payload) // 2 if words is None else words, opcode, tag) + payload


@pytest.mark.parametrize("message", [
    _gm(2, 0, b"\x06\x00", magic=b"XX"),          # bad magic
    _gm(2, 0, b"\x06\x00", words=3),              # length field disagrees with the data
    b"GM\x01",                                    # shorter than a header
    _gm(0x77, 0, b""),                            # unknown opcode
    _gm(2, 0, b"\x06\x00\x01\x00"),               # read-register with the wrong argument count
])
def test_malformed_commands_stall_and_leave_no_reply(emu, message):
    cam = _camera(emu)
    with pytest.raises(usb.core.USBError) as info:
        cam.ctrl_transfer(0x40, 0, 0, 0, message)
    assert info.value.errno == 32                  # EPIPE: the control pipe stalled
    assert len(cam.ctrl_transfer(0xC0, 0, 0, 0, 0x200)) == 0


def test_reply_with_wrong_tag_is_refused(emu, monkeypatch):
    camera = KinectCamera(_camera(emu)).open()
    original = emu._camera_command

    def stale_tag(message):                        # a device answering with an old tag
        original(message)
        reply = bytearray(emu._pending_reply)
        reply[6] ^= 0x01
        emu._pending_reply = bytes(reply)

    monkeypatch.setattr(emu, "_camera_command", stale_tag)
    with pytest.raises(ProtocolError, match="tag"):
        camera.read_register(6)
    camera.close()


def test_unplug_invalidates_handles_and_replug_enumerates_again(emu):
    camera = KinectCamera(_camera(emu)).open()
    emu.unplug()
    assert list(usb.core.find(find_all=True, backend=emu)) == []
    with pytest.raises(DeviceGone):
        camera.read_register(6)
    emu.replug()
    camera2 = KinectCamera(_camera(emu)).open()
    assert camera2.read_register(6) == 0           # power-on state again
    with pytest.raises(DeviceGone):
        camera.read_register(6)                    # the old handle stays dead


def test_access_denied_fault(real_depth):
    from kinect_retarget.device.errors import AccessDenied
    emu = EmulatedKinect(real_depth[:1], faults=Faults(access_denied=True))
    with pytest.raises(AccessDenied, match="udev|Zadig|refused"):
        KinectCamera(_camera(emu)).open()
