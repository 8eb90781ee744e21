"""Device commands of `python -m kinect_retarget`: `devices`, `capture`, `tilt`, `led`, `accel` (plain
Python; no Blender needed). `--simulate` runs any of them against the emulated Kinect instead of USB hardware.

Exit codes follow the rest of the CLI: 2 for bad input (arguments, a missing or damaged file), 1 when the
device fails (none found, no permission, unplugged, libusb missing, nothing captured). Errors are raised and
cli.main prints them and picks the code; only a capture that saved frames before failing returns its code.
"""
from __future__ import annotations

import json
import queue
import sys
import time

from ..device.capture_file import calibration_from, save_capture
from ..device.decode import decode_frame
from ..device.disparity_calibration import Calibration
from ..device.errors import KinectError
from ..device.protocol import TICKS_PER_FRAME, TIMESTAMP_HZ, ticks_between

SIMULATE_HELP = "use the emulated Kinect instead of USB hardware"
BAD_INPUT, DEVICE_FAILURE = 2, 1


def add_parsers(sub) -> None:
    p = sub.add_parser("devices", help="list connected Kinects and what keeps them from working")
    p.add_argument("--udev-rule", action="store_true", help="print the Linux udev rule (and how to install it)")
    p.add_argument("--json", action="store_true", help="one JSON object per Kinect")
    p.add_argument("--diagnose", action="store_true",
                   help="report for a bug report: what is on each bus, what was tried and what answered "
                        "(opens each Kinect and streams for up to 3 s)")
    _add_simulate(p)
    p.set_defaults(handler=run_devices)

    p = sub.add_parser("capture", help="record depth frames to an .npz (raw, mm, timestamp, calibration)")
    src = p.add_mutually_exclusive_group()
    src.add_argument("--simulate", action="store_true", help=SIMULATE_HELP)
    src.add_argument("--replay", metavar="DUMP", help="decode a packet dump offline instead of streaming")
    p.add_argument("--simulate-from", metavar="DIR", help="fakenect recording (d-*.pgm) for --simulate")
    p.add_argument("--seconds", type=float, default=5.0,
                   help="how much to record, in the Kinect's own time: 30 frames a second (default 5)")
    p.add_argument("--out", required=True, metavar="DEPTH.npz")
    p.add_argument("--dump", metavar="DUMP", help="also write every isochronous packet as received")
    p.add_argument("--calibration", metavar="DEPTH.npz",
                   help="with --replay: take the calibration from an earlier capture of the same Kinect")
    p.add_argument("--serial", help="which Kinect, when several are plugged in")
    p.add_argument("--wait", type=float, default=10.0, metavar="S",
                   help="give up if streaming has not started after S seconds, or stop (keeping what was "
                        "captured) when no frame came for S seconds (default 10)")
    p.set_defaults(handler=run_capture)

    p = sub.add_parser("tilt", help="tilt the Kinect (degrees from the horizon, -27..27)")
    p.add_argument("--angle", type=float, required=True)
    _add_simulate(p)
    p.set_defaults(handler=run_tilt)

    p = sub.add_parser("led", help="set the Kinect's LED")
    p.add_argument("mode", choices=["green", "red", "yellow", "blink", "off"])
    _add_simulate(p)
    p.set_defaults(handler=run_led)

    p = sub.add_parser("accel", help="print the accelerometer (gravity, in g) and the tilt angle")
    _add_simulate(p)
    p.set_defaults(handler=run_accel)


def _add_simulate(p) -> None:
    p.add_argument("--simulate", action="store_true", help=SIMULATE_HELP)
    p.add_argument("--serial", help="which Kinect, when several are plugged in")


def _backend(args):
    """The emulated Kinect for --simulate, else None (pyusb's libusb1 backend)."""
    if not getattr(args, "simulate", False):
        return None
    from ..sources.simulated_kinect import emulated_kinect
    return emulated_kinect(fakenect_dir=getattr(args, "simulate_from", None))


# --- devices ---------------------------------------------------------------------------------------------------
def run_devices(args) -> int:
    from ..device.discovery import UDEV_RULES, UDEV_RULES_PATH, list_devices, udev_rule_install_command
    if args.udev_rule:
        print(f"# {UDEV_RULES_PATH}\n{UDEV_RULES}\n# install it with:\n{udev_rule_install_command()}")
        return 0
    if args.diagnose:
        from ..device.diagnosis import diagnose
        print(diagnose(_backend(args)))
        return 0
    kinects = list_devices(_backend(args))
    if args.json:
        for k in kinects:
            print(json.dumps({"model": k.model, "serial": k.serial, "bus": k.bus, "address": k.address,
                              "camera_available": k.camera_available, "motor_available": k.motor_available,
                              "motor_note": k.motor_note, "problem": k.problem}))
    elif not kinects:
        print("no Kinect found (is it plugged in and powered by its own adapter?)")
    else:
        print("\n".join(k.describe() for k in kinects))
    return 0


