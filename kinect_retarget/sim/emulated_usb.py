"""USB topology and descriptors of the emulated Kinect (which devices each model shows, with real IDs), and
the calibration its camera answers with."""
from __future__ import annotations

import itertools
import struct
from dataclasses import dataclass, field

from ..device import protocol as P

ISO_960_X2 = P.MAX_ISO_PACKET_SIZE // 2 | (1 << 11)     # wMaxPacketSize: 960 bytes x 2 per microframe
MODELS = ("1414", "1473", "k4w")
TOPOLOGIES = ("hub", "no-ports", "split-bus")
K4W_AUDIO_SDK_FIRMWARE = 0x02C3    # what a Kinect for Windows audio chip running the SDK firmware reports


class Desc:
    """A descriptor as pyusb's backends return them: a bag of named fields."""

    def __init__(self, **fields):
        self.__dict__.update(fields)


def endpoint(address: int, max_packet: int, attributes: int = 0x01) -> Desc:
    return Desc(bLength=7, bDescriptorType=5, bEndpointAddress=address, bmAttributes=attributes,
                wMaxPacketSize=max_packet, bInterval=1, bRefresh=0, bSynchAddress=0, extra_descriptors=[])


def interface(number: int, alt: int, endpoints: list, cls: int = 0xFF) -> Desc:
    return Desc(bLength=9, bDescriptorType=4, bInterfaceNumber=number, bAlternateSetting=alt,
                bNumEndpoints=len(endpoints), bInterfaceClass=cls, bInterfaceSubClass=0xFF,
                bInterfaceProtocol=0xFF, iInterface=0, extra_descriptors=[], endpoints=endpoints)


@dataclass
class UsbFunction:
    """One USB device of the Kinect (camera, motor or audio) behind its internal hub."""
    kind: str
    product_id: int
    bcd_device: int
    product: str
    serial: str | None
    interfaces: list            # [interface number][alt setting] -> Desc
    port_numbers: tuple | None         # None: the OS does not say which hub port (libusb gives no path)
    address: int = 0
    bus_offset: int = 0                # on another bus than the camera (a USB 3 controller's companion)

    def device_descriptor(self, bus: int) -> Desc:
        bus += self.bus_offset
        return Desc(bLength=18, bDescriptorType=1, bcdUSB=0x0200, bDeviceClass=0, bDeviceSubClass=0,
                    bDeviceProtocol=0, bMaxPacketSize0=64, idVendor=P.VENDOR_MICROSOFT,
                    idProduct=self.product_id, bcdDevice=self.bcd_device, iManufacturer=1, iProduct=2,
                    iSerialNumber=3 if self.serial else 0, bNumConfigurations=1, address=self.address,
                    bus=bus, port_number=self.port_numbers[-1] if self.port_numbers else 0,
                    port_numbers=self.port_numbers, speed=3)

    def configuration_descriptor(self) -> Desc:
        return Desc(bLength=9, bDescriptorType=2, wTotalLength=0, bNumInterfaces=len(self.interfaces),
                    bConfigurationValue=1, iConfiguration=0, bmAttributes=0x80, bMaxPower=250,
                    extra_descriptors=[])

    def strings(self) -> dict[int, str]:
        return {1: "Microsoft", 2: self.product, 3: self.serial or ""}


_handle_ids = itertools.count(1)


@dataclass
class EmulatedHandle:
    """An open device handle; dead once its device leaves the bus (generation) or re-enumerates."""
    function: UsbFunction
    generation: int
    claimed: set = field(default_factory=set)
    alt: dict = field(default_factory=dict)
    id: int = field(default_factory=lambda: next(_handle_ids))

    @property
    def handle(self) -> int:          # what libusb's transfers carry as dev_handle (see emulated_libusb.py)
        return self.id

    @property
    def devid(self) -> UsbFunction:
        return self.function


