"""USB topology and descriptors of the emulated Kinect: which devices each model shows, with real IDs."""
from __future__ import annotations

from dataclasses import dataclass

from ..device import protocol as P

ISO_960_X2 = P.MAX_ISO_PACKET_SIZE // 2 | (1 << 11)     # wMaxPacketSize: 960 bytes x 2 per microframe
MODELS = ("1414", "1473", "k4w")


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
    port_numbers: tuple
    address: int = 0

    def device_descriptor(self, bus: int) -> Desc:
        return Desc(bLength=18, bDescriptorType=1, bcdUSB=0x0200, bDeviceClass=0, bDeviceSubClass=0,
                    bDeviceProtocol=0, bMaxPacketSize0=64, idVendor=P.VENDOR_MICROSOFT,
                    idProduct=self.product_id, bcdDevice=self.bcd_device, iManufacturer=1, iProduct=2,
                    iSerialNumber=3 if self.serial else 0, bNumConfigurations=1, address=self.address,
                    bus=bus, port_number=self.port_numbers[-1], port_numbers=self.port_numbers, speed=3)

    def configuration_descriptor(self) -> Desc:
        return Desc(bLength=9, bDescriptorType=2, wTotalLength=0, bNumInterfaces=len(self.interfaces),
                    bConfigurationValue=1, iConfiguration=0, bmAttributes=0x80, bMaxPower=250,
                    extra_descriptors=[])

    def strings(self) -> dict[int, str]:
        return {1: "Microsoft", 2: self.product, 3: self.serial or ""}


def build_functions(model: str, serial: str, audio_firmware: bool) -> list[UsbFunction]:
    """The devices a Kinect of this model enumerates as."""
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
        audio_pid = P.PID_AUDIO_K4W
    # Audio chip: in its bootloader it has one interface and no motor/LED; with the (proprietary) audio
    # firmware running it has more, and takes motor commands on bulk endpoints 0x01/0x81.
    interfaces = [[interface(0, 0, [endpoint(0x81, 512, 0x02), endpoint(0x01, 512, 0x02)])]]
    if audio_firmware:
        interfaces.append([interface(1, 0, [endpoint(0x82, 512)], cls=0x01)])
    audio = UsbFunction("audio", audio_pid, 0x0100, "Xbox Kinect Audio", serial, interfaces, (1, 3))
    return [camera, audio]