# --- capture ---------------------------------------------------------------------------------------------------
def _capture_replay(args) -> int:
    from ..device.dump import replay_dump
    frames, assembler, error = replay_dump(args.replay)
    if error is not None and not frames:
        raise error                    # nothing decoded (not a dump at all?): write no empty file
    # a dump holds packets only: the calibration comes from an earlier capture, else typical values
    calibration = calibration_from(args.calibration) if args.calibration else Calibration()
    lut = calibration.raw_to_mm_table()
    raws, mms = zip(*(decode_frame(f, lut) for f in frames)) if frames else ((), ())
    save_capture(args.out, list(raws), list(mms), [f.timestamp for f in frames], [f.lost_packets for f in frames],
          calibration)
    s = assembler.stats
    print(f"{len(frames)} frames decoded from {args.replay} ({s.packets_lost} packets lost, "
          f"{s.frames_missed} frames dropped) -> {args.out}")
    if error is not None:              # a damaged input file, even though what it held was saved
        print(f"warning: {error}; the frames before it were kept", file=sys.stderr)
        return BAD_INPUT
    return 0


def run_capture(args) -> int:
    if args.seconds <= 0 and not args.replay:
        raise ValueError("--seconds must be positive")
    if args.wait < 0:
        raise ValueError("--wait must not be negative")
    if args.simulate_from and not args.simulate:
        raise ValueError("--simulate-from only applies to --simulate")
    if args.calibration and not args.replay:
        raise ValueError("--calibration only applies to --replay (a live capture reads the device's)")
    if args.replay:
        return _capture_replay(args)
    return _capture_live(args)


def _frame_ticks(timestamp: int, previous: int | None) -> int:
    """Device time a new frame adds to a capture: the step from the previous frame (frames the device
    dropped count too), or one frame period for the first frame and the first after a reconnect."""
    step = ticks_between(previous, timestamp) if previous is not None else TICKS_PER_FRAME
    return step if 0 < step <= TIMESTAMP_HZ else TICKS_PER_FRAME


def _capture_live(args) -> int:
    from ..device.depth_stream import STREAMING, DepthStream
    from ..device.dump import DumpWriter
    backend = _backend(args)
    dump = DumpWriter(args.dump) if args.dump else None
    stream = DepthStream(backend, serial=args.serial, queue_size=64,
                         packet_hook=dump.write_packets if dump else None)
    raws, mms, stamps, lost = [], [], [], []
    calibration = Calibration()
    last_message, started, stalled = "", None, None
    # the length counts device time (frame timestamps), so a busy computer still records all of it
    wanted, recorded = round(args.seconds * TIMESTAMP_HZ), 0
    asked = progress = time.monotonic()
    stream.start()
    try:
        while recorded < wanted:
            status = stream.status
            if status.message != last_message:
                print(f"[{status.state}] {status.message}", file=sys.stderr)
                last_message = status.message
            if started is None and status.state == STREAMING:
                started = progress = time.monotonic()
            if started is None and (status.state == "error" or time.monotonic() - asked > args.wait):
                break
            if started is not None and time.monotonic() - progress > args.wait:
                stalled = f"no frame for {args.wait:g} s ({last_message})"
                break
            try:
                frame = stream.frames.get(timeout=0.05)
            except queue.Empty:
                continue
            recorded += _frame_ticks(frame.timestamp, stamps[-1] if stamps else None)
            progress = time.monotonic()
            raws.append(frame.raw)
            mms.append(frame.mm)
            stamps.append(frame.timestamp)
            lost.append(frame.lost_packets)
            calibration = frame.calibration
    except KeyboardInterrupt:
        print("interrupted: saving what was captured", file=sys.stderr)
    finally:
        stream.stop()
        if dump:
            dump.close()
    status = stream.status
    if not raws:
        raise KinectError(f"no depth frame was captured ({last_message}); nothing written")
    save_capture(args.out, raws, mms, stamps, lost, calibration)
    print(f"{len(raws)} frames -> {args.out} (dropped {status.frames_dropped}, "
          f"packets lost {status.packets_lost})" + (f"; packets -> {args.dump}" if dump else ""))
    if stalled:                        # a device failure, even though what came before it was saved
        print(f"error: {stalled}: {recorded / TIMESTAMP_HZ:.2f} of {args.seconds:g} s captured and saved",
              file=sys.stderr)
        return DEVICE_FAILURE
    return 0


# --- motor ---------------------------------------------------------------------------------------------------
def _motor(args):
    from ..device.motor import open_motor
    return open_motor(_backend(args), args.serial)


def run_tilt(args) -> int:
    sent = _motor(args).set_tilt(args.angle)
    print(f"tilting to {sent:g} degrees" + (" (clamped to the ±27 degree range)" if sent != args.angle else ""))
    return 0


def run_led(args) -> int:
    _motor(args).set_led(args.mode)
    print(f"LED {args.mode}")
    return 0


def run_accel(args) -> int:
    state = _motor(args).state()
    x, y, z = state.accel_g
    tilt = "unknown" if state.tilt_deg is None else f"{state.tilt_deg:g} degrees"
    print(f"accelerometer (g): x {x:+.3f}  y {y:+.3f}  z {z:+.3f}\ntilt: {tilt} ({state.status})")
    return 0
