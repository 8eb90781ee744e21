"""`lift`: 2D joint tracks from a single video -> a take; `track-2d`: the paper's joint tracker on frames."""
from __future__ import annotations

import json
import os
import sys


def add_parsers(sub) -> None:
    p = sub.add_parser("lift", help="lift 2D joint tracks (OpenPose, COCO, Blender clip tracks) to a 3D take")
    p.add_argument("input", help="OpenPose keypoint folder, COCO keypoints .json, or .blend with a tracked clip")
    p.add_argument("--format", choices=("auto", "openpose", "coco", "clip"), default="auto")
    p.add_argument("--out", required=True, help="output take (.krtake)")
    p.add_argument("--focal", type=float, help="camera focal length in pixels (default: unknown, "
                                               "scaled orthographic; clips use their camera settings)")
    p.add_argument("--image-size", type=float, nargs=2, metavar=("W", "H"), help="video size in pixels")
    p.add_argument("--height", type=float, default=None,
                   help="performer's height in metres (bone lengths; default 1.70, or the --calibrate take's)")
    p.add_argument("--calibrate", metavar="TAKE", help="take of the same performer to measure bone lengths")
    p.add_argument("--fps", type=float, default=30.0, help="video frame rate (keypoint files carry none)")
    p.add_argument("--clip", help="Movie Clip name in the .blend (default: the only clip)")
    p.add_argument("--signs", choices=("viterbi", "greedy", "camera"), default="viterbi",
                   help="depth-sign choice: whole take (viterbi), causal (greedy), or none (camera)")
    p.add_argument("--method", choices=("ours", "paper"), default="ours",
                   help="ours (default), or paper 004 as published: scaled orthographic camera, eq. 3 scale, "
                        "dz = +-sqrt(L^2 - d^2/s^2) with signs by continuity, no smoothing (docs/lifting.md)")
    p.add_argument("--hanim", metavar="BLEND", help="also write a .blend holding the paper's output: a "
                                                    "16-joint H-Anim armature keyed with IK Euler angles")
    p.set_defaults(handler=run_lift)

    p = sub.add_parser("track-2d", help="track joints through an image sequence (paper 004 §2): particle "
                                        "filter + colour-histogram match; writes OpenPose keypoint files")
    p.add_argument("frames", help="folder of frames (.ppm/.pgm/.npy; PNG/JPEG through Blender's loader)")
    p.add_argument("--init", required=True, help="JSON {joint name: [u, v]} marking the joints on frame 1")
    p.add_argument("--out", required=True, help="output folder for <name>_<frame>_keypoints.json")
    p.add_argument("--particles", type=int, default=150)
    p.add_argument("--patch", type=int, default=15, help="template half-size in pixels")
    p.add_argument("--seed", type=int, default=0)
    p.set_defaults(handler=run_track_2d)


def run_lift(args) -> int:
    if args.method == "paper" and args.signs != "viterbi":
        raise ValueError("--signs chooses among our sign solvers; --method paper has its own (continuity)")
    if args.method == "paper" and args.focal is not None:
        raise ValueError("--focal: --method paper uses the scaled orthographic camera of the paper (eq. 1), "
                         "which has no focal length")
    if args.hanim and not args.hanim.lower().endswith(".blend"):
        raise ValueError(f"--hanim {args.hanim}: the output must be a .blend file")
    from ..lift import LiftSettings, detect_2d_format, lift, read_2d
    from ..lift.bones import DEFAULT_HEIGHT_M, lengths_from_take, lengths_scaled_to_height
    from ..takes import krtake, load_take

    fmt = detect_2d_format(args.input) if args.format == "auto" else args.format
    size = tuple(args.image_size) if args.image_size else None
    focal = args.focal
    if fmt == "clip":
        from ..blender.clip_lift import tracks_from_blend
        tracks, clip_focal = tracks_from_blend(args.input, args.clip)
        focal = focal or clip_focal
    else:
        tracks = read_2d(args.input, fmt, args.fps, size)
    lengths = None
    if args.calibrate:
        lengths = lengths_from_take(load_take(args.calibrate))
        if args.height is not None:  # an explicit height rescales the calibrated proportions
            lengths = lengths_scaled_to_height(lengths, args.height)
    res = lift(tracks, LiftSettings(height_m=args.height or DEFAULT_HEIGHT_M, lengths=lengths, focal_px=focal,
                                    image_size=size, signs=args.signs, method=args.method))
    res.take.metadata["name"] = os.path.splitext(os.path.basename(os.path.normpath(args.out)))[0]
    krtake.write(args.out, res.take)
    for msg in res.problems:
        print(f"warning: {msg}", file=sys.stderr)
    summary = {"out": args.out, "method": args.method, "frames": res.take.frame_count, "rate": res.take.rate,
               "frames_with_body": int(res.take.any_tracked.sum()), "focal_px": res.camera.focal_px,
               "focal_known": res.camera.focal_known, "problems": len(res.problems)}
    if args.hanim:
        from ..blender.io.hanim_figure import hanim_to_file
        summary.update(hanim_to_file(res.take, args.hanim))
    print(json.dumps(summary))
    return 0


def run_track_2d(args) -> int:
    from ..lift.image_sequence import NATIVE, list_frames, load_frame
    from ..lift.joint_tracker import JointTracker, TrackerSettings, read_init, write_keypoints

    paths = list_frames(args.frames)
    loader = load_frame
    if any(not p.lower().endswith(NATIVE) for p in paths):
        from ..blender.clip_lift import load_image_rgb
        loader = load_image_rgb
    init = read_init(args.init)
    first = loader(paths[0])
    tracker = JointTracker(first, init, TrackerSettings(particles=args.particles, half=args.patch,
                                                        seed=args.seed))
    results = [tracker.initial()]
    for p in paths[1:]:
        results.append(tracker.step(loader(p)))
    written = write_keypoints(args.out, paths, results, tracker.names)
    lost = sum(int((~r.found).sum()) for r in results)
    print(json.dumps({"out": args.out, "frames": len(paths), "files": written, "joints": list(tracker.names),
                      "lost_joint_frames": lost}))
    return 0


__all__ = ["add_parsers"]
