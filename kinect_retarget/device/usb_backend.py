"""The seam between the driver and the USB stack: finding libusb, and keeping iso transfers in flight.

pyusb's own iso_read keeps a single transfer in flight and loses packets at the Kinect's ~7,260 packets/s.
LibusbIsoPump instead keeps `transfers` asynchronous transfers queued through the libusb that pyusb's libusb1
backend already loaded (its ctypes handle), resubmitting each one from its completion callback. The
callbacks run inside poll(), on the streaming thread; nothing here touches bpy.

open_iso_pump() builds one on the backend's libusb: pyusb's libusb1 backend, or the emulated Kinect's
emulated libusb (emulated_libusb.py), so emulated streams run this same code. poll() returns packets in
arrival order as bytes (an empty microframe is skipped), None for a slot the stack reported failed.
"""
from __future__ import annotations

import ctypes
import sys
import time

from .errors import DeviceGone, KinectError, LibusbMissing
from .protocol import MAX_ISO_PACKET_SIZE

# libusb_transfer_status
COMPLETED, ERROR, TIMED_OUT, CANCELLED, STALL, NO_DEVICE, OVERFLOW = range(7)
LIBUSB_ERROR_IO = -1
LIBUSB_ERROR_NO_DEVICE = -4
LIBUSB_ERROR_NOT_FOUND = -5
TRANSFER_TYPE_ISOCHRONOUS = 1
DEFAULT_TRANSFERS = 16            # libfreenect's Linux sizing: 16 x 16 packets; we keep 64 ms armed
DEFAULT_PACKETS_PER_TRANSFER = 32  # a multiple of 8 (WinUSB needs whole 1 ms frames)
STOP_WAIT_S = 2.0                 # how long stop() waits for cancelled transfers (libfreenect: forever)


def find_backend():
    """pyusb's libusb1 backend: the system libusb, else the one bundled as the libusb-package wheel."""
    import usb.backend.libusb1 as libusb1
    backend = libusb1.get_backend()
    if backend is None:
        try:
            import libusb_package   # shipped with the extension as a wheel where available
            backend = libusb1.get_backend(find_library=libusb_package.find_library)
        except ImportError:
            backend = None
    if backend is None:
        raise LibusbMissing(libusb_missing_advice())
    return backend


def libusb_missing_advice() -> str:
    base = "libusb-1.0 could not be loaded, so USB devices cannot be opened. "
    if sys.platform.startswith("linux"):
        return base + "Install it with your package manager (e.g. 'sudo apt install libusb-1.0-0')."
    if sys.platform == "darwin":
        return base + "Install it with 'brew install libusb', or reinstall the extension (it bundles one)."
    return base + "Reinstall the extension (it bundles libusb-1.0.dll) or put libusb-1.0.dll beside Blender."


class _Timeval(ctypes.Structure):
    _fields_ = [("tv_sec", ctypes.c_long), ("tv_usec", ctypes.c_long)]


