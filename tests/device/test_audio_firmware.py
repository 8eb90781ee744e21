"""The 1473 / Kinect for Windows audio firmware: found where libfreenect looks, uploaded to the emulated
bootloader through the same pyusb bulk transfers a real chip gets, and plain messages when it can't be."""
import struct

import pytest

from kinect_retarget.device import protocol as P
from kinect_retarget.device.audio_firmware import AUDIOS_MAGIC, PAGE, find_firmware, firmware_paths, read_firmware
from kinect_retarget.device.discovery import list_devices
from kinect_retarget.device.errors import BadInputFile, MotorUnavailable, ProtocolError
from kinect_retarget.device.motor import open_motor
from kinect_retarget.sim.emulated_kinect import DEFAULT_SERIAL, EmulatedKinect

BASE, ENTRY = 0x80000, 0x80040


def _image(size=2 * PAGE + 300, magic=AUDIOS_MAGIC) -> bytes:
    """A stand-in for audios.bin (the real one is Microsoft's): its header, then seeded filler."""
    header = struct.pack("<I4H3I", magic, 2, 1, 0, 7, BASE, size, ENTRY)
    body = bytes((i * 7919) & 0xFF for i in range(size - len(header)))
    return header + body


@pytest.fixture
def firmware_dir(tmp_path, monkeypatch):
    monkeypatch.setenv("LIBFREENECT_FIRMWARE_PATH", str(tmp_path / "fw"))
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    (tmp_path / "fw").mkdir()
    return tmp_path / "fw"


def test_search_order_is_libfreenects(firmware_dir):
    paths = [str(p) for p in firmware_paths()]
    assert paths[0] == str(firmware_dir / "audios.bin") and paths[1] == "audios.bin"
    assert paths[2].endswith("home/.libfreenect/audios.bin")
    assert paths[3:] == ["/usr/local/share/libfreenect/audios.bin", "/usr/share/libfreenect/audios.bin"]
    assert find_firmware() is None
    (firmware_dir / "audios.bin").write_bytes(_image())
    assert find_firmware() == firmware_dir / "audios.bin"


@pytest.mark.parametrize("model", ["1473", "k4w"])
def test_motor_commands_upload_the_firmware_first(real_depth, firmware_dir, model):
    (firmware_dir / "audios.bin").write_bytes(_image())
    emu = EmulatedKinect(real_depth[:1], model=model)
    assert list_devices(emu)[0].needs_audio_firmware
    motor = open_motor(emu)
    assert emu.firmware_uploads == 1 and motor.info.serial == DEFAULT_SERIAL
    if model == "k4w":
        assert motor.device.idProduct == 0x02C3                       # re-enumerated as the SDK firmware's id
    motor.set_tilt(10)
    motor.set_led("red")
    assert emu.motor.target_deg == 10 and emu.motor.led == 4
    assert list_devices(emu)[0].motor_available                      # it stays until power is lost
    emu.unplug()
    emu.replug()
    assert list_devices(emu)[0].needs_audio_firmware


def test_without_the_file_the_motor_says_where_it_comes_from(real_depth, firmware_dir):
    with pytest.raises(MotorUnavailable) as info:
        open_motor(EmulatedKinect(real_depth[:1], model="1473"))
    assert "audios.bin" in str(info.value) and "fwfetcher" in str(info.value)


def test_a_file_that_is_not_the_audio_firmware_is_refused_before_anything_is_sent(real_depth, firmware_dir):
    (firmware_dir / "audios.bin").write_bytes(_image(magic=0xF00BACCA))      # the second-stage loader's magic
    emu = EmulatedKinect(real_depth[:1], model="1473")
    with pytest.raises(BadInputFile, match="not the Kinect audio firmware"):
        open_motor(emu)
    assert emu.bootloader.memory == {} and emu.firmware_uploads == 0
    (firmware_dir / "audios.bin").write_bytes(_image()[:1000])
    with pytest.raises(BadInputFile, match="announces"):
        read_firmware(firmware_dir / "audios.bin")


def test_a_refused_upload_says_which_command_failed(real_depth):
    from kinect_retarget.device.audio_firmware import BOOT_RUN, _Bootloader
    emu = EmulatedKinect(real_depth[:1], model="1473")
    audio = list_devices(emu)[0].audio
    with pytest.raises(ProtocolError, match="refused command 4 at 0x80040"):
        _Bootloader(audio).command(BOOT_RUN, ENTRY)                  # run with nothing uploaded
    assert emu.firmware_uploads == 0 and list_devices(emu)[0].audio.idProduct == P.PID_AUDIO
