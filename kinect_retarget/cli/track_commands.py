"""`python -m kinect_retarget track DEPTH.npz --out TAKE`: Kinect v1 depth captures -> skeleton takes.

Input: a capture .npz (`mm` (F, 480, 640) uint16 millimetres and/or `raw` 11-bit; `timestamp` device ticks
at 60 MHz or `times` seconds; optional `gravity` (3,)), or `--replay DUMP` (a packet dump decoded through the
USB driver's reassembly). Output: a .krtake of Kinect v1 joints, states and times.
"""
from __future__ import annotations

import os
import sys

import numpy as np

from ..core.take import TakeError
from ..device.capture_file import load_capture, times_from


def add_parsers(subparsers) -> None:
    p = subparsers.add_parser("track", help="track skeletons in captured Kinect v1 depth and write a take",
                              description=__doc__.split("\n\n")[1])
    p.add_argument("depth", nargs="?", help="capture .npz (from `capture` or the synthetic renderer)")
    p.add_argument("--replay", metavar="DUMP", help="decode a USB packet dump instead of an .npz")
    p.add_argument("--out", required=True, help="take to write (.krtake)")
    p.add_argument("--gravity", metavar="GX,GY,GZ", help="accelerometer vector in camera space (default: level)")
    p.add_argument("--focal", type=float, default=575.0, help="depth focal length in pixels (default 575)")
    p.add_argument("--raw-joints", action="store_true", help="write the joints before the tracker's own "
                   "smoothing (steadied like the Kinect SDK's by default; docs/depth_tracking.md, step 14)")
    p.add_argument("--live-smoothing", action="store_true", help="write the joints as the live tracker "
                   "reports them: without the recorded take's cleanup with its future frames (step 15)")
    p.set_defaults(handler=run_track)


def load_replay(path: str):
    from ..device.decode import decode_frame
    from ..device.disparity_calibration import Calibration
    from ..device.dump import replay_dump
    frames, _, err = replay_dump(path)
    if err is not None:
        print(f"warning: {err} (tracking the {len(frames)} frames before it)", file=sys.stderr)
    if not frames:
        raise TakeError(f"{path}: the dump holds no complete depth frame")
    cal = Calibration()
    lut = cal.raw_to_mm_table()
    mm = np.stack([decode_frame(f, lut)[1] for f in frames])   # as capture and live decode them
    ticks = np.array([f.timestamp for f in frames], dtype=np.int64)
    return mm, times_from({"timestamp": ticks}, len(frames), path), None


def run_track(args) -> int:
    from ..depth.depth_camera import DepthCamera
    from ..depth.skeleton_tracker import TrackerSettings, track_depth_frames
    from ..takes import krtake
    if bool(args.depth) == bool(args.replay):
        raise TakeError("give either a capture .npz or --replay DUMP")
    src = args.replay or args.depth
    if not os.path.exists(src):
        raise TakeError(f"{src}: no such file")
    mm, times, gravity = load_replay(src) if args.replay else load_capture(src)
    if args.gravity:
        try:
            gravity = np.array([float(v) for v in args.gravity.split(",")])
        except ValueError:
            raise TakeError(f"--gravity {args.gravity!r}: expected three numbers like 0,-9.8,0") from None
        if gravity.shape != (3,) or not np.all(np.isfinite(gravity)) or not np.linalg.norm(gravity) > 0:
            raise TakeError(f"--gravity {args.gravity!r}: expected a non-zero vector of three numbers")
    def progress(i, n):
        if sys.stderr.isatty() and (i % 30 == 0 or i == n):
            print(f"\rtracking {i}/{n}", end="" if i < n else "\n", file=sys.stderr)
    settings = TrackerSettings(steady_output=not args.raw_joints)
    take = track_depth_frames(mm, times, DepthCamera(f=args.focal), gravity, settings, progress=progress,
                              cleanup=not args.live_smoothing)
    krtake.write(args.out, take)
    found = float(np.mean(take.any_tracked))
    print(f"{args.out}: {take.frame_count} frames, skeleton in {found * 100:.0f} % of them, "
          f"calibrated height {take.metadata.get('calibrated_height_m', 0):.2f} m")
    return 0