def build_functions(model: str, serial: str, audio_firmware: bool, topology: str = "hub") -> list[UsbFunction]:
    """The devices a Kinect of this model enumerates as. topology: "hub" (all behind the Kinect's own hub, as
    usual), "no-ports" (the OS reports no port path), "split-bus" (motor and audio on another bus number)."""
    if topology not in TOPOLOGIES:
        raise ValueError(f"unknown topology {topology!r}: use one of {', '.join(TOPOLOGIES)}")
    functions = _functions(model, serial, audio_firmware)
    for fn in functions:
        if topology == "no-ports":
            fn.port_numbers = None
        elif topology == "split-bus" and fn.kind != "camera":
            fn.bus_offset = 1
    return functions


def _functions(model: str, serial: str, audio_firmware: bool) -> list[UsbFunction]:
    if model not in MODELS:
        raise ValueError(f"unknown Kinect model {model!r}: use '1414', '1473' or 'k4w'")
    streaming = [endpoint(P.VIDEO_ENDPOINT, ISO_960_X2), endpoint(P.DEPTH_ENDPOINT, ISO_960_X2)]
    if model == "1414":
        camera = UsbFunction("camera", P.PID_CAMERA, P.BCD_MODEL_1414, "Xbox NUI Camera", serial,
                             [[interface(0, 0, streaming)]], (1, 1))
        motor = UsbFunction("motor", P.PID_MOTOR, 0x0107, "Xbox NUI Motor", None, [[interface(0, 0, [])]],
                            (1, 2))
        return [motor, camera]
    if model == "1473":     # the camera reports sixteen zeros as its serial; the audio device has the real one
        camera = UsbFunction("camera", P.PID_CAMERA, 0x0110, "Xbox NUI Camera", "0000000000000000",
                             [[interface(0, 0, streaming)]], (1, 1))
        audio_pid = P.PID_AUDIO
    else:                   # Kinect for Windows: alt setting 0 has zero-bandwidth endpoints, alt 1 streams
        idle = [endpoint(P.VIDEO_ENDPOINT, 0), endpoint(P.DEPTH_ENDPOINT, 0)]
        camera = UsbFunction("camera", P.PID_CAMERA_K4W, 0x0100, "Kinect for Windows Camera",
                             "0000000000000000", [[interface(0, 0, idle), interface(0, 1, streaming)]], (1, 1))
        audio_pid = K4W_AUDIO_SDK_FIRMWARE if audio_firmware else P.PID_AUDIO_K4W   # re-enumerates with it
    # Audio chip: in its bootloader it has one interface and no motor/LED; with the (proprietary) audio
    # firmware running it has more, and takes motor commands on bulk endpoints 0x01/0x81.
    interfaces = [[interface(0, 0, [endpoint(0x81, 512, 0x02), endpoint(0x01, 512, 0x02)])]]
    if audio_firmware:
        interfaces.append([interface(1, 0, [endpoint(0x82, 512)], cls=0x01)])
    audio = UsbFunction("audio", audio_pid, 0x0100, "Xbox Kinect Audio", serial, interfaces, (1, 3))
    return [camera, audio]


CONST_SHIFT = 200
FIXED_PARAMS = (7.5, 2.4, 120.0, 0.1052)       # emitter dist (cm), rcmos dist (cm), ref dist (mm), pixel (mm)


def calibration_reply(opcode: int, args: tuple, model: str) -> bytes | None:
    """The camera's reply payload to a fixed-parameters or algorithm-parameters command (None: not one)."""
    if opcode == P.OP_FIXED_PARAMS and len(args) == 5:
        body = bytearray(322 if model == "1414" else 334)
        struct.pack_into("<4f", body, 94, *FIXED_PARAMS)
        return bytes(body)
    if opcode == P.OP_ALGORITHM_PARAMS and len(args) == 5:
        sizes = {P.ALGO_CONST_SHIFT: 4, 0x40: 118, 0x41: 8}
        if args[0] not in sizes:
            return None
        body = bytearray(sizes[args[0]])
        if args[0] == P.ALGO_CONST_SHIFT:
            struct.pack_into("<H", body, 2, CONST_SHIFT)
        return bytes(body)
    return None