class LibusbIsoPump:
    """Several isochronous IN transfers kept in flight on one endpoint through libusb's async API."""

    def __init__(self, lib, ctx, handle, endpoint: int, transfers: int = DEFAULT_TRANSFERS,
                 packets_per_transfer: int = DEFAULT_PACKETS_PER_TRANSFER,
                 packet_size: int = MAX_ISO_PACKET_SIZE, transfer_module=None):
        if transfer_module is None:
            import usb.backend.libusb1 as transfer_module
        self._m = transfer_module               # provides _libusb_transfer, _get_iso_packet_list, callback type
        self._lib, self._ctx, self._handle = lib, ctx, handle
        self.endpoint = endpoint
        self.n_transfers = transfers
        self.packets_per_transfer = packets_per_transfer
        self.packet_size = packet_size
        self._callback = self._m._libusb_transfer_cb_fn_p(self._on_complete)   # keep: libusb calls it
        self._transfers: list = []
        self._buffers: dict[int, object] = {}   # transfer address -> its buffer
        self._in_flight: set[int] = set()
        self._out: list = []
        self._stopping = False
        self._started = False                   # poll() has run: later submits are resubmits
        self._gone: str | None = None
        self._failure: str | None = None        # a submit failed (not an unplug): poll() raises it
        self.stuck = ""                         # set when stop() could not get every transfer back
        self._prototype()

    def _prototype(self) -> None:
        lib, tp = self._lib, ctypes.POINTER(self._m._libusb_transfer)
        try:   # pyusb leaves these two unprototyped
            lib.libusb_cancel_transfer.argtypes = [tp]
            lib.libusb_handle_events_timeout_completed.argtypes = [
                ctypes.c_void_p, ctypes.POINTER(_Timeval), ctypes.POINTER(ctypes.c_int)]
        except AttributeError:
            pass

    # --- lifecycle ---------------------------------------------------------------------------------------
    def start(self) -> None:
        n, size = self.packets_per_transfer, self.packet_size
        for _ in range(self.n_transfers):
            transfer = self._lib.libusb_alloc_transfer(n)
            if not transfer:
                self.stop()
                raise KinectError("libusb could not allocate an isochronous transfer")
            buf = (ctypes.c_ubyte * (n * size))()
            t = transfer.contents
            t.dev_handle = self._handle
            t.endpoint = self.endpoint
            t.type = TRANSFER_TYPE_ISOCHRONOUS
            t.timeout = 0
            t.buffer = ctypes.cast(buf, ctypes.c_void_p)
            t.length = n * size
            t.num_iso_packets = n
            t.callback = self._callback
            for desc in self._m._get_iso_packet_list(t):
                desc.length = size
            key = ctypes.addressof(t)
            self._transfers.append(transfer)
            self._buffers[key] = buf
            self._submit(transfer, key)
            if self._gone or self._failure:       # libfreenect goes on with fewer; we say why at once
                message = self._gone or self._failure
                self.stop()
                raise (DeviceGone if self._gone else KinectError)(message)

    def _submit(self, transfer, key: int) -> None:
        """Submit (or resubmit, from the callback): never raises, since an exception inside a ctypes
        callback is swallowed and the transfer silently lost; a failure is kept for poll() to report."""
        rc = self._lib.libusb_submit_transfer(transfer)
        if rc == 0:
            self._in_flight.add(key)
        elif rc == LIBUSB_ERROR_NO_DEVICE:
            self._gone = "the Kinect was unplugged"
        elif not self._failure:
            self._failure = submit_failure_advice(rc, resubmit=self._started)

    def poll(self, timeout: float) -> list:
        """Run libusb's event loop up to `timeout` seconds; return the packets completed meanwhile.

        Raises DeviceGone once the device is gone, KinectError when a transfer could not be resubmitted
        (after the packets that came before it have been returned)."""
        self._started = True
        if self._gone:
            raise DeviceGone(self._gone)
        if self._failure:
            raise KinectError(self._failure)
        tv = _Timeval(int(timeout), int((timeout % 1) * 1e6))
        rc = self._lib.libusb_handle_events_timeout_completed(self._ctx, ctypes.byref(tv), None)
        if rc == LIBUSB_ERROR_NO_DEVICE:
            self._gone = "the Kinect was unplugged"
        out, self._out = self._out, []
        if self._gone and not out:
            raise DeviceGone(self._gone)
        if self._failure and not out:
            raise KinectError(self._failure)
        return out

    def stop(self, timeout: float = STOP_WAIT_S) -> bool:
        """Cancel every transfer and wait until libusb has handed each one back, then free them.

        True when all came back. After `timeout` seconds False, with `stuck` saying so: the transfers
        still belong to libusb, so they (and their buffers) are kept alive and must not be freed, and the
        caller must not close the device handle under them."""
        self._stopping = True
        for transfer in self._transfers:
            if ctypes.addressof(transfer.contents) in self._in_flight:
                self._lib.libusb_cancel_transfer(transfer)
        deadline = time.monotonic() + timeout
        while self._in_flight and time.monotonic() < deadline:   # after an unplug too: they come back
            tv = _Timeval(0, 10_000)                                # with NO_DEVICE or CANCELLED
            self._lib.libusb_handle_events_timeout_completed(self._ctx, ctypes.byref(tv), None)
        if self._in_flight:
            self._transfers = [t for t in self._transfers if ctypes.addressof(t.contents) in self._in_flight]
            self.stuck = (f"{len(self._in_flight)} isochronous transfers were not handed back by libusb within "
                          f"{timeout:g} s of being cancelled; the Kinect is left open so that libusb cannot "
                          "write into freed memory. Unplug and replug the Kinect (or restart the program) "
                          "before using it again.")
            return False
        for transfer in self._transfers:
            self._lib.libusb_free_transfer(transfer)
        self._transfers.clear()
        self._buffers.clear()
        return True

    # --- completion callback (runs inside poll) ------------------------------------------------------------
    def _on_complete(self, transfer_p) -> None:
        t = transfer_p.contents
        key = ctypes.addressof(t)
        self._in_flight.discard(key)
        status = t.status
        if status == NO_DEVICE:
            self._gone = "the Kinect was unplugged"
            return
        if status == CANCELLED:
            if not self._stopping:   # nobody asked: libusb on macOS reports an unplug this way
                self._gone = "the Kinect was unplugged (its transfers were cancelled by the system)"
            return
        if self._stopping:
            return
        if status == COMPLETED:
            base = ctypes.addressof(self._buffers[key])
            size, out = self.packet_size, self._out
            for i, desc in enumerate(self._m._get_iso_packet_list(t)):
                if desc.status != COMPLETED:
                    out.append(None)
                elif desc.actual_length:
                    out.append(ctypes.string_at(base + i * size, desc.actual_length))
        else:                          # ERROR, TIMED_OUT, STALL, OVERFLOW: its slots are lost, go on
            self._out.extend([None] * t.num_iso_packets)
        self._submit(transfer_p, key)


def submit_failure_advice(rc: int, resubmit: bool = False) -> str:
    """What a refused isochronous submit means, and what to try."""
    what = "resubmit an isochronous transfer" if resubmit else "start the isochronous depth transfers"
    if rc == LIBUSB_ERROR_IO:
        return (f"libusb could not {what} (LIBUSB_ERROR_IO): the USB controller has no bandwidth left for the "
                "Kinect's depth stream, or (some USB 3 controllers) does not schedule isochronous transfers "
                "for it. Plug the Kinect into another port, on a controller with no other camera or audio "
                "device on it (a USB 2 port, or a USB 2 hub between it and a USB 3 port, often helps).")
    return f"libusb could not {what} (error {rc})"


def open_iso_pump(device, endpoint: int, transfers: int = DEFAULT_TRANSFERS,
                  packets_per_transfer: int = DEFAULT_PACKETS_PER_TRANSFER) -> LibusbIsoPump:
    """An iso pump for a pyusb Device's endpoint, through its backend's libusb (pyusb's libusb1 backend, or
    the emulated Kinect's emulated libusb: the same pump either way)."""
    resources = device._ctx                    # pyusb's resource manager: backend + open handle
    backend = resources.backend
    handle = resources.managed_open()
    lib, ctx = getattr(backend, "lib", None), getattr(backend, "ctx", None)
    if lib is None or not hasattr(lib, "libusb_alloc_transfer"):
        raise KinectError("the depth stream needs pyusb's libusb1 backend (libusb-1.0); "
                          f"this one is {type(backend).__name__}")
    size = lib.libusb_get_max_iso_packet_size(handle.devid, endpoint)
    if size <= 0:
        # libusb only looks at alt setting 0, which has no bandwidth on a Kinect for Windows: use the slot
        # size libfreenect uses (macOS hands packets back in 2048-byte slots).
        size = 2048 if sys.platform == "darwin" else MAX_ISO_PACKET_SIZE
    return LibusbIsoPump(lib, ctx, handle.handle, endpoint, transfers, packets_per_transfer, size)
